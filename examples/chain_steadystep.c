/* A chain as ODE programs write one: ten capsule links on ball joints, hanging from a fixed point, the last link
 * pushed sideways by a force the program adds every frame. The world's CFM is tuned (1e-5, a usual choice), its ERP is
 * ODE's default, bodies are damped per step, and the links collide with the ground. This is chain_ode.c adopted with
 * steadystep: the lines marked "steadystep" take over what it tuned, run its per-frame logic before every physics step
 * at that step's time, and the stepper steps each frame.
 *
 *   chain_steadystep --policy implicit-euler --profile uniform:15:45 --duration 10 > run.csv      (t_s,end_x_m,end_z_m)
 *
 * Followed: the free end of the last link, its x (the push's direction) and its height z. */
#include <math.h>
#include <stdio.h>

#include <ode/ode.h>

#include <steadystep/steadystep.h> /* steadystep */

#include "example_cli.h"

#define PROGRAM "chain_steadystep"

#define LINK_COUNT 10
#define MAX_CONTACTS 4

static const double link_length = 0.25, link_radius = 0.04, link_mass = 0.3; /* m, m, kg */
static const double anchor_z = 3.0;                                           /* m */

static dWorldID world;
static dSpaceID space;
static dJointGroupID contacts;
static dBodyID links[LINK_COUNT];

static void nearCallback(void* data, dGeomID g1, dGeomID g2) {
  dBodyID b1 = dGeomGetBody(g1), b2 = dGeomGetBody(g2);
  if (b1 != 0 && b2 != 0) return; /* links touch the ground only */
  dContact contact[MAX_CONTACTS];
  int count = dCollide(g1, g2, MAX_CONTACTS, &contact[0].geom, sizeof(dContact));
  for (int i = 0; i < count; ++i) {
    contact[i].surface.mode = dContactSoftCFM | dContactApprox1; /* soft CFM only: ERP is the world's */
    contact[i].surface.mu = 0.4;
    contact[i].surface.soft_cfm = 1e-3;
    ssStepper_SoftenContact(data, &contact[i], b1, b2); /* steadystep: data is the stepper */
    dJointID joint = dJointCreateContact(world, contacts, &contact[i]);
    dJointAttach(joint, b1, b2);
  }
}

static void collide(void* context, ssStepper* stepper) { /* steadystep: before each step */
  (void)context;
  dSpaceCollide(space, stepper, nearCallback);
}

static void build(void) {
  world = dWorldCreate();
  space = dSimpleSpaceCreate(0);
  contacts = dJointGroupCreate(0);
  dWorldSetGravity(world, 0, 0, -9.81);
  dWorldSetCFM(world, 1e-5);
  dWorldSetQuickStepNumIterations(world, 50);
  dWorldSetLinearDamping(world, 0.002); /* per step, tuned at 60 fps; copied into bodies created from here on */
  dWorldSetAngularDamping(world, 0.01);
  dCreatePlane(space, 0, 0, 1, 0);

  dMass mass;
  dMassSetCapsuleTotal(&mass, link_mass, 3, link_radius, link_length - 2 * link_radius);
  for (int i = 0; i < LINK_COUNT; ++i) {
    links[i] = dBodyCreate(world);
    dBodySetPosition(links[i], 0, 0, anchor_z - (i + 0.5) * link_length);
    dBodySetMass(links[i], &mass);
    dGeomSetBody(dCreateCapsule(space, link_radius, link_length - 2 * link_radius), links[i]);
    dJointID ball = dJointCreateBall(world, 0);
    dJointAttach(ball, links[i], i == 0 ? 0 : links[i - 1]); /* the first hangs from the static world */
    dJointSetBallAnchor(ball, 0, 0, anchor_z - i * link_length);
  }
}

/* The push on the last link: two slow sideways oscillations (N), from the clock. */
static void push(double time_s) {
  dBodyAddForce(links[LINK_COUNT - 1], 1.0 * sin(2 * M_PI * time_s / 2.5), 0.4 * sin(2 * M_PI * time_s / 3.7), 0);
}

/* steadystep: the program's per-step logic (the push on the last link) runs before every physics step, at that step's simulated
 * time: run once a frame, it would make the motion depend on the frame rate under every policy. */
static void beforeStep(void* context, ssStepper* stepper) {
  (void)context;
  push(ssStepper_CurrentStep(stepper).time_s);
}

static int record(const ExampleFlags* flags, double time_s) {
  dVector3 end;
  dBodyGetRelPointPos(links[LINK_COUNT - 1], 0, 0, -link_length / 2, end);
  double values[2] = {end[0], end[2]};
  return exampleRow(flags, time_s, 2, values);
}

int main(int argc, char** argv) {
  ExampleFlags flags;
  int parsed = exampleParseFlags(PROGRAM, argc, argv, EXAMPLE_FLAGS_STEPPER, &flags);
  if (parsed != 0) return parsed < 0 ? 0 : parsed;
  /* naive freezes the softness at the step the numbers were tuned for: the program's own stepping */
  ssStepping stepping = ssDefaultStepping();
  stepping.max_step_s = flags.max_step_s;
  stepping.solver = SS_SOLVER_QUICK; /* steadystep: the ODE step this program calls */
  if (ssSteppingForPolicy(flags.policy, 1.0 / 60, &stepping) != SS_OK)
    return exampleRefuse(&flags, PROGRAM, "--policy", flags.policy, ssLastError());
  dInitODE2(0);
  build();
  /* steadystep: the stepper adopts the world and all the space reaches, as the program tuned them at 60 fps */
  ssStepperDef def = ssDefaultStepperDef();
  def.world = world;
  def.space = space;
  def.tuned_step_s = 1.0 / 60;
  def.stepping = stepping;
  def.before_step = beforeStep;
  def.collide = collide;
  def.contact_group = contacts;
  ssStepper* stepper = NULL;
  if (ssStepper_Create(&def, &stepper) != SS_OK) {
    fprintf(stderr, PROGRAM ": %s\n", ssLastError());
    return 1;
  }

  exampleHeader(&flags, "t_s,end_x_m,end_z_m");
  record(&flags, 0);
  int code = 0;
  ExampleClock started = exampleClock();
  for (double time_s = 0; time_s < flags.duration_s - 1e-12;) {
    double frame_s = fmin(ssProfile_Next(flags.frames), flags.duration_s - time_s);
    ssFrameReport report;
    if (ssStepper_Step(stepper, frame_s, &report) != SS_OK) { /* steadystep: a failed stepper refuses later frames */
      fprintf(stderr, PROGRAM ": t = %.6g s: %s\n", time_s, ssLastError());
      code = 1;
      break;
    }
    time_s = report.time_s; /* the stepper's clock: under fixed, part of a frame may wait for the next one */
    if (!record(&flags, time_s)) {
      fprintf(stderr, PROGRAM ": t = %.6g s: the chain's state is not finite\n", time_s);
      code = 1;
      break;
    }
  }
  exampleFinish(&flags, started);

  ssStepper_Destroy(stepper);
  dJointGroupDestroy(contacts);
  dSpaceDestroy(space);
  dWorldDestroy(world);
  dCloseODE();
  return code;
}

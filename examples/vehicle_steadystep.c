/* A car as ODE programs write one: a box chassis on four sphere wheels, each on a hinge-2 joint whose axis 1 is the
 * steering and suspension axis and axis 2 the wheel's spin. The rear wheels are driven by their axis-2 motors, the
 * front wheels steered by their axis-1 motors, and air drag is added to the chassis every frame. It drives over a
 * ground plane and a row of speed bumps. Its ERP/CFM numbers were tuned at 60 fps. This is vehicle_ode.c adopted with
 * steadystep: the lines marked "steadystep" take over what it tuned, run its per-frame logic before every physics step
 * at that step's time, and the stepper steps each frame.
 *
 *   vehicle_steadystep --policy implicit-euler --profile uniform:15:45 --duration 10 > run.csv      (t_s,height_m,pitch_rad)
 *
 * Followed: the chassis' height above the ground and its pitch (nose up > 0). */
#include <math.h>
#include <stdio.h>

#include <ode/ode.h>

#include <steadystep/steadystep.h> /* steadystep */

#include "example_cli.h"

#define PROGRAM "vehicle_steadystep"

#define WHEEL_COUNT 4
#define BUMP_COUNT 6
#define MAX_CONTACTS 4

static const double chassis_size[3] = {3.0, 1.5, 0.4}; /* m */
static const double chassis_mass = 900;                /* kg */
static const double wheel_radius = 0.34, wheel_mass = 20;
static const double bump_x[BUMP_COUNT] = {5, 12, 20, 30, 42, 55}; /* m along the road */

static dWorldID world;
static dSpaceID space;
static dJointGroupID contacts;
static dBodyID chassis;
static dBodyID wheels[WHEEL_COUNT]; /* front left, front right, rear left, rear right */
static dJointID hinges[WHEEL_COUNT];

static void nearCallback(void* data, dGeomID g1, dGeomID g2) {
  dBodyID b1 = dGeomGetBody(g1), b2 = dGeomGetBody(g2);
  if (b1 != 0 && b2 != 0) return; /* the car's own parts do not touch each other */
  dContact contact[MAX_CONTACTS];
  int count = dCollide(g1, g2, MAX_CONTACTS, &contact[0].geom, sizeof(dContact));
  for (int i = 0; i < count; ++i) {
    contact[i].surface.mode = dContactSoftERP | dContactSoftCFM | dContactApprox1;
    contact[i].surface.mu = 1.0;
    contact[i].surface.soft_erp = 0.5; /* tyres: tuned at 60 fps */
    contact[i].surface.soft_cfm = 1e-4;
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
  space = dHashSpaceCreate(0);
  contacts = dJointGroupCreate(0);
  dWorldSetGravity(world, 0, 0, -9.81);
  dWorldSetQuickStepNumIterations(world, 30);
  dCreatePlane(space, 0, 0, 1, 0);
  dMatrix3 across; /* a capsule's axis is its z: turn it to lie across the road */
  dRFromAxisAndAngle(across, 1, 0, 0, M_PI / 2);
  for (int i = 0; i < BUMP_COUNT; ++i) {
    dGeomID bump = dCreateCapsule(space, 0.08, 40);
    dGeomSetPosition(bump, bump_x[i], 0, 0);
    dGeomSetRotation(bump, across);
  }

  dMass mass;
  chassis = dBodyCreate(world);
  dBodySetPosition(chassis, 0, 0, 0.6);
  dMassSetBoxTotal(&mass, chassis_mass, chassis_size[0], chassis_size[1], chassis_size[2]);
  dBodySetMass(chassis, &mass);
  dGeomSetBody(dCreateBox(space, chassis_size[0], chassis_size[1], chassis_size[2]), chassis);

  const dReal up[3] = {0, 0, 1}, spin[3] = {0, 1, 0};
  for (int i = 0; i < WHEEL_COUNT; ++i) {
    double x = i < 2 ? 1.2 : -1.2, y = i % 2 == 0 ? 0.85 : -0.85;
    wheels[i] = dBodyCreate(world);
    dBodySetPosition(wheels[i], x, y, 0.42);
    dMassSetSphereTotal(&mass, wheel_mass, wheel_radius);
    dBodySetMass(wheels[i], &mass);
    dGeomSetBody(dCreateSphere(space, wheel_radius), wheels[i]);
    hinges[i] = dJointCreateHinge2(world, 0);
    dJointAttach(hinges[i], chassis, wheels[i]);
    dJointSetHinge2Anchor(hinges[i], x, y, 0.42);
    dJointSetHinge2Axes(hinges[i], up, spin);
    dJointSetHinge2Param(hinges[i], dParamSuspensionERP, 0.16); /* tuned at 60 fps: a soft, damped ride */
    dJointSetHinge2Param(hinges[i], dParamSuspensionCFM, 4.5e-4);
    dJointSetHinge2Param(hinges[i], dParamLoStop, i < 2 ? -0.5 : 0); /* rear wheels do not steer */
    dJointSetHinge2Param(hinges[i], dParamHiStop, i < 2 ? 0.5 : 0);
  }
}

/* The input: throttle (a speed target for the rear motors), steering and air drag, from the clock. */
static void drive(double time_s) {
  double speed = fmin(1.5 * time_s, 9.0); /* m/s */
  double steer = 0.12 * sin(2 * M_PI * time_s / 4.0);
  for (int i = 0; i < WHEEL_COUNT; ++i) {
    if (i >= 2) {
      dJointSetHinge2Param(hinges[i], dParamVel2, -speed / wheel_radius); /* axis 2 points left: forward is negative */
      dJointSetHinge2Param(hinges[i], dParamFMax2, 300);
    } else {
      double turn = 8.0 * (steer - dJointGetHinge2Angle1(hinges[i]));
      dJointSetHinge2Param(hinges[i], dParamVel, fmax(-2.0, fmin(2.0, turn)));
      dJointSetHinge2Param(hinges[i], dParamFMax, 800);
    }
  }
  const dReal* v = dBodyGetLinearVel(chassis);
  double drag = 0.8 * sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); /* N per m/s */
  dBodyAddForce(chassis, -drag * v[0], -drag * v[1], -drag * v[2]);
}

/* Height (m) and pitch (rad, nose up > 0): the chassis' forward axis is the first column of its rotation. */
/* steadystep: the program's per-step logic (throttle, steering and drag) runs before every physics step, at that step's simulated
 * time: run once a frame, it would make the motion depend on the frame rate under every policy. */
static void beforeStep(void* context, ssStepper* stepper) {
  (void)context;
  drive(ssStepper_CurrentStep(stepper).time_s);
}

static int record(const ExampleFlags* flags, double time_s) {
  const dReal* r = dBodyGetRotation(chassis);
  double values[2] = {dBodyGetPosition(chassis)[2], atan2(r[8], hypot(r[0], r[4]))};
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

  exampleHeader(&flags, "t_s,height_m,pitch_rad");
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
      fprintf(stderr, PROGRAM ": t = %.6g s: the chassis' state is not finite\n", time_s);
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

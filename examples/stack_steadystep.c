/* A stack of boxes as ODE programs write one: towers of up to eight 1 kg boxes on the ground, contacts softened by a
 * soft CFM alone (their ERP is the world's, ODE's default), contact feedback on every ground contact to read the load
 * the ground carries, body damping and auto-disable counted in steps, and the top box of the first tower nudged back
 * and forth by a force added every frame for the first three seconds. The world's ERP/CFM are ODE's defaults. This is
 * stack_ode.c adopted with steadystep: the lines marked "steadystep" take over what it tuned, run its per-frame logic
 * before every physics step at that step's time, and the stepper steps each frame.
 *
 *   stack_steadystep --policy implicit-euler --profile uniform:15:45 [--boxes 8] > run.csv      (t_s,top_z_m,ground_force_N)
 *
 * Followed: the height of the first tower's top box and the total normal force of the ground on the boxes. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <ode/ode.h>

#include <steadystep/steadystep.h> /* steadystep */

#include "example_cli.h"

#define PROGRAM "stack_steadystep"

#define TOWER_HEIGHT 8
#define MAX_CONTACTS 4

static const double box_side = 0.4, box_mass = 1.0, tower_spacing = 1.0; /* m, kg, m */

static dWorldID world;
static dSpaceID space;
static dGeomID ground;
static dJointGroupID contacts;
static int box_count;
static dBodyID* boxes;
/* Ground contacts of the current step: their feedback, and whether the box is the joint's first body. */
static dJointFeedback* ground_feedback;
static int* box_is_first;
static int ground_contact_count;

static void nearCallback(void* data, dGeomID g1, dGeomID g2) {
  dBodyID b1 = dGeomGetBody(g1), b2 = dGeomGetBody(g2);
  if ((b1 == 0 || !dBodyIsEnabled(b1)) && (b2 == 0 || !dBodyIsEnabled(b2))) return; /* asleep against asleep */
  dContact contact[MAX_CONTACTS];
  int count = dCollide(g1, g2, MAX_CONTACTS, &contact[0].geom, sizeof(dContact));
  for (int i = 0; i < count; ++i) {
    contact[i].surface.mode = dContactSoftCFM | dContactApprox1;
    contact[i].surface.mu = 0.8;
    contact[i].surface.soft_cfm = 1e-4; /* tuned at 60 fps */
    ssStepper_SoftenContact(data, &contact[i], b1, b2); /* steadystep: data is the stepper */
    dJointID joint = dJointCreateContact(world, contacts, &contact[i]);
    dJointAttach(joint, b1, b2);
    if ((g1 == ground || g2 == ground) && ground_contact_count < box_count * MAX_CONTACTS) {
      box_is_first[ground_contact_count] = g2 == ground;
      dJointSetFeedback(joint, &ground_feedback[ground_contact_count++]);
    }
  }
}

static void collide(void* context, ssStepper* stepper) { /* steadystep: before each step */
  (void)context;
  ground_contact_count = 0;
  dSpaceCollide(space, stepper, nearCallback);
}

static void build(void) {
  world = dWorldCreate();
  space = dHashSpaceCreate(0);
  contacts = dJointGroupCreate(0);
  dWorldSetGravity(world, 0, 0, -9.81);
  dWorldSetQuickStepNumIterations(world, 40);
  dWorldSetContactSurfaceLayer(world, 0.001);
  dWorldSetLinearDamping(world, 0.001); /* per step, tuned at 60 fps */
  dWorldSetAngularDamping(world, 0.005);
  dWorldSetAutoDisableFlag(world, 1);
  dWorldSetAutoDisableSteps(world, 20); /* idle for 20 steps, speeds averaged over 5 */
  dWorldSetAutoDisableAverageSamplesCount(world, 5);
  ground = dCreatePlane(space, 0, 0, 1, 0);

  int towers = (box_count + TOWER_HEIGHT - 1) / TOWER_HEIGHT;
  int columns = (int)ceil(sqrt((double)towers));
  dMass mass;
  dMassSetBoxTotal(&mass, box_mass, box_side, box_side, box_side);
  for (int i = 0; i < box_count; ++i) {
    int tower = i / TOWER_HEIGHT, level = i % TOWER_HEIGHT;
    boxes[i] = dBodyCreate(world);
    dBodySetPosition(boxes[i], tower % columns * tower_spacing, tower / columns * tower_spacing,
                     box_side / 2 + level * (box_side + 0.001));
    dBodySetMass(boxes[i], &mass);
    dGeomSetBody(dCreateBox(space, box_side, box_side, box_side), boxes[i]);
  }
}

/* The nudge on the first tower's top box (N), from the clock. */
static void nudge(double time_s) {
  dBodyID top = boxes[(box_count < TOWER_HEIGHT ? box_count : TOWER_HEIGHT) - 1];
  if (time_s < 3.0) dBodyAddForce(top, 1.5 * sin(2 * M_PI * time_s / 1.5), 0, 0);
}

/* steadystep: the program's per-step logic (the nudge on the top box) runs before every physics step, at that step's simulated
 * time: run once a frame, it would make the motion depend on the frame rate under every policy. */
static void beforeStep(void* context, ssStepper* stepper) {
  (void)context;
  nudge(ssStepper_CurrentStep(stepper).time_s);
}

/* The ground's load is the z force on the boxes at the ground contacts of the last step. A sleeping stack makes no
 * contacts: its last reading stands. */
static double ground_force = 0;

static int record(const ExampleFlags* flags, double time_s) {
  if (ground_contact_count > 0) {
    ground_force = 0;
    for (int i = 0; i < ground_contact_count; ++i)
      ground_force += box_is_first[i] ? ground_feedback[i].f1[2] : ground_feedback[i].f2[2];
  }
  int top = (box_count < TOWER_HEIGHT ? box_count : TOWER_HEIGHT) - 1;
  double values[2] = {dBodyGetPosition(boxes[top])[2], ground_force};
  return exampleRow(flags, time_s, 2, values);
}

int main(int argc, char** argv) {
  ExampleFlags flags;
  int parsed = exampleParseFlags(PROGRAM, argc, argv, EXAMPLE_FLAGS_STEPPER | EXAMPLE_FLAGS_BOXES, &flags);
  if (parsed != 0) return parsed < 0 ? 0 : parsed;
  /* naive freezes the softness at the step the numbers were tuned for: the program's own stepping */
  ssStepping stepping = ssDefaultStepping();
  stepping.max_step_s = flags.max_step_s;
  stepping.solver = SS_SOLVER_QUICK; /* steadystep: the ODE step this program calls */
  if (ssSteppingForPolicy(flags.policy, 1.0 / 60, &stepping) != SS_OK)
    return exampleRefuse(&flags, PROGRAM, "--policy", flags.policy, ssLastError());
  box_count = flags.boxes;
  boxes = calloc((size_t)box_count, sizeof *boxes);
  ground_feedback = calloc((size_t)box_count * MAX_CONTACTS, sizeof *ground_feedback);
  box_is_first = calloc((size_t)box_count * MAX_CONTACTS, sizeof *box_is_first);
  if (boxes == NULL || ground_feedback == NULL || box_is_first == NULL) {
    fprintf(stderr, PROGRAM ": out of memory for %d boxes\n", box_count);
    return 1;
  }
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

  exampleHeader(&flags, "t_s,top_z_m,ground_force_N");
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
      fprintf(stderr, PROGRAM ": t = %.6g s: the boxes' state is not finite\n", time_s);
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
  free(boxes);
  free(ground_feedback);
  free(box_is_first);
  return code;
}

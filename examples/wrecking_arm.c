/* A game-like ODE program, written as games write them: a motorized arm turns on a hinge to the static world, its
 * motor's target speed changing with time; a chain of three capsules hangs from its end on hinges with stops; a
 * steady wind pushes the chain, added once a frame; the chain swings into a stack of boxes on the ground, with soft
 * contacts from a near callback. QuickStep at 20 iterations, ODE's default world ERP/CFM, stops and contacts tuned
 * at 60 fps.
 *
 * Without --policy it steps on its own: the arm's logic once a frame, one dWorldQuickStep of the frame. With
 * --policy it is adopted the way the README shows for identical motion at every frame rate: the logic that depends
 * on time runs before every physics step at that step's time (before_step), the wind is still added once a frame
 * (the stepper holds it), and rows are labelled with the stepper's clock. One binary is both halves of an audit:
 *
 *   steadystep audit build/steadystep_example_wrecking_arm --own build/steadystep_example_wrecking_arm
 *
 * Followed: the chain's free end (x, z, m) and the top box's x (m). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <ode/ode.h>

#include <steadystep/lab/audit_flags.h>
#include <steadystep/steadystep.h>

#define PROGRAM "wrecking_arm"
#define TUNED_STEP_S (1.0 / 60)
#define LINK_COUNT 3
#define BOX_COUNT 3
#define MAX_CONTACTS 4

static const double pivot_z = 1.5, arm_length = 1.6;                     /* m */
static const double link_length = 0.4, link_radius = 0.06, link_mass = 1; /* m, m, kg */
static const double box_side = 0.3, box_mass = 0.8;                      /* m, kg */
static const double wind_n = 3.0;                                        /* N on each link, along +y */

static dWorldID world;
static dSpaceID space;
static dJointGroupID contacts;
static dJointID motor;
static dBodyID links[LINK_COUNT];
static dBodyID boxes[BOX_COUNT];

/* Contacts as the game tuned them at 60 fps; adopted, data is the stepper, which softens each for its step. */
static void nearCallback(void* data, dGeomID g1, dGeomID g2) {
  dBodyID b1 = dGeomGetBody(g1), b2 = dGeomGetBody(g2);
  if (b1 != 0 && b2 != 0 && dAreConnectedExcluding(b1, b2, dJointTypeContact)) return;
  dContact contact[MAX_CONTACTS];
  memset(contact, 0, sizeof contact); /* every surface field the program does not set is 0, not stack garbage */
  int count = dCollide(g1, g2, MAX_CONTACTS, &contact[0].geom, sizeof(dContact));
  for (int i = 0; i < count; ++i) {
    contact[i].surface.mode = dContactSoftCFM | dContactApprox1;
    contact[i].surface.mu = 0.6;
    contact[i].surface.soft_cfm = 1e-4;
    if (data != NULL) ssStepper_SoftenContact(data, &contact[i], b1, b2);
    dJointAttach(dJointCreateContact(world, contacts, &contact[i]), b1, b2);
  }
}

static void collide(void* context, ssStepper* stepper) {
  (void)context;
  dSpaceCollide(space, stepper, nearCallback);
}

static void build(void) {
  world = dWorldCreate();
  space = dHashSpaceCreate(0);
  contacts = dJointGroupCreate(0);
  dWorldSetGravity(world, 0, 0, -9.81);
  dWorldSetQuickStepNumIterations(world, 20);
  dCreatePlane(space, 0, 0, 1, 0);
  dMass mass;

  dBodyID arm = dBodyCreate(world); /* a beam along x from the pivot */
  dBodySetPosition(arm, arm_length / 2, 0, pivot_z);
  dMassSetBoxTotal(&mass, 4, arm_length, 0.15, 0.15);
  dBodySetMass(arm, &mass);
  motor = dJointCreateHinge(world, 0);
  dJointAttach(motor, arm, 0);
  dJointSetHingeAnchor(motor, 0, 0, pivot_z);
  dJointSetHingeAxis(motor, 0, 0, 1);
  dJointSetHingeParam(motor, dParamFMax, 400);

  dMassSetCapsuleTotal(&mass, link_mass, 3, link_radius, link_length - 2 * link_radius);
  for (int i = 0; i < LINK_COUNT; ++i) {
    links[i] = dBodyCreate(world);
    dBodySetPosition(links[i], arm_length, 0, pivot_z - (i + 0.5) * link_length);
    dBodySetMass(links[i], &mass);
    dGeomSetBody(dCreateCapsule(space, link_radius, link_length - 2 * link_radius), links[i]);
    dJointID hinge = dJointCreateHinge(world, 0);
    dJointAttach(hinge, links[i], i == 0 ? arm : links[i - 1]);
    dJointSetHingeAnchor(hinge, arm_length, 0, pivot_z - i * link_length);
    dJointSetHingeAxis(hinge, 1, 0, 0); /* the chain swings across the arm, as the wind pushes it */
    dJointSetHingeParam(hinge, dParamLoStop, -0.9);
    dJointSetHingeParam(hinge, dParamHiStop, 0.9);
    dJointSetHingeParam(hinge, dParamStopERP, 0.4); /* tuned at 60 fps */
    dJointSetHingeParam(hinge, dParamStopCFM, 1e-5);
  }

  dMassSetBoxTotal(&mass, box_mass, box_side, box_side, box_side);
  const double angle = 0.45; /* rad: where the arm's swing brings the chain */
  for (int i = 0; i < BOX_COUNT; ++i) {
    boxes[i] = dBodyCreate(world);
    dBodySetPosition(boxes[i], arm_length * cos(angle), arm_length * sin(angle), box_side * (i + 0.5) + 0.001 * i);
    dBodySetMass(boxes[i], &mass);
    dGeomSetBody(dCreateBox(space, box_side, box_side, box_side), boxes[i]);
  }
}

/* The game's logic at time t: the arm's motor target swings it back and forth. */
static void logic(double time_s) { dJointSetHingeParam(motor, dParamVel, 1.2 * sin(2 * M_PI * time_s / 3.0)); }

/* Adopted: the logic before every physics step, at the step's own simulated time. */
static void beforeStep(void* context, ssStepper* stepper) {
  (void)context;
  logic(ssStepper_CurrentStep(stepper).time_s);
}

/* A constant input, added once a frame like any game input: the stepper holds it over the frame's steps. */
static void addWind(void) {
  for (int i = 0; i < LINK_COUNT; ++i) dBodyAddForce(links[i], 0, wind_n, 0);
}

static int record(const ssAuditFlags* flags, double time_s, const ssAuditFrame* frame) {
  dVector3 end;
  dBodyGetRelPointPos(links[LINK_COUNT - 1], 0, 0, -link_length / 2, end);
  double values[3] = {end[0], end[2], dBodyGetPosition(boxes[BOX_COUNT - 1])[0]};
  return ssAuditRow(flags, time_s, 3, values, frame);
}

int main(int argc, char** argv) {
  ssAuditFlags flags;
  int parsed = ssAuditParseFlags(PROGRAM, argc, argv, &flags);
  if (parsed != 0) return parsed < 0 ? 0 : parsed;
  ssStepping stepping = ssDefaultStepping();
  stepping.solver = SS_SOLVER_QUICK;
  if (ssAuditStepping(&flags, TUNED_STEP_S, &stepping) != 0) return 2;
  dInitODE2(0);
  build();
  ssStepper* stepper = NULL;
  if (flags.policy != NULL) {
    ssStepperDef def = ssDefaultStepperDef();
    def.world = world;
    def.space = space;
    def.tuned_step_s = TUNED_STEP_S;
    def.stepping = stepping;
    def.before_step = beforeStep;
    def.collide = collide;
    def.contact_group = contacts;
    if (ssStepper_Create(&def, &stepper) != SS_OK) {
      fprintf(stderr, PROGRAM ": %s\n", ssLastError());
      return 1;
    }
  }

  ssAuditHeader(&flags, "t_s,end_x_m,end_z_m,top_box_x_m", 1);
  record(&flags, 0, NULL);
  int code = 0;
  for (double time_s = 0; ssAuditRunning(&flags, time_s);) {
    double frame_s = ssAuditNextFrame(&flags, time_s);
    ssAuditFrame frame = {1, {-1, -1, -1, -1, -1, -1}};
    addWind();
    if (stepper != NULL) {
      ssFrameReport report;
      if (ssStepper_Step(stepper, frame_s, &report) != SS_OK) {
        fprintf(stderr, PROGRAM ": t = %.6g s: %s\n", time_s, ssLastError());
        code = 1;
        break;
      }
      time_s = report.time_s;
      const ssServedCounts *rows = &report.rows, *touching = &report.contacts;
      frame = (ssAuditFrame){report.steps,
                             {rows->by_mapping, rows->handed_to_matched, rows->handed_to_implicit_euler,
                              touching->by_mapping, touching->handed_to_matched, touching->handed_to_implicit_euler}};
    } else { /* its own stepping: the logic once a frame, one step of the frame */
      logic(time_s);
      collide(NULL, NULL);
      dWorldQuickStep(world, frame_s);
      dJointGroupEmpty(contacts);
      time_s += frame_s;
    }
    if (!record(&flags, time_s, &frame)) {
      fprintf(stderr, PROGRAM ": t = %.6g s: the arm's state is not finite\n", time_s);
      code = 1;
      break;
    }
  }
  ssAuditFinish(&flags);
  ssStepper_Destroy(stepper);
  dJointGroupDestroy(contacts);
  dSpaceDestroy(space);
  dWorldDestroy(world);
  dCloseODE();
  return code;
}

/* A program that substeps itself, as the maze game does: each frame it reads its tilt, then takes three equal
 * dWorldStep substeps, each with its own collision: a ball rolling on a floor among walls. Adopted the documented way
 * (docs/adopting.md, "Programs that substep themselves"), it calls ssStepper_Step once for each of its substeps;
 * under naive that is its own stepping, bit for bit (a test compares the CSVs). Takes part in the audit protocol
 * (lab/include/steadystep/lab/audit_flags.h): without --policy it steps on its own.
 *
 * Followed: the ball's x and y (m). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <ode/ode.h>

#include <steadystep/lab/audit_flags.h>
#include <steadystep/steadystep.h>

#define PROGRAM "substepping_program"
#define SUBSTEPS 3
#define MAX_CONTACTS 4

static dWorldID world;
static dSpaceID space;
static dJointGroupID contacts;
static dBodyID ball;

static void nearCallback(void* data, dGeomID g1, dGeomID g2) {
  dBodyID b1 = dGeomGetBody(g1), b2 = dGeomGetBody(g2);
  dContact contact[MAX_CONTACTS];
  memset(contact, 0, sizeof contact); /* bounce_vel and the rest: no stack garbage in the surface */
  int count = dCollide(g1, g2, MAX_CONTACTS, &contact[0].geom, sizeof(dContact));
  for (int i = 0; i < count; ++i) {
    contact[i].surface.mode = dContactBounce | dContactSoftERP | dContactSoftCFM;
    contact[i].surface.mu = 0.3;
    contact[i].surface.bounce = 0.4;
    contact[i].surface.soft_erp = 0.6; /* tuned at its substep of 1/180 s */
    contact[i].surface.soft_cfm = 1e-5;
    if (data != NULL && ssStepper_SoftenContact(data, &contact[i], b1, b2) != SS_OK) continue;
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
  dCreatePlane(space, 0, 0, 1, 0);
  const double walls[][4] = {{1.0, 0, 0.1, 2.0}, {-1.0, 0, 0.1, 2.0}, {0, 1.0, 2.0, 0.1}, {0, -1.0, 2.0, 0.1},
                             {0.3, 0.2, 0.6, 0.1}};
  for (int i = 0; i < 5; ++i) {
    dGeomID wall = dCreateBox(space, walls[i][2], walls[i][3], 0.3);
    dGeomSetPosition(wall, walls[i][0], walls[i][1], 0.15);
  }
  ball = dBodyCreate(world);
  dMass mass;
  dMassSetSphereTotal(&mass, 0.05, 0.05);
  dBodySetMass(ball, &mass);
  dBodySetPosition(ball, -0.5, -0.5, 0.05);
  dGeomSetBody(dCreateSphere(space, 0.05), ball);
}

/* The frame's input: the board's tilt, as gravity along the floor, from the game's clock. */
static void tilt(double time_s) {
  dWorldSetGravity(world, 3.0 * sin(1.3 * time_s), 3.0 * cos(0.9 * time_s), -9.81);
}

static int record(const ssAuditFlags* flags, double time_s, const ssAuditFrame* frame) {
  const dReal* p = dBodyGetPosition(ball);
  double values[2] = {p[0], p[1]};
  return ssAuditRow(flags, time_s, 2, values, frame);
}

int main(int argc, char** argv) {
  ssAuditFlags flags;
  int parsed = ssAuditParseFlags(PROGRAM, argc, argv, &flags);
  if (parsed != 0) return parsed < 0 ? 0 : parsed;
  ssStepping stepping = ssDefaultStepping();
  stepping.solver = SS_SOLVER_STEP;
  if (ssAuditStepping(&flags, 0, &stepping) != 0) return 2; /* naive: frozen at the tuned step */
  dInitODE2(0);
  build();
  ssStepper* stepper = NULL;
  if (flags.policy != NULL) {
    ssStepperDef def = ssDefaultStepperDef();
    def.world = world;
    def.space = space;
    def.tuned_step_s = 1.0 / 180; /* its substep at 60 fps */
    def.stepping = stepping;
    def.collide = collide;
    def.contact_group = contacts;
    if (ssStepper_Create(&def, &stepper) != SS_OK) {
      fprintf(stderr, PROGRAM ": %s\n", ssLastError());
      return 1;
    }
  }
  ssAuditHeader(&flags, "t_s,ball_x_m,ball_y_m", 1);
  record(&flags, 0, NULL);
  int code = 0;
  for (double time_s = 0; ssAuditRunning(&flags, time_s) && code == 0;) {
    double frame_s = ssAuditNextFrame(&flags, time_s);
    tilt(time_s);
    ssAuditFrame frame = {SUBSTEPS, {-1, -1, -1, -1, -1, -1}};
    for (int i = 0; i < SUBSTEPS; ++i) { /* its own substeps: one ssStepper_Step each, adopted */
      if (stepper == NULL) {
        collide(NULL, NULL);
        dWorldStep(world, frame_s / SUBSTEPS);
        dJointGroupEmpty(contacts);
      } else if (ssStepper_Step(stepper, frame_s / SUBSTEPS, NULL) != SS_OK) {
        fprintf(stderr, PROGRAM ": t = %.6g s: %s\n", time_s, ssLastError());
        code = 1;
      }
    }
    time_s += frame_s;
    if (code == 0 && !record(&flags, time_s, &frame)) {
      fprintf(stderr, PROGRAM ": t = %.6g s: the ball's state is not finite\n", time_s);
      code = 1;
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

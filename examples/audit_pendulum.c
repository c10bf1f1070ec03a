/* A program taking part in `steadystep audit` (docs/audit.md) through the lab's audit_flags.h: a double pendulum of
 * two capsules on hinges, released from near the horizontal, the elbow's swing limited by soft stops tuned at
 * 60 fps (ERP 0.3, CFM 1e-3); world CFM 1e-5, no gravity damping. Chaotic: after a few seconds two runs at
 * slightly different steps part, and the audit says so instead of measuring chaos as frame-rate dependence.
 *
 * With --policy it is adopted and stepped by the library; without, it steps on its own, one dWorldQuickStep per
 * frame, as a program without the library does. So one binary is both halves of the audit:
 *
 *   steadystep audit build/steadystep_example_audit_pendulum --own build/steadystep_example_audit_pendulum
 *
 * Followed: the tip of the second link, x and z (m). The optional count columns carry each frame's steps and what
 * served its rows. */
#include <math.h>
#include <stdio.h>

#include <ode/ode.h>

#include <steadystep/lab/audit_flags.h>
#include <steadystep/steadystep.h>

#define PROGRAM "audit_pendulum"
#define TUNED_STEP_S (1.0 / 60)

static const double link_length = 0.5, link_radius = 0.03, link_mass = 1.0; /* m, m, kg */
static const double pivot_z = 2.0;                                          /* m */

static dWorldID world;
static dBodyID links[2];

static void build(void) {
  world = dWorldCreate();
  dWorldSetGravity(world, 0, 0, -9.81);
  dWorldSetCFM(world, 1e-5);
  dWorldSetQuickStepNumIterations(world, 40);
  dMass mass;
  dMassSetCapsuleTotal(&mass, link_mass, 1, link_radius, link_length - 2 * link_radius);
  const double angle = 1.4; /* rad from the vertical, both links in line */
  for (int i = 0; i < 2; ++i) {
    links[i] = dBodyCreate(world);
    double along = (i + 0.5) * link_length;
    dBodySetPosition(links[i], along * sin(angle), 0, pivot_z - along * cos(angle));
    dMatrix3 rotation;
    dRFromAxisAndAngle(rotation, 0, 1, 0, angle); /* the capsule's z axis along the link */
    dBodySetRotation(links[i], rotation);
    dBodySetMass(links[i], &mass);
    dJointID hinge = dJointCreateHinge(world, 0);
    dJointAttach(hinge, links[i], i == 0 ? 0 : links[0]);
    dJointSetHingeAxis(hinge, 0, 1, 0);
    double anchor = i * link_length;
    dJointSetHingeAnchor(hinge, anchor * sin(angle), 0, pivot_z - anchor * cos(angle));
    if (i == 1) { /* the elbow bends at most 2.5 rad either way, against soft stops */
      dJointSetHingeParam(hinge, dParamLoStop, -2.5);
      dJointSetHingeParam(hinge, dParamHiStop, 2.5);
      dJointSetHingeParam(hinge, dParamStopERP, 0.3);
      dJointSetHingeParam(hinge, dParamStopCFM, 1e-3);
    }
  }
}

static int record(const ssAuditFlags* flags, double time_s, const ssAuditFrame* frame) {
  dVector3 tip;
  dBodyGetRelPointPos(links[1], 0, 0, link_length / 2, tip);
  double values[2] = {tip[0], tip[2]};
  return ssAuditRow(flags, time_s, 2, values, frame);
}

/* What served the frame's rows and contacts, from its report. */
static ssAuditFrame counts(const ssFrameReport* report) {
  const ssServedCounts *rows = &report->rows, *contacts = &report->contacts;
  return (ssAuditFrame){report->steps,
                        {rows->by_mapping, rows->handed_to_matched, rows->handed_to_implicit_euler,
                         contacts->by_mapping, contacts->handed_to_matched, contacts->handed_to_implicit_euler}};
}

int main(int argc, char** argv) {
  ssAuditFlags flags;
  int parsed = ssAuditParseFlags(PROGRAM, argc, argv, &flags);
  if (parsed != 0) return parsed < 0 ? 0 : parsed;
  ssStepping stepping = ssDefaultStepping();
  stepping.solver = SS_SOLVER_QUICK; /* the program's own step: dWorldQuickStep */
  if (ssAuditStepping(&flags, TUNED_STEP_S, &stepping) != 0) return 2;
  dInitODE2(0);
  build();
  ssRegistry* registry = NULL;
  ssStepper* stepper = NULL;
  if (flags.policy != NULL) { /* adopted: the library steps it */
    registry = ssRegistry_Create(world);
    ssStepperDef def = ssDefaultStepperDef();
    def.world = world;
    def.registry = registry;
    def.stepping = stepping;
    if (registry == NULL || ssRegistry_AdoptWorld(registry, TUNED_STEP_S, NULL) != SS_OK ||
        ssRegistry_AdoptBody(registry, links[0], NULL) != SS_OK || /* and links[1], through the elbow */
        ssStepper_Create(&def, &stepper) != SS_OK) {
      fprintf(stderr, PROGRAM ": %s\n", ssLastError());
      return 1;
    }
  }

  ssAuditHeader(&flags, "t_s,tip_x_m,tip_z_m", 1);
  record(&flags, 0, NULL);
  int code = 0;
  for (double time_s = 0; ssAuditRunning(&flags, time_s);) {
    double frame_s = ssAuditNextFrame(&flags, time_s);
    ssAuditFrame frame = {1, {-1, -1, -1, -1, -1, -1}}; /* its own step: nothing served by the library */
    if (stepper != NULL) {
      ssFrameReport report;
      if (ssStepper_Step(stepper, frame_s, &report) != SS_OK) {
        fprintf(stderr, PROGRAM ": t = %.6g s: %s\n", time_s, ssLastError());
        code = 1;
        break;
      }
      time_s = report.time_s; /* the stepper's clock: the same bits at the same step whatever the frame rate */
      frame = counts(&report);
    } else {
      dWorldQuickStep(world, frame_s);
      time_s += frame_s;
    }
    if (!record(&flags, time_s, &frame)) {
      fprintf(stderr, PROGRAM ": t = %.6g s: the pendulum's state is not finite\n", time_s);
      code = 1;
      break;
    }
  }
  ssAuditFinish(&flags);
  ssStepper_Destroy(stepper);
  ssRegistry_Destroy(registry);
  dWorldDestroy(world);
  dCloseODE();
  return code;
}

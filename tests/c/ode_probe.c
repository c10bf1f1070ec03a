/* A child process for test_limits: steps a small real ODE world with the values given on the command line and
 * reports whether the state stays finite. ODE aborts the process on some values (that is what limits.h bounds), so
 * the test runs this program in a child and reads its exit status, never calling ODE with such values itself.
 *
 * Usage: ode_probe SOLVER STEP_S ERP CFM MASS_KG INERTIA STEPS [SPEED [FORCE [RUNAWAY_SPEED]]]
 *   SOLVER quick or step; ERP, CFM go to the world, a slider stop (lo = hi = 0) and a contact; MASS_KG and INERTIA
 *   (kg·m², the three principal moments) to each of the three bodies; SPEED (default 1) scales every body's
 *   initial linear (m/s) and angular (rad/s) velocity, to probe a state that is finite but far from rest; FORCE
 *   (N and N·m, default 0) is added to every body along each axis before every step, as a program's are;
 *   RUNAWAY_SPEED (m/s, rad/s; default 0 = none) stops stepping once a body is faster, as the stepper stops a
 *   runaway (stepping.max_speed, at most SS_MAX_SAFE_SPEED): the steps taken must each end finite.
 * Every number is rounded once to dReal, as the library writes it.
 * Exit status: 0 and "finite" when every body's position and velocity stayed finite, 3 and "not finite" when not,
 * 2 for a bad command line; an abort inside ODE ends it by SIGABRT. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <ode/ode.h>

static int parse(const char* text, double* out) {
  char* end = NULL;
  *out = strtod(text, &end);
  return end != text && *end == '\0';
}

static int body_finite(dBodyID body) {
  const dReal* p = dBodyGetPosition(body);
  const dReal* v = dBodyGetLinearVel(body);
  const dReal* w = dBodyGetAngularVel(body);
  for (int i = 0; i < 3; ++i)
    if (!isfinite(p[i]) || !isfinite(v[i]) || !isfinite(w[i])) return 0;
  return 1;
}

static int any_faster(const dBodyID* bodies, double limit) {
  for (int i = 0; i < 3; ++i) {
    const dReal* v = dBodyGetLinearVel(bodies[i]);
    const dReal* w = dBodyGetAngularVel(bodies[i]);
    double speed2 = 0, spin2 = 0; /* in double: a float's square overflows from 2e19 */
    for (int j = 0; j < 3; ++j) {
      speed2 += (double)v[j] * v[j];
      spin2 += (double)w[j] * w[j];
    }
    if (!(speed2 <= limit * limit && spin2 <= limit * limit)) return 1;
  }
  return 0;
}

int main(int argc, char** argv) {
  double step_s, erp, cfm, mass, inertia, steps, speed = 1, force = 0, runaway_speed = 0;
  if (argc < 8 || argc > 11 || (argc >= 9 && !parse(argv[8], &speed)) || (argc >= 10 && !parse(argv[9], &force)) ||
      (argc == 11 && !parse(argv[10], &runaway_speed)) ||
      (strcmp(argv[1], "quick") != 0 && strcmp(argv[1], "step") != 0) || !parse(argv[2], &step_s) ||
      !parse(argv[3], &erp) || !parse(argv[4], &cfm) || !parse(argv[5], &mass) || !parse(argv[6], &inertia) ||
      !parse(argv[7], &steps)) {
    fprintf(stderr,
            "usage: ode_probe quick|step STEP_S ERP CFM MASS_KG INERTIA STEPS [SPEED [FORCE [RUNAWAY_SPEED]]]\n");
    return 2;
  }
  dInitODE2(0);
  dWorldID world = dWorldCreate();
  dWorldSetGravity(world, 0, 0, -9.81);
  dWorldSetERP(world, erp);
  dWorldSetCFM(world, cfm);
  dMass m;
  dMassSetParameters(&m, mass, 0, 0, 0, inertia, inertia, inertia, 0, 0, 0);

  dBodyID bodies[3];
  for (int i = 0; i < 3; ++i) {
    bodies[i] = dBodyCreate(world);
    dBodySetMass(bodies[i], &m);
    dBodySetPosition(bodies[i], 2.0 * i, 0, 0.1);
    dBodySetLinearVel(bodies[i], 0.5 * speed, 0, 1.0 * speed);
    dBodySetAngularVel(bodies[i], 0.3 * speed, 0.2 * speed, 0.1 * speed);
  }
  /* A slider whose stop is the spring (the oscillator's row). */
  dJointID slider = dJointCreateSlider(world, 0);
  dJointAttach(slider, bodies[0], 0);
  dJointSetSliderAxis(slider, 0, 0, 1);
  dJointSetSliderParam(slider, dParamLoStop, 0);
  dJointSetSliderParam(slider, dParamHiStop, 0);
  dJointSetSliderParam(slider, dParamStopERP, erp);
  dJointSetSliderParam(slider, dParamStopCFM, cfm);
  /* A ball joint to the world: its rows copied the world's erp and cfm. */
  dJointID ball = dJointCreateBall(world, 0);
  dJointAttach(ball, bodies[1], 0);
  dJointSetBallAnchor(ball, 2.0, 0, 0);
  dJointGroupID contacts = dJointGroupCreate(0);

  for (long n = 0; n < (long)steps && !(runaway_speed > 0 && any_faster(bodies, runaway_speed)); ++n) {
    /* A soft contact of the third body with the ground plane z = 0, remade every step as a near callback does. */
    dContact contact;
    memset(&contact, 0, sizeof contact);
    contact.surface.mode = dContactSoftERP | dContactSoftCFM;
    contact.surface.mu = 1.0;
    contact.surface.soft_erp = erp;
    contact.surface.soft_cfm = cfm;
    const dReal* p = dBodyGetPosition(bodies[2]);
    contact.geom.pos[0] = p[0];
    contact.geom.pos[1] = p[1];
    contact.geom.pos[2] = 0;
    contact.geom.normal[2] = 1;
    contact.geom.depth = 0.01;
    dJointAttach(dJointCreateContact(world, contacts, &contact), bodies[2], 0);
    for (int i = 0; i < 3; ++i) {
      dBodyAddForce(bodies[i], force, -force, force);
      dBodyAddTorque(bodies[i], force, force, -force);
    }
    if (argv[1][0] == 'q')
      dWorldQuickStep(world, step_s);
    else
      dWorldStep(world, step_s);
    dJointGroupEmpty(contacts);
  }
  int finite = 1;
  for (int i = 0; i < 3; ++i) finite = finite && body_finite(bodies[i]);
  printf("%s\n", finite ? "finite" : "not finite");
  dJointGroupDestroy(contacts);
  dWorldDestroy(world);
  dCloseODE();
  return finite ? 0 : 3;
}

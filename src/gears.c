/* ODE 0.16's transmission joint: the turn a step may give a gear, and measuring its phase afresh. */
#include "gears.h"

#include <math.h>

int ssGeared(dBodyID body) {
  for (int i = dBodyGetNumJoints(body) - 1; i >= 0; --i)
    if (dJointGetType(dBodyGetJoint(body, i)) == dJointTypeTransmission) return 1;
  return 0;
}

static double length(const dReal* v) { return sqrt((double)v[0] * v[0] + (double)v[1] * v[1] + (double)v[2] * v[2]); }

double ssGearTurn(dBodyID body, double step_s) {
  double spin = length(dBodyGetAngularVel(body)), speed = length(dBodyGetLinearVel(body));
  double turn = 0;
  for (int i = dBodyGetNumJoints(body) - 1; i >= 0; --i) {
    dJointID joint = dBodyGetJoint(body, i);
    if (dJointGetType(joint) != dJointTypeTransmission) continue;
    double radius = dJointGetBody(joint, 0) == body ? dJointGetTransmissionRadius1(joint)
                                                    : dJointGetTransmissionRadius2(joint);
    double slide = radius > 0 ? speed / radius : 0; /* a radius ODE has not computed yet: the spin alone */
    turn = fmax(turn, (spin + slide) * step_s);
  }
  return turn;
}

/* A gear's axis as ODE reports it in the world: a unit vector when the body's rotation is finite and orthonormal. */
static int unitAxis(const dReal* axis) {
  double n = length(axis);
  return n > 0.5 && n < 2; /* false for a NaN */
}

/* ODE builds a gear's reference frame (phase 0) at the next step whenever one of its axes or anchors is set. Each
 * gear's own axis is set back as ODE reports it; the setters for one gear at a time exist only in the
 * intersecting-axes mode, so the mode is switched for the two calls and back (setting the mode touches nothing else).
 * The shared-axis setter of the other modes would give the second gear the first gear's axis, which drift may have
 * moved apart from its own. */
static void rebase(dJointID joint) {
  if (dJointGetBody(joint, 0) == 0 || dJointGetBody(joint, 1) == 0) return;
  dVector3 axis1, axis2;
  dJointGetTransmissionAxis1(joint, axis1);
  dJointGetTransmissionAxis2(joint, axis2);
  if (!unitAxis(axis1) || !unitAxis(axis2)) return;
  int mode = dJointGetTransmissionMode(joint);
  dJointSetTransmissionMode(joint, dTransmissionIntersectingAxes);
  dJointSetTransmissionAxis1(joint, axis1[0], axis1[1], axis1[2]);
  dJointSetTransmissionAxis2(joint, axis2[0], axis2[1], axis2[2]);
  dJointSetTransmissionMode(joint, mode);
}

void ssGearsRebase(const dBodyID* bodies, int count) {
  for (int g = 0; g < count; ++g)
    for (int i = dBodyGetNumJoints(bodies[g]) - 1; i >= 0; --i) {
      dJointID joint = dBodyGetJoint(bodies[g], i);
      /* from its first body's side only: both bodies of a joint on a known body are known */
      if (dJointGetType(joint) == dJointTypeTransmission && dJointGetBody(joint, 0) == bodies[g]) rebase(joint);
    }
}

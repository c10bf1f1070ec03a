/* ODE 0.16's transmission joint: the turn a step may give a gear, and measuring its phase afresh. */
#include "gears.h"

#include <math.h>

int ssGeared(dBodyID body) {
  for (int i = dBodyGetNumJoints(body) - 1; i >= 0; --i)
    if (dJointGetType(dBodyGetJoint(body, i)) == dJointTypeTransmission) return 1;
  return 0;
}

static double length(const dReal* v) { return sqrt((double)v[0] * v[0] + (double)v[1] * v[1] + (double)v[2] * v[2]); }

/* How far the line between a transmission joint's two anchors may swing in a step of step_s (rad): ODE measures
 * each gear's phase towards the mesh, which lies between them, so their relative motion turns it too. Moving by
 * less than their distance it swings by at most asin(moved / distance); by as much or more it may turn round (pi,
 * where the anchors pass each other). */
static double meshSwing(dJointID joint, double step_s) {
  dBodyID first = dJointGetBody(joint, 0), second = dJointGetBody(joint, 1);
  if (first == 0 || second == 0) return 0;
  dVector3 anchor1, anchor2, velocity1, velocity2;
  dJointGetTransmissionAnchor1(joint, anchor1);
  dJointGetTransmissionAnchor2(joint, anchor2);
  dBodyGetPointVel(first, anchor1[0], anchor1[1], anchor1[2], velocity1);
  dBodyGetPointVel(second, anchor2[0], anchor2[1], anchor2[2], velocity2);
  dReal apart[3] = {anchor1[0] - anchor2[0], anchor1[1] - anchor2[1], anchor1[2] - anchor2[2]};
  dReal relative[3] = {velocity1[0] - velocity2[0], velocity1[1] - velocity2[1], velocity1[2] - velocity2[2]};
  double moved = length(relative) * step_s, distance = length(apart);
  if (!(moved < distance)) return M_PI; /* a NaN too */
  return asin(moved / distance);
}

/* The turn of body's gears in a step of step_s at this spin (rad/s) and speed (m/s), with the mesh's swing: the
 * largest over its transmission joints. */
static double gearTurnAt(dBodyID body, double spin, double speed, double step_s) {
  double turn = 0;
  for (int i = dBodyGetNumJoints(body) - 1; i >= 0; --i) {
    dJointID joint = dBodyGetJoint(body, i);
    if (dJointGetType(joint) != dJointTypeTransmission) continue;
    double radius = dJointGetBody(joint, 0) == body ? dJointGetTransmissionRadius1(joint)
                                                    : dJointGetTransmissionRadius2(joint);
    double slide = radius > 0 ? speed / radius : 0; /* a radius ODE has not computed yet: the spin alone */
    turn = fmax(turn, (spin + slide) * step_s + meshSwing(joint, step_s));
  }
  return turn;
}

/* The smallest principal moment of inertia (kg m^2) of a symmetric 3x3 inertia (dMass.I, rows of 4), from its
 * characteristic polynomial (the trigonometric form); 0 where it is not positive or not finite. */
static double smallestMoment(const dReal* I) {
  double a = I[0], b = I[5], c = I[10], d = I[1], e = I[6], f = I[2]; /* xx yy zz, xy yz xz */
  double off = d * d + e * e + f * f, q = (a + b + c) / 3, smallest;
  if (off == 0) {
    smallest = fmin(a, fmin(b, c));
  } else {
    double p = sqrt(((a - q) * (a - q) + (b - q) * (b - q) + (c - q) * (c - q) + 2 * off) / 6);
    double ba = (a - q) / p, bb = (b - q) / p, bc = (c - q) / p, bd = d / p, be = e / p, bf = f / p;
    double r = (ba * (bb * bc - be * be) - bd * (bd * bc - be * bf) + bf * (bd * be - bb * bf)) / 2;
    double phi = r <= -1 ? M_PI / 3 : r >= 1 ? 0 : acos(r) / 3;
    smallest = q + 2 * p * cos(phi + 2 * M_PI / 3);
  }
  return smallest > 0 && isfinite(smallest) ? smallest : 0;
}

double ssGearTurnInStep(dBodyID body, double step_s) {
  dMass mass;
  dBodyGetMass(body, &mass);
  double moment = smallestMoment(mass.I);
  double spin = length(dBodyGetAngularVel(body)), speed = length(dBodyGetLinearVel(body));
  /* a moment that cannot be bounded (ODE refuses such a mass) leaves the torque's share to the check after */
  double spun = spin + (moment > 0 ? step_s * length(dBodyGetTorque(body)) / moment : 0);
  double pushed = speed + (mass.mass > 0 ? step_s * length(dBodyGetForce(body)) / mass.mass : 0);
  return gearTurnAt(body, spun, pushed, step_s);
}

double ssGearTurn(dBodyID body, double step_s) {
  return gearTurnAt(body, length(dBodyGetAngularVel(body)), length(dBodyGetLinearVel(body)), step_s);
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

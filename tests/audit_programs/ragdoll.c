/* A ragdoll (a torso, a head, upper and lower arms and legs: ten bodies on ball joints and hinges with stops tuned
 * at 60 fps) dropped from 1.6 m, tilted, onto four heavy boxes of different heights, as a game would write it.
 * Chaotic: two fine-step runs part within a second or two of the first impact; how much the frame rate changes the
 * fall is still measurable over the whole run. A test program of `steadystep audit`
 * (tests/python/test_audit_programs.py), built against the installed core and steadystep/audit/protocol.h alone.
 *
 * Followed: the head's height and the torso's position (m). */
#include "game.h"

static dBodyID torso, head;

static dBodyID capsule(Game* game, double radius, double length, double mass_kg, const double from[3],
                       const double to[3]) {
  dBodyID body = dBodyCreate(game->world);
  dMass mass;
  dMassSetCapsuleTotal(&mass, mass_kg, 3, radius, length);
  dBodySetMass(body, &mass);
  dBodySetPosition(body, 0.5 * (from[0] + to[0]), 0.5 * (from[1] + to[1]), 0.5 * (from[2] + to[2]));
  double axis[3] = {to[0] - from[0], to[1] - from[1], to[2] - from[2]};
  dMatrix3 rotation;
  dRFromZAxis(rotation, axis[0], axis[1], axis[2]);
  dBodySetRotation(body, rotation);
  dGeomSetBody(dCreateCapsule(game->space, radius, length), body);
  return body;
}

static void ball(Game* game, dBodyID a, dBodyID b, const double at[3]) {
  dJointID joint = dJointCreateBall(game->world, 0);
  dJointAttach(joint, a, b);
  dJointSetBallAnchor(joint, at[0], at[1], at[2]);
}

static void hinge(Game* game, dBodyID a, dBodyID b, const double at[3], double lo, double hi) {
  dJointID joint = dJointCreateHinge(game->world, 0);
  dJointAttach(joint, a, b);
  dJointSetHingeAnchor(joint, at[0], at[1], at[2]);
  dJointSetHingeAxis(joint, 0, 1, 0);
  dJointSetHingeParam(joint, dParamLoStop, lo);
  dJointSetHingeParam(joint, dParamHiStop, hi);
  dJointSetHingeParam(joint, dParamStopERP, 0.3);
  dJointSetHingeParam(joint, dParamStopCFM, 1e-4);
}

static void build(Game* game) {
  game->world = dWorldCreate();
  game->space = dHashSpaceCreate(0);
  game->contacts = dJointGroupCreate(0);
  dWorldSetGravity(game->world, 0, 0, -9.81);
  dWorldSetCFM(game->world, 1e-5);
  dWorldSetQuickStepNumIterations(game->world, 20);
  dCreatePlane(game->space, 0, 0, 1, 0);
  const double heights[4] = {0.3, 0.6, 0.45, 0.25};
  for (int i = 0; i < 4; ++i)
    gameBox(game, 0.5, 0.5, heights[i], 20, (i % 2) * 0.55 - 0.25, (i / 2) * 0.55 - 0.25, heights[i] / 2);
  const double z = 1.6; /* the pelvis */
  torso = gameBox(game, 0.35, 0.2, 0.5, 8, 0, 0, z + 0.25);
  dMatrix3 tilt;
  dRFromAxisAndAngle(tilt, 1, 1, 0, 0.5);
  dBodySetRotation(torso, tilt);
  dBodySetPosition(torso, 0, 0, z + 0.25);
  head = dBodyCreate(game->world);
  dMass mass;
  dMassSetSphereTotal(&mass, 2.5, 0.11);
  dBodySetMass(head, &mass);
  dBodySetPosition(head, 0, 0, z + 0.62);
  dGeomSetBody(dCreateSphere(game->space, 0.11), head);
  const double neck[3] = {0, 0, z + 0.51};
  ball(game, torso, head, neck);
  for (int side = -1; side <= 1; side += 2) {
    const double shoulder[3] = {0.24 * side, 0, z + 0.45}, elbow[3] = {0.24 * side, 0, z + 0.13},
                 hand[3] = {0.24 * side, 0, z - 0.17};
    dBodyID upper = capsule(game, 0.05, 0.22, 1.2, shoulder, elbow);
    dBodyID lower = capsule(game, 0.045, 0.22, 0.9, elbow, hand);
    ball(game, torso, upper, shoulder);
    hinge(game, upper, lower, elbow, 0, 2.4);
    const double hip[3] = {0.1 * side, 0, z}, knee[3] = {0.1 * side, 0, z - 0.42}, foot[3] = {0.1 * side, 0, z - 0.84};
    dBodyID thigh = capsule(game, 0.07, 0.28, 3.0, hip, knee);
    dBodyID shin = capsule(game, 0.06, 0.3, 2.0, knee, foot);
    ball(game, torso, thigh, hip);
    hinge(game, thigh, shin, knee, -2.4, 0);
  }
}

static void read(Game* game, double* values) {
  (void)game;
  const dReal *h = dBodyGetPosition(head), *t = dBodyGetPosition(torso);
  values[0] = h[2];
  values[1] = t[0];
  values[2] = t[1];
  values[3] = t[2];
}

int main(int argc, char** argv) {
  Game game = {0};
  game.name = "ragdoll";
  game.columns = "t_s,head_z_m,torso_x_m,torso_y_m,torso_z_m";
  game.count = 4;
  game.surface.mode = dContactSoftERP | dContactSoftCFM | dContactApprox1;
  game.surface.mu = 0.8;
  game.surface.soft_erp = 0.3;
  game.surface.soft_cfm = 1e-4;
  game.build = build;
  game.read = read;
  return gameMain(&game, argc, argv, NULL);
}

/* A stack of six boxes of unequal masses (3, 0.3, 2, 0.2, 1.5 and 0.1 kg, the heavy ones on light ones), each a
 * little off the one below, on the ground; a push of 8 N on the fourth box from t = 1 s to 1.2 s (the program's
 * logic). QuickStep at 10 iterations, contacts tuned at 60 fps. A test program of `steadystep audit`
 * (tests/python/test_audit_programs.py), built against the installed core and steadystep/audit/protocol.h alone.
 *
 * Followed: the top box's height, the boxes' mean height (m), their energy (kinetic and potential, J) and the deepest
 * contact (m): an error-like quantity of a tiny range, which must not decide a claim alone. No input depends on the
 * frame: under fixed it is the same at every frame rate, bit for bit. */
#include "game.h"

#define BOXES 6

static const double masses_kg[BOXES] = {3.0, 0.3, 2.0, 0.2, 1.5, 0.1};
static const double side_m = 0.3;
static dBodyID boxes[BOXES];

static void build(Game* game) {
  game->world = dWorldCreate();
  game->space = dHashSpaceCreate(0);
  game->contacts = dJointGroupCreate(0);
  dWorldSetGravity(game->world, 0, 0, -9.81);
  dWorldSetCFM(game->world, 1e-5);
  dWorldSetQuickStepNumIterations(game->world, 10);
  dCreatePlane(game->space, 0, 0, 1, 0);
  for (int i = 0; i < BOXES; ++i)
    boxes[i] = gameBox(game, side_m, side_m, side_m, masses_kg[i], (i % 2 ? 0.04 : -0.04) * (i > 0), 0,
                       side_m * (i + 0.5) + 0.002 * i);
}

static void logic(Game* game, double time_s) {
  (void)game;
  if (time_s >= 1.0 && time_s < 1.2) dBodyAddForce(boxes[3], 8.0, 0, 0);
}

static void read(Game* game, double* values) {
  double top = 0, sum = 0, energy = 0;
  for (int i = 0; i < BOXES; ++i) {
    const dReal *p = dBodyGetPosition(boxes[i]), *v = dBodyGetLinearVel(boxes[i]), *w = dBodyGetAngularVel(boxes[i]);
    top = p[2] > top ? p[2] : top;
    sum += p[2];
    double inertia = masses_kg[i] * side_m * side_m / 6; /* a cube's, about any axis */
    energy += 0.5 * masses_kg[i] * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) +
              0.5 * inertia * (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]) + masses_kg[i] * 9.81 * p[2];
  }
  values[0] = top;
  values[1] = sum / BOXES;
  values[2] = energy;
  values[3] = game->deepest_contact_m;
}

int main(int argc, char** argv) {
  Game game = {0};
  game.name = "box_stack";
  game.columns = "t_s,top_z_m,mean_z_m,energy_J,depth_m";
  game.count = 4;
  game.surface.mode = dContactSoftERP | dContactSoftCFM | dContactApprox1;
  game.surface.mu = 0.6;
  game.surface.soft_erp = 0.3;
  game.surface.soft_cfm = 1e-4;
  game.build = build;
  game.logic = logic;
  game.read = read;
  return gameMain(&game, argc, argv, NULL);
}

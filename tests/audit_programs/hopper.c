/* A hopping buggy whose fine-step runs misbehave: a 40 kg chassis driven forward by a constant force (added once a
 * frame), dropped from 1 m, with the game's "landing boost": for 0.1 s after it touches down, every step (every
 * frame, on its own) adds 0.2 m/s upwards, a velocity sized for a 60 fps step. At 15-60 fps that is a hop; at 1 ms
 * steps a hundred boosts throw it tens of metres up: the fine-step reference is unphysical, and the audit must say
 * so rather than trust it. A test program
 * of `steadystep audit` (tests/python/test_audit_programs.py), built against the installed core and
 * steadystep/audit/protocol.h alone.
 *
 * Followed: the chassis's height and its x (m). */
#include "game.h"

static dBodyID chassis;

static void build(Game* game) {
  game->world = dWorldCreate();
  game->space = dHashSpaceCreate(0);
  game->contacts = dJointGroupCreate(0);
  dWorldSetGravity(game->world, 0, 0, -9.81);
  dWorldSetQuickStepNumIterations(game->world, 20);
  dCreatePlane(game->space, 0, 0, 1, 0);
  chassis = gameBox(game, 1.0, 0.6, 0.3, 40, 0, 0, 1.0);
}

/* The game's landing boost, after collide: when the chassis touches down after being in the air, it is boosted for
 * 0.1 s, 0.2 m/s upwards every step (six steps at 60 fps: a hop of 1.2 m/s). Sized for a 60 fps step, it adds 20
 * m/s in 1 ms steps. */
static double now_s, boost_until_s = -1;
static int touching;

static void clockLogic(Game* game, double time_s) {
  (void)game;
  now_s = time_s;
}

static void boost(Game* game) {
  if (game->contacts_last_collide > 0 && !touching) boost_until_s = now_s + 0.1;
  touching = game->contacts_last_collide > 0;
  if (now_s < boost_until_s) {
    const dReal* v = dBodyGetLinearVel(chassis);
    dBodySetLinearVel(chassis, v[0], v[1], v[2] + 0.2);
  }
}

static void collideAndBoost(void* context, ssStepper* stepper) {
  gameCollide(context, stepper);
  boost(game_);
}

static void drive(Game* game) {
  (void)game;
  dBodyAddForce(chassis, 60, 0, 0);
}

static void read(Game* game, double* values) {
  (void)game;
  const dReal* p = dBodyGetPosition(chassis);
  values[0] = p[2];
  values[1] = p[0];
}

int main(int argc, char** argv) {
  Game game = {0};
  game.name = "hopper";
  game.columns = "t_s,chassis_z_m,chassis_x_m";
  game.count = 2;
  game.surface.mode = dContactSoftERP | dContactSoftCFM | dContactApprox1;
  game.surface.mu = 0.2;
  game.surface.soft_erp = 0.2;
  game.surface.soft_cfm = 1e-4;
  game.build = build;
  game.frame_input = drive;
  game.logic = clockLogic;
  game.read = read;
  game.collide = collideAndBoost;
  return gameMain(&game, argc, argv, NULL);
}

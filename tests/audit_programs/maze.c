/* A tilting maze: a ball among walls on a floor, the board tilted by a scripted player (gravity's x and y follow the
 * time), with a game clock of whole milliseconds (as SDL_GetTicks gives): each frame steps the milliseconds that
 * passed, none at all when the frame was shorter than the next tick; its own stepping cuts that into three equal
 * QuickSteps, as mokomaze does. Bouncy contacts tuned at 60 fps. A test program of `steadystep audit`
 * (tests/python/test_audit_programs.py), built against the installed core and steadystep/audit/protocol.h alone.
 *
 * The clock's floor matters to the audit: its check of the reference at 4000 frames a second takes 1 ms steps, as
 * the reference does, and the audit must say so. Followed: the ball's x and y (m). */
#include "game.h"

static dBodyID ball;

static void wall(Game* game, double x, double y, double sx, double sy) {
  dGeomID geom = dCreateBox(game->space, sx, sy, 0.1);
  dGeomSetPosition(geom, x, y, 0.05);
}

static void build(Game* game) {
  game->world = dWorldCreate();
  game->space = dHashSpaceCreate(0);
  game->contacts = dJointGroupCreate(0);
  dWorldSetGravity(game->world, 0, 0, -9.81);
  dWorldSetQuickStepNumIterations(game->world, 20);
  dCreatePlane(game->space, 0, 0, 1, 0);
  wall(game, 0, 1.05, 2.2, 0.1); /* the frame */
  wall(game, 0, -1.05, 2.2, 0.1);
  wall(game, 1.05, 0, 0.1, 2.2);
  wall(game, -1.05, 0, 0.1, 2.2);
  wall(game, -0.3, -0.4, 1.2, 0.06); /* the maze's walls */
  wall(game, 0.35, 0.3, 1.1, 0.06);
  wall(game, 0.2, -0.2, 0.06, 0.5);
  wall(game, -0.5, 0.5, 0.06, 0.8);
  ball = dBodyCreate(game->world);
  dMass mass;
  dMassSetSphereTotal(&mass, 0.05, 0.04);
  dBodySetMass(ball, &mass);
  dBodySetPosition(ball, -0.8, -0.8, 0.04);
  dGeomSetBody(dCreateSphere(game->space, 0.04), ball);
}

/* The scripted player tilts the board: gravity's x and y (m/s^2) follow the time. */
static void logic(Game* game, double time_s) {
  dWorldSetGravity(game->world, 2.5 * sin(2 * M_PI * time_s / 3.1), 2.5 * cos(2 * M_PI * time_s / 4.3), -9.81);
}

static void read(Game* game, double* values) {
  (void)game;
  const dReal* p = dBodyGetPosition(ball);
  values[0] = p[0];
  values[1] = p[1];
}

/* The game's clock: whole milliseconds of the time played; a frame steps the milliseconds that passed. */
static double played_s_;
static long ticks_ms_;

static double tick(double frame_s) {
  played_s_ += frame_s;
  long ticks = (long)floor(played_s_ * 1000 + 1e-9);
  double step_s = (double)(ticks - ticks_ms_) / 1000;
  ticks_ms_ = ticks;
  return step_s;
}

int main(int argc, char** argv) {
  Game game = {0};
  game.name = "maze";
  game.columns = "t_s,ball_x_m,ball_y_m";
  game.count = 2;
  game.own_substeps = 3;
  game.surface.mode = dContactBounce | dContactSoftERP | dContactSoftCFM | dContactApprox1;
  game.surface.mu = 0.3;
  game.surface.bounce = 0.4;
  game.surface.bounce_vel = 0.05;
  game.surface.soft_erp = 0.4;
  game.surface.soft_cfm = 1e-4;
  game.build = build;
  game.logic = logic;
  game.read = read;
  return gameMain(&game, argc, argv, tick);
}

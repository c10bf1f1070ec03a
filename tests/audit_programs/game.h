/* What the audit's test programs share (tests/audit_programs): each is an ODE program written the usual way (its own
 * loop: collide, one dWorldQuickStep a frame, empty the contacts) that takes part in `steadystep audit` through the
 * installed header steadystep/audit/protocol.h alone, built against the installed core (no lab). Without --policy it
 * steps on its own; with --policy it is adopted by a stepper, its per-step logic in before_step at the step's time.
 *
 * A program fills a Game (its world, space, contacts and hooks) and calls gameMain. */
#ifndef STEADYSTEP_AUDIT_PROGRAMS_GAME_H
#define STEADYSTEP_AUDIT_PROGRAMS_GAME_H

#include <math.h>
#include <stdio.h>

#include <ode/ode.h>

#include <steadystep/audit/protocol.h>
#include <steadystep/steadystep.h>

#define GAME_TUNED_STEP_S (1.0 / 60)
#define GAME_MAX_CONTACTS 4
#define GAME_MAX_QUANTITIES 8
#ifndef GAME_FORGETS_SOFTEN
#define GAME_FORGETS_SOFTEN 0 /* 1: the near callback forgets ssStepper_SoftenContact (the audit says so) */
#endif

typedef struct Game {
  const char* name;                    /* the program's name, for messages */
  const char* columns;                 /* its CSV header: "t_s,<quantity>_<unit>,..." */
  int count;                           /* the quantities read() fills */
  dWorldID world;
  dSpaceID space;
  dJointGroupID contacts;
  dSurfaceParameters surface;          /* every contact's surface, as the program tuned it at 60 fps */
  void (*build)(struct Game* game);    /* makes the world, space, contact group and bodies */
  void (*logic)(struct Game* game, double time_s); /* per step under a policy; once a frame on its own; or NULL */
  void (*frame_input)(struct Game* game);          /* once a frame, held by the stepper over the frame's steps */
  void (*read)(struct Game* game, double* values);
  ssStepCallback* collide;             /* collide before each step: gameCollide unless the program has its own */
  int own_substeps;                    /* its own stepping: equal QuickSteps a frame (0 or 1: one) */
  int contacts_last_collide;           /* contacts made by the last collide */
  double deepest_contact_m;            /* the deepest of them (m) */
  void* user;
} Game;

static Game* game_;

/* The program's near callback: its own surface; adopted, data is the stepper, which softens each contact for its
 * step (unless built with GAME_FORGETS_SOFTEN=1, as a program that forgot the line would be). */
static inline void gameNear(void* data, dGeomID g1, dGeomID g2) {
  dBodyID b1 = dGeomGetBody(g1), b2 = dGeomGetBody(g2);
  if (b1 != 0 && b2 != 0 && dAreConnectedExcluding(b1, b2, dJointTypeContact)) return;
  dContact contact[GAME_MAX_CONTACTS];
  int count = dCollide(g1, g2, GAME_MAX_CONTACTS, &contact[0].geom, sizeof(dContact));
  for (int i = 0; i < count; ++i) {
    contact[i].surface = game_->surface;
    if (data != NULL && !GAME_FORGETS_SOFTEN) ssStepper_SoftenContact((ssStepper*)data, &contact[i], b1, b2);
    dJointAttach(dJointCreateContact(game_->world, game_->contacts, &contact[i]), b1, b2);
    game_->contacts_last_collide += 1;
    if (contact[i].geom.depth > game_->deepest_contact_m) game_->deepest_contact_m = contact[i].geom.depth;
  }
}

static inline void gameCollide(void* context, ssStepper* stepper) {
  (void)context;
  game_->contacts_last_collide = 0;
  game_->deepest_contact_m = 0;
  dSpaceCollide(game_->space, stepper, gameNear);
}

static inline void gameBeforeStep(void* context, ssStepper* stepper) {
  (void)context;
  if (game_->logic != NULL) game_->logic(game_, ssStepper_CurrentStep(stepper).time_s);
}

/* The program's own frame: its logic once a frame, then collide and a QuickStep, own_substeps times (its frame
 * input, added before, acts on the first only, as in a plain ODE loop). */
static inline void gameOwnFrame(Game* game, double time_s, double frame_s) {
  if (game->logic != NULL) game->logic(game, time_s);
  int substeps = game->own_substeps > 1 ? game->own_substeps : 1;
  for (int i = 0; i < substeps; ++i) {
    game->collide(NULL, NULL);
    dWorldQuickStep(game->world, frame_s / substeps);
    dJointGroupEmpty(game->contacts);
  }
}

/* Parses the flags, builds the world, and runs it frame by frame, printing the protocol's rows. own_frame: NULL for
 * gameOwnFrame; clock: NULL for the profile's frames as they come, else a function that turns the frame time into
 * the time the program steps (its own clock), and returns it. */
static inline int gameMain(Game* game, int argc, char** argv, double (*clock)(double frame_s)) {
  game_ = game;
  if (game->collide == NULL) game->collide = gameCollide;
  ssAuditRun run;
  int parsed = ssAuditRun_Parse(game->name, argc, argv, &run);
  if (parsed != 0) return parsed < 0 ? 0 : parsed;
  ssStepperDef def = ssDefaultStepperDef();
  def.tuned_step_s = GAME_TUNED_STEP_S;
  def.stepping.solver = SS_SOLVER_QUICK;
  if (ssAuditRun_Stepping(&run, def.tuned_step_s, &def.stepping) != 0) {
    ssAuditRun_Finish(&run);
    return 2;
  }
  dInitODE2(0);
  game->build(game);
  ssAuditRun_World(&run, game->world);
  ssStepper* stepper = NULL;
  if (run.policy != NULL) {
    def.world = game->world;
    def.space = game->space;
    def.before_step = gameBeforeStep;
    def.collide = game->collide;
    def.contact_group = game->contacts;
    if (ssStepper_Create(&def, &stepper) != SS_OK) {
      fprintf(stderr, "%s: %s\n", game->name, ssLastError());
      return 1;
    }
  }
  double values[GAME_MAX_QUANTITIES];
  ssAuditRun_Header(&run, game->columns, 1);
  game->read(game, values);
  ssAuditRun_Row(&run, 0, game->count, values, NULL);
  int code = 0;
  double played_s = 0, time_s = 0; /* the profile's clock, and the simulated time the rows are labelled with */
  while (ssAuditRun_Running(&run, played_s)) {
    double frame_s = ssAuditRun_NextFrame(&run, played_s);
    played_s += frame_s;
    double step_s = clock != NULL ? clock(frame_s) : frame_s;
    if (game->frame_input != NULL) game->frame_input(game);
    int printed;
    if (stepper != NULL) {
      ssFrameReport report;
      if (ssStepper_Step(stepper, step_s, &report) != SS_OK) {
        fprintf(stderr, "%s: t = %.6g s: %s\n", game->name, time_s, ssLastError());
        code = 1;
        break;
      }
      time_s = report.time_s;
      game->read(game, values);
      printed = ssAuditRun_Row(&run, time_s, game->count, values, &report);
    } else {
      if (step_s > 0) gameOwnFrame(game, time_s, step_s);
      time_s += step_s;
      game->read(game, values);
      printed = ssAuditRun_OwnRow(&run, time_s, game->count, values,
                                  step_s > 0 ? (game->own_substeps > 1 ? game->own_substeps : 1) : 0);
    }
    if (!printed) {
      fprintf(stderr, "%s: t = %.6g s: a quantity is not finite\n", game->name, time_s);
      code = 1;
      break;
    }
  }
  ssAuditRun_Finish(&run);
  ssStepper_Destroy(stepper);
  dJointGroupDestroy(game->contacts);
  dSpaceDestroy(game->space);
  dWorldDestroy(game->world);
  dCloseODE();
  return code;
}

/* A dynamic box of the given size (m) and mass (kg) at (x, y, z), with its geom in the game's space. */
static inline dBodyID gameBox(Game* game, double sx, double sy, double sz, double mass_kg, double x, double y,
                              double z) {
  dBodyID body = dBodyCreate(game->world);
  dMass mass;
  dMassSetBoxTotal(&mass, mass_kg, sx, sy, sz);
  dBodySetMass(body, &mass);
  dBodySetPosition(body, x, y, z);
  dGeomSetBody(dCreateBox(game->space, sx, sy, sz), body);
  return body;
}

#endif

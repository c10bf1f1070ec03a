/* Fuzz target: what a program does from the stepper's own callbacks, and the states it sets between frames, on the
 * small worlds of fuzz_world.h.
 *
 * The input arms actions, each for one callback (before_step, collide, step_done) at one step index of the frame
 * or at every step: add a force or a torque (any double: NaN, infinities, huge), set a body's position, velocity or
 * spin (likewise), destroy a body or a joint through ssStepper_DestroyBody/DestroyJoint, or re-enter the stepper
 * (ssStepper_Step, SetStepping, Reset, ResetHistory, Destroy) from inside its own callback. Between frames it steps
 * frames of any length, sets states and forces as a program does (a spin read from a corrupt save, a teleport),
 * changes the stepping, calls ssStepper_Reset with or without repairing the bodies first, and disarms the actions.
 *
 * Promises checked: the process never aborts and no sanitizer reports (ODE's asserts included: nothing the program
 * does the ordinary way may make ODE abort); every refusal is a named ssStatus with a non-empty ssLastError(); a
 * frame reported OK that took a step leaves every body finite (unless the program itself set a state after the
 * frame's last check, in the last step_done); ssStepper_Step and SetStepping from a callback are refused with
 * SS_ERROR_REENTERED, and Reset records why it did nothing; a frame whose callback destroyed its stepper returns
 * SS_OK (stepper.h). */
#include "fuzz_world.h"

enum { MAX_OPS = 40, MAX_ACTIONS = 6, EVERY_STEP = -1 };

typedef enum When { WHEN_BEFORE_STEP, WHEN_COLLIDE, WHEN_STEP_DONE, WHEN_COUNT } When;

typedef enum What {
  ADD_FORCE, SET_STATE, DESTROY_BODY, DESTROY_JOINT, REENTER_STEP, REENTER_SET_STEPPING, REENTER_RESET,
  REENTER_RESET_HISTORY, REENTER_DESTROY, WHAT_COUNT
} What;

static const char* const WHEN_NAMES[WHEN_COUNT] = {"before_step", "collide", "step_done"};
static const char* const WHAT_NAMES[WHAT_COUNT] = {"add force", "set state", "destroy body", "destroy joint",
                                                   "Step", "SetStepping", "Reset", "ResetHistory", "Destroy"};

typedef struct Action {
  When when;
  What what;
  int step;         /* the step index within the frame it fires at, or EVERY_STEP */
  uint8_t target;   /* the body or joint, by pickBody / pickJoint */
  uint8_t which;    /* ADD_FORCE and SET_STATE: what of the body (see push and setState) */
  double values[3]; /* the vector; REENTER_STEP: values[0] is the frame (s) */
  uint8_t policy;   /* REENTER_SET_STEPPING: the policy index (one past the end is NULL) */
} Action;

typedef struct Program {
  World w;
  Action actions[MAX_ACTIONS];
  int action_count;
  int in_action;          /* an action is running: callbacks it causes (a re-entered frame) fire none */
  int steps_done;         /* step_done calls in this frame: step_done gets no step index */
  int set_after_check;    /* a state was set in step_done, after the frame's last check */
  int stepper_destroyed;  /* ssStepper_Destroy was called from a callback in this frame */
} Program;

static Program program;

static int named(ssStatus status) {
  return (int)status >= 0 && strcmp(ssStatusName(status), "unknown status") != 0;
}

/* A refusal is a named status with a message. */
static void checkStatus(ssStatus status, const char* what) {
  FUZZ_REQUIRE(named(status), "%s returned an unnamed status %d", what, (int)status);
  FUZZ_REQUIRE(status == SS_OK || ssLastError()[0] != '\0', "%s refused (%s) without a message", what,
               ssStatusName(status));
}

/* Forgets the body (and its geom) or the joint in the islands' lists, once the stepper destroyed it. */
static void forgetBody(World* w, dBodyID body) {
  for (int k = 0; k < ISLAND_COUNT; ++k) {
    Island* island = &w->islands[k];
    for (int i = 0; i < island->body_count; ++i)
      if (island->bodies[i] == body) {
        for (int j = i + 1; j < island->body_count; ++j) {
          island->bodies[j - 1] = island->bodies[j];
          island->geoms[j - 1] = island->geoms[j];
          memcpy(island->built_at[j - 1], island->built_at[j], sizeof island->built_at[j]);
        }
        island->body_count -= 1;
        island->bodies[island->body_count] = 0;
        island->geoms[island->body_count] = 0;
        return;
      }
  }
}

static void forgetJoint(World* w, dJointID joint) {
  for (int k = 0; k < ISLAND_COUNT; ++k) {
    Island* island = &w->islands[k];
    for (int i = 0; i < island->joint_count; ++i)
      if (island->joints[i] == joint) {
        for (int j = i + 1; j < island->joint_count; ++j) island->joints[j - 1] = island->joints[j];
        island->joint_count -= 1;
        island->joints[island->joint_count] = 0;
        return;
      }
  }
}

static dGeomID geomOf(World* w, dBodyID body) {
  for (int k = 0; k < ISLAND_COUNT; ++k)
    for (int i = 0; i < w->islands[k].body_count; ++i)
      if (w->islands[k].bodies[i] == body) return w->islands[k].geoms[i];
  return 0;
}

/* A program's destroying of a body: its geom first (never inside dSpaceCollide: actions run outside it), then the
 * stepper's DestroyBody. */
static void destroyBody(World* w, ssStepper* stepper, dBodyID body) {
  dGeomID geom = geomOf(w, body);
  if (geom != 0) {
    dGeomSetBody(geom, 0);
    dGeomDisable(geom); /* a geom without a body sits in the space until the body is gone */
  }
  ssStatus status = ssStepper_DestroyBody(stepper, body);
  checkStatus(status, "ssStepper_DestroyBody");
  if (status == SS_OK) {
    if (geom != 0) dGeomDestroy(geom);
    forgetBody(w, body);
  } else if (geom != 0) {
    dGeomSetBody(geom, body);
    dGeomEnable(geom);
  }
}

/* Adds a force or torque the ordinary ways: which % 4 is world force, world torque, relative force, force at a
 * relative point (which also adds its torque). */
static void push(dBodyID body, uint8_t which, const double* v) {
  switch (which % 4) {
    case 0: dBodyAddForce(body, v[0], v[1], v[2]); break;
    case 1: dBodyAddTorque(body, v[0], v[1], v[2]); break;
    case 2: dBodyAddRelForce(body, v[0], v[1], v[2]); break;
    default: dBodyAddForceAtRelPos(body, v[0], v[1], v[2], 0.1, 0, 0); break;
  }
}

/* Sets a state the way a program does: which % 3 is the position, the velocity, the spin. */
static void setState(World* w, dBodyID body, uint8_t which, const double* v) {
  switch (which % 3) {
    case 0: teleport(w, body, v[0], v[1], v[2]); break;
    case 1: dBodySetLinearVel(body, v[0], v[1], v[2]); break;
    default: dBodySetAngularVel(body, v[0], v[1], v[2]); break;
  }
}

static void fire(Program* p, ssStepper* stepper, const Action* a) {
  World* w = &p->w;
  if (verbose)
    fprintf(stderr, "  in %s: %s (target %d, which %d, %.17g %.17g %.17g)\n", WHEN_NAMES[a->when],
            WHAT_NAMES[a->what], a->target, a->which, a->values[0], a->values[1], a->values[2]);
  switch (a->what) {
    case ADD_FORCE: {
      dBodyID body = pickBody(w, a->target);
      if (body != 0) push(body, a->which, a->values);
      break;
    }
    case SET_STATE: {
      dBodyID body = pickBody(w, a->target);
      if (body == 0) break;
      setState(w, body, a->which, a->values);
      if (a->when == WHEN_STEP_DONE) p->set_after_check = 1;
      break;
    }
    case DESTROY_BODY: {
      dBodyID body = pickBody(w, a->target);
      if (body != 0) {
        destroyBody(w, stepper, body);
      } else {
        ssStatus status = ssStepper_DestroyBody(stepper, 0);
        FUZZ_REQUIRE(status != SS_OK, "ssStepper_DestroyBody(NULL) accepted");
        checkStatus(status, "ssStepper_DestroyBody(NULL)");
      }
      break;
    }
    case DESTROY_JOINT: {
      dJointID joint = pickJoint(w, a->target);
      ssStatus status = ssStepper_DestroyJoint(stepper, joint);
      checkStatus(status, "ssStepper_DestroyJoint");
      if (joint == 0) FUZZ_REQUIRE(status != SS_OK, "ssStepper_DestroyJoint(NULL) accepted");
      if (status == SS_OK) forgetJoint(w, joint);
      break;
    }
    case REENTER_STEP: {
      if (!withinBudget(w, a->values[0])) break;
      ssFrameReport report;
      ssStatus status = ssStepper_Step(stepper, a->values[0], &report);
      if (verbose) fprintf(stderr, "    = %s %s\n", ssStatusName(status), status == SS_OK ? "" : ssLastError());
      FUZZ_REQUIRE(status == SS_ERROR_REENTERED && ssLastError()[0] != '\0', "ssStepper_Step from a callback: %s",
                   ssStatusName(status));
      break;
    }
    case REENTER_SET_STEPPING: {
      ssStepping stepping = w->stepping;
      const char* name = ssSteppingPolicyNameAt(a->policy % (ssSteppingPolicyCount() + 1));
      if (ssSteppingForPolicy(name, 1.0 / 60, &stepping) != SS_OK) break;
      ssStatus status = ssStepper_SetStepping(stepper, &stepping);
      if (verbose) fprintf(stderr, "    = %s %s\n", ssStatusName(status), status == SS_OK ? "" : ssLastError());
      FUZZ_REQUIRE(status == SS_ERROR_REENTERED && ssLastError()[0] != '\0',
                   "ssStepper_SetStepping from a callback: %s", ssStatusName(status));
      break;
    }
    case REENTER_RESET:
      ssStepper_Reset(stepper);
      FUZZ_REQUIRE(strstr(ssLastError(), "ssStepper_Reset") != NULL, "ssStepper_Reset from a callback said nothing");
      break;
    case REENTER_RESET_HISTORY: ssStepper_ResetHistory(stepper); break;
    case REENTER_DESTROY:
      ssStepper_Destroy(stepper);
      p->stepper_destroyed = 1;
      break;
    default: break;
  }
}

/* Runs the actions armed for this callback and step, in the outermost frame only, and not after the stepper was
 * destroyed (the program no longer has it). */
static void runActions(Program* p, ssStepper* stepper, When when, int step) {
  if (p->in_action) return;
  p->in_action = 1;
  for (int i = 0; i < p->action_count && !p->stepper_destroyed; ++i) {
    const Action* a = &p->actions[i];
    if (a->when == when && (a->step == EVERY_STEP || a->step == step)) fire(p, stepper, a);
  }
  p->in_action = 0;
}

static void beforeStep(void* context, ssStepper* stepper) {
  Program* p = context;
  p->set_after_check = 0;
  runActions(p, stepper, WHEN_BEFORE_STEP, ssStepper_CurrentStep(stepper).index);
}

static void collide(void* context, ssStepper* stepper) {
  Program* p = context;
  runActions(p, stepper, WHEN_COLLIDE, ssStepper_CurrentStep(stepper).index);
  if (!p->stepper_destroyed) collideAll(&p->w, stepper);
}

static void stepDone(void* context, double step_s) {
  (void)step_s;
  Program* p = context;
  if (p->in_action) return;
  runActions(p, p->w.stepper, WHEN_STEP_DONE, p->steps_done++);
}

static ssStepperDef programDef(void) {
  ssStepperDef def = ssDefaultStepperDef();
  def.before_step = beforeStep;
  def.before_step_context = &program;
  def.collide = collide;
  def.collide_context = &program;
  def.step_done = stepDone;
  def.step_done_context = &program;
  return def;
}

/* After ssStepper_Destroy from a callback: the program makes a new stepper with the stepping it had, and watches its
 * bodies again. */
static void replaceStepper(Program* p) {
  World* w = &p->w;
  ssStepperDef def = programDef();
  def.world = w->world;
  def.registry = w->registry;
  def.contact_group = w->contacts;
  def.stepping = w->stepping;
  /* the world may have been adopted since the first stepper was made: one made now freezes at the tuned step, since
   * any other frozen step is refused (stepping.h) */
  if (def.stepping.frozen_step_s > 0 && ssRegistry_TunedStep(def.registry) > 0)
    def.stepping.frozen_step_s = SS_FROZEN_AT_TUNED_STEP;
  FUZZ_REQUIRE(ssStepper_Create(&def, &w->stepper) == SS_OK, "a stepper like the destroyed one: %s", ssLastError());
  w->stepping = ssStepper_Stepping(w->stepper);
  for (int k = 0; k < ISLAND_COUNT; ++k)
    for (int i = 0; i < w->islands[k].body_count; ++i)
      FUZZ_REQUIRE(ssStepper_WatchBody(w->stepper, w->islands[k].bodies[i]) == SS_OK, "watch: %s", ssLastError());
  p->stepper_destroyed = 0;
}

/* One frame; a frame beyond the step budget is not stepped. After a failure the input goes on: the program may
 * repair, reset without repairing, or step again. */
static void frame(Program* p, double frame_s, int op) {
  World* w = &p->w;
  if (!withinBudget(w, frame_s)) return;
  p->steps_done = 0;
  p->set_after_check = 0;
  ssFrameReport report;
  memset(&report, 0, sizeof report); /* what a refusal leaves unwritten reads as nothing */
  ssStatus status = ssStepper_Step(w->stepper, frame_s, &report);
  if (verbose)
    fprintf(stderr, "op %d: %s/%s frame %.17g s: %s, %d steps, %s\n", op,
            NAME_OR_UNKNOWN(ssFrameCutName(w->stepping.cut)), NAME_OR_UNKNOWN(ssMappingName(w->stepping.mapping)),
            frame_s, ssStatusName(status), report.steps, status == SS_OK ? "" : ssLastError());
  checkStatus(status, "ssStepper_Step");
  if (p->stepper_destroyed) {
    /* stepper.h: the frame stops where it is, the report is filled, SS_OK, and the stepper is freed. */
    FUZZ_REQUIRE(status == SS_OK, "op %d: the frame that destroyed its stepper returned %s", op, ssStatusName(status));
    replaceStepper(p);
    return;
  }
  w->steps_left -= report.steps > 0 ? report.steps : 0;
  /* A frame that takes no step (0 s, or carried over) hands ODE nothing: a state the program set stays as set. */
  if (status == SS_OK && report.steps > 0 && !p->set_after_check) {
    BodyState after[STATE_CAPACITY];
    int count = snapshot(w, after), which = -1;
    FUZZ_REQUIRE(allFinite(after, count, &which), "op %d: frame %.17g s reported OK but body %d is not finite", op,
                 frame_s, which);
  }
  if (status == SS_ERROR_BLOWUP || status == SS_ERROR_SPEED_LIMIT)
    FUZZ_REQUIRE(report.failed_body != 0, "op %d: %s without a body", op, ssStatusName(status));
}

/* What a program does after a refused frame: every body back where it was built, at rest, no forces. */
static void repair(World* w) {
  for (int k = 0; k < ISLAND_COUNT; ++k)
    for (int i = 0; i < w->islands[k].body_count; ++i) {
      dBodyID body = w->islands[k].bodies[i];
      const dReal* at = w->islands[k].built_at[i];
      dBodySetPosition(body, at[0], at[1], at[2]);
      dBodySetLinearVel(body, 0, 0, 0);
      dBodySetAngularVel(body, 0, 0, 0);
      dBodySetForce(body, 0, 0, 0);
      dBodySetTorque(body, 0, 0, 0);
    }
}

static void readVector(FuzzInput* in, double* v) {
  for (int i = 0; i < 3; ++i) v[i] = fuzzDouble(in);
}

/* An action from the input: [when, what, step] [target] [which] [its values]. */
static Action readAction(FuzzInput* in) {
  Action a;
  memset(&a, 0, sizeof a);
  uint8_t kind = fuzz_byte(in);
  a.when = (When)(kind % WHEN_COUNT);
  a.what = (What)((kind / WHEN_COUNT) % WHAT_COUNT);
  uint8_t step = fuzz_byte(in);
  a.step = step & 0x80 ? EVERY_STEP : step % 8;
  a.target = fuzz_byte(in);
  a.which = fuzz_byte(in);
  switch (a.what) {
    case ADD_FORCE:
    case SET_STATE: readVector(in, a.values); break;
    case REENTER_STEP: a.values[0] = fuzzDouble(in); break;
    case REENTER_SET_STEPPING: a.policy = a.which; break;
    default: break;
  }
  return a;
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzInput in = {data, size};
  Program* p = &program;
  memset(p, 0, sizeof *p);
  ssStepperDef def = programDef();
  makeWorld(&p->w, &in, &def);
  World* w = &p->w;
  for (int op = 0; op < MAX_OPS && !fuzzEmpty(&in); ++op) {
    uint8_t code = fuzz_byte(&in);
    if (verbose) fprintf(stderr, "op %d: code %d\n", op, code % 9);
    switch (code % 9) {
      case 0:
        frame(p, fuzzDouble(&in), op);
        break;
      case 1: {
        int repeat = 1 + fuzz_byte(&in) % 8;
        double frame_s = fuzzDouble(&in);
        for (int i = 0; i < repeat; ++i) frame(p, frame_s, op);
        break;
      }
      case 2: {
        Action a = readAction(&in);
        if (p->action_count < MAX_ACTIONS) p->actions[p->action_count++] = a;
        if (verbose)
          fprintf(stderr, "  armed %s in %s at step %d\n", WHAT_NAMES[a.what], WHEN_NAMES[a.when], a.step);
        break;
      }
      case 3:
      case 4: {
        /* Between frames: a state set (a teleport, a corrupt save) or a force added, any value. */
        dBodyID body = pickBody(w, fuzz_byte(&in));
        uint8_t which = fuzz_byte(&in);
        double v[3];
        readVector(&in, v);
        if (body == 0) break;
        if (code % 9 == 3) setState(w, body, which, v);
        else push(body, which, v);
        if (verbose)
          fprintf(stderr, "  %s %d: %.17g %.17g %.17g\n", code % 9 == 3 ? "state" : "force", which, v[0], v[1], v[2]);
        break;
      }
      case 5:
        repair(w);
        ssStepper_Reset(w->stepper);
        break;
      case 6:
        ssStepper_Reset(w->stepper); /* without the repair: the runaway state is still there */
        break;
      case 7: {
        ssStepping stepping = w->stepping;
        const char* name = ssSteppingPolicyNameAt(fuzz_byte(&in) % (ssSteppingPolicyCount() + 1));
        if (ssSteppingForPolicy(name, fuzzDouble(&in), &stepping) != SS_OK) break;
        ssStatus status = ssStepper_SetStepping(w->stepper, &stepping);
        checkStatus(status, "ssStepper_SetStepping");
        if (status == SS_OK) w->stepping = ssStepper_Stepping(w->stepper);
        break;
      }
      case 8:
        p->action_count = 0;
        break;
    }
  }
  destroyWorld(w);
  return 0;
}

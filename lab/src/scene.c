/* The table of scenes, and a scene's life: validate, build the world, step it frame by frame, sample it.
 *
 * Everything a caller can get wrong is checked before ODE is touched, so a refused scene leaves no world behind
 * and the message names the value. The stepper gets a speed limit so that a scene that explodes ends its run with
 * SS_ERROR_SPEED_LIMIT instead of running on with nonsense. After every step the scene's sanity bounds are checked
 * (scene.h): the first step outside one is kept, with its time, for the run to end on (a run that is finite but
 * wrong is no error of the library, so it is not an ssStatus). */
#include <float.h>
#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "lab_error.h"
#include "scene_internal.h"
#include "steadystep/interpolation.h"

/* No reference scene moves anything faster than a few m/s; 100 m/s means it exploded. */
#define SS_SCENE_MAX_SPEED_M_PER_S 100.0

static const ssSceneDesc* const scenes[] = {
    &ssOscillatorScene, &ssBuggyScene, &ssDropScene, &ssChainScene, &ssPileScene,
    &ssStackScene,      &ssWallScene,  &ssPistonScene,
};
enum { SCENE_COUNT = sizeof scenes / sizeof scenes[0] };

struct ssScene {
  const ssSceneDesc* desc;
  ssSceneWorld parts;
  void* state;
  double time_s;
  unsigned long ode_random_seed; /* this scene's state of ODE's one global generator */
  ssSceneStepCallback* observer;
  void* observer_context;
  double bound_use;    /* the largest value/bound ratio of the sanity bounds so far */
  int broken;          /* a step has left a sanity bound: broken_message says which */
  char broken_message[256];
  ssSceneCounters counters;
  int timing;          /* inside ssScene_TimeFrames: the lab's own bounds are not checked (scene.h) */
};

static pthread_once_t ode_once = PTHREAD_ONCE_INIT;
static _Thread_local int ode_thread_ready;

static void initOde(void) { dInitODE2(0); }

void ssEnsureOde(void) {
  pthread_once(&ode_once, initOde);
  /* An ODE built with thread-local collision data needs this on every thread that collides. */
  if (!ode_thread_ready) ode_thread_ready = dAllocateODEDataForThread(dAllocateMaskAll);
}

int ssSceneCount(void) { return SCENE_COUNT; }

const ssSceneInfo* ssSceneInfoAt(int index) {
  if (index < 0 || index >= SCENE_COUNT) return NULL;
  return &scenes[index]->info;
}

static const ssSceneDesc* findDesc(const char* name) {
  if (name == NULL) return NULL;
  for (int i = 0; i < SCENE_COUNT; ++i)
    if (strcmp(scenes[i]->info.name, name) == 0) return scenes[i];
  return NULL;
}

const ssSceneInfo* ssSceneFind(const char* name) {
  const ssSceneDesc* desc = findDesc(name);
  return desc != NULL ? &desc->info : NULL;
}

static ssStatus findOrFail(const char* name, const ssSceneDesc** out) {
  if (name == NULL) return ssLabFail(SS_ERROR_OUT_OF_RANGE, "name = NULL: needs a scene name (oscillator, buggy, ...)");
  *out = findDesc(name);
  if (*out != NULL) return SS_OK;
  char known[128] = ""; /* the table's names, so that a new scene is one line */
  for (int i = 0; i < SCENE_COUNT; ++i) {
    strncat(known, i ? ", " : "", sizeof known - strlen(known) - 1);
    strncat(known, scenes[i]->info.name, sizeof known - strlen(known) - 1);
  }
  return ssLabFail(SS_ERROR_NOT_FOUND, "scene = \"%s\": unknown (%s)", name, known);
}

ssStatus ssDefaultSceneParams(const char* name, ssSceneParams* out) {
  const ssSceneDesc* desc;
  ssStatus status = findOrFail(name, &desc);
  if (status != SS_OK) return status;
  if (out == NULL) return ssLabFail(SS_ERROR_OUT_OF_RANGE, "out = NULL: needs somewhere to write the parameters");
  *out = desc->defaults;
  return SS_OK;
}

ssStatus ssLabStepping(const char* policy, ssStepping* out) {
  if (out == NULL) return ssLabFail(SS_ERROR_OUT_OF_RANGE, "out = NULL: needs somewhere to write the stepping");
  ssStepping stepping = ssDefaultStepping();
  stepping.solver = SS_SOLVER_QUICK;
  stepping.max_step_s = SS_LAB_STEP_S;
  stepping.fixed_step_s = SS_LAB_STEP_S;
  ssStatus status = ssSteppingForPolicy(policy, SS_LAB_NAIVE_REFERENCE_STEP_S, &stepping);
  if (status == SS_OK) *out = stepping;
  return status;
}

ssStepping ssReferenceStepping(double step_s) {
  ssStepping stepping = ssDefaultStepping();
  stepping.solver = SS_SOLVER_QUICK;
  stepping.max_step_s = step_s;
  stepping.fixed_step_s = step_s;
  return stepping;
}

static ssStatus validateParams(const ssSceneDesc* desc, const ssSceneParams* params) {
  ssStatus status = ssValidateSpring(params->spring);
  if (status == SS_OK) status = ssLabCheckRange("mass", "kg", params->mass, SS_MIN_MASS_KG, SS_MAX_MASS_KG);
  if (status == SS_OK) status = ssLabCheckRange("x0", "m", params->x0, -DBL_MAX, DBL_MAX);
  if (status == SS_OK) status = ssLabCheckRange("gravity", "m/s^2", params->gravity, -DBL_MAX, DBL_MAX);
  if (status != SS_OK) return status;
  /* A scene is a few metres across and moves at a few m/s; far beyond that, ODE's products overflow in a step. */
  if (!(fabs(params->x0) <= SS_SCENE_MAX_X0_M))
    return ssLabFail(SS_ERROR_OUT_OF_RANGE, "x0 = %g m: must be within +-%g m", params->x0, SS_SCENE_MAX_X0_M);
  if (!(fabs(params->gravity) <= SS_SCENE_MAX_GRAVITY_M_PER_S2))
    return ssLabFail(SS_ERROR_OUT_OF_RANGE, "gravity = %g m/s^2: must be within +-%g m/s^2", params->gravity,
                     SS_SCENE_MAX_GRAVITY_M_PER_S2);
  if (params->body_count < 0)
    return ssLabFail(SS_ERROR_OUT_OF_RANGE, "body_count = %d: must not be negative (0 = the scene's default)",
                     params->body_count);
  if (desc->max_body_count > 0 && params->body_count > desc->max_body_count)
    return ssLabFail(SS_ERROR_OUT_OF_RANGE, "body_count = %d: scene \"%s\" takes at most %d", params->body_count,
                     desc->info.name, desc->max_body_count);
  return SS_OK;
}

void ssBoundMessage(char* worst, size_t size, const char* format, ...) {
  if (worst == NULL) return;
  va_list arguments;
  va_start(arguments, format);
  vsnprintf(worst, size, format, arguments);
  va_end(arguments);
}

static void checkBounds(ssScene* scene) {
  if (scene->desc->check == NULL || scene->timing) return;
  double use = scene->desc->check(scene->state, NULL, 0);
  if (use > scene->bound_use) scene->bound_use = use;
  if (use > 1 && !scene->broken) {
    char worst[192] = "";
    scene->desc->check(scene->state, worst, sizeof worst); /* the same state: the same bound, now named */
    scene->broken = 1;
    snprintf(scene->broken_message, sizeof scene->broken_message, "t = %.9g s: %s %s", scene->time_s,
             scene->desc->info.name, worst);
  }
}

static void sceneStepDone(void* context, double step_s) {
  ssScene* scene = context;
  scene->time_s += step_s;
  checkBounds(scene);
  if (scene->observer != NULL) scene->observer(scene->observer_context, scene, step_s);
}

/* The stepper's before_step: the scene's per-step input for the step about to be taken. */
static void sceneBeforeStep(void* context, ssStepper* stepper) {
  ssScene* scene = context;
  scene->desc->drive(scene->state, ssStepper_CurrentStep(stepper).step_s);
}

static void freeWorld(ssSceneWorld* parts) {
  ssStepper_Destroy(parts->stepper);
  ssRegistry_Destroy(parts->registry);
  if (parts->contacts != 0) dJointGroupDestroy(parts->contacts);
  if (parts->space != 0) dSpaceDestroy(parts->space);
  if (parts->world != 0) dWorldDestroy(parts->world);
}

static ssStatus makeStepper(ssScene* scene, const ssStepping* stepping) {
  ssStepperDef def = ssDefaultStepperDef();
  def.world = scene->parts.world;
  def.registry = scene->parts.registry;
  def.stepping = *stepping;
  /* a frozen softness means the scene's numbers as they were tuned: an adopted scene's at its tuned step (naive is
   * then the program's own stepping), springs bound by hand at the lab's reference step (ssLabStepping) */
  if (def.stepping.frozen_step_s != 0 && ssRegistry_TunedStep(def.registry) > 0)
    def.stepping.frozen_step_s = SS_FROZEN_AT_TUNED_STEP;
  def.stepping.max_speed = fmin(stepping->max_speed > 0 ? stepping->max_speed : SS_MAX_SAFE_SPEED,
                                SS_SCENE_MAX_SPEED_M_PER_S);
  def.before_step = scene->desc->drive != NULL ? sceneBeforeStep : NULL;
  def.before_step_context = scene;
  def.collide = scene->desc->collide;
  def.collide_context = scene->state;
  def.step_done = sceneStepDone;
  def.step_done_context = scene;
  def.contact_group = scene->parts.contacts;
  ssStatus status = ssStepper_Create(&def, &scene->parts.stepper);
  if (status != SS_OK) return status;
  if (scene->desc->watch != NULL) status = scene->desc->watch(scene->state, scene->parts.stepper);
  return status;
}

ssStatus ssScene_Create(const char* name, const ssSceneParams* params, const ssStepping* stepping, ssScene** out) {
  const ssSceneDesc* desc;
  ssStatus status = findOrFail(name, &desc);
  if (status != SS_OK) return status;
  if (params == NULL || stepping == NULL || out == NULL)
    return ssLabFail(SS_ERROR_OUT_OF_RANGE, "%s = NULL: ssScene_Create needs params, stepping and out",
                     params == NULL ? "params" : stepping == NULL ? "stepping" : "out");
  status = validateParams(desc, params);
  if (status == SS_OK) status = ssValidateStepping(stepping);
  if (status != SS_OK) return status;

  ssSceneParams resolved = *params;
  if (resolved.body_count == 0) resolved.body_count = desc->defaults.body_count;

  ssScene* scene = calloc(1, sizeof *scene);
  if (scene == NULL) return ssLabFail(SS_ERROR_OUT_OF_MEMORY, "scene \"%s\": out of memory", name);
  scene->desc = desc;
  ssEnsureOde();
  scene->parts.world = dWorldCreate();
  scene->parts.space = dHashSpaceCreate(0);
  scene->parts.contacts = dJointGroupCreate(0);
  scene->parts.registry = ssRegistry_Create(scene->parts.world);
  if (scene->parts.registry == NULL) {
    status = ssLabFail(SS_ERROR_OUT_OF_MEMORY, "scene \"%s\": out of memory for the registry", name);
  } else {
    status = desc->build(&scene->parts, &resolved, &scene->state);
  }
  if (status == SS_OK) status = makeStepper(scene, stepping);
  if (status != SS_OK) {
    if (scene->state != NULL) desc->destroy(scene->state);
    freeWorld(&scene->parts);
    free(scene);
    return status;
  }
  *out = scene;
  return SS_OK;
}

void ssScene_Destroy(ssScene* scene) {
  if (scene == NULL) return;
  ssStepper_Destroy(scene->parts.stepper);
  scene->parts.stepper = NULL;
  scene->desc->destroy(scene->state);
  freeWorld(&scene->parts);
  free(scene);
}

static void addServed(ssSceneServedCounts* sum, const ssServedCounts* counts) {
  sum->by_mapping += counts->by_mapping;
  sum->handed_to_matched += counts->handed_to_matched;
  sum->handed_to_implicit_euler += counts->handed_to_implicit_euler;
}

ssStatus ssScene_Frame(ssScene* scene, double frame_s, int* steps) {
  if (scene == NULL) return ssLabFail(SS_ERROR_OUT_OF_RANGE, "scene = NULL: no scene to step");
  ssEnsureOde();
  /* dWorldQuickStep shuffles its constraints with ODE's process-wide generator. Giving each scene its own state of
   * it makes a run the same whatever ran before it in the process (or between its frames, on the same thread). */
  dRandSetSeed(scene->ode_random_seed);
  ssFrameReport report = {0};
  ssStatus status = ssStepper_Step(scene->parts.stepper, frame_s, &report);
  scene->ode_random_seed = dRandGetSeed();
  if (steps != NULL) *steps = report.steps;
  ssSceneCounters* counters = &scene->counters;
  ++counters->frames;
  counters->steps += report.steps;
  addServed(&counters->rows, &report.rows);
  addServed(&counters->contacts, &report.contacts);
  counters->row_writes += report.row_writes;
  return status;
}

ssSceneCounters ssScene_Counters(const ssScene* scene) {
  if (scene != NULL) return scene->counters;
  ssLabFail(SS_ERROR_OUT_OF_RANGE, "scene = NULL: no scene to read counters from");
  return (ssSceneCounters){0};
}

int ssScene_Points(const ssScene* scene, double* xyz, int capacity) {
  if (scene == NULL || capacity < 0 || (xyz == NULL && capacity > 0)) {
    ssLabFail(SS_ERROR_OUT_OF_RANGE, "%s: ssScene_Points needs a scene, capacity >= 0 and xyz for capacity > 0",
              scene == NULL ? "scene = NULL" : capacity < 0 ? "capacity < 0" : "xyz = NULL");
    return 0;
  }
  if (scene->desc->points == NULL) return 0;
  return scene->desc->points(scene->state, NULL, xyz, capacity);
}

int ssScene_InterpolatedPoints(const ssScene* scene, double* xyz, int capacity) {
  if (scene == NULL || capacity < 0 || (xyz == NULL && capacity > 0)) {
    ssLabFail(SS_ERROR_OUT_OF_RANGE,
              "%s: ssScene_InterpolatedPoints needs a scene, capacity >= 0 and xyz for capacity > 0",
              scene == NULL ? "scene = NULL" : capacity < 0 ? "capacity < 0" : "xyz = NULL");
    return 0;
  }
  if (scene->desc->points == NULL) return 0;
  return scene->desc->points(scene->state, scene->parts.stepper, xyz, capacity);
}

void ssScenePointOnBody(const ssStepper* drawn_by, dBodyID body, const double rel[3], double out[3]) {
  double position[3], q[4];
  if (drawn_by == NULL || ssStepper_InterpolatedPose(drawn_by, body, position, q) != SS_OK) {
    dVector3 point;
    dBodyGetRelPointPos(body, rel[0], rel[1], rel[2], point);
    for (int k = 0; k < 3; ++k) out[k] = point[k];
    return;
  }
  /* position + R(q) rel, R the rotation of the unit quaternion (w, x, y, z), as ODE's dQtoR. */
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  const double r[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                          {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                          {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}};
  for (int k = 0; k < 3; ++k) out[k] = position[k] + r[k][0] * rel[0] + r[k][1] * rel[1] + r[k][2] * rel[2];
}

/* The enabled bodies of space's geoms (and of its nested spaces'), each counted once: a body with several geoms is
 * counted at its first geom in the walk (seen[], of at most capacity bodies; past it a body may count twice). */
static int awakeIn(dSpaceID space, dBodyID* seen, int* seen_count, int capacity) {
  int awake = 0;
  int geoms = dSpaceGetNumGeoms(space);
  for (int i = 0; i < geoms; ++i) {
    dGeomID geom = dSpaceGetGeom(space, i);
    if (dGeomIsSpace(geom)) {
      awake += awakeIn((dSpaceID)geom, seen, seen_count, capacity);
      continue;
    }
    dBodyID body = dGeomGetBody(geom);
    if (body == 0) continue;
    int known = 0;
    for (int j = 0; j < *seen_count && !known; ++j) known = seen[j] == body;
    if (known) continue;
    if (*seen_count < capacity) seen[(*seen_count)++] = body;
    awake += dBodyIsEnabled(body) != 0;
  }
  return awake;
}

int ssScene_AwakeBodies(const ssScene* scene) {
  if (scene == NULL) {
    ssLabFail(SS_ERROR_OUT_OF_RANGE, "scene = NULL: no scene to count the awake bodies of");
    return -1;
  }
  enum { SEEN_CAPACITY = 4096 };
  dBodyID* seen = malloc(SEEN_CAPACITY * sizeof *seen);
  int seen_count = 0;
  int awake = awakeIn(scene->parts.space, seen, &seen_count, seen != NULL ? SEEN_CAPACITY : 0);
  free(seen);
  return awake;
}

/* The calling thread's CPU time (s): what the timed frames cost this thread, not what other work on a shared machine
 * took from it meanwhile (wall time would count that too). */
static double threadCpuSeconds(void) {
  struct timespec now;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
  return (double)now.tv_sec + 1e-9 * (double)now.tv_nsec;
}

/* What a program without the library does each frame: its per-step input (the stack's push, the piston's motor)
 * for the frame's one step, collide, one step of the whole frame, empty the contacts. Softness stays as the stepper
 * last wrote it; the contacts are softened as for the stepper's last step. */
static ssStatus plainFrame(ssScene* scene, double frame_s) {
  const ssSceneWorld* parts = &scene->parts;
  if (scene->desc->drive != NULL) scene->desc->drive(scene->state, frame_s);
  if (scene->desc->collide != NULL) scene->desc->collide(scene->state, parts->stepper);
  if (ssStepper_Stepping(parts->stepper).solver == SS_SOLVER_STEP) {
    dWorldStep(parts->world, frame_s);
  } else {
    dWorldQuickStep(parts->world, frame_s);
  }
  dJointGroupEmpty(parts->contacts);
  scene->time_s += frame_s;
  double sample[SS_MAX_QUANTITIES];
  scene->desc->sample(scene->state, sample);
  for (int i = 0; i < scene->desc->info.quantity_count; ++i)
    if (!isfinite(sample[i]))
      return ssLabFail(SS_ERROR_BLOWUP, "plain frame at t = %g s: %s is not finite", scene->time_s,
                       scene->desc->info.quantity_names[i]);
  return SS_OK;
}

ssStatus ssScene_TimeFrames(ssScene* scene, const double* frames_s, int count, int plain, double* cpu_s) {
  if (scene == NULL || frames_s == NULL || cpu_s == NULL)
    return ssLabFail(SS_ERROR_OUT_OF_RANGE, "%s = NULL: ssScene_TimeFrames needs a scene, frames and cpu_s",
                     scene == NULL ? "scene" : frames_s == NULL ? "frames_s" : "cpu_s");
  if (count < 0) return ssLabFail(SS_ERROR_OUT_OF_RANGE, "count = %d: must not be negative", count);
  if (plain != 0 && plain != 1) return ssLabFail(SS_ERROR_OUT_OF_RANGE, "plain = %d: must be 0 or 1", plain);
  if (plain && scene->counters.frames == 0)
    return ssLabFail(SS_ERROR_OUT_OF_RANGE, "plain = 1: step one frame with ssScene_Frame first, so that every "
                                         "softness has been written");
  for (int i = 0; plain && i < count; ++i)
    if (!(frames_s[i] >= SS_MIN_STEP_S && frames_s[i] <= SS_MAX_STEP_S))
      return ssLabFail(SS_ERROR_OUT_OF_RANGE, "frames_s[%d] = %g s: a plain frame is one step, in [%g, %g] s", i,
                       frames_s[i], SS_MIN_STEP_S, SS_MAX_STEP_S);
  ssEnsureOde();
  ssStatus status = SS_OK;
  double start_s = threadCpuSeconds();
  if (plain) {
    dRandSetSeed(scene->ode_random_seed);
    for (int i = 0; status == SS_OK && i < count; ++i) status = plainFrame(scene, frames_s[i]);
    scene->ode_random_seed = dRandGetSeed();
  } else {
    scene->timing = 1;
    for (int i = 0; status == SS_OK && i < count; ++i) status = ssScene_Frame(scene, frames_s[i], NULL);
    scene->timing = 0;
  }
  *cpu_s = threadCpuSeconds() - start_s;
  return status;
}

void ssScene_Sample(const ssScene* scene, double* out) {
  if (scene == NULL || out == NULL) {
    ssLabFail(SS_ERROR_OUT_OF_RANGE, "%s = NULL: ssScene_Sample needs a scene and somewhere to write",
              scene == NULL ? "scene" : "out");
    return;
  }
  scene->desc->sample(scene->state, out);
}

double ssScene_Time(const ssScene* scene) {
  if (scene == NULL) {
    ssLabFail(SS_ERROR_OUT_OF_RANGE, "scene = NULL: no scene to read the time of");
    return NAN;
  }
  return scene->time_s;
}

void ssSceneSetStepObserver(ssScene* scene, ssSceneStepCallback* observer, void* context) {
  scene->observer = observer;
  scene->observer_context = context;
}

const char* ssScene_Broken(const ssScene* scene) {
  if (scene == NULL) {
    ssLabFail(SS_ERROR_OUT_OF_RANGE, "scene = NULL: no scene to read the sanity bounds of");
    return NULL;
  }
  return scene->broken ? scene->broken_message : NULL;
}

double ssScene_BoundUse(const ssScene* scene) {
  if (scene == NULL) {
    ssLabFail(SS_ERROR_OUT_OF_RANGE, "scene = NULL: no scene to read the sanity bounds of");
    return NAN;
  }
  return scene->bound_use;
}

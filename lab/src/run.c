/* A run: one scene under one frame-time profile, recorded after every physics step.
 *
 * Records come from the scene's step observer rather than after each frame, because a frame may hold several
 * substeps (or, for policy fixed, none) and the comparison between policies is about the physics, not the frames.
 * The state before the first step is kept apart (initial), so that records and steps stay one to one. The last frame
 * is shortened so that every run ends at duration_s of frame time exactly. A run ends early at the first step that
 * blows up (the stepper's error) or leaves one of the scene's sanity bounds (broken: that step is recorded, the ones
 * after it in its frame are not). A run is bounded (scene.h): its duration, the frames it is expected to take
 * (refused before it starts) and the frames and steps it does take (stopped with an error when an unlucky random
 * profile reaches them). */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "lab_error.h"
#include "profile_internal.h"
#include "scene_internal.h"
#include "steadystep/lab/profile.h"
#include "steadystep/stepper.h"

struct ssRun {
  int count, capacity;
  double* times_s;
  double* steps_s;
  double* quantities[SS_MAX_QUANTITIES];
  double initial[SS_MAX_QUANTITIES];
  int quantity_count;
  int frame_count;
  double wall_s;
  ssStatus status;
  ssRunOutcome outcome;
  double bound_use;
  char message[256];
  int out_of_memory;
  int too_many_steps; /* a step past SS_MAX_RUN_STEPS was not recorded */
  ssSceneCounters counters;
};

void ssRun_Destroy(ssRun* run) {
  if (run == NULL) return;
  free(run->times_s);
  free(run->steps_s);
  for (int i = 0; i < SS_MAX_QUANTITIES; ++i) free(run->quantities[i]);
  free(run);
}

static int grow(double** array, int capacity) {
  double* bigger = realloc(*array, (size_t)capacity * sizeof **array);
  if (bigger == NULL) return 0;
  *array = bigger;
  return 1;
}

static int reserve(ssRun* run, int needed) {
  if (needed <= run->capacity) return 1;
  int capacity = run->capacity > 0 ? 2 * run->capacity : 1024;
  if (!grow(&run->times_s, capacity) || !grow(&run->steps_s, capacity)) return 0;
  for (int i = 0; i < run->quantity_count; ++i)
    if (!grow(&run->quantities[i], capacity)) return 0;
  run->capacity = capacity;
  return 1;
}

static void record(void* context, const ssScene* scene, double step_s) {
  ssRun* run = context;
  if (run->outcome == SS_RUN_BROKEN) return; /* the rest of the frame in which it broke */
  if (run->count >= SS_MAX_RUN_STEPS) {
    run->too_many_steps = 1;
    return;
  }
  if (!reserve(run, run->count + 1)) {
    run->out_of_memory = 1;
    return;
  }
  double sample[SS_MAX_QUANTITIES];
  ssScene_Sample(scene, sample);
  run->times_s[run->count] = ssScene_Time(scene);
  run->steps_s[run->count] = step_s;
  for (int i = 0; i < run->quantity_count; ++i) run->quantities[i][run->count] = sample[i];
  ++run->count;
  const char* broken = ssScene_Broken(scene);
  if (broken != NULL) {
    run->outcome = SS_RUN_BROKEN;
    snprintf(run->message, sizeof run->message, "%s", broken);
  }
}

static double nowSeconds(void) {
  struct timespec now;
  clock_gettime(CLOCK_MONOTONIC, &now);
  return (double)now.tv_sec + 1e-9 * (double)now.tv_nsec;
}

/* Steps frames until duration_s of frame time has passed or a step blows up. */
static ssStatus play(ssRun* run, ssScene* scene, ssProfile* profile, double duration_s) {
  /* Frame times add up with rounding; a remainder this small is the end, not one more frame of 1e-12 s. */
  const double end_tolerance_s = 1e-9 * fmax(1.0, duration_s);
  double elapsed_s = 0;
  while (duration_s - elapsed_s > end_tolerance_s) {
    if (run->frame_count >= SS_MAX_RUN_FRAMES)
      return ssLabFail(SS_ERROR_OUT_OF_RANGE,
                       "run: %d frames and %g of duration_s = %g s left: a run takes at most %d frames",
                       run->frame_count, duration_s - elapsed_s, duration_s, SS_MAX_RUN_FRAMES);
    double frame_s = fmin(ssProfile_Next(profile), duration_s - elapsed_s);
    double start_s = nowSeconds();
    ssStatus status = ssScene_Frame(scene, frame_s, NULL);
    run->wall_s += nowSeconds() - start_s;
    ++run->frame_count;
    elapsed_s += frame_s;
    run->bound_use = ssScene_BoundUse(scene);
    if (run->outcome == SS_RUN_BROKEN) return SS_OK; /* first: it came before anything later in its frame */
    if (run->out_of_memory) return ssLabFail(SS_ERROR_OUT_OF_MEMORY, "run: out of memory after %d steps", run->count);
    if (run->too_many_steps)
      return ssLabFail(SS_ERROR_OUT_OF_RANGE,
                       "run: %d steps after %g s of duration_s = %g s: a run takes at most %d steps", run->count,
                       elapsed_s, duration_s, SS_MAX_RUN_STEPS);
    if (status == SS_ERROR_BLOWUP || status == SS_ERROR_SPEED_LIMIT || status == SS_ERROR_POSITION_LIMIT) {
      run->status = status;
      run->outcome = SS_RUN_BLEW_UP;
      strncpy(run->message, ssLastError(), sizeof run->message - 1);
      return SS_OK;
    }
    if (status != SS_OK) return status;
  }
  return SS_OK;
}

/* The physics steps a run of frames of mean_frame_s will take, roughly: one per frame, more when a policy cuts
 * frames into substeps, duration / fixed_step_s under the accumulator. */
static double expectedSteps(const ssStepping* stepping, double duration_s, double frames, double mean_frame_s) {
  if (stepping->cut == SS_CUT_FIXED) return duration_s / stepping->fixed_step_s;
  if (stepping->cut == SS_CUT_WHOLE_FRAME) return frames;
  return frames * fmax(ceil(mean_frame_s / stepping->max_step_s), 1.0);
}

/* Refuses, before anything runs, a run that would take more frames or steps than scene.h allows. */
static ssStatus checkSize(const ssRunDef* def, const ssProfile* profile) {
  double mean_frame_s = ssProfileMeanFrame(profile);
  double frames = def->duration_s / mean_frame_s;
  if (frames > SS_MAX_RUN_FRAMES)
    return ssLabFail(SS_ERROR_OUT_OF_RANGE,
                     "duration_s = %g s: profile \"%s\" (mean frame %g s) needs about %.3g frames, a run takes at "
                     "most %d",
                     def->duration_s, ssProfile_Spec(profile), mean_frame_s, frames, SS_MAX_RUN_FRAMES);
  double steps = expectedSteps(&def->stepping, def->duration_s, frames, mean_frame_s);
  if (steps > SS_MAX_RUN_STEPS)
    return ssLabFail(SS_ERROR_OUT_OF_RANGE,
                     "duration_s = %g s: cut %s with max_step_s = %g s, fixed_step_s = %g s needs about %.3g steps, "
                     "a run takes at most %d",
                     def->duration_s, ssFrameCutName(def->stepping.cut), def->stepping.max_step_s,
                     def->stepping.fixed_step_s, steps, SS_MAX_RUN_STEPS);
  return SS_OK;
}

ssStatus ssRun_Execute(const ssRunDef* def, ssRun** out) {
  if (def == NULL || out == NULL)
    return ssLabFail(SS_ERROR_OUT_OF_RANGE, "%s = NULL: ssRun_Execute needs a definition and out",
                     def == NULL ? "def" : "out");
  if (def->scene == NULL || def->profile == NULL)
    return ssLabFail(SS_ERROR_OUT_OF_RANGE, "def.%s = NULL: a run needs a scene name and a profile spec",
                     def->scene == NULL ? "scene" : "profile");
  ssStatus status = ssLabCheckRange("duration_s", "s", def->duration_s, -DBL_MAX, DBL_MAX);
  if (status == SS_OK && !(def->duration_s > 0))
    status = ssLabFail(SS_ERROR_OUT_OF_RANGE, "duration_s = %g s: must be positive", def->duration_s);
  if (status == SS_OK && def->duration_s > SS_MAX_RUN_DURATION_S)
    status = ssLabFail(SS_ERROR_OUT_OF_RANGE, "duration_s = %g s: a run lasts at most %g s", def->duration_s,
                       SS_MAX_RUN_DURATION_S);
  if (status != SS_OK) return status;
  const ssSceneInfo* info = ssSceneFind(def->scene);
  if (info == NULL)
    return ssLabFail(SS_ERROR_NOT_FOUND, "scene = \"%.64s\": unknown (oscillator, buggy, drop, chain, pile)",
                     def->scene);
  ssProfile* profile = NULL;
  status = ssProfile_Create(def->profile, def->seed, &profile);
  if (status != SS_OK) return status;
  ssScene* scene = NULL;
  status = ssScene_Create(def->scene, &def->params, &def->stepping, &scene);
  if (status == SS_OK) status = checkSize(def, profile); /* after the scene has checked the stepping's fields */
  ssRun* run = status == SS_OK ? calloc(1, sizeof *run) : NULL;
  if (status == SS_OK && run == NULL) status = ssLabFail(SS_ERROR_OUT_OF_MEMORY, "run: out of memory");
  if (status == SS_OK) {
    run->quantity_count = info->quantity_count;
    ssScene_Sample(scene, run->initial);
    ssSceneSetStepObserver(scene, record, run);
    status = play(run, scene, profile, def->duration_s);
    run->counters = ssScene_Counters(scene);
  }
  ssScene_Destroy(scene);
  ssProfile_Destroy(profile);
  if (status != SS_OK) {
    ssRun_Destroy(run);
    return status;
  }
  *out = run;
  return SS_OK;
}

/* The accessors of a NULL run record why and answer with nothing: 0, NULL, or an error status. */
static int nullRun(const ssRun* run, const char* what) {
  if (run != NULL) return 0;
  ssLabFail(SS_ERROR_OUT_OF_RANGE, "run = NULL: no run to read %s from", what);
  return 1;
}

int ssRun_StepCount(const ssRun* run) { return nullRun(run, "a step count") ? 0 : run->count; }
const double* ssRun_Times(const ssRun* run) { return nullRun(run, "times") ? NULL : run->times_s; }
const double* ssRun_StepLengths(const ssRun* run) { return nullRun(run, "step lengths") ? NULL : run->steps_s; }

const double* ssRun_Quantity(const ssRun* run, int index) {
  if (nullRun(run, "a quantity") || index < 0 || index >= run->quantity_count) return NULL;
  return run->quantities[index];
}

const double* ssRun_Initial(const ssRun* run) { return nullRun(run, "an initial state") ? NULL : run->initial; }

int ssRun_FrameCount(const ssRun* run) { return nullRun(run, "a frame count") ? 0 : run->frame_count; }
double ssRun_WallSeconds(const ssRun* run) { return nullRun(run, "wall seconds") ? 0 : run->wall_s; }
ssStatus ssRun_Status(const ssRun* run) { return nullRun(run, "a status") ? SS_ERROR_OUT_OF_RANGE : run->status; }
ssRunOutcome ssRun_Outcome(const ssRun* run) { return nullRun(run, "an outcome") ? SS_RUN_NONE : run->outcome; }
double ssRun_BoundUse(const ssRun* run) { return nullRun(run, "a bound use") ? NAN : run->bound_use; }
const char* ssRun_Message(const ssRun* run) { return nullRun(run, "a message") ? "" : run->message; }
ssSceneCounters ssRun_Counters(const ssRun* run) {
  return nullRun(run, "counters") ? (ssSceneCounters){0} : run->counters;
}

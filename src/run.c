/* A run: one scene under one frame-time profile, recorded after every physics step.
 *
 * Records come from the scene's step observer rather than after each frame, because a frame may hold several
 * substeps (or, for policy fixed, none) and the comparison between policies is about the physics, not the frames.
 * The last frame is shortened so that every run ends at duration_s of frame time exactly. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "error.h"
#include "scene_internal.h"
#include "steadystep/profile.h"

struct ssRun {
  int count, capacity;
  double* times_s;
  double* steps_s;
  double* quantities[SS_MAX_QUANTITIES];
  int quantity_count;
  int frame_count;
  double wall_s;
  ssStatus status;
  char message[256];
  int out_of_memory;
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
}

static double now_s(void) {
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
    double frame_s = fmin(ssProfile_Next(profile), duration_s - elapsed_s);
    double start_s = now_s();
    ssStatus status = ssScene_Frame(scene, frame_s, NULL);
    run->wall_s += now_s() - start_s;
    ++run->frame_count;
    elapsed_s += frame_s;
    if (run->out_of_memory) return ssFail(SS_ERROR_OUT_OF_MEMORY, "run: out of memory after %d steps", run->count);
    if (status == SS_ERROR_BLOWUP || status == SS_ERROR_SPEED_LIMIT) {
      run->status = status;
      strncpy(run->message, ssLastError(), sizeof run->message - 1);
      return SS_OK;
    }
    if (status != SS_OK) return status;
  }
  return SS_OK;
}

ssStatus ssRun_Execute(const ssRunDef* def, ssRun** out) {
  if (def == NULL || out == NULL)
    return ssFail(SS_ERROR_OUT_OF_RANGE, "%s = NULL: ssRun_Execute needs a definition and out",
                  def == NULL ? "def" : "out");
  ssStatus status = ssCheckPositive("duration_s", "s", def->duration_s);
  if (status != SS_OK) return status;
  const ssSceneInfo* info = ssSceneFind(def->scene);
  if (info == NULL) return ssFail(SS_ERROR_NOT_FOUND, "scene = \"%s\": unknown (oscillator, buggy, drop, chain, pile)",
                                  def->scene != NULL ? def->scene : "(null)");
  ssProfile* profile = NULL;
  status = ssProfile_Create(def->profile, def->seed, &profile);
  if (status != SS_OK) return status;
  ssScene* scene = NULL;
  status = ssScene_Create(def->scene, &def->params, &def->stepping, &scene);
  ssRun* run = status == SS_OK ? calloc(1, sizeof *run) : NULL;
  if (status == SS_OK && run == NULL) status = ssFail(SS_ERROR_OUT_OF_MEMORY, "run: out of memory");
  if (status == SS_OK) {
    run->quantity_count = info->quantity_count;
    ssScene_SetStepObserver(scene, record, run);
    status = play(run, scene, profile, def->duration_s);
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

int ssRun_StepCount(const ssRun* run) { return run->count; }
const double* ssRun_Times(const ssRun* run) { return run->times_s; }
const double* ssRun_StepLengths(const ssRun* run) { return run->steps_s; }

const double* ssRun_Quantity(const ssRun* run, int index) {
  if (index < 0 || index >= run->quantity_count) return NULL;
  return run->quantities[index];
}

int ssRun_FrameCount(const ssRun* run) { return run->frame_count; }
double ssRun_WallSeconds(const ssRun* run) { return run->wall_s; }
ssStatus ssRun_Status(const ssRun* run) { return run->status; }
const char* ssRun_Message(const ssRun* run) { return run->message; }

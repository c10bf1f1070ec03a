/* The pose history of fixed steps (interpolation_internal.h) and the blended pose a program draws
 * (steadystep/interpolation.h). */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "error.h"
#include "interpolation_internal.h"
#include "pointer_set.h"
#include "steadystep/interpolation.h"

typedef struct Pose {
  double position[3];
  double quaternion[4]; /* ODE's (w, x, y, z) */
} Pose;

typedef struct History {
  dBodyID body;
  Pose previous, current;
} History;

struct ssPoseHistory {
  History* bodies;    /* in the order of the stepper's known list */
  dBodyID* ids;       /* bodies[i].body, packed: the check that the known list is unchanged reads nothing else */
  ssPointerMap index; /* body -> its place in bodies */
  int count;
  int restart; /* every body starts again from its pose at the next frame */
  int off;     /* ssStepper_SetInterpolation(stepper, 0): nothing kept */
  double interpolation;
};

/* Element by element: dReal is float in a single-precision ODE. */
static void poseNow(dBodyID body, Pose* pose) {
  const dReal* position = dBodyGetPosition(body);
  const dReal* quaternion = dBodyGetQuaternion(body);
  for (int i = 0; i < 3; ++i) pose->position[i] = position[i];
  for (int i = 0; i < 4; ++i) pose->quaternion[i] = quaternion[i];
}

static void restartAt(History* history) {
  poseNow(history->body, &history->current);
  history->previous = history->current;
}

static const History* find(const ssPoseHistory* history, dBodyID body) {
  int at = ssPointerMapGet(&history->index, body, -1);
  return at >= 0 ? &history->bodies[at] : NULL;
}

/* The same bodies as before, in the same order: nothing to do (the usual frame). */
static int sameBodies(const ssPoseHistory* history, const dBodyID* bodies, int count) {
  return history->count == count && (count == 0 || memcmp(history->ids, bodies, (size_t)count * sizeof *bodies) == 0);
}

static ssStatus make(ssPoseHistory** out) {
  if (*out != NULL) return SS_OK;
  *out = calloc(1, sizeof **out);
  if (*out == NULL) return ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory for the pose history");
  (*out)->restart = 1;
  return SS_OK;
}

ssStatus ssPoseHistoryBeginFrame(ssPoseHistory** out, const dBodyID* bodies, int count) {
  ssStatus status = make(out);
  if (status != SS_OK) return status;
  ssPoseHistory* history = *out;
  if (history->off) return SS_OK;
  if (!sameBodies(history, bodies, count)) {
    History* kept = malloc((size_t)(count > 0 ? count : 1) * sizeof *kept);
    dBodyID* ids = malloc((size_t)(count > 0 ? count : 1) * sizeof *ids);
    ssPointerMap index = {NULL, NULL, 0, 0};
    int indexed = 1;
    for (int i = 0; i < count && indexed; ++i) indexed = ssPointerMapPut(&index, bodies[i], i) >= 0;
    if (kept == NULL || ids == NULL || !indexed) {
      free(kept);
      free(ids);
      ssPointerMapFree(&index);
      return ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory for the pose history of %d bodies", count);
    }
    if (count > 0) memcpy(ids, bodies, (size_t)count * sizeof *ids);
    for (int i = 0; i < count; ++i) {
      const History* old = find(history, bodies[i]);
      if (old != NULL) {
        kept[i] = *old;
      } else {
        kept[i].body = bodies[i];
        restartAt(&kept[i]);
      }
    }
    free(history->bodies);
    free(history->ids);
    ssPointerMapFree(&history->index);
    history->bodies = kept;
    history->ids = ids;
    history->index = index;
    history->count = count;
  }
  if (history->restart) {
    for (int i = 0; i < history->count; ++i) restartAt(&history->bodies[i]);
    history->restart = 0;
    history->interpolation = 0;
  }
  return SS_OK;
}

void ssPoseHistoryBeforeLastStep(ssPoseHistory* history) {
  if (history == NULL || history->off) return;
  for (int i = 0; i < history->count; ++i) poseNow(history->bodies[i].body, &history->bodies[i].previous);
}

void ssPoseHistoryEndFrame(ssPoseHistory* history, int steps, double interpolation) {
  if (history == NULL || history->off) return;
  history->interpolation = interpolation;
  if (steps > 0) {
    for (int i = 0; i < history->count; ++i) poseNow(history->bodies[i].body, &history->bodies[i].current);
    return;
  }
  /* No step: a pose that moved was set by the program (a teleport), drawn where it put it. */
  for (int i = 0; i < history->count; ++i) {
    History* h = &history->bodies[i];
    Pose now;
    poseNow(h->body, &now);
    if (memcmp(&now, &h->current, sizeof now) != 0) {
      h->current = now;
      h->previous = now;
    }
  }
}

void ssPoseHistoryForgetBody(ssPoseHistory* history, dBodyID body) {
  if (history == NULL || history->count == 0) return;
  int at = ssPointerMapGet(&history->index, body, -1), last = history->count - 1;
  if (at < 0) return;
  ssPointerMapRemove(&history->index, body);
  if (at != last) { /* the last takes its place, as on the known list (known_bodies.c) */
    history->bodies[at] = history->bodies[last];
    history->ids[at] = history->ids[last];
    ssPointerMapPut(&history->index, history->ids[at], at); /* replaces a value: allocates nothing */
  }
  history->count = last;
}

void ssPoseHistoryForget(ssPoseHistory* history) {
  if (history != NULL) history->restart = 1;
}

void ssPoseHistoryDestroy(ssPoseHistory* history) {
  if (history == NULL) return;
  free(history->bodies);
  free(history->ids);
  ssPointerMapFree(&history->index);
  free(history);
}

void ssSlerp(const double from[4], const double to[4], double a, double out[4]) {
  double dot = from[0] * to[0] + from[1] * to[1] + from[2] * to[2] + from[3] * to[3];
  double sign = dot < 0 ? -1.0 : 1.0; /* q and -q are one rotation: take the shorter way round */
  dot = fmin(fabs(dot), 1.0);
  double theta = acos(dot), sine = sin(theta);
  double wf, wt;
  if (sine < 1e-9) { /* below that, the linear blend (normalised below) is the slerp to far under 1e-12 */
    wf = 1 - a;
    wt = a;
  } else {
    wf = sin((1 - a) * theta) / sine;
    wt = sin(a * theta) / sine;
  }
  double norm = 0;
  for (int i = 0; i < 4; ++i) {
    out[i] = wf * from[i] + sign * wt * to[i];
    norm += out[i] * out[i];
  }
  norm = sqrt(norm);
  for (int i = 0; i < 4; ++i) out[i] /= norm;
}

ssStatus ssPoseHistoryPose(const ssPoseHistory* history, dBodyID body, double position[3], double quaternion[4]) {
  const History* h = history != NULL ? find(history, body) : NULL;
  if (h == NULL)
    return ssFail(SS_ERROR_NOT_FOUND, "body %p: not known to the stepper at its last frame (bind, adopt or watch "
                  "it)", (void*)body);
  double a = history->interpolation;
  for (int i = 0; i < 3; ++i) position[i] = (1 - a) * h->previous.position[i] + a * h->current.position[i];
  ssSlerp(h->previous.quaternion, h->current.quaternion, a, quaternion);
  return SS_OK;
}

ssStatus ssStepper_InterpolatedPose(const ssStepper* stepper, dBodyID body, double position[3],
                                    double quaternion[4]) {
  if (stepper == NULL || body == NULL || position == NULL || quaternion == NULL)
    return ssFail(SS_ERROR_OUT_OF_RANGE, "%s = NULL: must point to %s",
                  stepper == NULL ? "stepper" : body == NULL ? "body" : position == NULL ? "position" : "quaternion",
                  stepper == NULL ? "a stepper" : body == NULL ? "a body" : "room for the pose");
  const ssPoseHistory* history = *ssStepperPoseSlot((ssStepper*)stepper);
  /* Other cuts end every frame on a physics state; before the first fixed frame, just reset, or with the
   * interpolation off, there is no history: ODE's pose either way. */
  if (ssStepper_Stepping(stepper).cut != SS_CUT_FIXED || history == NULL || history->restart || history->off) {
    Pose now;
    poseNow(body, &now);
    memcpy(position, now.position, sizeof now.position);
    memcpy(quaternion, now.quaternion, sizeof now.quaternion);
    return SS_OK;
  }
  return ssPoseHistoryPose(history, body, position, quaternion);
}

ssStatus ssStepper_SetInterpolation(ssStepper* stepper, int on) {
  if (stepper == NULL) return ssFail(SS_ERROR_OUT_OF_RANGE, "stepper = NULL: a stepper is required");
  if (on != 0 && on != 1) return ssFail(SS_ERROR_OUT_OF_RANGE, "on = %d: must be 1 (keep poses) or 0 (none)", on);
  ssPoseHistory** slot = ssStepperPoseSlot(stepper);
  ssStatus status = make(slot);
  if (status != SS_OK) return status;
  if ((*slot)->off && on) (*slot)->restart = 1; /* turned on again: it starts from the poses then */
  (*slot)->off = !on;
  return SS_OK;
}

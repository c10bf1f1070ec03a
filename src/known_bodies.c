/* The bodies a stepper knows: listed once from the registry, the watch list and the joints between them, and checked
 * at the boundary with ODE in one pass over their packed handles. */
#include "known_bodies.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "error.h"
#include "array.h"
#include "gears.h"
#include "pointer_set.h"
#include "steadystep/limits.h"

void ssKnownFree(ssKnownBodies* known) {
  free(known->bodies);
  free(known->ids);
  free(known->values);
  free(known->joints);
  free(known->pushed);
  free(known->geared);
  memset(known, 0, sizeof *known);
}

/* ---- the walk through joints: a growing list and the set of the bodies in it ---- */

typedef struct BodyWalk {
  dBodyID* list;
  int count, capacity;
  ssPointerSet seen;
  int failed; /* out of memory */
} BodyWalk;

/* Adds body to the walk unless it is there already. */
static void visitBody(void* context, dBodyID body) {
  BodyWalk* walk = context;
  if (walk->failed || body == 0) return;
  if (walk->count == walk->capacity &&
      !ssReserveOne((void**)&walk->list, walk->count, &walk->capacity, sizeof *walk->list)) {
    walk->failed = 1;
    return;
  }
  int added = ssPointerSetAdd(&walk->seen, body);
  if (added < 0) walk->failed = 1;
  if (added > 0) walk->list[walk->count++] = body;
}

/* The body's joints as the stepper sees them (ssJointSignature): a step's contacts are made after the program's
 * joints and emptied after the step, and hide nothing. */
static ssJointSignature jointSignature(dBodyID body) {
  ssJointSignature signature = {0, 0};
  for (int i = 0, count = dBodyGetNumJoints(body); i < count; ++i) {
    dJointID joint = dBodyGetJoint(body, i);
    if (dJointGetType(joint) == dJointTypeContact) continue;
    if (signature.count++ == 0) signature.first = joint;
  }
  return signature;
}

static const ssKnownBody* findOld(const ssKnownBodies* known, dBodyID body) {
  if (!known->valid) return NULL;
  const dBodyID* found = bsearch(&body, known->ids, (size_t)known->count, sizeof body, ssCompareHandles);
  return found != NULL ? &known->bodies[found - known->ids] : NULL;
}

static void listPushed(ssKnownBodies* known) {
  known->pushed_count = 0;
  for (int i = 0; i < known->count; ++i)
    if (known->bodies[i].pushed) known->pushed[known->pushed_count++] = i;
}

/* How far (m, in any coordinate) the body's geoms lie from it: the largest offset a program gave one. */
static double geomReach(dBodyID body) {
  double reach = 0;
  for (dGeomID geom = dBodyGetFirstGeom(body); geom != 0; geom = dBodyGetNextGeom(geom)) {
    if (!dGeomIsOffset(geom)) continue;
    const dReal* offset = dGeomGetOffsetPosition(geom);
    for (int i = 0; i < 3; ++i) {
      double distance = fabs(offset[i]);
      if (!(distance <= reach)) reach = isnan(distance) ? INFINITY : distance; /* a NaN offset reaches anywhere */
    }
  }
  return reach;
}

static uint64_t magnitudeBits(dReal value);

/* The body's position bound (ssBodyValues): 0 bits when its geoms reach beyond the bound themselves (no position
 * but the origin passes, and the check names the offset). */
static uint64_t positionBound(dBodyID body) {
  double bound = SS_MAX_POSITION_M - geomReach(body);
  return bound > 0 ? magnitudeBits(bound) : 0;
}

ssStatus ssKnownRebuild(ssKnownBodies* known, const ssRegistry* registry, const dBodyID* watched, int watched_count) {
  BodyWalk walk = {0};
  ssRegistry_VisitBodies(registry, visitBody, &walk);
  for (int i = 0; i < watched_count; ++i) visitBody(&walk, watched[i]);
  /* what they reach through joints (contacts are transient, and reach only what collision reaches anyway) */
  for (int i = 0; i < walk.count && !walk.failed; ++i) {
    dBodyID body = walk.list[i];
    for (int j = 0, joints = dBodyGetNumJoints(body); j < joints; ++j) {
      dJointID joint = dBodyGetJoint(body, j);
      if (dJointGetType(joint) == dJointTypeContact) continue;
      visitBody(&walk, dJointGetBody(joint, 0));
      visitBody(&walk, dJointGetBody(joint, 1));
    }
  }
  size_t count = (size_t)walk.count, room = count > 0 ? count : 1;
  ssKnownBody* bodies = walk.failed ? NULL : calloc(room, sizeof *bodies);
  dBodyID* ids = walk.failed ? NULL : malloc(room * sizeof *ids);
  ssBodyValues* values = walk.failed ? NULL : malloc(room * sizeof *values);
  ssJointSignature* joints = walk.failed ? NULL : malloc(room * sizeof *joints);
  int* pushed = walk.failed ? NULL : malloc(room * sizeof *pushed);
  ssPointerSetFree(&walk.seen);
  if (bodies == NULL || ids == NULL || values == NULL || joints == NULL || pushed == NULL) {
    free(walk.list);
    free(bodies);
    free(ids);
    free(values);
    free(joints);
    free(pushed);
    return ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory listing the known bodies");
  }
  if (count > 0) qsort(walk.list, count, sizeof(dBodyID), ssCompareHandles);
  for (size_t i = 0; i < count; ++i) {
    dBodyID body = walk.list[i];
    const ssKnownBody* old = findOld(known, body);
    bodies[i] = old != NULL ? *old : (ssKnownBody){.body = body};
    ids[i] = body;
    values[i] = (ssBodyValues){dBodyGetPosition(body),  dBodyGetLinearVel(body), dBodyGetAngularVel(body),
                               dBodyGetForce(body),     dBodyGetTorque(body),
                               positionBound(body)};
    /* a body that stays keeps the joints it was listed with: a joint attached since is still seen as new */
    joints[i] = old != NULL ? known->joints[old - known->bodies] : jointSignature(body);
  }
  free(walk.list);
  int geared_count = 0;
  for (size_t i = 0; i < count; ++i) geared_count += ssGeared(ids[i]);
  dBodyID* geared_ids = geared_count > 0 ? malloc((size_t)geared_count * sizeof *geared_ids) : NULL;
  if (geared_count > 0 && geared_ids == NULL) {
    free(bodies);
    free(ids);
    free(values);
    free(joints);
    free(pushed);
    return ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory listing the known bodies");
  }
  for (size_t i = 0, g = 0; i < count; ++i)
    if (ssGeared(ids[i])) geared_ids[g++] = ids[i];
  unsigned registry_generation = known->registry_generation, watched_generation = known->watched_generation;
  int carrying = known->carrying;
  ssKnownFree(known);
  *known = (ssKnownBodies){.bodies = bodies,
                           .ids = ids,
                           .values = values,
                           .joints = joints,
                           .count = (int)count,
                           .pushed = pushed,
                           .carrying = carrying,
                           .geared = geared_ids,
                           .geared_count = geared_count,
                           .valid = 1,
                           .registry_generation = registry_generation,
                           .watched_generation = watched_generation};
  listPushed(known);
  return SS_OK;
}

int ssKnownContains(const ssKnownBodies* known, dBodyID body) { return findOld(known, body) != NULL; }

void ssKnownForget(ssKnownBodies* known, dBodyID body) {
  const ssKnownBody* found = findOld(known, body);
  if (found == NULL) return;
  size_t k = (size_t)(found - known->bodies), after = (size_t)known->count - k - 1;
  memmove(&known->bodies[k], &known->bodies[k + 1], after * sizeof *known->bodies);
  memmove(&known->ids[k], &known->ids[k + 1], after * sizeof *known->ids);
  memmove(&known->values[k], &known->values[k + 1], after * sizeof *known->values);
  memmove(&known->joints[k], &known->joints[k + 1], after * sizeof *known->joints);
  known->count -= 1;
  for (int g = 0; g < known->geared_count; ++g)
    if (known->geared[g] == body) known->geared[g--] = known->geared[--known->geared_count];
  listPushed(known);
}

/* How many bodies ahead the passes ask for a body's memory: a large world's bodies are out of cache after ODE's step
 * or the program's frame, and the loads of several bodies then overlap instead of waiting one after the other. */
enum { kPrefetchAhead = 8, kPrefetchFrom = 256 };

/* Up to which body a pass over count bodies asks for the one kPrefetchAhead ahead: none for a list that stays in
 * cache. */
static int prefetchUntil(int count) { return count >= kPrefetchFrom ? count - kPrefetchAhead : 0; }

/* The body and the head of its first joint (where ODE keeps its joint list): what dBodyGetJoint reads. */
static void prefetchJoints(const ssKnownBodies* known, int k) {
  const char* joint = (const char*)known->joints[k].first;
  __builtin_prefetch(known->ids[k]);
  if (joint != NULL) __builtin_prefetch(joint), __builtin_prefetch(joint + 64);
}

static int jointsChangedAt(const ssKnownBodies* known, int k) {
  ssJointSignature now = jointSignature(known->ids[k]);
  return now.first != known->joints[k].first || now.count != known->joints[k].count;
}

ssStatus ssKnownCollectJoints(const ssKnownBodies* known, ssPointerSet* joints) {
  for (int k = 0; k < known->count; ++k) {
    dBodyID body = known->ids[k];
    for (int i = 0, count = dBodyGetNumJoints(body); i < count; ++i) {
      dJointID joint = dBodyGetJoint(body, i);
      if (dJointGetType(joint) != dJointTypeContact && ssPointerSetAdd(joints, joint) < 0)
        return ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory listing the known bodies' joints");
    }
  }
  return SS_OK;
}

void ssKnownTakeJointsOf(ssKnownBodies* known, dBodyID body) {
  const ssKnownBody* found = findOld(known, body);
  if (found != NULL) known->joints[found - known->bodies] = jointSignature(body);
}

int ssKnownJointsChanged(const ssKnownBodies* known, dBodyID* body) {
  for (int k = 0; k < known->count; ++k)
    if (jointsChangedAt(known, k)) {
      if (body != NULL) *body = known->ids[k];
      return 1;
    }
  return 0;
}

void ssKnownResetAccumulators(const ssKnownBodies* known, int with_frame_forces) {
  for (int i = 0; i < known->count; ++i) {
    const ssKnownBody* body = &known->bodies[i];
    const double* f = body->frame_force;
    int pushed = with_frame_forces && body->pushed;
    dBodySetForce(body->body, pushed ? f[0] : 0, pushed ? f[1] : 0, pushed ? f[2] : 0);
    dBodySetTorque(body->body, pushed ? f[3] : 0, pushed ? f[4] : 0, pushed ? f[5] : 0);
  }
}

/* ---- the check ---- */

static int within(const dReal* v, double bound) {
  return fabs(v[0]) <= bound && fabs(v[1]) <= bound && fabs(v[2]) <= bound;
}

/* in double whatever dReal is: a float speed's square overflows from 2e19 m/s, which is still a finite runaway */
static double squared(const dReal* v) {
  double x = v[0], y = v[1], z = v[2];
  return x * x + y * y + z * z;
}

/* |v| without overflow, for messages: a spin of 1e200 rad/s is named as such, not as inf */
static double norm(const dReal* v) {
  double largest = fmax(fabs(v[0]), fmax(fabs(v[1]), fabs(v[2])));
  if (!(largest > 0) || isinf(largest)) return largest;
  double x = v[0] / largest, y = v[1] / largest, z = v[2] / largest;
  return largest * sqrt(x * x + y * y + z * z);
}

/* The failure of a body that did not pass, named: the quantity, its value, the bound. */
static ssStatus describe(dBodyID body, const ssBodyBounds* bounds, const char* when) {
  struct {
    const char* name;
    const char* unit;
    const dReal* value;
  } quantities[] = {{"position", "m", dBodyGetPosition(body)},
                    {"linear velocity", "m/s", dBodyGetLinearVel(body)},
                    {"angular velocity", "rad/s", dBodyGetAngularVel(body)},
                    {"force", "N", dBodyGetForce(body)},
                    {"torque", "N*m", dBodyGetTorque(body)}};
  int checked = bounds->forces ? 5 : 3;
  for (int q = 0; q < checked; ++q) {
    const dReal* v = quantities[q].value;
    if (isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2])) continue;
    return ssFail(q < 3 ? SS_ERROR_BLOWUP : SS_ERROR_NOT_FINITE, "body %p: %s (%g, %g, %g) %s %s: not finite",
                  (void*)body, quantities[q].name, v[0], v[1], v[2], quantities[q].unit, when);
  }
  const dReal* p = quantities[0].value;
  double reach = geomReach(body);
  if (reach > 0 && !within(p, SS_MAX_POSITION_M - reach))
    return ssFail(SS_ERROR_POSITION_LIMIT, "body %p: position (%g, %g, %g) m %s, with a geom offset %g m from it: "
                  "beyond SS_MAX_POSITION_M = %g m, where ODE's collision spaces overflow", (void*)body, p[0], p[1],
                  p[2], when, reach, SS_MAX_POSITION_M);
  if (!within(p, SS_MAX_POSITION_M))
    return ssFail(SS_ERROR_POSITION_LIMIT, "body %p: position (%g, %g, %g) m %s: beyond SS_MAX_POSITION_M = %g m, "
                  "where ODE's collision spaces overflow", (void*)body, p[0], p[1], p[2], when, SS_MAX_POSITION_M);
  double speed = norm(quantities[1].value), spin = norm(quantities[2].value);
  if (!(speed <= bounds->max_speed))
    return ssFail(SS_ERROR_SPEED_LIMIT, "body %p: speed %g m/s %s: above max_speed = %g m/s", (void*)body, speed,
                  when, bounds->max_speed);
  if (!(spin <= bounds->max_angular_speed))
    return ssFail(SS_ERROR_SPEED_LIMIT, "body %p: angular speed %g rad/s %s: above max_angular_speed = %g rad/s",
                  (void*)body, spin, when, bounds->max_angular_speed);
  for (int q = 3; q < checked; ++q) {
    const dReal* v = quantities[q].value;
    if (!within(v, SS_MAX_FORCE_N))
      return ssFail(SS_ERROR_OUT_OF_RANGE, "body %p: %s (%g, %g, %g) %s %s: beyond SS_MAX_FORCE_N = %g",
                    (void*)body, quantities[q].name, v[0], v[1], v[2], quantities[q].unit, when, SS_MAX_FORCE_N);
  }
  return ssFail(SS_ERROR_BLOWUP, "body %p: failed a check %s", (void*)body, when); /* not reached */
}

/* A double's magnitude as an integer: non-negative doubles order as their bit patterns do, and a NaN's or an
 * infinity's lies above every finite number's, so one integer comparison tests finiteness and a bound together. */
static uint64_t magnitudeBits(dReal value) {
  double x = value;
  uint64_t bits;
  memcpy(&bits, &x, sizeof bits);
  return bits & ~(UINT64_C(1) << 63);
}

static uint64_t largestOf(const dReal* v) {
  uint64_t a = magnitudeBits(v[0]), b = magnitudeBits(v[1]), c = magnitudeBits(v[2]);
  uint64_t m = a > b ? a : b;
  return m > c ? m : c;
}

/* Whether a body's state is one ODE can step: position within SS_MAX_POSITION_M, speeds within the bounds (every
 * comparison is false for a NaN). Combined with & (no branch a number): the slow naming path runs only on failure. */
static int stateWithin(const ssBodyValues* v, double max_speed2, double max_spin2) {
  int position_within = largestOf(v->position) <= v->position_bound;
  int speed_within = squared(v->linear_vel) <= max_speed2, spin_within = squared(v->angular_vel) <= max_spin2;
  return position_within & speed_within & spin_within;
}

/* Whether a body's force and torque accumulators are within SS_MAX_FORCE_N (and finite), as stateWithin. */
static int forcesWithin(const ssBodyValues* v) {
  uint64_t f = largestOf(v->force), t = largestOf(v->torque);
  return (f > t ? f : t) <= magnitudeBits(SS_MAX_FORCE_N);
}

static void prefetchState(const ssBodyValues* v) {
  __builtin_prefetch(v->position);
  __builtin_prefetch(v->linear_vel);
  __builtin_prefetch(v->angular_vel);
}

ssStatus ssKnownCheck(const ssKnownBodies* known, const ssBodyBounds* bounds, const char* when, int step, int steps,
                      dBodyID* failed) {
  const double max_speed2 = bounds->max_speed * bounds->max_speed;
  const double max_spin2 = bounds->max_angular_speed * bounds->max_angular_speed;
  const ssBodyValues* values = known->values;
  /* the whole list first, with no branch a body (the usual case: all pass); the first failure is found after */
  int all = 1;
  const int count = known->count, until = prefetchUntil(count), forces = bounds->forces;
  for (int k = 0; k < count; ++k) {
    if (k < until) prefetchState(&values[k + kPrefetchAhead]);
    all &= stateWithin(&values[k], max_speed2, max_spin2) & (!forces || forcesWithin(&values[k]));
  }
  char named[64];
  for (int k = 0; !all && k < known->count; ++k) {
    if (stateWithin(&values[k], max_speed2, max_spin2) && (!bounds->forces || forcesWithin(&values[k]))) continue;
    *failed = known->ids[k];
    snprintf(named, sizeof named, "%s step %d of %d", when, step, steps);
    return describe(known->ids[k], bounds, named);
  }
  for (int g = 0; g < known->geared_count && bounds->gear_step_s > 0; ++g) {
    dBodyID body = known->geared[g];
    double turn = ssGearTurn(body, bounds->gear_step_s);
    if (turn <= SS_MAX_GEAR_TURN_RAD) continue;
    *failed = body;
    snprintf(named, sizeof named, "%s step %d of %d", when, step, steps);
    return ssFail(SS_ERROR_SPEED_LIMIT, "body %p: turns its transmission gear %g rad in a step of %g s %s (spin, and "
                  "speed over the gear's radius): above SS_MAX_GEAR_TURN_RAD = %g rad (ODE 0.16 aborts from pi)",
                  (void*)body, turn, bounds->gear_step_s, named, SS_MAX_GEAR_TURN_RAD);
  }
  return SS_OK;
}

static int anyNonZero(const double* values) {
  return values[0] != 0 || values[1] != 0 || values[2] != 0 || values[3] != 0 || values[4] != 0 || values[5] != 0;
}

/* One body at the frame's start: 0 when its state or forces fail the check; else, with a force or torque (not all
 * zeros, -0 included: the largest magnitude is not 0) or a carried force, its frame force read and the body marked
 * pushed. */
static int startBody(ssKnownBodies* known, int k, double max_speed2, double max_spin2) {
  const ssBodyValues* values = &known->values[k];
  uint64_t force = largestOf(values->force), torque = largestOf(values->torque);
  uint64_t largest = force > torque ? force : torque;
  if (!(stateWithin(values, max_speed2, max_spin2) & (largest <= magnitudeBits(SS_MAX_FORCE_N)))) return 0;
  ssKnownBody* body = &known->bodies[k];
  if (largest == 0 && !(known->carrying && anyNonZero(body->carried_force))) return 1;
  const dReal *f = values->force, *t = values->torque;
  double* frame = body->frame_force;
  frame[0] = f[0], frame[1] = f[1], frame[2] = f[2], frame[3] = t[0], frame[4] = t[1], frame[5] = t[2];
  body->pushed = 1;
  known->pushed[known->pushed_count++] = k;
  return 1;
}

ssStatus ssKnownStartFrame(ssKnownBodies* known, const ssBodyBounds* bounds, dBodyID* failed, int* joints_changed) {
  const double max_speed2 = bounds->max_speed * bounds->max_speed;
  const double max_spin2 = bounds->max_angular_speed * bounds->max_angular_speed;
  *joints_changed = 0;
  /* last frame's pushed bodies are unmarked through their list: only a pushed body's entry is written */
  for (int p = 0; p < known->pushed_count; ++p) known->bodies[known->pushed[p]].pushed = 0;
  known->pushed_count = 0;
  const int count = known->count, until = prefetchUntil(count);
  for (int k = 0; k < count; ++k) { /* one loop: startBody inlined once */
    if (k < until) {
      const ssBodyValues* ahead = &known->values[k + kPrefetchAhead];
      prefetchJoints(known, k + kPrefetchAhead);
      prefetchState(ahead);
      __builtin_prefetch(ahead->force);
      __builtin_prefetch(ahead->torque);
    }
    if (jointsChangedAt(known, k)) {
      *joints_changed = 1;
      return SS_OK;
    }
    if (startBody(known, k, max_speed2, max_spin2)) continue;
    *failed = known->ids[k];
    return describe(known->ids[k], bounds, "before the frame");
  }
  return SS_OK;
}

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
#include "prefetch.h"
#include "steadystep/limits.h"

/* awake[] holds this many bytes past the list, set to 1 by a check that runs over sleepers: a run of them then ends
 * there with no count compared (firstNotStillAsleep, which reads four marks at once) */
enum { kAwakeSentinels = 4 };

/* A body's check, inlined where it is called (GCC keeps it out of line): the passes make it for every awake body,
 * two or three times a frame, and the call was a sixth of it */
#if defined(__GNUC__)
#define SS_BODY_CHECK static inline __attribute__((always_inline))
#else
#define SS_BODY_CHECK static inline
#endif

void ssKnownFree(ssKnownBodies* known) {
  free(known->bodies);
  free(known->ids);
  free(known->values);
  free(known->joints);
  free(known->awake);
  free(known->moves_unseen);
  free(known->reached);
  free(known->queue);
  free(known->pushed);
  free(known->geared);
  free(known->woken);
  ssPointerMapFree(&known->index);
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
static ssJointSignature signatureOf(dBodyID body, int joints) {
  ssJointSignature signature = {0, 0, joints};
  for (int i = 0; i < joints; ++i) {
    dJointID joint = dBodyGetJoint(body, i);
    if (dJointGetType(joint) == dJointTypeContact) continue;
    if (signature.count++ == 0) signature.first = joint;
  }
  return signature;
}

static ssJointSignature jointSignature(dBodyID body) { return signatureOf(body, dBodyGetNumJoints(body)); }

/* body's place in the list, or -1 */
static int placeOf(const ssKnownBodies* known, dBodyID body) {
  return known->valid ? ssPointerMapGet(&known->index, body, -1) : -1;
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

/* Room for capacity bodies in every array (the list as it was when out of memory: 0 returned). */
static int reserve(ssKnownBodies* known, int capacity) {
  if (capacity <= known->capacity) return 1;
  int room = known->capacity > 0 ? 2 * known->capacity : 16;
  while (room < capacity) room *= 2;
  size_t n = (size_t)room;
  void* grown[] = {realloc(known->bodies, n * sizeof *known->bodies), NULL, NULL, NULL, NULL, NULL, NULL, NULL, NULL};
  if (grown[0] != NULL) known->bodies = grown[0];
  if ((grown[1] = realloc(known->ids, n * sizeof *known->ids)) != NULL) known->ids = grown[1];
  if ((grown[2] = realloc(known->values, n * sizeof *known->values)) != NULL) known->values = grown[2];
  if ((grown[3] = realloc(known->joints, n * sizeof *known->joints)) != NULL) known->joints = grown[3];
  if ((grown[4] = realloc(known->awake, n + kAwakeSentinels)) != NULL) known->awake = grown[4];
  if ((grown[5] = realloc(known->reached, n * sizeof *known->reached)) != NULL) known->reached = grown[5];
  if ((grown[6] = realloc(known->queue, n * sizeof *known->queue)) != NULL) known->queue = grown[6];
  if ((grown[7] = realloc(known->pushed, n * sizeof *known->pushed)) != NULL) known->pushed = grown[7];
  if ((grown[8] = realloc(known->moves_unseen, n)) != NULL) known->moves_unseen = grown[8];
  for (int i = 0; i < 9; ++i)
    if (grown[i] == NULL) return 0;
  known->capacity = room;
  return 1;
}

/* Whether one of body's geoms is in space or in a space nested in it (0: none). */
static int hasGeomIn(dBodyID body, dSpaceID space) {
  for (dGeomID geom = dBodyGetFirstGeom(body); geom != 0 && space != 0; geom = dBodyGetNextGeom(geom))
    for (dSpaceID in = dGeomGetSpace(geom); in != 0; in = dGeomGetSpace((dGeomID)in))
      if (in == space) return 1;
  return 0;
}

/* Appends body (not listed): 1, or 0 when out of memory. */
static int append(ssKnownBodies* known, dBodyID body) {
  if (!reserve(known, known->count + 1)) return 0;
  int k = known->count;
  if (ssPointerMapPut(&known->index, body, k) < 0) return 0;
  if (ssGeared(body)) {
    dBodyID* geared = realloc(known->geared, (size_t)(known->geared_count + 1) * sizeof *geared);
    if (geared == NULL) {
      ssPointerMapRemove(&known->index, body);
      return 0;
    }
    known->geared = geared;
    known->geared[known->geared_count++] = body;
  }
  known->bodies[k] = (ssKnownBody){.body = body};
  known->ids[k] = body;
  known->values[k] = (ssBodyValues){dBodyGetPosition(body), dBodyGetLinearVel(body), dBodyGetAngularVel(body),
                                    dBodyGetForce(body),    dBodyGetTorque(body),    positionBound(body)};
  known->joints[k] = jointSignature(body);
  known->awake[k] = 1; /* checked at the next check, whatever ODE does with it */
  known->moves_unseen[k] = !hasGeomIn(body, known->seen_space);
  known->joined_count += known->joints[k].count > 0;
  known->unseen_count += known->moves_unseen[k];
  known->reached[k] = 0;
  known->count += 1;
  known->stepped_valid = 0;
  return 1;
}

/* Adds the bodies of walk->list that are not listed, and what they reach through joints (appended to the walk). */
static int addReached(ssKnownBodies* known, BodyWalk* walk) {
  for (int i = 0; i < walk->count && !walk->failed; ++i) {
    dBodyID body = walk->list[i];
    if (placeOf(known, body) >= 0) continue; /* listed: what it reaches is listed with it */
    if (!append(known, body)) return 0;
    for (int j = 0, joints = dBodyGetNumJoints(body); j < joints; ++j) {
      dJointID joint = dBodyGetJoint(body, j);
      if (dJointGetType(joint) == dJointTypeContact) continue;
      visitBody(walk, dJointGetBody(joint, 0));
      visitBody(walk, dJointGetBody(joint, 1));
    }
  }
  return !walk->failed;
}

ssStatus ssKnownRebuild(ssKnownBodies* known, const ssRegistry* registry, const dBodyID* watched, int watched_count) {
  BodyWalk walk = {0};
  ssRegistry_VisitBodies(registry, visitBody, &walk);
  for (int i = 0; i < watched_count; ++i) visitBody(&walk, watched[i]);
  /* the new list, bodies that stay keeping their forces and the joints they were listed with (a joint attached
   * since is still seen as new) */
  ssKnownBodies rebuilt = {.valid = 1,
                           .seen_space = known->seen_space,
                           .carrying = known->carrying,
                           .registry_generation = known->registry_generation,
                           .watched_generation = known->watched_generation};
  int added = addReached(&rebuilt, &walk);
  free(walk.list);
  ssPointerSetFree(&walk.seen);
  if (!added) {
    ssKnownFree(&rebuilt);
    return ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory listing the known bodies");
  }
  for (int k = 0; k < rebuilt.count; ++k) {
    int old = placeOf(known, rebuilt.ids[k]);
    if (old < 0) continue;
    rebuilt.bodies[k] = known->bodies[old];
    rebuilt.joined_count += (known->joints[old].count > 0) - (rebuilt.joints[k].count > 0);
    rebuilt.joints[k] = known->joints[old];
  }
  rebuilt.woken = known->woken, rebuilt.woken_count = known->woken_count; /* still to be written */
  rebuilt.woken_capacity = known->woken_capacity;
  known->woken = NULL;
  ssKnownFree(known);
  *known = rebuilt;
  listPushed(known);
  return SS_OK;
}

ssStatus ssKnownAdd(ssKnownBodies* known, dBodyID body) {
  if (placeOf(known, body) >= 0) return SS_OK;
  BodyWalk walk = {0};
  visitBody(&walk, body);
  int added = addReached(known, &walk);
  free(walk.list);
  ssPointerSetFree(&walk.seen);
  return added ? SS_OK : ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory listing the known bodies");
}

void ssKnownCheckAllOnce(ssKnownBodies* known) {
  known->stepped_valid = 0;
  if (known->count > 0) memset(known->awake, 1, (size_t)known->count);
}

int ssKnownJoined(const ssKnownBodies* known, dBodyID body) {
  int k = placeOf(known, body);
  return k >= 0 && known->joints[k].count > 0;
}

void ssKnownForget(ssKnownBodies* known, dBodyID body) {
  int k = placeOf(known, body), last = known->count - 1;
  if (k < 0) return;
  int pushed = known->bodies[k].pushed;
  ssPointerMapRemove(&known->index, body);
  known->joined_count -= known->joints[k].count > 0;
  known->unseen_count -= known->moves_unseen[k];
  if (k != last) {
    known->bodies[k] = known->bodies[last];
    known->ids[k] = known->ids[last];
    known->values[k] = known->values[last];
    known->joints[k] = known->joints[last];
    known->awake[k] = known->awake[last];
    known->moves_unseen[k] = known->moves_unseen[last];
    known->reached[k] = known->reached[last];
    ssPointerMapPut(&known->index, known->ids[k], k); /* replaces a value: allocates nothing */
  }
  known->count = last;
  known->stepped_valid = 0; /* the queue names places */
  for (int w = 0; w < known->woken_count; ++w)
    if (known->woken[w] == body) known->woken[w--] = known->woken[--known->woken_count];
  for (int g = 0; g < known->geared_count; ++g)
    if (known->geared[g] == body) known->geared[g--] = known->geared[--known->geared_count];
  /* the pushed list names places: the forgotten body's goes, the moved body's follows it */
  for (int p = 0; p < known->pushed_count; ++p) {
    if (pushed && known->pushed[p] == k) known->pushed[p--] = known->pushed[--known->pushed_count];
    else if (known->pushed[p] == last) known->pushed[p] = k;
  }
}

/* The head of a body's first joint (where ODE keeps its joint list): what dBodyGetJoint reads beyond the body. */
SS_PREFETCH_HELPER void prefetchJoints(const ssKnownBodies* known, int k) {
  const char* joint = (const char*)known->joints[k].first;
  if (joint != NULL) SS_PREFETCH(joint), SS_PREFETCH(joint + 64);
}

#if defined(__GNUC__)
__attribute__((noinline))
#endif
static int signatureChanged(const ssKnownBodies* known, int k, int joints) {
  /* listed with joints and no contact, as many now, the listed first at the head: the joints it had (ODE puts a joint
   * attached since at the head, and one gone with none attached leaves fewer), known in one more read of ODE's */
  const ssJointSignature* listed = &known->joints[k];
  if (joints == listed->count && joints == listed->total && dBodyGetJoint(known->ids[k], 0) == listed->first) return 0;
  ssJointSignature now = signatureOf(known->ids[k], joints);
  return now.first != listed->first || now.count != listed->count;
}

/* Most bodies have no joint, and had none (the first is 0 then too): one read of ODE's. */
static inline int jointsChangedAt(const ssKnownBodies* known, int k) {
  int joints = dBodyGetNumJoints(known->ids[k]);
  return joints == 0 ? known->joints[k].count != 0 : signatureChanged(known, k, joints);
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

int ssKnownJointsChangedOf(const ssKnownBodies* known, dBodyID body) {
  int k = placeOf(known, body);
  return k < 0 || jointsChangedAt(known, k);
}

void ssKnownTakeJointsOf(ssKnownBodies* known, dBodyID body) {
  int k = placeOf(known, body);
  if (k < 0) return;
  ssJointSignature now = jointSignature(body);
  known->joined_count += (now.count > 0) - (known->joints[k].count > 0);
  known->joints[k] = now;
}

/* A body asleep at the last check with no joint but contacts then has its joints read when it is found awake
 * (bodyWoke): while it sleeps ODE steps no joint attached to it, and it has none bound that could be destroyed. */
static inline int jointsRead(const ssKnownBodies* known, int k) { return known->awake[k] || known->joints[k].count; }

int ssKnownJointsChanged(const ssKnownBodies* known, dBodyID* body) {
  for (int k = 0; k < known->count; ++k)
    if (jointsRead(known, k) && jointsChangedAt(known, k)) {
      if (body != NULL) *body = known->ids[k];
      return 1;
    }
  return 0;
}

void ssKnownResetAccumulators(const ssKnownBodies* known, int with_frame_forces) {
  for (int i = 0; i < known->count; ++i) {
    const ssKnownBody* body = &known->bodies[i];
    if (!body->pushed && !known->awake[i]) continue; /* asleep: its force waits for the step that wakes it */
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

SS_PREFETCH_HELPER void prefetchState(const ssBodyValues* v) {
  SS_PREFETCH(v->position);
  SS_PREFETCH(v->linear_vel);
  SS_PREFETCH(v->angular_vel);
}

/* "`when` step `step` of `steps`", the moment a failure is named at. */
static void namedStep(char named[64], const char* when, int step, int steps) {
  snprintf(named, 64, "%s step %d of %d", when, step, steps);
}

/* Body k's failure of the check, named: *failed set to it, its status returned. */
static ssStatus nameFailure(const ssKnownBodies* known, int k, const ssBodyBounds* bounds, const char* when, int step,
                            int steps, dBodyID* failed) {
  char named[64];
  *failed = known->ids[k];
  namedStep(named, when, step, steps);
  return describe(known->ids[k], bounds, named);
}

SS_BODY_CHECK int bodyWithin(const ssBodyValues* v, double max_speed2, double max_spin2, int forces) {
  return stateWithin(v, max_speed2, max_spin2) & (!forces || forcesWithin(v));
}

/* Body k found woken, by the program or by ODE through a joint: kept for ssKnownTakeWoken (out of memory: not kept;
 * its numbers are written at the next change of step, as before it woke), and its joints read when they were passed
 * over while it slept (jointsRead). */
static void bodyWoke(ssKnownBodies* known, int k) {
  if (ssReserveOne((void**)&known->woken, known->woken_count, &known->woken_capacity, sizeof *known->woken))
    known->woken[known->woken_count++] = known->ids[k];
  if (known->joints[k].count == 0 && jointsChangedAt(known, k)) known->joints_due = 1;
}

int ssKnownTakeJointsDue(ssKnownBodies* known) {
  int due = known->joints_due;
  known->joints_due = 0;
  return due;
}

const dBodyID* ssKnownTakeWoken(ssKnownBodies* known, int* count) {
  *count = known->woken_count;
  known->woken_count = 0;
  return known->woken;
}

/* The walk from the bodies ODE steps to the sleeping ones it wakes through their joints (contacts too): ODE's island
 * takes a disabled body joined to an enabled one, and every disabled body joined to that. Visits each listed body
 * it reaches once (reached[] holds this check's number); visit returns 0 to stop the walk at a failing body, which
 * the walk returns (else -1). The queue starts with the bodies ODE steps as the pass found them (stepped_count), and
 * ends with every body it steps. */
static int wakeWalk(ssKnownBodies* known, int (*visit)(ssKnownBodies*, int, void*), void* context) {
  int queued = known->stepped_count;
  for (int head = 0; head < queued; ++head) {
    dBodyID body = known->ids[known->queue[head]];
    for (int j = 0, joints = dBodyGetNumJoints(body); j < joints; ++j) {
      dJointID joint = dBodyGetJoint(body, j);
      for (int side = 0; side < 2; ++side) {
        dBodyID other = dJointGetBody(joint, side);
        int k = other != 0 && other != body ? placeOf(known, other) : -1;
        if (k < 0 || known->reached[k] == known->checks) continue;
        known->reached[k] = known->checks;
        if (!known->awake[k]) bodyWoke(known, k);
        known->awake[k] = 1;
        known->queue[queued] = k;
        known->stepped_count = ++queued;
        if (!visit(known, k, context)) return k;
      }
    }
  }
  return -1;
}

typedef struct CheckVisit {
  double max_speed2, max_spin2;
  int forces;
} CheckVisit;

static int checkVisit(ssKnownBodies* known, int k, void* context) {
  const CheckVisit* check = context;
  return bodyWithin(&known->values[k], check->max_speed2, check->max_spin2, check->forces);
}

/* A check's mark of body k, in the pass that reads it: whether ODE steps it (enabled, or awake at the last check:
 * ODE stepped it before it disabled it), then reached[] is this check's number and it is queued (stepped_count); a
 * sleeping body is counted in *unseen when the program could move it unseen (moves_unseen). awake[] becomes whether
 * it is enabled, and a body that was asleep is noted woken. */
static inline int markBody(ssKnownBodies* known, int k, int* unseen) {
  int enabled = dBodyIsEnabled(known->ids[k]) != 0, due = enabled | known->awake[k];
  if (enabled > known->awake[k]) bodyWoke(known, k);
  known->awake[k] = (unsigned char)enabled;
  if (due) {
    known->reached[k] = known->checks;
    known->queue[known->stepped_count++] = k;
  } else {
    *unseen += known->moves_unseen[k];
  }
  return due;
}

/* A large world's next body asked for: the flags and joints at its head, and, awake, the values a pass reads. */
SS_PREFETCH_HELPER void prefetchBody(const ssKnownBodies* known, int k, int forces) {
  const ssBodyValues* v = &known->values[k];
  SS_PREFETCH(known->ids[k]);
  if (!known->awake[k]) return; /* asleep at the last check: most likely its values are not read */
  prefetchState(v);
  if (forces) SS_PREFETCH(v->force), SS_PREFETCH(v->torque);
}

/* After the walk: the first sleeping body the program could move unseen whose state (and with check->forces its
 * accumulators) fails the check, or -1. Each is marked as met by this check. */
static int checkUnseen(ssKnownBodies* known, int unseen, const CheckVisit* check) {
  for (int k = 0; unseen > 0 && k < known->count; ++k) {
    if (known->reached[k] == known->checks || !known->moves_unseen[k]) continue;
    known->reached[k] = known->checks;
    if (!bodyWithin(&known->values[k], check->max_speed2, check->max_spin2, check->forces)) return k;
    unseen -= 1;
  }
  return -1;
}

/* The first body this check marked whose state (and with check->forces its accumulators) fails the check, or -1:
 * looked for only after the pass found that one does. */
static int firstMarkedFailing(const ssKnownBodies* known, const CheckVisit* check) {
  for (int q = 0; q < known->stepped_count; ++q) {
    int k = known->queue[q];
    if (!bodyWithin(&known->values[k], check->max_speed2, check->max_spin2, check->forces)) return k;
  }
  return -1;
}

/* The pass over the bodies ODE stepped, when nothing but ODE's step ran since the last check (stepped_valid): a body
 * asleep then is asleep now unless the step woke it through a joint (the wake walk finds it), so only those are read,
 * each marked as markBody marks it. Whether all passed. */
static int checkStepped(ssKnownBodies* known, const CheckVisit* check) {
  int all = 1;
  const int stepped = known->stepped_count, until = ssPrefetchUntil(stepped);
  for (int q = 0; q < stepped; ++q) {
    int k = known->queue[q];
    if (q < until) prefetchBody(known, known->queue[q + kPrefetchAhead], check->forces);
    known->awake[k] = (unsigned char)(dBodyIsEnabled(known->ids[k]) != 0);
    known->reached[k] = known->checks;
    all &= bodyWithin(&known->values[k], check->max_speed2, check->max_spin2, check->forces);
  }
  return all;
}

/* The place of body on the list, marked as met by this check (-1: not listed, or met already). */
static int meetAlso(ssKnownBodies* known, dBodyID body) {
  int k = placeOf(known, body);
  if (k < 0 || known->reached[k] == known->checks) return -1;
  known->reached[k] = known->checks;
  return k;
}

static int anyNonZero(const double* values) {
  return values[0] != 0 || values[1] != 0 || values[2] != 0 || values[3] != 0 || values[4] != 0 || values[5] != 0;
}

/* One body at the frame's start: 0 when its state or forces fail the check; else, with a force or torque (not all
 * zeros, -0 included: the largest magnitude is not 0) or a carried force, its frame force read and the body marked
 * pushed. */
SS_BODY_CHECK int startBody(ssKnownBodies* known, int k, double max_speed2, double max_spin2) {
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

/* Every geared body's turn in a step of step_s within SS_MAX_GEAR_TURN_RAD: at the spin and speed it has, or with
 * with_forces at those its force and torque can give it in the step (ssGearTurnInStep). */
static ssStatus checkGears(const ssKnownBodies* known, double step_s, int with_forces, const char* when, int step,
                           int steps, dBodyID* failed) {
  for (int g = 0; g < known->geared_count; ++g) {
    dBodyID body = known->geared[g];
    double turn = with_forces ? ssGearTurnInStep(body, step_s) : ssGearTurn(body, step_s);
    if (turn <= SS_MAX_GEAR_TURN_RAD) continue;
    char named[64];
    *failed = body;
    namedStep(named, when, step, steps);
    /* within the 256 bytes of ssLastError; why pi/2 is in limits.h */
    return ssFail(SS_ERROR_SPEED_LIMIT, "body %p turns its transmission gear %g rad in a step of %g s %s: above "
                  "SS_MAX_GEAR_TURN_RAD = %g rad (spin, speed%s, and the swing of the line between the gears' anchors)",
                  (void*)body, turn, step_s, named, SS_MAX_GEAR_TURN_RAD,
                  with_forces ? " with its force and torque" : "");
  }
  return SS_OK;
}

/* The first place from k on of a body awake at the last check or awake now, or the list's end, where awake[] holds
 * kAwakeSentinels ones: the bodies passed over sleep still, and none moves unseen. Its own loop, the arrays held in
 * registers across ODE's calls, four marks read at once: most of a sleeping level passes here. */
static int firstNotStillAsleep(const dBodyID* ids, const unsigned char* awake, int k) {
  for (uint32_t four; memcpy(&four, awake + k, sizeof four), four == 0; k += 4) {
    if (dBodyIsEnabled(ids[k])) return k;
    if (dBodyIsEnabled(ids[k + 1])) return k + 1;
    if (dBodyIsEnabled(ids[k + 2])) return k + 2;
    if (dBodyIsEnabled(ids[k + 3])) return k + 3;
  }
  while (!awake[k] && !dBodyIsEnabled(ids[k])) ++k;
  return k;
}

ssStatus ssKnownCheck(ssKnownBodies* known, const ssBodyBounds* bounds, const char* when, int step, int steps,
                      const dBodyID* also, int also_count, int only_stepped, dBodyID* failed) {
  CheckVisit check = {bounds->max_speed * bounds->max_speed, bounds->max_angular_speed * bounds->max_angular_speed,
                      bounds->forces};
  const ssBodyValues* values = known->values;
  const int count = known->count, until = ssPrefetchUntil(count);
  ++known->checks;
  int all = 1, unseen = 0;
  ssBodyBounds named = *bounds;
  if (only_stepped && known->stepped_valid) {
    all = checkStepped(known, &check);
  } else {
    /* one pass reads each body once, marks it and checks what ODE steps (the usual case: all pass; the first
     * failure is found after); a sleeping body's values are not read. A body the frame's start passed over asleep
     * and found awake now is started here: its frame force read, with its state (ssKnownStartFrame). */
    const int late_start = known->sleepers_unread, none_unseen = known->unseen_count == 0;
    known->stepped_count = 0;
    if (count > 0) memset(known->awake + count, 1, kAwakeSentinels); /* firstNotStillAsleep's end */
    for (int k = 0; k < count; ++k) {
      if (k < until) prefetchBody(known, k + kPrefetchAhead, check.forces);
      else if (none_unseen && !known->awake[k] &&
               (k = firstNotStillAsleep(known->ids, known->awake, k)) == count)
        break;
      int was_awake = known->awake[k];
      /* asleep at the last check and still (most of a sleeping level): its mark stays, and only its moves count */
      if (!was_awake && !dBodyIsEnabled(known->ids[k])) {
        unseen += known->moves_unseen[k];
        continue;
      }
      if (!markBody(known, k, &unseen)) continue;
      all &= late_start && !was_awake ? startBody(known, k, check.max_speed2, check.max_spin2)
                                      : bodyWithin(&values[k], check.max_speed2, check.max_spin2, check.forces);
    }
    known->stepped_valid = 1;
    known->sleepers_unread = 0;
    if (late_start) check.forces = named.forces = 1; /* a started body's forces were checked: named as such */
  }
  int failing = all ? -1 : firstMarkedFailing(known, &check);
  if (failing < 0 && known->stepped_count < count) failing = wakeWalk(known, checkVisit, &check);
  if (failing < 0) failing = checkUnseen(known, unseen, &check);
  if (failing >= 0) return nameFailure(known, failing, &named, when, step, steps, failed);
  for (int a = 0; a < also_count; ++a) {
    int k = meetAlso(known, also[a]);
    if (k >= 0 && !checkVisit(known, k, &check)) return nameFailure(known, k, &named, when, step, steps, failed);
  }
  return bounds->gear_step_s > 0 ? checkGears(known, bounds->gear_step_s, 0, when, step, steps, failed) : SS_OK;
}

ssStatus ssKnownCheckGearsInStep(const ssKnownBodies* known, double step_s, int step, int steps, dBodyID* failed) {
  return checkGears(known, step_s, 1, "before", step, steps, failed);
}

static int startVisit(ssKnownBodies* known, int k, void* context) {
  const CheckVisit* check = context;
  return startBody(known, k, check->max_speed2, check->max_spin2);
}

ssStatus ssKnownStartFrame(ssKnownBodies* known, const ssBodyBounds* bounds, const dBodyID* also, int also_count,
                           int sleepers_later, dBodyID* failed, int* joints_changed) {
  CheckVisit check = {bounds->max_speed * bounds->max_speed, bounds->max_angular_speed * bounds->max_angular_speed, 1};
  *joints_changed = 0;
  /* last frame's pushed bodies are unmarked through their list: only a pushed body's entry is written */
  for (int p = 0; p < known->pushed_count; ++p) known->bodies[known->pushed[p]].pushed = 0;
  known->pushed_count = 0;
  const int count = known->count, until = ssPrefetchUntil(count);
  ++known->checks;
  /* one pass reads each body once: its joints (a sleeping body's joint may be destroyed too, so every body's are read
   * before a failure is told, but one that had none: jointsRead), its mark, and the state and forces of what ODE
   * steps. A body found woken here or by the walk has its joints read then (bodyWoke). */
  /* a level mostly asleep (as the last check found it), where no sleeping body has anything to read (joints besides
   * contacts, or moves the looks cannot see): the awake ones are found in the marks (memchr); where most are awake,
   * the pass below asks for each body ahead */
  const int awake_alone = sleepers_later && known->joined_count == 0 && known->unseen_count == 0 &&
                          known->stepped_count < count / 4;
  int all = 1, changed = 0, unseen = 0;
  known->stepped_count = 0;
  known->joints_due = 0; /* every body awake at the last check is read below */
  for (int k = 0; awake_alone && k < count; ++k) {
    if (!known->awake[k]) { /* the next awake body, past the sleepers; those after an awake one are met in turn */
      const unsigned char* next = memchr(known->awake + k, 1, (size_t)(count - k));
      if (next == NULL) break;
      k = (int)(next - known->awake);
    }
    changed |= jointsChangedAt(known, k);
    if (markBody(known, k, &unseen)) all &= startBody(known, k, check.max_speed2, check.max_spin2);
  }
  for (int k = 0; !awake_alone && k < count; ++k) {
    int ahead = k + kPrefetchAhead;
    if (k < until && (known->awake[ahead] || !sleepers_later)) /* else at most its joints are read below */
      prefetchBody(known, ahead, 1), prefetchJoints(known, ahead);
    if (sleepers_later && !known->awake[k]) { /* asleep at the last check: read by the check before the step */
      unseen += known->moves_unseen[k];
      if (known->joints[k].count > 0) changed |= jointsChangedAt(known, k);
      continue;
    }
    if (jointsRead(known, k)) changed |= jointsChangedAt(known, k);
    if (markBody(known, k, &unseen)) all &= startBody(known, k, check.max_speed2, check.max_spin2);
  }
  known->stepped_valid = 1;
  known->sleepers_unread = sleepers_later;
  if (changed) { /* the caller lists the bodies again, each then checked at the next call, and calls again */
    *joints_changed = 1;
    return SS_OK;
  }
  int failing = all ? -1 : firstMarkedFailing(known, &check);
  if (failing < 0 && known->stepped_count < count) failing = wakeWalk(known, startVisit, &check);
  if (ssKnownTakeJointsDue(known)) { /* a body the walk or the marks woke has a joint attached since: as above */
    *joints_changed = 1;
    return SS_OK;
  }
  if (failing < 0) failing = checkUnseen(known, unseen, &check); /* checked only: a sleeping body's force waits */
  for (int a = 0; failing < 0 && a < also_count; ++a) {
    int k = meetAlso(known, also[a]);
    if (k >= 0 && !startVisit(known, k, &check)) failing = k;
  }
  if (failing < 0) return SS_OK;
  *failed = known->ids[failing];
  return describe(*failed, bounds, "before the frame");
}

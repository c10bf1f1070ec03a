/* Adoption: a program's tuned numbers read back from ODE and bound as what they stand for (adopt.h).
 *
 * ODE 0.16 cannot list a world's bodies or joints, so adoption walks what it can reach: spaces -> geoms -> bodies
 * -> joints -> bodies. It plans every binding first and commits only when the whole plan is valid, so an error
 * leaves the registry as it was. */
#include "steadystep/adopt.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "array.h"
#include "error.h"
#include "joint_rows.h"
#include "ode_bounds.h"
#include "registry_internal.h"
#include "row_law.h"

typedef struct PlannedRow {
  dJointID joint;
  ssJointParam param;
  int axis;
  ssRowLaw law;
} PlannedRow;

typedef struct PlannedBody {
  dBodyID body;
  double linear_rate_per_s, angular_rate_per_s;
  int has_auto_disable;
  double idle_time_s, average_window_s;
} PlannedBody;

/* Pointers seen by the walk: open addressing, grown at half full. */
typedef struct PointerSet {
  const void** slots;
  size_t capacity, count;
} PointerSet;

typedef struct Plan {
  ssRegistry* registry;
  dWorldID world;
  double tuned_step_s;
  PlannedRow* rows;
  int row_count, row_capacity;
  PlannedBody* bodies;
  int body_count, body_capacity;
  dBodyID* pending; /* bodies still to walk from */
  int pending_count, pending_capacity;
  PointerSet seen;
  ssAdoptReport counts;
  int out_of_memory;
} Plan;

/* As the registry's index (binding_index.c): objects made together stay near each other in the set. */
static size_t slotOf(const void* pointer, size_t capacity) {
  uint64_t address = (uint64_t)(uintptr_t)pointer;
  return (size_t)((address >> 4) + ((address >> 20) * 0x9E3779B97F4A7C15ull >> 32)) & (capacity - 1);
}

/* Adds pointer; returns 1 if it was new, 0 if seen before, -1 when out of memory. */
static int addSeen(PointerSet* set, const void* pointer) {
  if (2 * (set->count + 1) > set->capacity) {
    size_t capacity = set->capacity ? 2 * set->capacity : 64;
    const void** slots = calloc(capacity, sizeof *slots);
    if (slots == NULL) return -1;
    for (size_t i = 0; i < set->capacity; ++i) {
      if (set->slots[i] == NULL) continue;
      size_t j = slotOf(set->slots[i], capacity);
      while (slots[j] != NULL) j = (j + 1) & (capacity - 1);
      slots[j] = set->slots[i];
    }
    free(set->slots);
    set->slots = slots;
    set->capacity = capacity;
  }
  size_t j = slotOf(pointer, set->capacity);
  while (set->slots[j] != NULL) {
    if (set->slots[j] == pointer) return 0;
    j = (j + 1) & (set->capacity - 1);
  }
  set->slots[j] = pointer;
  set->count += 1;
  return 1;
}

static void freePlan(Plan* plan) {
  free(plan->rows);
  free(plan->bodies);
  free(plan->pending);
  free(plan->seen.slots);
}

static ssStatus outOfMemory(void) { return ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory adopting"); }

static ssStatus requireTuned(const ssRegistry* registry) {
  if (registry == NULL) return ssFail(SS_ERROR_OUT_OF_RANGE, "registry = NULL: a registry is required");
  if (ssRegistry_TunedStep(registry) == 0)
    return ssFail(SS_ERROR_OUT_OF_RANGE, "tuned step = 0 s: adopt the world first (ssRegistry_Adopt or "
                                         "ssRegistry_AdoptWorld)");
  return SS_OK;
}

/* A damping scale s, removed from the velocity once per step of h0, as a rate per second. */
static ssStatus dampingRate(const char* what, double scale, double tuned_step_s, double* rate) {
  if (!isfinite(scale)) return ssFail(SS_ERROR_NOT_FINITE, "%s damping scale = %g: must be finite", what, scale);
  if (!(scale >= 0 && scale < 1))
    return ssFail(SS_ERROR_OUT_OF_RANGE, "%s damping scale = %g: must be in [0, 1)", what, scale);
  *rate = -log1p(-scale) / tuned_step_s;
  return SS_OK;
}

/* Auto-disable after `steps` idle steps of h0 and `seconds` idle seconds (ODE waits for both) as an idle time, and
 * an average over `samples` steps as a window. */
static ssStatus autoDisableTimes(const char* what, int steps, double seconds, int samples, double tuned_step_s,
                                 PlannedBody* out) {
  if (!isfinite(seconds) || seconds < 0)
    return ssFail(isfinite(seconds) ? SS_ERROR_OUT_OF_RANGE : SS_ERROR_NOT_FINITE,
                  "%s auto-disable time = %g s: must be finite and not negative", what, seconds);
  double idle_s = fmax(fmax(steps, 0) * tuned_step_s, seconds);
  out->has_auto_disable = idle_s > 0; /* 0 idle steps and 0 s: disabled at once, at every step length alike */
  out->idle_time_s = idle_s;
  out->average_window_s = samples > 1 ? samples * tuned_step_s : 0;
  return SS_OK;
}

static int pushPending(Plan* plan, dBodyID body) {
  if (!ssReserveOne((void**)&plan->pending, plan->pending_count, &plan->pending_capacity, sizeof body)) return 0;
  plan->pending[plan->pending_count++] = body;
  return 1;
}

static ssStatus planBody(Plan* plan, dBodyID body) {
  int added = addSeen(&plan->seen, body);
  if (added < 0) return outOfMemory();
  if (added == 0) return SS_OK;
  if (!pushPending(plan, body)) return outOfMemory();
  if (ssRegistryHasBody(plan->registry, body)) return SS_OK;
  char what[64];
  snprintf(what, sizeof what, "body %p", (void*)body);
  PlannedBody planned = {.body = body};
  /* ODE copied the world's current defaults into a body made after an earlier adoption: those stand for the
   * world's rates, not for values tuned at h0 */
  const ssBodyBinding* world = ssRegistryFindBody(plan->registry, 0);
  double linear = dBodyGetLinearDamping(body), angular = dBodyGetAngularDamping(body);
  if (world != NULL && world->has_damping && linear == dWorldGetLinearDamping(plan->world) &&
      angular == dWorldGetAngularDamping(plan->world)) {
    planned.linear_rate_per_s = world->linear_rate_per_s;
    planned.angular_rate_per_s = world->angular_rate_per_s;
  } else {
    ssStatus status = dampingRate(what, linear, plan->tuned_step_s, &planned.linear_rate_per_s);
    if (status == SS_OK) status = dampingRate(what, angular, plan->tuned_step_s, &planned.angular_rate_per_s);
    if (status != SS_OK) return status;
  }
  int steps = dBodyGetAutoDisableSteps(body), samples = dBodyGetAutoDisableAverageSamplesCount(body);
  double seconds = dBodyGetAutoDisableTime(body);
  if (world != NULL && world->has_auto_disable && steps == dWorldGetAutoDisableSteps(plan->world) &&
      seconds == dWorldGetAutoDisableTime(plan->world) &&
      samples == dWorldGetAutoDisableAverageSamplesCount(plan->world)) {
    planned.has_auto_disable = 1;
    planned.idle_time_s = world->idle_time_s;
    planned.average_window_s = world->average_window_s;
  } else {
    ssStatus status = autoDisableTimes(what, steps, seconds, samples, plan->tuned_step_s, &planned);
    if (status != SS_OK) return status;
  }
  if (!ssReserveOne((void**)&plan->bodies, plan->body_count, &plan->body_capacity, sizeof planned))
    return outOfMemory();
  plan->bodies[plan->body_count++] = planned;
  return SS_OK;
}

static ssStatus planRow(Plan* plan, dJointID joint, ssJointParam param, int axis) {
  if (ssRegistryHasJointRow(plan->registry, joint, param, axis)) return SS_OK;
  double erp, cfm;
  ssJointReadSoftness(joint, param, axis, &erp, &cfm);
  PlannedRow row = {joint, param, axis, {{0, 0}, 0, 0}};
  ssRowLaw world_law;
  ssSoftness world_now = {dWorldGetERP(plan->world), dWorldGetCFM(plan->world)};
  /* a row still holding the world's current ERP/CFM (ODE copies them at creation; the registry rewrites them for
   * each step) stands for the world's tuned spring. Motor rows are dampers, whose cfm is adopted as it is. */
  if (param != SS_PARAM_MOTOR && erp == world_now.erp && cfm == world_now.cfm &&
      ssRegistryWorldBound(plan->registry, &world_law)) {
    row.law = world_law;
  } else {
    char what[96];
    snprintf(what, sizeof what, "%s joint %p, %s axis %d", ssJointTypeName(joint), (void*)joint,
             ssJointParamName(param), axis);
    ssStatus status = ssRowLawFromTuned(what, erp, cfm, plan->tuned_step_s, &row.law);
    if (status == SS_OK) status = ssCheckLawForEveryStep(what, &row.law);
    if (status != SS_OK) return status;
  }
  if (!ssReserveOne((void**)&plan->rows, plan->row_count, &plan->row_capacity, sizeof row)) return outOfMemory();
  plan->rows[plan->row_count++] = row;
  plan->counts.hard_rows += row.law.hard;
  switch (param) {
    case SS_PARAM_JOINT: plan->counts.joint_rows += 1; break;
    case SS_PARAM_STOP: plan->counts.stop_rows += 1; break;
    case SS_PARAM_MOTOR: plan->counts.motor_rows += 1; break;
    case SS_PARAM_SUSPENSION: plan->counts.suspension_rows += 1; break;
  }
  return SS_OK;
}

/* Plans the joint's rows and its bodies (queued in pending: walk() goes on from them, AdoptJoint does not). */
static ssStatus planJoint(Plan* plan, dJointID joint) {
  int added = addSeen(&plan->seen, joint);
  if (added < 0) return outOfMemory();
  if (added == 0) return SS_OK;
  int type = dJointGetType(joint);
  if (type <= dJointTypeNone || type > dJointTypeTransmission)
    return ssFail(SS_ERROR_UNSUPPORTED, "joint %p: type %d is not one ODE 0.16 knows", (void*)joint, type);
  if (type == dJointTypeContact || type == dJointTypeNull || type == dJointTypePlane2D) {
    plan->counts.skipped_joints += 1;
    return SS_OK; /* contacts are transient: the bodies they touch are reached through the space */
  }
  plan->counts.joints += 1;
  ssStatus status = SS_OK;
  if (ssJointSupports(joint, SS_PARAM_JOINT, 1)) status = planRow(plan, joint, SS_PARAM_JOINT, 1);
  for (int axis = 1; axis <= ssJointLimitAxisCount(joint) && status == SS_OK; ++axis) {
    status = planRow(plan, joint, SS_PARAM_STOP, axis);
    if (status == SS_OK) status = planRow(plan, joint, SS_PARAM_MOTOR, axis);
  }
  if (status == SS_OK && ssJointSupports(joint, SS_PARAM_SUSPENSION, 1))
    status = planRow(plan, joint, SS_PARAM_SUSPENSION, 1);
  for (int side = 0; side < 2 && status == SS_OK; ++side) {
    dBodyID body = dJointGetBody(joint, side);
    if (body == 0) continue;
    status = planBody(plan, body);
  }
  return status;
}

/* Walks from the pending bodies through their joints until nothing new is reached. */
static ssStatus walk(Plan* plan) {
  while (plan->pending_count > 0) {
    dBodyID body = plan->pending[--plan->pending_count];
    int joints = dBodyGetNumJoints(body);
    for (int i = 0; i < joints; ++i) {
      ssStatus status = planJoint(plan, dBodyGetJoint(body, i));
      if (status != SS_OK) return status;
    }
  }
  return SS_OK;
}

static ssStatus planSpace(Plan* plan, dSpaceID space) {
  int count = dSpaceGetNumGeoms(space);
  for (int i = 0; i < count; ++i) {
    dGeomID geom = dSpaceGetGeom(space, i);
    ssStatus status = SS_OK;
    if (dGeomIsSpace(geom)) {
      status = planSpace(plan, (dSpaceID)geom);
    } else if (dGeomGetBody(geom) != 0) {
      status = planBody(plan, dGeomGetBody(geom));
      if (status == SS_OK) status = walk(plan);
    }
    if (status != SS_OK) return status;
  }
  return SS_OK;
}

/* Binds the whole plan; nothing can fail after the reservation. */
static ssStatus commit(Plan* plan, ssAdoptReport* report) {
  ssStatus status = ssRegistryReserve(plan->registry, plan->row_count, plan->body_count);
  if (status != SS_OK) return status;
  for (int i = 0; i < plan->row_count; ++i) {
    const PlannedRow* row = &plan->rows[i];
    ssRegistryBindJointLaw(plan->registry, row->joint, row->param, row->axis, row->law, 0);
  }
  for (int i = 0; i < plan->body_count; ++i) {
    const PlannedBody* body = &plan->bodies[i];
    ssRegistry_BindDamping(plan->registry, body->body, body->linear_rate_per_s, body->angular_rate_per_s);
    if (body->has_auto_disable)
      ssRegistry_BindAutoDisable(plan->registry, body->body, body->idle_time_s, body->average_window_s);
  }
  plan->counts.bodies += plan->body_count;
  if (report != NULL) {
    report->world += plan->counts.world;
    report->joints += plan->counts.joints;
    report->joint_rows += plan->counts.joint_rows;
    report->stop_rows += plan->counts.stop_rows;
    report->motor_rows += plan->counts.motor_rows;
    report->suspension_rows += plan->counts.suspension_rows;
    report->hard_rows += plan->counts.hard_rows;
    report->bodies += plan->counts.bodies;
    report->skipped_joints += plan->counts.skipped_joints;
  }
  return SS_OK;
}

static Plan startPlan(ssRegistry* registry) {
  Plan plan;
  memset(&plan, 0, sizeof plan);
  plan.registry = registry;
  plan.world = ssRegistryWorld(registry);
  plan.tuned_step_s = ssRegistry_TunedStep(registry);
  return plan;
}

ssStatus ssRegistry_AdoptWorld(ssRegistry* registry, double tuned_step_s, ssAdoptReport* report) {
  if (registry == NULL) return ssFail(SS_ERROR_OUT_OF_RANGE, "registry = NULL: a registry is required");
  ssStatus status = ssCheckStepLength("tuned_step_s", tuned_step_s);
  if (status != SS_OK) return status;
  double adopted_s = ssRegistry_TunedStep(registry);
  if (adopted_s != 0 && adopted_s != tuned_step_s)
    return ssFail(SS_ERROR_OUT_OF_RANGE, "tuned_step_s = %g s: this registry adopted values tuned at %g s",
                  tuned_step_s,
                  adopted_s);
  if (adopted_s != 0) return SS_OK; /* adopted already: idempotent */
  dWorldID world = ssRegistryWorld(registry);
  ssSoftness tuned = {dWorldGetERP(world), dWorldGetCFM(world)};
  ssRowLaw law;
  status = ssRowLawFromTuned("world", tuned.erp, tuned.cfm, tuned_step_s, &law);
  if (status == SS_OK) status = ssCheckLawForEveryStep("world", &law);
  PlannedBody defaults = {0};
  if (status == SS_OK)
    status = dampingRate("world", dWorldGetLinearDamping(world), tuned_step_s, &defaults.linear_rate_per_s);
  if (status == SS_OK)
    status = dampingRate("world", dWorldGetAngularDamping(world), tuned_step_s, &defaults.angular_rate_per_s);
  if (status == SS_OK)
    status = autoDisableTimes("world", dWorldGetAutoDisableSteps(world), dWorldGetAutoDisableTime(world),
                              dWorldGetAutoDisableAverageSamplesCount(world), tuned_step_s, &defaults);
  if (status == SS_OK) status = ssRegistryReserve(registry, 0, 1);
  if (status != SS_OK) return status;
  ssRegistryBindWorldLaw(registry, law, 0);
  ssRegistrySetTuned(registry, tuned_step_s, tuned);
  ssRegistry_BindDamping(registry, 0, defaults.linear_rate_per_s, defaults.angular_rate_per_s);
  if (defaults.has_auto_disable)
    ssRegistry_BindAutoDisable(registry, 0, defaults.idle_time_s, defaults.average_window_s);
  if (report != NULL) {
    report->world += 1;
    report->hard_rows += law.hard;
  }
  return SS_OK;
}

ssStatus ssRegistry_AdoptSpace(ssRegistry* registry, dSpaceID space, ssAdoptReport* report) {
  ssStatus status = requireTuned(registry);
  if (status != SS_OK) return status;
  if (space == 0) return ssFail(SS_ERROR_OUT_OF_RANGE, "space = NULL: a space is required");
  Plan plan = startPlan(registry);
  status = planSpace(&plan, space);
  if (status == SS_OK) status = commit(&plan, report);
  freePlan(&plan);
  return status;
}

ssStatus ssRegistry_Adopt(ssRegistry* registry, double tuned_step_s, dSpaceID space, ssAdoptReport* report) {
  if (space == 0) return ssFail(SS_ERROR_OUT_OF_RANGE, "space = NULL: a space is required");
  int world_was_adopted = ssRegistry_TunedStep(registry) != 0;
  ssStatus status = ssRegistry_AdoptWorld(registry, tuned_step_s, report);
  if (status != SS_OK) return status;
  status = ssRegistry_AdoptSpace(registry, space, report);
  if (status != SS_OK && !world_was_adopted) ssRegistryForgetWorldAdoption(registry);
  return status;
}

ssStatus ssRegistry_AdoptBody(ssRegistry* registry, dBodyID body, ssAdoptReport* report) {
  ssStatus status = requireTuned(registry);
  if (status != SS_OK) return status;
  if (body == 0) return ssFail(SS_ERROR_OUT_OF_RANGE, "body = NULL: a body is required");
  Plan plan = startPlan(registry);
  status = planBody(&plan, body);
  if (status == SS_OK) status = walk(&plan);
  if (status == SS_OK) status = commit(&plan, report);
  freePlan(&plan);
  return status;
}

ssStatus ssRegistry_AdoptJoint(ssRegistry* registry, dJointID joint, ssAdoptReport* report) {
  ssStatus status = requireTuned(registry);
  if (status != SS_OK) return status;
  if (joint == 0) return ssFail(SS_ERROR_OUT_OF_RANGE, "joint = NULL: a joint is required");
  Plan plan = startPlan(registry);
  status = planJoint(&plan, joint);
  if (status == SS_OK) status = commit(&plan, report);
  freePlan(&plan);
  return status;
}

/* Adoption: a program's tuned numbers read back from ODE and bound as what they stand for (adopt.h).
 *
 * ODE 0.16 cannot list a world's bodies or joints, so adoption walks what it can reach: spaces -> geoms -> bodies
 * -> joints -> bodies. It plans every binding first, the world's included, and commits only when the whole plan is
 * valid, so an error leaves the registry as it was. */
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
#include "pointer_set.h"
#include "registry_internal.h"
#include "row_law.h"

typedef struct PlannedRow {
  dJointID joint;
  uint8_t joint_type; /* a dJointType, read once */
  uint8_t param;      /* an ssJointParam */
  uint8_t axis;
  ssRowLaw law;
} PlannedRow;

/* A body's binding as it will be made (body 0: the world's defaults; any other body, whole, as the registry will
 * hold it), and the sample count the body holds, which is not written again where it is already the one to write
 * (ODE restarts the average when it is set). */
typedef struct PlannedBody {
  ssBodyBinding binding;
  int samples_held;
} PlannedBody;

typedef struct Plan {
  ssRegistry* registry;
  dWorldID world;
  double tuned_step_s;
  /* the world's ERP/CFM and defaults, when this adoption binds them */
  int world_planned;
  ssRowLaw world_law;
  PlannedBody world_defaults;
  PlannedRow* rows;
  int row_count, row_capacity;
  PlannedBody* bodies;
  int body_count, body_capacity;
  dBodyID* pending; /* bodies still to walk from */
  int pending_count, pending_capacity;
  ssPointerSet seen; /* bodies and joints the walk has met */
  ssAdoptReport counts;
  int out_of_memory;
} Plan;

static void freePlan(Plan* plan) {
  free(plan->rows);
  free(plan->bodies);
  free(plan->pending);
  ssPointerSetFree(&plan->seen);
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
 * an average over `samples` steps as a window; the numbers themselves are kept for the tuned step. */
static ssStatus autoDisableTimes(const char* what, int steps, double seconds, int samples, double tuned_step_s,
                                 ssBodyBinding* out) {
  if (!isfinite(seconds) || seconds < 0)
    return ssFail(isfinite(seconds) ? SS_ERROR_OUT_OF_RANGE : SS_ERROR_NOT_FINITE,
                  "%s auto-disable time = %g s: must be finite and not negative", what, seconds);
  double idle_s = fmax(fmax(steps, 0) * tuned_step_s, seconds);
  /* 0 idle steps and 0 s: disabled at once; 0 samples: ODE never samples, so the body never sleeps. Both are so at
   * every step length alike: left as the program set them. */
  out->has_auto_disable = idle_s > 0 && samples > 0;
  out->idle_time_s = idle_s;
  out->average_window_s = samples > 1 ? samples * tuned_step_s : 0;
  out->tuned.auto_disable_step_s = tuned_step_s;
  out->tuned.idle_steps = steps;
  out->tuned.idle_time_s = seconds;
  out->tuned.average_samples = samples;
  return SS_OK;
}

/* The damping scales of a body (or the world) as rates, the scales themselves kept for the tuned step. */
static ssStatus dampingRates(const char* what, double linear, double angular, double tuned_step_s,
                             ssBodyBinding* out) {
  ssStatus status = dampingRate(what, linear, tuned_step_s, &out->linear_rate_per_s);
  if (status == SS_OK) status = dampingRate(what, angular, tuned_step_s, &out->angular_rate_per_s);
  if (status != SS_OK) return status;
  out->has_damping = 1;
  out->tuned.damping_step_s = tuned_step_s;
  out->tuned.linear_scale = linear;
  out->tuned.angular_scale = angular;
  return SS_OK;
}

ssStatus ssBodyValuesAsTuned(const char* what, dWorldID world, dBodyID body, double tuned_step_s, ssBodyBinding* out) {
  memset(out, 0, sizeof *out);
  out->body = body;
  double linear = body ? dBodyGetLinearDamping(body) : dWorldGetLinearDamping(world);
  double angular = body ? dBodyGetAngularDamping(body) : dWorldGetAngularDamping(world);
  int steps = body ? dBodyGetAutoDisableSteps(body) : dWorldGetAutoDisableSteps(world);
  double seconds = body ? dBodyGetAutoDisableTime(body) : dWorldGetAutoDisableTime(world);
  int samples = body ? dBodyGetAutoDisableAverageSamplesCount(body) : dWorldGetAutoDisableAverageSamplesCount(world);
  ssStatus status = dampingRates(what, linear, angular, tuned_step_s, out);
  if (status == SS_OK) status = autoDisableTimes(what, steps, seconds, samples, tuned_step_s, out);
  if (status != SS_OK) return status;
  /* as the registry's own binding calls would leave it (see bindBody) */
  out->written_step_s = NAN;
  out->average_samples_written = samples;
  if (!out->has_auto_disable) {
    out->idle_time_s = out->average_window_s = 0;
    out->tuned.auto_disable_step_s = out->tuned.idle_time_s = 0;
    out->tuned.idle_steps = out->tuned.average_samples = 0;
  }
  return SS_OK;
}

/* The world's defaults as this adoption binds them, or as bound before; NULL when neither. */
static const ssBodyBinding* worldDefaults(Plan* plan) {
  if (plan->world_planned) return &plan->world_defaults.binding;
  return ssRegistryFindBody(plan->registry, 0);
}

/* The world's law as this adoption binds it, or as bound before; 0 when neither. */
static int worldLaw(const Plan* plan, ssRowLaw* law) {
  if (plan->world_planned) {
    *law = plan->world_law;
    return 1;
  }
  return ssRegistryWorldBound(plan->registry, law);
}

/* Refuses a body of another world than the registry's: ODE would step it with another world, and the registry would
 * rewrite numbers the registry's world never reads. joint: the joint it was reached through, or 0. */
static ssStatus requireSameWorld(const Plan* plan, dJointID joint, dBodyID body) {
  dWorldID world = dBodyGetWorld(body);
  if (world == plan->world) return SS_OK;
  char through[64] = "";
  if (joint != 0) snprintf(through, sizeof through, "%s joint %p: ", ssJointTypeName(joint), (void*)joint);
  return ssFail(SS_ERROR_OUT_OF_RANGE, "%sbody %p is of world %p, not of the registry's world %p", through,
                (void*)body, (void*)world, (void*)plan->world);
}

static int pushPending(Plan* plan, dBodyID body) {
  if (!ssReserveOne((void**)&plan->pending, plan->pending_count, &plan->pending_capacity, sizeof body)) return 0;
  plan->pending[plan->pending_count++] = body;
  return 1;
}

static ssStatus planBody(Plan* plan, dBodyID body) {
  int added = ssPointerSetAdd(&plan->seen, body);
  if (added < 0) return outOfMemory();
  if (added == 0) return SS_OK;
  ssStatus status = requireSameWorld(plan, 0, body);
  if (status != SS_OK) return status;
  if (!pushPending(plan, body)) return outOfMemory();
  if (ssRegistryHasBody(plan->registry, body)) return SS_OK;
  /* the message names the body; it is written only on a refusal (one snprintf a body was 4.5 % of adopting) */
  char what[64] = "body";
  PlannedBody planned;
  memset(&planned, 0, sizeof planned);
  planned.binding.body = body;
  ssBodyBinding* binding = &planned.binding;
  /* ODE copied the world's current defaults into a body made after an earlier adoption: those stand for the
   * world's rates, not for values tuned at h0 */
  const ssBodyBinding* world = worldDefaults(plan);
  double linear = dBodyGetLinearDamping(body), angular = dBodyGetAngularDamping(body);
  if (world != NULL && world->has_damping && linear == dWorldGetLinearDamping(plan->world) &&
      angular == dWorldGetAngularDamping(plan->world)) {
    binding->has_damping = 1;
    binding->linear_rate_per_s = world->linear_rate_per_s;
    binding->angular_rate_per_s = world->angular_rate_per_s;
    binding->tuned.damping_step_s = world->tuned.damping_step_s;
    binding->tuned.linear_scale = world->tuned.linear_scale;
    binding->tuned.angular_scale = world->tuned.angular_scale;
  } else if ((status = dampingRates(what, linear, angular, plan->tuned_step_s, binding)) != SS_OK) {
    snprintf(what, sizeof what, "body %p", (void*)body);
    return dampingRates(what, linear, angular, plan->tuned_step_s, binding);
  }
  int steps = dBodyGetAutoDisableSteps(body), samples = dBodyGetAutoDisableAverageSamplesCount(body);
  double seconds = dBodyGetAutoDisableTime(body);
  planned.samples_held = samples;
  if (world != NULL && world->has_auto_disable && steps == dWorldGetAutoDisableSteps(plan->world) &&
      seconds == dWorldGetAutoDisableTime(plan->world) &&
      samples == dWorldGetAutoDisableAverageSamplesCount(plan->world)) {
    binding->has_auto_disable = 1;
    binding->idle_time_s = world->idle_time_s;
    binding->average_window_s = world->average_window_s;
    binding->tuned.auto_disable_step_s = world->tuned.auto_disable_step_s;
    binding->tuned.idle_steps = world->tuned.idle_steps;
    binding->tuned.idle_time_s = world->tuned.idle_time_s;
    binding->tuned.average_samples = world->tuned.average_samples;
  } else if ((status = autoDisableTimes(what, steps, seconds, samples, plan->tuned_step_s, binding)) != SS_OK) {
    snprintf(what, sizeof what, "body %p", (void*)body);
    return autoDisableTimes(what, steps, seconds, samples, plan->tuned_step_s, binding);
  }
  /* as the registry's own binding calls would leave it (see bindBody) */
  binding->written_step_s = NAN;
  if (binding->has_auto_disable) {
    binding->average_samples_written = samples;
  } else {
    binding->idle_time_s = binding->average_window_s = 0;
    binding->tuned.auto_disable_step_s = binding->tuned.idle_time_s = 0;
    binding->tuned.idle_steps = binding->tuned.average_samples = 0;
  }
  if (!ssReserveOne((void**)&plan->bodies, plan->body_count, &plan->body_capacity, sizeof planned))
    return outOfMemory();
  plan->bodies[plan->body_count++] = planned;
  return SS_OK;
}

/* A row's law from its tuned ERP/CFM, writable at every step length. */
static ssStatus planRowLaw(const char* what, double erp, double cfm, double tuned_step_s, ssRowLaw* law) {
  ssStatus status = ssRowLawFromTuned(what, erp, cfm, tuned_step_s, law);
  return status == SS_OK ? ssCheckLawForEveryStep(what, law) : status;
}

static ssStatus planRow(Plan* plan, dJointID joint, int joint_type, ssJointParam param, int axis) {
  if (ssRegistryHasJointRow(plan->registry, joint, param, axis)) return SS_OK;
  double erp, cfm;
  ssJointReadSoftness(joint, param, axis, &erp, &cfm);
  PlannedRow row = {.joint = joint, .joint_type = (uint8_t)joint_type, .param = (uint8_t)param, .axis = (uint8_t)axis};
  ssRowLaw world_law;
  ssSoftness world_now = {dWorldGetERP(plan->world), dWorldGetCFM(plan->world)};
  /* a row still holding the world's current ERP/CFM (ODE copies them at creation; the registry rewrites them for
   * each step) stands for the world's tuned spring. Motor rows are dampers, whose cfm is adopted as it is. */
  if (param != SS_PARAM_MOTOR && erp == world_now.erp && cfm == world_now.cfm && worldLaw(plan, &world_law)) {
    row.law = world_law;
  } else if (planRowLaw("row", erp, cfm, plan->tuned_step_s, &row.law) != SS_OK) {
    /* refused: again, with the message naming the row (written only on a refusal, as for bodies) */
    char what[96];
    snprintf(what, sizeof what, "%s joint %p, %s axis %d", ssJointTypeName(joint), (void*)joint,
             ssJointParamName(param), axis);
    return planRowLaw(what, erp, cfm, plan->tuned_step_s, &row.law);
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
  int added = ssPointerSetAdd(&plan->seen, joint);
  if (added < 0) return outOfMemory();
  if (added == 0) return SS_OK;
  int type = dJointGetType(joint);
  if (type <= dJointTypeNone || type > dJointTypeTransmission)
    return ssFail(SS_ERROR_UNSUPPORTED, "joint %p: type %d is not one ODE 0.16 knows", (void*)joint, type);
  /* ODE 0.16 has no getter for a joint's world: its bodies tell (a joint attached to none acts on nothing) */
  for (int side = 0; side < 2; ++side) {
    dBodyID body = dJointGetBody(joint, side);
    ssStatus status = body != 0 ? requireSameWorld(plan, joint, body) : SS_OK;
    if (status != SS_OK) return status;
  }
  if (type == dJointTypeContact || type == dJointTypeNull || type == dJointTypePlane2D) {
    plan->counts.skipped_joints += 1;
    return SS_OK; /* contacts are transient: the bodies they touch are reached through the space */
  }
  plan->counts.joints += 1;
  ssStatus status = SS_OK;
  if (ssJointSupports(joint, SS_PARAM_JOINT, 1)) status = planRow(plan, joint, type, SS_PARAM_JOINT, 1);
  for (int axis = 1; axis <= ssJointLimitAxisCount(joint) && status == SS_OK; ++axis) {
    status = planRow(plan, joint, type, SS_PARAM_STOP, axis);
    if (status == SS_OK) status = planRow(plan, joint, type, SS_PARAM_MOTOR, axis);
  }
  if (status == SS_OK && ssJointSupports(joint, SS_PARAM_SUSPENSION, 1))
    status = planRow(plan, joint, type, SS_PARAM_SUSPENSION, 1);
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

static ssStatus planSpace(Plan* plan, dSpaceID space, const char* what) {
  ssStatus listable = ssCheckSpaceListable(what, space);
  if (listable != SS_OK) return listable;
  int count = dSpaceGetNumGeoms(space);
  for (int i = 0; i < count; ++i) {
    dGeomID geom = dSpaceGetGeom(space, i);
    ssStatus status = SS_OK;
    if (dGeomIsSpace(geom)) {
      status = planSpace(plan, (dSpaceID)geom, "nested space");
    } else if (dGeomGetBody(geom) != 0) {
      status = planBody(plan, dGeomGetBody(geom));
      if (status == SS_OK) status = walk(plan);
    }
    if (status != SS_OK) return status;
  }
  return SS_OK;
}

/* Binds the world's planned defaults, with what the program had for the tuned step, over any bound by hand. */
static void bindBody(ssRegistry* registry, const PlannedBody* planned) {
  const ssBodyBinding* binding = &planned->binding;
  ssRegistry_BindDamping(registry, binding->body, binding->linear_rate_per_s, binding->angular_rate_per_s);
  if (binding->has_auto_disable)
    ssRegistry_BindAutoDisable(registry, binding->body, binding->idle_time_s, binding->average_window_s);
  ssBodyBinding* bound = ssRegistryFindBody(registry, binding->body);
  bound->tuned.damping_step_s = binding->tuned.damping_step_s;
  bound->tuned.linear_scale = binding->tuned.linear_scale;
  bound->tuned.angular_scale = binding->tuned.angular_scale;
  if (!binding->has_auto_disable) return;
  bound->tuned.auto_disable_step_s = binding->tuned.auto_disable_step_s;
  bound->tuned.idle_steps = binding->tuned.idle_steps;
  bound->tuned.idle_time_s = binding->tuned.idle_time_s;
  bound->tuned.average_samples = binding->tuned.average_samples;
  bound->average_samples_written = planned->samples_held;
}

/* Binds the whole plan; nothing can fail after the reservation. */
static ssStatus commit(Plan* plan, ssAdoptReport* report) {
  ssStatus status = ssRegistryReserve(plan->registry, plan->row_count, plan->body_count + plan->world_planned);
  if (status != SS_OK) return status;
  if (plan->world_planned) {
    ssRegistryBindWorldLaw(plan->registry, plan->world_law, 0);
    ssRegistrySetTuned(plan->registry, plan->tuned_step_s, plan->world_law.tuned);
    bindBody(plan->registry, &plan->world_defaults);
    plan->counts.world = 1;
    plan->counts.hard_rows += plan->world_law.hard;
  }
  /* the plan holds only rows and bodies not bound before, each once */
  for (int i = 0; i < plan->row_count; ++i) {
    const PlannedRow* row = &plan->rows[i];
    ssRegistryAppendJointLaw(plan->registry, row->joint, row->joint_type, (ssJointParam)row->param, row->axis,
                             row->law);
  }
  for (int i = 0; i < plan->body_count; ++i) ssRegistryAppendBody(plan->registry, &plan->bodies[i].binding);
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

/* Plans the world's ERP/CFM and defaults as tuned at tuned_step_s, unless adopted already at that step. */
static ssStatus planWorld(Plan* plan, double tuned_step_s) {
  ssStatus status = ssCheckStepLength("tuned_step_s", tuned_step_s);
  if (status != SS_OK) return status;
  double adopted_s = ssRegistry_TunedStep(plan->registry);
  if (adopted_s != 0 && adopted_s != tuned_step_s)
    return ssFail(SS_ERROR_OUT_OF_RANGE, "tuned_step_s = %g s: this registry adopted values tuned at %g s",
                  tuned_step_s, adopted_s);
  if (adopted_s != 0) return SS_OK; /* adopted already: idempotent */
  plan->tuned_step_s = tuned_step_s;
  dWorldID world = plan->world;
  status = ssRowLawFromTuned("world", dWorldGetERP(world), dWorldGetCFM(world), tuned_step_s, &plan->world_law);
  if (status == SS_OK) status = ssCheckLawForEveryStep("world", &plan->world_law);
  ssBodyBinding* defaults = &plan->world_defaults.binding;
  if (status == SS_OK)
    status = dampingRates("world", dWorldGetLinearDamping(world), dWorldGetAngularDamping(world), tuned_step_s,
                          defaults);
  if (status == SS_OK)
    status = autoDisableTimes("world", dWorldGetAutoDisableSteps(world), dWorldGetAutoDisableTime(world),
                              dWorldGetAutoDisableAverageSamplesCount(world), tuned_step_s, defaults);
  if (status != SS_OK) return status;
  plan->world_defaults.samples_held = dWorldGetAutoDisableAverageSamplesCount(world);
  plan->world_planned = 1;
  return SS_OK;
}

ssStatus ssRegistry_AdoptWorld(ssRegistry* registry, double tuned_step_s, ssAdoptReport* report) {
  if (registry == NULL) return ssFail(SS_ERROR_OUT_OF_RANGE, "registry = NULL: a registry is required");
  Plan plan = startPlan(registry);
  ssStatus status = planWorld(&plan, tuned_step_s);
  if (status == SS_OK) status = commit(&plan, report);
  freePlan(&plan);
  return status;
}

ssStatus ssRegistry_AdoptSpace(ssRegistry* registry, dSpaceID space, ssAdoptReport* report) {
  ssStatus status = requireTuned(registry);
  if (status != SS_OK) return status;
  if (space == 0) return ssFail(SS_ERROR_OUT_OF_RANGE, "space = NULL: a space is required");
  Plan plan = startPlan(registry);
  status = planSpace(&plan, space, "space");
  if (status == SS_OK) status = commit(&plan, report);
  freePlan(&plan);
  return status;
}

ssStatus ssRegistry_Adopt(ssRegistry* registry, double tuned_step_s, dSpaceID space, ssAdoptReport* report) {
  if (registry == NULL) return ssFail(SS_ERROR_OUT_OF_RANGE, "registry = NULL: a registry is required");
  if (space == 0) return ssFail(SS_ERROR_OUT_OF_RANGE, "space = NULL: a space is required");
  Plan plan = startPlan(registry);
  ssStatus status = planWorld(&plan, tuned_step_s);
  if (status == SS_OK) status = planSpace(&plan, space, "space");
  if (status == SS_OK) status = commit(&plan, report);
  freePlan(&plan);
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

/* The stepper: a frame's time becomes physics steps, each with its softness rewritten for its length. */
#include <math.h>
#include <stdlib.h>
#include <stdint.h>
#include <string.h>

#include "array.h"
#include "error.h"
#include "registry_internal.h"
#include "steadystep/stepper.h"

/* Frame times are sums of floating-point parts: a frame of exactly 2·max_step_s must not become 3 substeps. */
static const double kStepCountSlack = 1e-9;

struct ssStepper {
  ssStepperDef def;
  double previous_step_s; /* 0: no usable history */
  double accumulator_s;   /* FIXED: time not yet stepped */
  dBodyID* watched;
  int watched_count, watched_capacity;
  /* the registry's bodies, each once, rebuilt when its generation changes */
  dBodyID* bound;
  int bound_count, bound_capacity;
  unsigned bound_generation;
  int bound_valid;
  /* the check of one step, filled by checkBody */
  dBodyID failed_body;
  ssStatus failed_status;
};

ssStepperDef ssDefaultStepperDef(void) {
  ssStepperDef def;
  memset(&def, 0, sizeof def);
  def.policy = SS_POLICY_SPRING;
  def.solver = SS_SOLVER_QUICK;
  def.quick_iterations = 20;
  def.max_step_s = 1.0 / 60.0;
  def.reference_step_s = 1.0 / 30.0;
  def.fixed_step_s = 1.0 / 60.0;
  def.max_steps_per_frame = 8;
  return def;
}

const char* ssPolicyName(ssPolicy policy) {
  switch (policy) {
    case SS_POLICY_NAIVE: return "naive";
    case SS_POLICY_SPRING: return "spring";
    case SS_POLICY_MATCHED: return "matched";
    case SS_POLICY_EXACT: return "exact";
    case SS_POLICY_FIXED: return "fixed";
  }
  return NULL;
}

ssStatus ssPolicyParse(const char* name, ssPolicy* out) {
  for (int policy = SS_POLICY_NAIVE; policy <= SS_POLICY_FIXED; ++policy) {
    if (name != NULL && strcmp(name, ssPolicyName((ssPolicy)policy)) == 0) {
      *out = (ssPolicy)policy;
      return SS_OK;
    }
  }
  return ssFail(SS_ERROR_PARSE, "policy \"%s\": unknown (naive, spring, matched, exact, fixed)",
                name ? name : "(null)");
}

static ssStatus validateDef(const ssStepperDef* def) {
  if (def == NULL || def->world == 0) return ssFail(SS_ERROR_OUT_OF_RANGE, "world = NULL: a world is required");
  if (ssPolicyName(def->policy) == NULL) return ssFail(SS_ERROR_UNSUPPORTED, "policy = %d: unknown", (int)def->policy);
  if (def->solver != SS_SOLVER_QUICK && def->solver != SS_SOLVER_STEP)
    return ssFail(SS_ERROR_UNSUPPORTED, "solver = %d: unknown", (int)def->solver);
  if (def->quick_iterations <= 0)
    return ssFail(SS_ERROR_OUT_OF_RANGE, "quick_iterations = %d: must be positive", def->quick_iterations);
  if (def->max_steps_per_frame <= 0)
    return ssFail(SS_ERROR_OUT_OF_RANGE, "max_steps_per_frame = %d: must be positive", def->max_steps_per_frame);
  ssStatus status = ssCheckPositive("max_step_s", "s", def->max_step_s);
  if (status == SS_OK) status = ssCheckPositive("reference_step_s", "s", def->reference_step_s);
  if (status == SS_OK) status = ssCheckPositive("fixed_step_s", "s", def->fixed_step_s);
  if (status == SS_OK) status = ssCheckNonNegative("max_speed", "m/s", def->max_speed);
  return status;
}

ssStatus ssStepper_Create(const ssStepperDef* def, ssStepper** out) {
  ssStatus status = validateDef(def);
  if (status != SS_OK) return status;
  ssStepper* stepper = calloc(1, sizeof *stepper);
  if (stepper == NULL) return ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory creating a stepper");
  stepper->def = *def;
  *out = stepper;
  return SS_OK;
}

void ssStepper_Destroy(ssStepper* stepper) {
  if (stepper == NULL) return;
  free(stepper->watched);
  free(stepper->bound);
  free(stepper);
}

ssStatus ssStepper_WatchBody(ssStepper* stepper, dBodyID body) {
  if (body == 0) return ssFail(SS_ERROR_OUT_OF_RANGE, "body = NULL: a body is required");
  for (int i = 0; i < stepper->watched_count; ++i)
    if (stepper->watched[i] == body) return SS_OK;
  if (!ssReserveOne((void**)&stepper->watched, stepper->watched_count, &stepper->watched_capacity, sizeof body))
    return ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory watching a body");
  stepper->watched[stepper->watched_count++] = body;
  return SS_OK;
}

ssStatus ssStepper_UnwatchBody(ssStepper* stepper, dBodyID body) {
  for (int i = 0; i < stepper->watched_count; ++i) {
    if (stepper->watched[i] != body) continue;
    stepper->watched[i] = stepper->watched[--stepper->watched_count];
    return SS_OK;
  }
  return ssFail(SS_ERROR_NOT_FOUND, "body %p: not watched", (void*)body);
}

void ssStepper_ResetHistory(ssStepper* stepper) { stepper->previous_step_s = 0; }

ssStatus ssStepper_SetPolicy(ssStepper* stepper, ssPolicy policy) {
  if (ssPolicyName(policy) == NULL) return ssFail(SS_ERROR_UNSUPPORTED, "policy = %d: unknown", (int)policy);
  stepper->def.policy = policy;
  stepper->previous_step_s = 0;
  stepper->accumulator_s = 0;
  return SS_OK;
}

/* Checks one body after a step; the first failure of the step is kept. Rotation is not read: a non-finite angular
 * velocity makes ODE 0.16 abort inside the step (dxNormalize4), so a rotation that comes back is finite. */
static void checkBody(ssStepper* stepper, dBodyID body) {
  const dReal* position = dBodyGetPosition(body);
  const dReal* velocity = dBodyGetLinearVel(body);
  /* a NaN or an infinity anywhere makes the sum non-finite: one test for six numbers */
  double sum = position[0] + position[1] + position[2] + velocity[0] + velocity[1] + velocity[2];
  double speed_squared = velocity[0] * velocity[0] + velocity[1] * velocity[1] + velocity[2] * velocity[2];
  double max_speed = stepper->def.max_speed;
  if (isfinite(sum) && (max_speed == 0 || speed_squared <= max_speed * max_speed)) return;
  stepper->failed_body = body;
  if (!isfinite(sum) || !isfinite(speed_squared))
    stepper->failed_status = ssFail(SS_ERROR_BLOWUP, "body %p: position or velocity is not finite", (void*)body);
  else
    stepper->failed_status = ssFail(SS_ERROR_SPEED_LIMIT, "body %p: speed %g m/s is above max_speed = %g m/s",
                                    (void*)body, sqrt(speed_squared), max_speed);
}

static void appendBound(void* context, dBodyID body) {
  ssStepper* stepper = context;
  if (stepper->bound_count < stepper->bound_capacity) stepper->bound[stepper->bound_count++] = body;
}

/* The registry's bodies, each once; rebuilt only when the registry's bindings changed. */
static ssStatus refreshBound(ssStepper* stepper) {
  const ssRegistry* registry = stepper->def.registry;
  unsigned generation = ssRegistryGeneration(registry);
  if (stepper->bound_valid && stepper->bound_generation == generation) return SS_OK;
  int most = 2 * ssRegistry_JointBindingCount(registry) + ssRegistryBodyBindingCount(registry);
  if (most > stepper->bound_capacity) {
    dBodyID* larger = realloc(stepper->bound, (size_t)most * sizeof *larger);
    if (larger == NULL) return ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory listing the bound bodies");
    stepper->bound = larger;
    stepper->bound_capacity = most;
  }
  stepper->bound_count = 0;
  ssRegistry_VisitBodies(registry, appendBound, stepper);
  stepper->bound_generation = generation;
  stepper->bound_valid = 1;
  return SS_OK;
}

/* One physics step of step_s, the registry having been applied for it. */
static ssStatus takeStep(ssStepper* stepper, ssMapping mapping, double softness_step_s, double previous_step_s,
                         double step_s, ssFrameReport* report) {
  const ssStepperDef* def = &stepper->def;
  if (def->collide) def->collide(def->collide_context, mapping, softness_step_s, previous_step_s);
  if (def->solver == SS_SOLVER_STEP) {
    if (!dWorldStep(def->world, step_s)) return ssFail(SS_ERROR_OUT_OF_MEMORY, "dWorldStep ran out of memory");
  } else {
    dWorldSetQuickStepNumIterations(def->world, def->quick_iterations);
    if (!dWorldQuickStep(def->world, step_s))
      return ssFail(SS_ERROR_OUT_OF_MEMORY, "dWorldQuickStep ran out of memory");
  }
  if (def->contact_group) dJointGroupEmpty(def->contact_group);
  report->steps += 1;
  report->step_s = step_s;
  report->simulated_s += step_s;

  stepper->failed_body = 0;
  stepper->failed_status = SS_OK;
  for (int i = 0; i < stepper->watched_count && !stepper->failed_body; ++i) checkBody(stepper, stepper->watched[i]);
  for (int i = 0; i < stepper->bound_count && !stepper->failed_body; ++i) checkBody(stepper, stepper->bound[i]);
  if (stepper->failed_body != 0) {
    report->failed_body = stepper->failed_body;
    stepper->previous_step_s = 0;
    return stepper->failed_status;
  }
  if (def->step_done) def->step_done(def->step_done_context, step_s);
  return SS_OK;
}

static ssStatus apply(ssStepper* stepper, ssMapping mapping, double step_s, double previous_step_s,
                      ssFrameReport* report) {
  if (stepper->def.registry == NULL) return SS_OK;
  ssApplyReport applied;
  ssStatus status = ssRegistry_Apply(stepper->def.registry, mapping, step_s, previous_step_s, &applied);
  if (status != SS_OK) return status;
  report->apply.rows_written += applied.rows_written;
  report->apply.rows_over_nyquist += applied.rows_over_nyquist;
  report->apply.rows_exact_fallback += applied.rows_exact_fallback;
  return SS_OK;
}

static ssMapping policyMapping(ssPolicy policy) {
  switch (policy) {
    case SS_POLICY_MATCHED: return SS_MAPPING_MATCHED;
    case SS_POLICY_EXACT: return SS_MAPPING_EXACT;
    default: return SS_MAPPING_SPRING;
  }
}

/* NAIVE: one step of the whole frame, softness frozen at the reference step. */
static ssStatus stepNaive(ssStepper* stepper, double frame_s, ssFrameReport* report) {
  double reference_s = stepper->def.reference_step_s;
  ssStatus status = apply(stepper, SS_MAPPING_SPRING, reference_s, 0, report);
  if (status != SS_OK) return status;
  return takeStep(stepper, SS_MAPPING_SPRING, reference_s, 0, frame_s, report);
}

/* SPRING, MATCHED, EXACT: n equal substeps no longer than max_step_s. */
static ssStatus stepSubsteps(ssStepper* stepper, double frame_s, ssFrameReport* report) {
  double count = ceil(frame_s / stepper->def.max_step_s - kStepCountSlack);
  if (count < 1) count = 1;
  if (count > (double)INT32_MAX)
    return ssFail(SS_ERROR_OUT_OF_RANGE, "frame_s = %g s: more than %d substeps of max_step_s = %g s", frame_s,
                  INT32_MAX, stepper->def.max_step_s);
  int steps = (int)count;
  double step_s = frame_s / steps;
  ssMapping mapping = policyMapping(stepper->def.policy);
  for (int i = 0; i < steps; ++i) {
    /* the spring mapping depends on h alone, equal for all substeps: one write a frame is enough */
    if (i == 0 || mapping != SS_MAPPING_SPRING) {
      ssStatus status = apply(stepper, mapping, step_s, stepper->previous_step_s, report);
      if (status != SS_OK) return status;
    }
    ssStatus status = takeStep(stepper, mapping, step_s, stepper->previous_step_s, step_s, report);
    if (status != SS_OK) return status;
    stepper->previous_step_s = step_s;
  }
  return SS_OK;
}

/* FIXED: constant steps from an accumulator, capped against the spiral of death. */
static ssStatus stepFixed(ssStepper* stepper, double frame_s, ssFrameReport* report) {
  double step_s = stepper->def.fixed_step_s;
  double accumulator_s = stepper->accumulator_s + frame_s;
  double due = floor(accumulator_s / step_s + kStepCountSlack);
  int cap = stepper->def.max_steps_per_frame;
  if (due > cap) {
    report->dropped_s = (due - cap) * step_s;
    accumulator_s -= report->dropped_s;
    due = cap;
  }
  int steps = (int)due;
  if (steps > 0) {
    ssStatus status = apply(stepper, SS_MAPPING_SPRING, step_s, 0, report);
    if (status != SS_OK) return status;
  }
  for (int i = 0; i < steps; ++i) {
    ssStatus status = takeStep(stepper, SS_MAPPING_SPRING, step_s, step_s, step_s, report);
    accumulator_s -= step_s;
    if (status != SS_OK) {
      stepper->accumulator_s = fmax(accumulator_s, 0);
      return status;
    }
  }
  stepper->accumulator_s = fmax(accumulator_s, 0);
  report->interpolation = fmin(stepper->accumulator_s / step_s, nextafter(1.0, 0.0));
  return SS_OK;
}

ssStatus ssStepper_Step(ssStepper* stepper, double frame_s, ssFrameReport* report) {
  ssFrameReport local;
  if (report == NULL) report = &local;
  memset(report, 0, sizeof *report);
  ssStatus status = ssCheckNonNegative("frame_s", "s", frame_s);
  if (status != SS_OK || frame_s == 0) return status;
  if (stepper->def.registry != NULL && (status = refreshBound(stepper)) != SS_OK) return status;
  switch (stepper->def.policy) {
    case SS_POLICY_NAIVE: return stepNaive(stepper, frame_s, report);
    case SS_POLICY_FIXED: return stepFixed(stepper, frame_s, report);
    default: return stepSubsteps(stepper, frame_s, report);
  }
}

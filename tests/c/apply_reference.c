/* The tests' reference Apply (apply_reference.h): compute every row, then write what changed. */
#include "apply_reference.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "error.h"
#include "joint_rows.h"
#include "ode_bounds.h"
#include "registry_internal.h"
#include "row_law.h"
#include "steadystep/limits.h"

/* A row's effective mass from its bodies now; NAN when it has none. */
static double measuredMass(const ssJointRowBinding* row) {
  dBodyID first = dJointGetBody(row->joint, 0);
  ssRowGeometry geometry;
  if (first == 0 || !ssJointRowGeometry(row->joint, dJointGetType(row->joint), row->param, row->axis, &geometry))
    return NAN;
  dBodyID bodies[2] = {first, dJointGetBody(row->joint, 1)};
  double inverse = 0;
  for (int side = 0; side < 2; ++side) {
    if (bodies[side] == 0) continue;
    ssBodyInverse body;
    ssBodyInverseOf(bodies[side], &body);
    inverse += ssRowInverseMass(&body, &geometry);
  }
  double mass = inverse > 0 ? 1.0 / inverse : 0;
  return mass > 0 && isfinite(mass) ? mass : NAN;
}

typedef struct Computed {
  ssSoftness softness;
  double correction;
} Computed;

/* Each row counted once, by who served it. */
static void count(const ssRowFallback* fallback, ssApplyReport* report) {
  if (fallback->to_implicit_euler) report->rows.handed_to_implicit_euler += 1;
  else if (fallback->exact_to_matched) report->rows.handed_to_matched += 1;
  else report->rows.by_mapping += 1;
}

static ssStatus computeRow(const ssJointRowBinding* row, ssMapping mapping, double step_s, double previous_s,
                           ssApplyReport* report, Computed* out) {
  double mass = row->effective_mass > 0 ? row->effective_mass : row->law.hard ? NAN : measuredMass(row);
  ssRowFallback fallback;
  ssStatus status =
      ssRowSoftness(&row->law, mapping, mass, step_s, previous_s, row->load != 0, &fallback, &out->softness);
  if (status == SS_OK) status = ssCheckSoftnessForOde("softness", out->softness.erp, out->softness.cfm);
  if (status != SS_OK) return status;
  out->correction = 0;
  const ssSpring* spring = &row->law.spring;
  if (mapping != SS_MAPPING_IMPLICIT_EULER && row->load != 0 && !row->law.hard && spring->stiffness != 0) {
    double correction = row->load * (out->softness.erp / (step_s * out->softness.cfm) / spring->stiffness - 1);
    if (fabs(correction) <= SS_MAX_FORCE_N) {
      out->correction = correction;
    } else { /* no accurate softness that carries the load: implicit Euler, whose static stiffness is k */
      fallback = (ssRowFallback){0, 1};
      status = ssImplicitEulerSoftness(*spring, step_s, &out->softness);
      if (status != SS_OK) return status;
    }
  }
  count(&fallback, report);
  return SS_OK;
}

static double stepsIn(double seconds, double step_s) { return ceil(seconds / step_s - 1e-9); }

/* A body binding's values for the step, each written where ODE holds another: at the step adoption read them for,
 * the program's own numbers; at any other, what the rates and seconds stand for, with at most
 * SS_MAX_AVERAGE_SAMPLES samples. */
static void writeBody(const ssBodyBinding* binding, dWorldID world, double step_s) {
  dBodyID body = binding->body;
  const ssBodyTuned* tuned = &binding->tuned;
  if (binding->has_damping) {
    int as_tuned = step_s == tuned->damping_step_s;
    double linear = as_tuned ? tuned->linear_scale : -expm1(-binding->linear_rate_per_s * step_s);
    double angular = as_tuned ? tuned->angular_scale : -expm1(-binding->angular_rate_per_s * step_s);
    if (body) {
      if (dBodyGetLinearDamping(body) != linear) dBodySetLinearDamping(body, linear);
      if (dBodyGetAngularDamping(body) != angular) dBodySetAngularDamping(body, angular);
    } else {
      if (dWorldGetLinearDamping(world) != linear) dWorldSetLinearDamping(world, linear);
      if (dWorldGetAngularDamping(world) != angular) dWorldSetAngularDamping(world, angular);
    }
  }
  if (binding->has_auto_disable) {
    int as_tuned = step_s == tuned->auto_disable_step_s;
    double steps = stepsIn(binding->idle_time_s, step_s);
    int idle_steps = as_tuned ? tuned->idle_steps : steps < INT32_MAX ? (int)steps : INT32_MAX;
    double idle_time_s = as_tuned ? tuned->idle_time_s : binding->idle_time_s;
    double samples = fmin(fmax(1.0, stepsIn(binding->average_window_s, step_s)), SS_MAX_AVERAGE_SAMPLES);
    unsigned average = as_tuned ? (unsigned)tuned->average_samples : (unsigned)samples;
    if (body) {
      if (dBodyGetAutoDisableSteps(body) != idle_steps) dBodySetAutoDisableSteps(body, idle_steps);
      if (dBodyGetAutoDisableTime(body) != idle_time_s) dBodySetAutoDisableTime(body, idle_time_s);
      if ((unsigned)dBodyGetAutoDisableAverageSamplesCount(body) != average)
        dBodySetAutoDisableAverageSamplesCount(body, average);
    } else {
      if (dWorldGetAutoDisableSteps(world) != idle_steps) dWorldSetAutoDisableSteps(world, idle_steps);
      if (dWorldGetAutoDisableTime(world) != idle_time_s) dWorldSetAutoDisableTime(world, idle_time_s);
      if ((unsigned)dWorldGetAutoDisableAverageSamplesCount(world) != average)
        dWorldSetAutoDisableAverageSamplesCount(world, average);
    }
  }
}

ssStatus ssRegistryApplyReference(ssRegistry* registry, unsigned* applied_stamp, ssMapping mapping, double step_s,
                                  double previous_step_s, ssApplyReport* report) {
  if (registry == NULL) return ssFail(SS_ERROR_OUT_OF_RANGE, "registry = NULL: a registry is required");
  ssStatus status = ssCheckStepLength("step_s", step_s);
  if (status == SS_OK && previous_step_s != 0) status = ssCheckStepLength("previous_step_s", previous_step_s);
  if (status != SS_OK) return status;
  if (ssMappingName(mapping) == NULL) return ssFail(SS_ERROR_UNSUPPORTED, "mapping = %d: unknown", (int)mapping);
  double previous_s = mapping == SS_MAPPING_EXACT ? previous_step_s : 0;
  ssApplyReport counts = {{0, 0, 0}, 0};
  ssRowLaw world_law;
  ssSoftness world = {0, 0};
  int world_bound = ssRegistryWorldBound(registry, &world_law);
  if (world_bound) {
    double mass = ssRegistryWorldMass(registry);
    ssRowFallback fallback;
    status = ssRowSoftness(&world_law, mapping, mass, step_s, previous_s, 0, &fallback, &world);
    if (status == SS_OK) status = ssCheckSoftnessForOde("softness", world.erp, world.cfm);
    if (status != SS_OK) return status;
    count(&fallback, &counts);
  }
  int rows = ssRegistry_JointBindingCount(registry);
  Computed* computed = malloc((size_t)(rows > 0 ? rows : 1) * sizeof *computed);
  if (computed == NULL) return ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory in the reference Apply");
  for (int i = 0; i < rows && status == SS_OK; ++i) {
    status = computeRow(ssRegistryJointRowAt(registry, i), mapping, step_s, previous_s, &counts, &computed[i]);
  }
  if (status != SS_OK) {
    free(computed);
    return status;
  }
  dWorldID world_id = ssRegistryWorld(registry);
  if (world_bound &&
      (!ssSameInOde(dWorldGetERP(world_id), world.erp) || !ssSameInOde(dWorldGetCFM(world_id), world.cfm))) {
    dWorldSetERP(world_id, world.erp);
    dWorldSetCFM(world_id, world.cfm);
    counts.row_writes += 1;
  }
  for (int i = 0; i < rows; ++i) {
    const ssJointRowBinding row = *ssRegistryJointRowAt(registry, i);
    double erp, cfm;
    ssJointReadSoftness(row.joint, row.param, row.axis, &erp, &cfm);
    ssRowWriter writer;
    ssJointRowWriterOf(row.joint, row.param, row.axis, &writer);
    /* a motor row has no erp: ODE holds only its cfm */
    int erp_differs = writer.erp_number >= 0 && !ssSameInOde(erp, computed[i].softness.erp);
    /* a row bound since the last Apply is written whatever ODE holds (registry.h: binding again rewrites it) */
    if (row.stamp > *applied_stamp || erp_differs || !ssSameInOde(cfm, computed[i].softness.cfm)) {
      ssRowWrite(&writer, row.joint, computed[i].softness.erp, computed[i].softness.cfm);
      counts.row_writes += 1;
    }
  }
  for (int i = 0; i < rows; ++i) {
    const ssJointRowBinding* row = ssRegistryJointRowAt(registry, i);
    if (computed[i].correction != 0) ssJointAddRowForce(row->joint, row->param, row->axis, computed[i].correction);
  }
  free(computed);
  for (int i = 0; i < ssRegistryBodyBindingCount(registry); ++i)
    writeBody(ssRegistryBodyAt(registry, i), world_id, step_s);
  *applied_stamp = ssRegistryLastStamp(registry);
  if (report != NULL) *report = counts;
  return SS_OK;
}

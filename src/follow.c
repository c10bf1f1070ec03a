/* The program stays in charge (registry_internal.h, ssRegistryFollowProgram): values a program writes into ODE after
 * adoption (a settings menu, an entity's fields, a script) are noticed where they differ from what Apply last wrote,
 * and bound again as what they stand for, the way adoption read them. Without this, a program that sets world ERP
 * 0.8 between frames keeps it while the frames keep their length and loses it to the adopted value as soon as one
 * frame is longer: the library itself would make the program's setting depend on the frame rate.
 *
 * Two passes, as Apply's: every changed value is read and turned into its law first, and the bindings change only
 * when all of them passed, so that an error leaves the registry as it was. */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>

#include "apply_internal.h"
#include "array.h"
#include "error.h"
#include "joint_rows.h"
#include "ode_bounds.h"
#include "prefetch.h"
#include "registry_internal.h"
#include "steadystep/adopt.h"

/* A row the program wrote: its binding, what ODE holds now and the law that stands for it. */
typedef struct FollowedRow {
  int binding;
  ssSoftness held;
  ssRowLaw law;
} FollowedRow;


/* The law a value the program wrote stands for, checked as adoption checks it; the message names the row. */
static ssStatus lawOfWritten(const char* what, ssSoftness held, double step_s, ssRowLaw* law) {
  ssStatus status = ssRowLawFromTuned(what, held.erp, held.cfm, step_s, law);
  return status == SS_OK ? ssCheckLawForEveryStep(what, law) : status;
}

/* The rows the program wrote over, each with the law it stands for, gathered by followRows. */
typedef struct FollowedRows {
  ssRegistry* registry;
  double step_s;
  FollowedRow* rows;
  int count, capacity;
} FollowedRows;

static ssStatus takeRowWrittenOver(void* context, int i, ssSoftness held) {
  FollowedRows* followed = context;
  const ssJointRowBinding* binding = ssRegistryJointRowAt(followed->registry, i);
  FollowedRow row = {i, held, {{0, 0}, 0, 0, 0, {0, 0}}};
  char what[96];
  snprintf(what, sizeof what, "%s joint %p, %s axis %d, as the program wrote it", ssJointTypeName(binding->joint),
           (void*)binding->joint, ssJointParamName(binding->param), binding->axis);
  /* a motor row (no erp) stands for a damper: its law is read with erp 0, as adoption reads it */
  ssStatus status = lawOfWritten(what, held, followed->step_s, &row.law);
  if (status != SS_OK) return status;
  if (!ssReserveOne((void**)&followed->rows, followed->count, &followed->capacity, sizeof *followed->rows))
    return ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory following the program's writes");
  followed->rows[followed->count++] = row;
  return SS_OK;
}

/* Every row the program wrote over since Apply's last write (ssApplyEachRowWrittenOver), with its law, into *out
 * (*count of them; free it); an error leaves *out NULL. */
static ssStatus followRows(ssRegistry* registry, double step_s, FollowedRow** out, int* count) {
  FollowedRows followed = {registry, step_s, NULL, 0, 0};
  ssStatus status = ssApplyEachRowWrittenOver(registry, takeRowWrittenOver, &followed);
  if (status != SS_OK) {
    free(followed.rows);
    followed.rows = NULL, followed.count = 0;
  }
  *out = followed.rows;
  *count = followed.count;
  return status;
}

/* A large world's body binding kPrefetchAhead places on asked for: its body's flags, and the auto-disable and damping
 * numbers ODE 0.16 keeps a few lines past the torque accumulator, torque_at bytes into every body (dxBody: a hint;
 * another layout costs a load). */
SS_PREFETCH_HELPER void prefetchBinding(const ssBodyBinding* binding, ptrdiff_t torque_at) {
  const char* body = (const char*)binding->body;
  if (body == NULL) return;
  SS_PREFETCH(body);
  SS_PREFETCH(body + torque_at + 64);
  SS_PREFETCH(body + torque_at + 192);
}

/* Whether the body binding's numbers in ODE are `written`. */
static int bodyHolds(dWorldID world, const ssBodyBinding* binding, ssBodyWritten written) {
  dBodyID body = binding->body;
  if (binding->has_damping &&
      (!ssSameInOde(written.linear_scale, body ? dBodyGetLinearDamping(body) : dWorldGetLinearDamping(world)) ||
       !ssSameInOde(written.angular_scale, body ? dBodyGetAngularDamping(body) : dWorldGetAngularDamping(world))))
    return 0;
  if (!binding->has_auto_disable) return 1;
  int steps = body ? dBodyGetAutoDisableSteps(body) : dWorldGetAutoDisableSteps(world);
  double seconds = body ? dBodyGetAutoDisableTime(body) : dWorldGetAutoDisableTime(world);
  int samples = body ? dBodyGetAutoDisableAverageSamplesCount(body) : dWorldGetAutoDisableAverageSamplesCount(world);
  return steps == written.idle_steps && ssSameInOde(seconds, written.idle_time_s) &&
         samples == binding->average_samples_written;
}

ssStatus ssRegistryFollowProgram(ssRegistry* registry, int with_bodies, int* followed) {
  if (followed != NULL) *followed = 0;
  double step_s = ssRegistry_TunedStep(registry); /* what adopted numbers mean; nothing adopted, nothing to follow */
  if (step_s == 0) return SS_OK;
  dWorldID world = ssRegistryWorld(registry);
  /* the world's rows */
  int world_followed = 0;
  ssRowLaw world_law;
  ssSoftness world_held = {dWorldGetERP(world), dWorldGetCFM(world)};
  ssRowLaw bound_law;
  int world_bound = ssRegistryWorldBound(registry, &bound_law) && bound_law.tuned_step_s > 0;
  ssSoftness world_written = world_bound ? ssApplyWorldLastWritten(registry) : (ssSoftness){NAN, NAN};
  if (world_bound && !isnan(world_written.cfm) &&
      (!ssSameInOde(world_held.erp, world_written.erp) || !ssSameInOde(world_held.cfm, world_written.cfm))) {
    ssStatus status = lawOfWritten("world ERP/CFM, as the program wrote them,", world_held, step_s, &world_law);
    if (status != SS_OK) return status;
    world_followed = 1;
  }
  FollowedRow* rows;
  int row_count;
  ssStatus status = followRows(registry, step_s, &rows, &row_count);
  if (status != SS_OK) return status;
  /* the bodies (and the world's defaults, body 0), each planned whole */
  ssBodyBinding* bodies = NULL;
  int* body_at = NULL;
  int body_count = 0;
  const int bound = with_bodies ? ssRegistryBodyBindingCount(registry) : 0;
  const ssBodyBinding* bindings = bound > 0 ? ssRegistryBodyAt(registry, 0) : NULL; /* not changed before the end */
  const int until = ssPrefetchUntil(bound);
  ptrdiff_t torque_at = 0; /* the same in every body: read once */
  for (int i = 0; i < until && torque_at == 0; ++i) {
    const char* body = (const char*)bindings[i].body;
    if (body != NULL) torque_at = (const char*)dBodyGetTorque(bindings[i].body) - body;
  }
  for (int i = 0; i < bound && status == SS_OK; ++i) {
    const ssBodyBinding* binding = &bindings[i];
    if (i < until) prefetchBinding(&bindings[i + kPrefetchAhead], torque_at);
    int adopted = binding->tuned.damping_step_s > 0 || binding->tuned.auto_disable_step_s > 0;
    /* a sleeping body's values are read when it wakes: ODE neither damps it nor counts its idle steps, and Apply
     * writes it no more than this reads it (ssRegistryWriteBodies) */
    int asleep = binding->body != 0 && !dBodyIsEnabled(binding->body);
    if (!adopted || asleep || isnan(binding->written_step_s) || bodyHolds(world, binding, binding->written)) continue;
    ssBodyBinding* larger_bodies = realloc(bodies, (size_t)(body_count + 1) * sizeof *bodies);
    int* larger_at = realloc(body_at, (size_t)(body_count + 1) * sizeof *body_at);
    if (larger_bodies != NULL) bodies = larger_bodies;
    if (larger_at != NULL) body_at = larger_at;
    if (larger_bodies == NULL || larger_at == NULL) {
      status = ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory following the program's writes");
      break;
    }
    char what[64] = "world's defaults, as the program set them,";
    if (binding->body) snprintf(what, sizeof what, "body %p, as the program set it,", (void*)binding->body);
    status = ssBodyValuesAsTuned(what, world, binding->body, step_s, &bodies[body_count]);
    body_at[body_count++] = i;
  }
  if (status != SS_OK) {
    free(rows);
    free(bodies);
    free(body_at);
    return status;
  }

  /* Nothing below can fail: every followed value is bound as what it stands for, and what ODE holds now is what
   * Apply compares its next softness with (it writes the law's over it where they differ). */
  for (int r = 0; r < row_count; ++r) ssRegistryFollowJointLaw(registry, rows[r].binding, rows[r].law);
  if (world_followed) ssRegistryFollowWorldLaw(registry, world_law);
  for (int b = 0; b < body_count; ++b) ssRegistryFollowBody(registry, body_at[b], &bodies[b]);
  for (int r = 0; r < row_count; ++r) ssApplyTakeHeld(registry, rows[r].binding, rows[r].held);
  if (world_followed) ssApplyTakeHeld(registry, -1, world_held);
  int total = world_followed + row_count + body_count;
  if (followed != NULL) *followed = total;
  free(rows);
  free(bodies);
  free(body_at);
  return SS_OK;
}

ssStatus ssRegistryFollowWoken(ssRegistry* registry, const dBodyID* woken, int count, int* followed) {
  *followed = 0;
  double step_s = ssRegistry_TunedStep(registry);
  if (step_s == 0 || count == 0) return SS_OK;
  dWorldID world = ssRegistryWorld(registry);
  ssBodyBinding* planned = malloc((size_t)count * sizeof *planned);
  int* planned_at = malloc((size_t)count * sizeof *planned_at);
  ssStatus status = planned != NULL && planned_at != NULL
                        ? SS_OK
                        : ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory following the program's writes");
  int planned_count = 0;
  for (int w = 0; w < count && status == SS_OK; ++w) {
    const ssBodyBinding* binding = ssRegistryFindBody(registry, woken[w]);
    if (binding == NULL || !(binding->tuned.damping_step_s > 0 || binding->tuned.auto_disable_step_s > 0)) continue;
    /* what the registry left there: what it last wrote, or, never written, what adoption read */
    ssBodyWritten left = binding->written;
    if (isnan(binding->written_step_s)) ssBodyWrittenFor(binding, step_s, &left);
    if (bodyHolds(world, binding, left)) continue;
    char what[64];
    snprintf(what, sizeof what, "body %p, as the program set it while it slept,", (void*)binding->body);
    status = ssBodyValuesAsTuned(what, world, binding->body, step_s, &planned[planned_count]);
    planned_at[planned_count++] = (int)(binding - ssRegistryBodyAt(registry, 0));
  }
  for (int p = 0; p < planned_count && status == SS_OK; ++p) ssRegistryFollowBody(registry, planned_at[p], &planned[p]);
  if (status == SS_OK) *followed = planned_count;
  free(planned);
  free(planned_at);
  return status;
}

/* Apply's state (apply_state.h states its invariants): built from the registry's bindings whenever they change, with
 * what Apply last wrote carried over to the rows bound as they were; the body cache; what Apply last wrote, for
 * follow.c. */
#include "apply_state.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pointer_set.h"

static void freeState(void* pointer) {
  ApplyState* state = pointer;
  if (state == NULL) return;
  free(state->rows);
  free(state->hot_rows);
  free(state->bodies);
  free(state->bound_rows);
  free(state);
}

static int sameLaw(const ssRowLaw* a, const ssRowLaw* b) {
  return a->hard == b->hard && a->spring.stiffness == b->spring.stiffness && a->spring.damping == b->spring.damping &&
         a->hard_rate_per_s == b->hard_rate_per_s && a->tuned_step_s == b->tuned_step_s &&
         a->tuned.erp == b->tuned.erp && a->tuned.cfm == b->tuned.cfm;
}

/* Whether two rows drive the same axis of the same joint (a stop and a motor) with the same mass: given alike, or
 * measured for both (a hard row measures none). */
static int sharesRow(const ssJointRowBinding* a, const ssJointRowBinding* b) {
  int a_limit = a->param == SS_PARAM_STOP || a->param == SS_PARAM_MOTOR;
  int b_limit = b->param == SS_PARAM_STOP || b->param == SS_PARAM_MOTOR;
  return a->joint == b->joint && a->axis == b->axis && a_limit && b_limit && a->effective_mass == b->effective_mass &&
         !a->law.hard && !b->law.hard;
}

void ssApplyMaterializeRows(ApplyState* state) {
  if (!state->written_by_law) return;
  for (int i = 0; i < state->row_count; ++i) {
    ApplyRow* row = &state->rows[i];
    if (row->law_slot >= 0) row->written = state->law_written[row->law_slot];
  }
  state->written_by_law = 0;
}

void ssApplyRebuildBodies(ApplyState* state) {
  state->bodies_stale = 0;
  free(state->bodies);
  state->bodies = NULL;
  state->body_count = 0;
  size_t most = 2 * (size_t)state->row_count;
  BodyCache* cache = most > 0 ? malloc(most * sizeof *cache) : NULL;
  int count = 0;
  if (cache != NULL) { /* out of memory: every row computes its bodies itself */
    for (int i = 0; i < state->row_count; ++i)
      for (int side = 0; side < 2; ++side) {
        dBodyID body = dJointGetBody(state->rows[i].joint, side);
        if (body != 0) cache[count++] = (BodyCache){.body = body, .stamp = 0};
      }
    /* a BodyCache starts with its body: ordered as handles are */
    qsort(cache, (size_t)count, sizeof *cache, ssCompareHandles);
    int unique = 0;
    for (int i = 0; i < count; ++i)
      if (unique == 0 || cache[i].body != cache[unique - 1].body) cache[unique++] = cache[i];
    count = unique;
  }
  for (int i = 0; i < state->row_count; ++i)
    for (int side = 0; side < 2; ++side) {
      dBodyID body = dJointGetBody(state->rows[i].joint, side);
      const BodyCache* found =
          cache != NULL && body != 0 ? bsearch(&body, cache, (size_t)count, sizeof *cache, ssCompareHandles) : NULL;
      state->rows[i].body_slot[side] = found != NULL ? (int)(found - cache) : -1;
    }
  state->bodies = cache;
  state->body_count = count;
  state->bound_row_count = 0;
  for (int i = 0; i < state->row_count && state->bound_rows != NULL; ++i) {
    const ApplyRow* row = &state->rows[i];
    const ssJointRowBinding* binding = &row->binding;
    if (row->law_slot < 0 || binding->law.hard || binding->effective_mass > 0) continue;
    const uint8_t angular = (uint8_t)ssJointRowIsAngular(binding->joint_type, binding->param, binding->axis);
    BoundRow* last = state->bound_row_count > 0 ? &state->bound_rows[state->bound_row_count - 1] : NULL;
    if (last != NULL && last->joint == row->joint && last->angular == angular && last->law_slot[1] < 0) {
      last->law_slot[1] = (int16_t)row->law_slot;
      continue;
    }
    BoundRow* bound = &state->bound_rows[state->bound_row_count++];
    *bound = (BoundRow){.joint = row->joint, .law_slot = {(int16_t)row->law_slot, -1}, .angular = angular};
    for (int side = 0; side < 2; ++side) { /* the slots just found: no joint read again */
      const int slot = row->body_slot[side];
      bound->body[side] = slot >= 0 ? cache[slot].body : 0;
      bound->bound[side] = slot >= 0 ? &cache[slot].bound : NULL;
    }
  }
}

const ssBodyInverse* ssApplyBodyInverse(ApplyState* state, int slot, dBodyID body, ssBodyInverse* local) {
  if (APPLY_CACHE_ON(state, SS_APPLY_BODIES) && slot >= 0 && state->bodies[slot].body == body) {
    BodyCache* cached = &state->bodies[slot];
    if (cached->stamp != state->apply_stamp) {
      ssBodyInverseOf(body, &cached->inverse);
      cached->stamp = state->apply_stamp;
    }
    return &cached->inverse;
  }
  if (APPLY_CACHE_ON(state, SS_APPLY_BODIES)) state->bodies_stale = 1;
  ssBodyInverseOf(body, local);
  return local;
}

/* The law table, each row's slot in it, and the hot rows by law (a counting sort, in row order within a law). */
static void buildLaws(ApplyState* state) {
  state->law_count = 0;
  state->rows_outside_laws = 0;
  state->hard_rows = 0;
  memset(state->law_unsure, 0, sizeof state->law_unsure);
  memset(state->law_given_mass, 0, sizeof state->law_given_mass);
  for (int i = 0; i < state->row_count; ++i) {
    ApplyRow* row = &state->rows[i];
    row->law_slot = -1;
    for (int j = 0; j < state->law_count && row->law_slot < 0; ++j)
      if (sameLaw(&state->laws[j], &row->binding.law)) row->law_slot = j;
    if (row->law_slot < 0 && state->law_count < kLawTableSize) {
      state->laws[state->law_count] = row->binding.law;
      row->law_slot = state->law_count++;
    }
    state->rows_outside_laws += row->law_slot < 0;
    const ssJointRowBinding* binding = &row->binding;
    if (row->law_slot < 0 || binding->law.hard) {
      state->hard_rows += row->law_slot >= 0;
      continue;
    }
    const int given = binding->effective_mass > 0;
    state->law_unsure[row->law_slot] |= (binding->load != 0 && binding->law.spring.stiffness > 0) ||
                                        (!given && binding->joint_type == dJointTypeAMotor);
    if (given && binding->effective_mass > state->law_given_mass[row->law_slot])
      state->law_given_mass[row->law_slot] = binding->effective_mass;
  }
  int* next = state->law_rows;
  memset(next, 0, sizeof state->law_rows);
  for (int i = 0; i < state->row_count; ++i)
    if (state->rows[i].law_slot >= 0 && state->rows[i].writer.set != NULL) next[state->rows[i].law_slot + 1] += 1;
  for (int j = 0; j < kLawTableSize; ++j) next[j + 1] += next[j];
  int placed[kLawTableSize];
  memcpy(placed, next, sizeof placed);
  for (int i = 0; i < state->row_count; ++i) {
    const ApplyRow* row = &state->rows[i];
    if (row->law_slot < 0 || row->writer.set == NULL) continue;
    state->hot_rows[placed[row->law_slot]++] = (HotRow){.joint = row->joint,
                                                        .set = row->writer.set,
                                                        .erp_number = (int16_t)row->writer.erp_number,
                                                        .cfm_number = (int16_t)row->writer.cfm_number,
                                                        .row = i};
  }
}

/* The rows again from the bindings. A binding whose stamp the last build knew keeps what was written: the registry
 * keeps the order of the rows it does not rebind, so they are found in one walk. Returns 0 when out of memory (the
 * state as it was). */
static int rebuild(ApplyState* state, ssRegistry* registry) {
  int count = ssRegistry_JointBindingCount(registry);
  size_t rows_size = (size_t)(count > 0 ? count : 1);
  ApplyRow* rows = malloc(rows_size * sizeof *rows);
  HotRow* hot = malloc(rows_size * sizeof *hot);
  BoundRow* bound = malloc(rows_size * sizeof *bound);
  if (rows == NULL || hot == NULL || bound == NULL) {
    free(rows);
    free(hot);
    free(bound);
    return 0;
  }
  ssApplyMaterializeRows(state);
  int old = 0;
  for (int i = 0; i < count; ++i) {
    const ssJointRowBinding* binding = ssRegistryJointRowAt(registry, i);
    ApplyRow* row = &rows[i];
    *row = (ApplyRow){.joint = binding->joint,
                      .written = {NAN, NAN},
                      .computed_mapping = SS_MAPPING_IMPLICIT_EULER,
                      .mass = NAN,
                      .computed_step_s = NAN,
                      .computed_previous_s = NAN,
                      .binding = *binding};
    ssJointRowWriterOfType(binding->joint_type, binding->param, binding->axis, &row->writer);
    row->get = row->writer.set != NULL ? ssRowGetterOfType(binding->joint_type) : NULL;
    row->shares_previous_row = i > 0 && sharesRow(&rows[i - 1].binding, binding);
    if (binding->stamp > state->stamp) continue; /* bound since: nothing written */
    int k = old;
    while (k < state->row_count && state->rows[k].binding.stamp != binding->stamp) ++k;
    if (k == state->row_count) continue;
    const ApplyRow* before = &state->rows[k];
    row->written = before->written;
    if (sameLaw(&before->binding.law, &binding->law) && before->binding.load == binding->load) {
      row->mass = before->mass; /* implicit Euler reads the last mass; the accurate mappings' reuse, what it had */
      row->computed = before->computed;
      row->computed_fallback = before->computed_fallback;
      row->computed_mapping = before->computed_mapping;
      row->computed_step_s = before->computed_step_s;
      row->computed_previous_s = before->computed_previous_s;
    }
    old = k + 1;
  }
  free(state->rows);
  free(state->hot_rows);
  free(state->bound_rows);
  state->rows = rows;
  state->hot_rows = hot;
  state->bound_rows = bound;
  state->row_count = count;
  state->loaded_rows = 0;
  for (int i = 0; i < count; ++i) state->loaded_rows += rows[i].binding.load != 0;
  state->revision = ssRegistryRowsRevision(registry);
  state->stamp = ssRegistryLastStamp(registry);
  buildLaws(state);
  state->handed_wait = state->handed_failed = 0;
  ssApplyRebuildBodies(state);
  return 1;
}

ApplyState* ssApplyStateOf(ssRegistry* registry) {
  ssRegistryAttachment* attachment = ssRegistryApplyAttachment(registry);
  ApplyState* state = attachment->state;
  if (state == NULL) {
    state = calloc(1, sizeof *state);
    if (state == NULL) return NULL;
    state->world_written = (ssSoftness){NAN, NAN};
    state->applied_step_s = NAN;
    state->revision = ssRegistryRowsRevision(registry) - 1; /* built at once below */
    attachment->state = state;
    attachment->free_state = freeState;
  }
  if (state->revision != ssRegistryRowsRevision(registry) && !rebuild(state, registry)) return NULL;
  return state;
}

ssSoftness ssApplyWorldLastWritten(ssRegistry* registry) {
  ApplyState* state = ssApplyStateOf(registry);
  return state != NULL ? state->world_written : (ssSoftness){NAN, NAN};
}

ssStatus ssApplyEachRowWrittenOver(ssRegistry* registry, ssRowWrittenOver* visit, void* context) {
  ApplyState* state = ssApplyStateOf(registry);
  if (state == NULL) return SS_OK;
  for (int i = 0; i < state->row_count; ++i) {
    const ApplyRow* row = &state->rows[i];
    if (row->get == NULL || row->binding.law.tuned_step_s == 0) continue;
    const ssSoftness written =
        state->written_by_law && row->law_slot >= 0 ? state->law_written[row->law_slot] : row->written;
    if (isnan(written.cfm)) continue;
    const int has_erp = row->writer.erp_number >= 0;
    const double cfm = row->get(row->joint, row->writer.cfm_number);
    const double erp = has_erp ? row->get(row->joint, row->writer.erp_number) : 0;
    if (ssSameInOde(cfm, written.cfm) && (!has_erp || ssSameInOde(erp, written.erp))) continue;
    ssStatus status = visit(context, i, (ssSoftness){erp, cfm});
    if (status != SS_OK) return status;
  }
  return SS_OK;
}

void ssApplyTakeHeld(ssRegistry* registry, int i, ssSoftness held) {
  ApplyState* state = ssApplyStateOf(registry);
  if (state == NULL) return; /* the next Apply reports it */
  state->applied_step_s = NAN;
  if (i < 0) {
    state->world_written = held;
    return;
  }
  ssApplyMaterializeRows(state);
  state->rows[i].written = held;
}

#ifdef SS_APPLY_SWITCHES
void ssApplyDisableCaches(ssRegistry* registry, unsigned mask) {
  ApplyState* state = ssApplyStateOf(registry);
  if (state == NULL) return;
  state->disabled = mask;
  state->applied_step_s = NAN; /* nothing computed with other caches is taken for this Apply's */
  for (int i = 0; i < state->row_count; ++i) state->rows[i].computed_step_s = NAN;
}
#endif

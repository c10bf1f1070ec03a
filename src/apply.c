/* Apply: every binding written for one step, in two passes, compute then write, so that an error leaves every ODE
 * object as it was. The first pass gives each row its mass (given, or measured from its bodies), its law's softness
 * under the mapping (ssRowSoftness: where an accurate mapping cannot serve a row, implicit Euler does, counted),
 * checked for ODE, and its load's correction; the second writes what differs from what ODE holds by Apply's last
 * writes, the world's ERP/CFM, the load forces, and the bodies' damping and auto-disable (registry.c).
 *
 * What Apply derives from the bindings is its own (apply_state.h, with the invariants each cache keeps). The caches
 * kept are those bench_apply shows to pay, each switchable in the tests' and benchmarks' build (SS_APPLY_SWITCHES):
 *  - same step: implicit Euler depends on h alone, so a step as long as the last, with nothing rebound, writes
 *    nothing (a program with constant frames pays nothing here);
 *  - by law: under implicit Euler each law's softness is computed once and its rows written by law;
 *  - bodies: each body's inverse mass and inertia computed once per Apply for all the rows on it;
 *  - same axis: a stop and a motor on one axis share the mass measured for the first;
 *  - reuse: the accurate mappings are pure functions of the law, mass, step and step before; a row whose inputs did
 *    not change keeps its softness (constant steps, masses a motion leaves unchanged);
 *  - shared: within one Apply, rows of one law and one mass (identical links, wheels) share one softness;
 *  - sure fallback: a row that ssSurelyFailsStaticResponse says the accurate mappings hand on gets implicit Euler's
 *    softness without their arithmetic (row_law.h; test_apply.cpp checks it against ssRowSoftness);
 *  - handed on (apply_handed.c): under an accurate mapping, when ssSurelyFailsUpToMass hands every law on at every
 *    mass its rows can have (bounded from their bodies' masses and inertias, which no rotation changes), implicit
 *    Euler's by-law pass serves the Apply, no row measured (a program tuned near-rigid, adopted: nothing served).
 * The plain reference Apply (tests/c/apply_reference.c) computes every row with none of them; the differential test
 * and fuzz_apply require both to write the same values into ODE, with every cache on, off, or some of them. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "apply_state.h"
#include "error.h"
#include "steadystep/limits.h"

/* Prefixes the current message with what failed, so that a caller of Apply learns which binding it was. */
static ssStatus failBinding(ssStatus status, const ssJointRowBinding* binding) {
  char cause[200];
  strncpy(cause, ssLastError(), sizeof cause - 1);
  cause[sizeof cause - 1] = '\0';
  if (binding == NULL) return ssFail(status, "world ERP/CFM: %s", cause);
  return ssFail(status, "%s joint %p, %s axis %d: %s", ssJointTypeName(binding->joint), (void*)binding->joint,
                ssJointParamName(binding->param), binding->axis, cause);
}

/* Counts one row of this Apply in the report, once, by who served it. */
static void countRow(ssRowFallback fallback, ssApplyReport* report) {
  if (fallback.to_implicit_euler) report->rows.handed_to_implicit_euler += 1;
  else if (fallback.exact_to_matched) report->rows.handed_to_matched += 1;
  else report->rows.by_mapping += 1;
}

/* The softnesses one Apply computed, by law (a slot of the law table), mass and load: a row looks at its home entry
 * and the kSharedProbes - 1 after it, and stops at an unused one. After kSharedTrial computed rows that found fewer
 * than one in four shared (rows of distinct masses never share), the rest of the Apply computes every row. */
enum { kSharedSize = 16, kSharedProbes = 4, kSharedTrial = 2 * kSharedSize };
typedef struct SharedSoftness {
  int law_slot;
  int load_declared;
  double mass; /* compared only where the mapping reads it */
  ssSoftness softness;
  ssRowFallback fallback;
} SharedSoftness;
typedef struct SharedTable {
  int on, hits, computed;
  unsigned char used[kSharedSize];
  SharedSoftness entries[kSharedSize];
} SharedTable;

static unsigned sharedHome(int law_slot, int any_mass, double mass, int load_declared) {
  uint64_t key = (uint64_t)law_slot, bits;
  memcpy(&bits, &mass, sizeof bits);
  if (!any_mass) key ^= bits * 0x9E3779B97F4A7C15ull;
  key = (key ^ (uint64_t)load_declared) * 0x9E3779B97F4A7C15ull;
  return (unsigned)(key >> 60); /* the top 4 bits: kSharedSize entries */
}

/* The entry of (law_slot, mass, load) computed in this Apply, or, when absent, where a new one goes (*found 0). */
static SharedSoftness* findShared(SharedTable* table, int law_slot, int any_mass, double mass, int load_declared,
                                  int* found) {
  unsigned home = sharedHome(law_slot, any_mass, mass, load_declared);
  for (unsigned p = 0; p < kSharedProbes; ++p) {
    unsigned slot = (home + p) & (kSharedSize - 1);
    SharedSoftness* entry = &table->entries[slot];
    *found = table->used[slot];
    if (!*found) return entry;
    if (entry->law_slot == law_slot && (any_mass || entry->mass == mass) && entry->load_declared == load_declared)
      return entry;
  }
  *found = 0;
  return &table->entries[home];
}

/* The row's effective mass from its bodies (through the body cache); NAN when the row has none to measure. */
static double rowMass(ApplyState* state, const ApplyRow* row) {
  dJointID joint = row->joint;
  dBodyID bodies[2] = {dJointGetBody(joint, 0), 0};
  ssRowGeometry geometry;
  if (bodies[0] == 0 ||
      !ssJointRowGeometry(joint, row->binding.joint_type, row->binding.param, row->binding.axis, &geometry))
    return NAN;
  bodies[1] = dJointGetBody(joint, 1);
  ssBodyInverse local; /* for a body the cache does not know: one at a time */
  double inverse = ssRowInverseMass(ssApplyBodyInverse(state, row->body_slot[0], bodies[0], &local), &geometry);
  if (bodies[1] != 0)
    inverse += ssRowInverseMass(ssApplyBodyInverse(state, row->body_slot[1], bodies[1], &local), &geometry);
  double mass = inverse > 0 ? 1.0 / inverse : 0;
  return mass > 0 && isfinite(mass) ? mass : NAN;
}

/* The law's softness for the row (into row->computed), through the reuse and sharing caches, checked for ODE. */
static ssStatus lawSoftness(ApplyState* state, ApplyRow* row, const ssRowLaw* law, ssMapping mapping, double mass,
                            double step_s, double previous_s, SharedTable* shared) {
  const int load_declared = row->binding.load != 0;
  if (mapping != SS_MAPPING_IMPLICIT_EULER && APPLY_CACHE_ON(state, SS_APPLY_REUSE) &&
      row->computed_step_s == step_s && row->mass == mass && row->computed_mapping == mapping &&
      row->computed_previous_s == previous_s)
    return SS_OK;
  row->mass = mass;
  row->computed_mapping = (uint8_t)mapping;
  row->computed_step_s = NAN; /* until it is computed and checked */
  int any_mass = mapping == SS_MAPPING_IMPLICIT_EULER || law->hard, found = 0;
  SharedSoftness* entry = NULL;
  if (shared->on && row->law_slot >= 0) {
    entry = findShared(shared, row->law_slot, any_mass, mass, load_declared, &found);
    if (found) {
      row->computed = entry->softness;
      row->computed_fallback = entry->fallback;
      shared->hits += 1;
    }
  }
  if (!found) {
    ssStatus status;
    if (!any_mass && APPLY_CACHE_ON(state, SS_APPLY_SURE_FALLBACK) && !(load_declared && law->spring.stiffness > 0) &&
        ssSurelyFailsStaticResponse(law->spring, mass, step_s)) {
      /* a row the rule surely hands to implicit Euler gets its law's implicit-Euler softness, as ssRowSoftness gives
       * it, without the accurate arithmetic whose only use would be to decide so (a declared load keeps the
       * accurate softness instead) */
      row->computed_fallback = (ssRowFallback){0, 1};
      status = ssRowSoftness(law, SS_MAPPING_IMPLICIT_EULER, NAN, step_s, 0, 0, NULL, &row->computed);
    } else {
      status = ssRowSoftness(law, mapping, mass, step_s, previous_s, load_declared, &row->computed_fallback,
                             &row->computed);
    }
    if (status == SS_OK) status = ssCheckSoftnessForOde("softness", row->computed.erp, row->computed.cfm);
    if (status != SS_OK) return status;
    if (entry != NULL) {
      *entry = (SharedSoftness){row->law_slot, load_declared, mass, row->computed, row->computed_fallback};
      shared->used[entry - shared->entries] = 1;
      if (++shared->computed >= kSharedTrial && 4 * shared->hits < shared->computed) shared->on = 0;
    }
  }
  row->computed_step_s = step_s;
  row->computed_previous_s = previous_s;
  return SS_OK;
}

/* The first pass in general: each row's softness into pending with its load's correction, all checked before
 * anything is written. *unwritten counts the rows whose pending differs from what ODE holds. */
static ssStatus computeRows(ApplyState* state, ssMapping mapping, double step_s, double previous_s,
                            ssApplyReport* counts, int* unwritten) {
  SharedTable shared = {.on = APPLY_CACHE_ON(state, SS_APPLY_SHARED)};
  const int same_axis = APPLY_CACHE_ON(state, SS_APPLY_SAME_AXIS);
  const int measure = mapping != SS_MAPPING_IMPLICIT_EULER; /* implicit Euler reads no mass */
  double last_mass = NAN;
  for (int i = 0; i < state->row_count; ++i) {
    ApplyRow* row = &state->rows[i];
    const ssJointRowBinding* binding = &row->binding;
    const ssRowLaw* law = row->law_slot >= 0 ? &state->laws[row->law_slot] : &binding->law;
    double mass = binding->effective_mass > 0 ? binding->effective_mass
                  : law->hard || !measure         ? NAN
                  : same_axis && row->shares_previous_row ? last_mass
                                                          : rowMass(state, row);
    last_mass = mass;
    ssStatus status = lawSoftness(state, row, law, mapping, mass, step_s, previous_s, &shared);
    if (status != SS_OK) return failBinding(status, binding);
    row->pending = row->computed;
    ssRowFallback fallback = row->computed_fallback;
    row->load_correction = 0;
    const ssSpring* spring = &law->spring;
    if (measure && binding->load != 0 && !law->hard && spring->stiffness != 0) {
      /* the step's static stiffness is k' = erp/(h·cfm): this force puts the rest position back at load/k */
      double correction = binding->load * (row->pending.erp / (step_s * row->pending.cfm) / spring->stiffness - 1);
      if (fabs(correction) <= SS_MAX_FORCE_N) {
        row->load_correction = correction;
      } else { /* no accurate softness that carries the load: implicit Euler, whose static stiffness is k itself */
        fallback = (ssRowFallback){0, 1};
        status = ssImplicitEulerSoftness(*spring, step_s, &row->pending);
        if (status != SS_OK) return failBinding(status, binding);
      }
    }
    countRow(fallback, counts);
    *unwritten += !ssSameWrite(row->writer.erp_number, &row->pending, &row->written);
  }
  return SS_OK;
}

/* The second pass in general: the rows whose softness changed, then the load forces. Returns the rows written. */
static int writeRows(ApplyState* state, ssMapping mapping) {
  int writes = 0;
  for (int i = 0; i < state->row_count; ++i) {
    ApplyRow* row = &state->rows[i];
    if (ssSameWrite(row->writer.erp_number, &row->pending, &row->written)) continue;
    ssRowWrite(&row->writer, row->joint, row->pending.erp, row->pending.cfm);
    row->written = row->pending;
    writes += 1;
  }
  if (mapping != SS_MAPPING_IMPLICIT_EULER && state->loaded_rows > 0)
    for (int i = 0; i < state->row_count; ++i) {
      const ApplyRow* row = &state->rows[i];
      if (row->load_correction != 0)
        ssJointAddRowForce(row->joint, row->binding.param, row->binding.axis, row->load_correction);
    }
  return writes;
}

/* Implicit Euler when every row's law is in the table: the softness of each law, checked (the only part that can
 * fail), so that the rows can then be written by law. */
static ssStatus lawSoftnesses(const ApplyState* state, double step_s, ssSoftness* softness) {
  for (int j = 0; j < state->law_count; ++j) {
    ssStatus status = ssRowSoftness(&state->laws[j], SS_MAPPING_IMPLICIT_EULER, NAN, step_s, 0, 0, NULL, &softness[j]);
    if (status == SS_OK) status = ssCheckSoftnessForOde("softness", softness[j].erp, softness[j].cfm);
    if (status == SS_OK) continue;
    for (int i = 0; i < state->row_count; ++i)
      if (state->rows[i].law_slot == j) return failBinding(status, &state->rows[i].binding);
    return status;
  }
  return SS_OK;
}

/* A law's rows written with its softness s: each row's erp where it has one, and its cfm; with erp_rows_only (only
 * the law's erp changed) only the rows that hold an erp. Returns the rows written. */
static int writeLawRows(const HotRow* from, const HotRow* end, ssSoftness s, int erp_rows_only) {
  int writes = 0;
  for (const HotRow* row = from; row < end; ++row) {
    if (erp_rows_only && row->erp_number < 0) continue;
    if (row->erp_number >= 0) row->set(row->joint, row->erp_number, s.erp);
    row->set(row->joint, row->cfm_number, s.cfm);
    writes += 1;
  }
  return writes;
}

/* The one pass of lawSoftnesses' case, which cannot fail: each law's rows written where their softness changed. Where
 * the last such pass wrote every row of a law, law_written says what they hold, and a law whose softness is what
 * they hold has none of its rows read (a damper's, k = 0, at any step). Returns the rows written. */
static int writeRowsByLaw(ApplyState* state, const ssSoftness* softness) {
  int writes = 0;
  for (int j = 0; j < state->law_count; ++j) {
    const HotRow *from = state->hot_rows + state->law_rows[j], *end = state->hot_rows + state->law_rows[j + 1];
    if (!state->written_by_law) { /* each row holds its own written */
      for (const HotRow* row = from; row < end; ++row) {
        if (ssSameWrite(row->erp_number, &softness[j], &state->rows[row->row].written)) continue;
        writes += writeLawRows(row, row + 1, softness[j], 0);
      }
    } else if (!ssSameInOde(softness[j].cfm, state->law_written[j].cfm)) {
      writes += writeLawRows(from, end, softness[j], 0);
    } else if (!ssSameInOde(softness[j].erp, state->law_written[j].erp)) {
      writes += writeLawRows(from, end, softness[j], 1);
    }
  }
  for (int j = 0; j < state->law_count; ++j) state->law_written[j] = softness[j];
  state->written_by_law = 1;
  return writes;
}

ssStatus ssRegistry_Apply(ssRegistry* registry, ssMapping mapping, double step_s, double previous_step_s,
                          ssApplyReport* report) {
  REQUIRE_REGISTRY(registry);
  ssStatus status = ssCheckStepLength("step_s", step_s);
  if (status == SS_OK && previous_step_s != 0) status = ssCheckStepLength("previous_step_s", previous_step_s);
  if (status != SS_OK) return status;
  if (ssMappingName(mapping) == NULL) return ssFail(SS_ERROR_UNSUPPORTED, "mapping = %d: unknown", (int)mapping);
  ApplyState* state = ssApplyStateOf(registry);
  if (state == NULL) return ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory in Apply");

  if (mapping == SS_MAPPING_IMPLICIT_EULER && APPLY_CACHE_ON(state, SS_APPLY_SAME_STEP) &&
      state->applied_mapping == mapping && state->applied_step_s == step_s &&
      state->applied_revision == ssRegistryRevision(registry)) {
    if (report != NULL) *report = (ssApplyReport){state->applied_counts.rows, 0};
    return SS_OK;
  }
  const double previous_s = mapping == SS_MAPPING_EXACT ? previous_step_s : 0;
  ssApplyReport counts = {{0, 0, 0}, 0};
  if (state->bodies_stale) ssApplyRebuildBodies(state);
  if (++state->apply_stamp == 0) { /* after 2^32 Applies: no cached body may look computed for this one */
    for (int i = 0; i < state->body_count; ++i) state->bodies[i].stamp = 0;
    state->apply_stamp = 1;
  }
  ssRowLaw world_law;
  ssSoftness world = {0, 0};
  const int world_bound = ssRegistryWorldBound(registry, &world_law);
  if (world_bound) {
    ssRowFallback fallback;
    status = ssRowSoftness(&world_law, mapping, ssRegistryWorldMass(registry), step_s, previous_s, 0, &fallback,
                           &world);
    if (status == SS_OK) status = ssCheckSoftnessForOde("softness", world.erp, world.cfm);
    if (status != SS_OK) return failBinding(status, NULL);
    countRow(fallback, &counts);
  }
  const int accurate = mapping != SS_MAPPING_IMPLICIT_EULER;
  const int handed_on = accurate && APPLY_CACHE_ON(state, SS_APPLY_HANDED_ON);
  const int by_law = APPLY_CACHE_ON(state, SS_APPLY_BY_LAW) && state->rows_outside_laws == 0 &&
                     (!accurate || (handed_on && ssApplyEveryLawHandedOn(state, step_s)));
  ssSoftness law_softness[kLawTableSize];
  if (!by_law) ssApplyMaterializeRows(state); /* computeRows and writeRows compare each row's own */
  int unwritten = 0; /* rows whose pending differs from what ODE holds: with none (constant steps), no second pass */
  status = by_law ? lawSoftnesses(state, step_s, law_softness)
                  : computeRows(state, mapping, step_s, previous_s, &counts, &unwritten);
  if (status != SS_OK) return status;

  /* Nothing below can fail. */
  dWorldID world_id = ssRegistryWorld(registry);
  if (world_bound &&
      (!ssSameInOde(dWorldGetERP(world_id), world.erp) || !ssSameInOde(dWorldGetCFM(world_id), world.cfm))) {
    dWorldSetERP(world_id, world.erp);
    dWorldSetCFM(world_id, world.cfm);
    counts.row_writes += 1;
  }
  if (world_bound) state->world_written = world;
  if (by_law) {
    /* implicit Euler serves every row; under an accurate mapping it was handed all but the hard ones */
    counts.rows.by_mapping += accurate ? state->hard_rows : state->row_count;
    counts.rows.handed_to_implicit_euler += accurate ? state->row_count - state->hard_rows : 0;
    counts.row_writes += writeRowsByLaw(state, law_softness);
  } else if (unwritten > 0 || (mapping != SS_MAPPING_IMPLICIT_EULER && state->loaded_rows > 0)) {
    counts.row_writes += writeRows(state, mapping);
  }
  ssRegistryWriteBodies(registry, step_s);
  state->applied_mapping = mapping;
  state->applied_step_s = step_s;
  state->applied_revision = ssRegistryRevision(registry);
  state->applied_counts = counts;
  if (report != NULL) *report = counts;
  return SS_OK;
}

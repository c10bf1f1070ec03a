/* Apply: every binding written for one step, through caches that each hold an invariant stated here. The reference
 * Apply (apply_reference.c, built for tests) computes every row plainly; the differential test and fuzz target
 * require both to write the same values into ODE.
 *
 * Apply works in two passes, compute then write, so that an error leaves every ODE object as it was. What it keeps
 * between Applies, and what makes each piece valid:
 *
 *  - revision (registry.c) changes whenever any binding does; generation whenever the set of bound objects does.
 *  - The same-step shortcut (applied_mapping, applied_step_s, applied_revision, applied_counts): when the last Apply
 *    was implicit Euler at this step with applied_revision == revision, ODE holds every value this Apply would write
 *    (implicit Euler depends on h alone) and applied_counts is its report.
 *  - The Apply cache, valid while body_cache_revision == revision and !body_cache_stale (rebuildApplyCache):
 *      body_cache lists the bound joints' bodies once each; joints[i].body_slot[side] is the slot of the body the
 *      joint had there, or -1. A row that finds its joint attached elsewhere computes that body itself and sets
 *      body_cache_stale. A slot's inverse is the body's for this Apply when its stamp == apply_stamp.
 *      laws[0..law_count) are distinct; joints[i].law_slot is the slot of a law equal to joints[i].law, or -1 (the
 *      table was full; rows_outside_laws counts those). loaded_rows counts the rows with a load.
 *      hot_rows[law_rows[j] .. law_rows[j + 1]) mirror the joint and writer of law j's rows that have a writer,
 *      each with its binding's position. joints[i].shares_previous_row says whether joints[i] shares the row of
 *      joints[i - 1] (sharesRow).
 *  - joints[i].written is what ODE holds for the row (NAN after a binding: written at the next Apply), except while
 *    written_by_law: then a row with law_slot >= 0 holds law_written[law_slot] (the by-law pass writes no row's
 *    own); ssApplyMaterializeWritten puts those back before anything reads or moves the rows' own. A row without
 *    an erp (a motor's) holds only its cfm: its rows are compared on the cfm alone (sameWrite).
 *  - joints[i].pending, once computed, is the softness of the row's law for (computed_mapping, mass,
 *    computed_step_s, computed_previous_s) where computed_mapping is an accurate one (implicit Euler's general pass
 *    leaves its own there and says so in computed_mapping); a binding, a load or a load's fallback voids it
 *    (computed_step_s = NAN). The mappings are pure functions of these inputs, so equal inputs reuse it.
 *  - Within one Apply only: the shared-softness table maps (law, mass) to a softness computed in this Apply, and a
 *    stop and a motor on one axis (sharesRow) share the mass measured for the first. The law fallbacks hold the
 *    implicit-Euler softness of each law of the table for this step, given (without the accurate arithmetic) to
 *    the unloaded rows that ssSurelyFailsStaticResponse says the rule hands on: ssRowSoftness gives those rows
 *    exactly that softness and fallback (row_law.h; tested against it in test_apply.cpp).
 *  - disabled_caches turns caches off one by one (ssRegistryDisableCaches): bench_apply measures what each buys,
 *    and the differential check requires the same values either way. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "error.h"
#include "matched_internal.h"
#include "ode_bounds.h"
#include "registry_layout.h"
#include "steadystep/limits.h"

/* After an ODE step the bindings are out of the cache and each row does little: the lines of a row a few ahead
 * are asked for while this one is worked on. */
enum { kPrefetchAhead = 8 };
#if defined(__GNUC__)
#define PREFETCH_ROWS(joints, count, i, lines)                                             \
  do {                                                                                     \
    if ((i) + kPrefetchAhead < (count)) {                                                  \
      const char* ahead = (const char*)&(joints)[(i) + kPrefetchAhead];                    \
      for (int line = 0; line < (lines); ++line) __builtin_prefetch(ahead + 64 * line, 1); \
    }                                                                                      \
    if ((i) + kPrefetchAhead / 2 < (count)) {                                              \
      const char* joint = (const char*)(joints)[(i) + kPrefetchAhead / 2].joint;           \
      __builtin_prefetch(joint);                                                           \
      __builtin_prefetch(joint + 64);                                                      \
    }                                                                                      \
  } while (0)
#else
#define PREFETCH_ROWS(joints, count, i, lines) ((void)0)
#endif

/* Prefixes the current message with what failed, so that a caller of Apply learns which binding it was. */
static ssStatus failBinding(ssStatus status, const JointBinding* binding) {
  char cause[200];
  strncpy(cause, ssLastError(), sizeof cause - 1);
  cause[sizeof cause - 1] = '\0';
  if (binding == NULL) return ssFail(status, "world ERP/CFM: %s", cause);
  return ssFail(status, "%s joint %p, %s axis %d: %s", ssJointTypeName(binding->joint), (void*)binding->joint,
                ssJointParamName(binding->param), binding->axis, cause);
}

/* Counts one row of this Apply in the report, once, by who served it. */
static void countRow(const ssRowFallback* fallback, ssApplyReport* report) {
  if (fallback->to_implicit_euler) report->rows.handed_to_implicit_euler += 1;
  else if (fallback->exact_to_matched) report->rows.handed_to_matched += 1;
  else report->rows.by_mapping += 1;
}

/* The softness of one row for this step, counting in the report how it was obtained. */
static ssStatus softnessFor(const ssRowLaw* law, ssMapping mapping, double mass, double step_s,
                            double previous_step_s, int load_declared, ssApplyReport* report,
                            ssRowFallback* fallback, ssSoftness* out) {
  ssStatus status = ssRowSoftness(law, mapping, mass, step_s, previous_step_s, load_declared, fallback, out);
  countRow(fallback, report);
  return status;
}

/* Whether an accurate mapping serves the row as a pure damper (a motor's friction), with its matched softness in
 * *out: ssRowSoftness's tests for such a row in its order (a mass, c > 0; k = 0 is never above Nyquist; a finite
 * softness; the static damping's rule), without its general path. Both mappings serve a damper with the matched
 * softness (row_law.c: its velocity decays by e^(-c·h/m) a step whatever the steps before); a declared load on it
 * has nothing to correct. 0: the general path decides (out may be written). */
static int damperServed(const ssRowLaw* law, double mass, double step_s, ssSoftness* out) {
  return !law->hard && law->spring.stiffness == 0 && mass > 0 && isfinite(mass) && law->spring.damping > 0 &&
         ssMatchedDamper(law->spring.damping, mass, step_s, out) &&
         ssDamperKeepsStaticResponse(law->spring.damping, out->cfm);
}

/* One softness an Apply computed, for the rows with the same law and mass that follow. */
typedef struct SharedSoftness {
  const ssRowLaw* law;
  int law_slot;
  double mass; /* compared only where the mapping reads it */
  int load_declared; /* an accurate mapping keeps a loaded row's softness where it hands an unloaded one on */
  ssSoftness softness;
  ssRowFallback fallback;
} SharedSoftness;

static int sameLaw(const ssRowLaw* a, const ssRowLaw* b) {
  return a->hard == b->hard && a->spring.stiffness == b->spring.stiffness && a->spring.damping == b->spring.damping &&
         a->hard_rate_per_s == b->hard_rate_per_s && a->tuned_step_s == b->tuned_step_s &&
         a->tuned.erp == b->tuned.erp && a->tuned.cfm == b->tuned.cfm;
}

/* Whether the row's law is the shared one's: by slot where both are in the law table (distinct there). */
static int sharedLaw(const SharedSoftness* shared, const ssRowLaw* law, int law_slot) {
  if (shared->law_slot >= 0 && law_slot >= 0) return shared->law_slot == law_slot;
  return sameLaw(shared->law, law);
}

/* The softnesses one Apply computed, by law, mass and load: a row looks at its home entry and the kSharedProbes - 1
 * after it, and stops at an unused one (nothing leaves the table within an Apply). Rows of distinct masses, which
 * never share, pay a few comparisons of the mass; a handful of pairs (laws times the masses of identical links)
 * each find their entry although two of them share a home (one entry a home thrashed: every row computed again). */
enum { kSharedSize = 16, kSharedProbes = 4, kSharedTrial = 2 * kSharedSize };
typedef struct SharedTable {
  unsigned char used[kSharedSize];
  SharedSoftness entries[kSharedSize];
} SharedTable;

static uint64_t bitsOf(double value) {
  uint64_t bits;
  memcpy(&bits, &value, sizeof bits);
  return bits;
}

/* The entry of (law, mass, load): equal laws (by slot, or outside the table by k and c) and equal masses land on
 * one entry. any_mass: the mapping reads no mass for the law. */
static unsigned sharedSlot(const ssRowLaw* law, int law_slot, int any_mass, double mass, int load_declared) {
  uint64_t key = law_slot >= 0 ? (uint64_t)law_slot : bitsOf(law->spring.stiffness) ^ bitsOf(law->spring.damping);
  if (!any_mass) key ^= bitsOf(mass) * 0x9E3779B97F4A7C15ull;
  key = (key ^ (uint64_t)load_declared) * 0x9E3779B97F4A7C15ull;
  return (unsigned)(key >> 60); /* the top 4 bits: kSharedSize entries */
}

/* The softness computed in this Apply for the row's law and mass (any mass where the mapping reads none) with the
 * same load declared, or NULL. */
static const SharedSoftness* findShared(const SharedTable* table, unsigned home, const ssRowLaw* law, int law_slot,
                                        int any_mass, double mass, int load_declared) {
  for (unsigned p = 0; p < kSharedProbes; ++p) {
    unsigned slot = (home + p) & (kSharedSize - 1);
    if (!table->used[slot]) return NULL;
    const SharedSoftness* entry = &table->entries[slot];
    if ((any_mass || entry->mass == mass) && entry->load_declared == load_declared && sharedLaw(entry, law, law_slot))
      return entry;
  }
  return NULL;
}

/* Where a new softness goes: the first unused entry from its home on, else (all probed entries used) its home. */
static unsigned sharedFreeSlot(const SharedTable* table, unsigned home) {
  for (unsigned p = 0; p < kSharedProbes; ++p) {
    unsigned slot = (home + p) & (kSharedSize - 1);
    if (!table->used[slot]) return slot;
  }
  return home;
}

/* Gives every row in the law table its written back from law_written: before a pass that reads the rows' own, and
 * before the rows or their law slots change. */
void ssApplyMaterializeWritten(ssRegistry* registry) {
  if (!registry->written_by_law) return;
  for (int i = 0; i < registry->joint_count; ++i) {
    JointBinding* binding = &registry->joints[i];
    if (binding->law_slot >= 0) binding->written = registry->law_written[binding->law_slot];
  }
  registry->written_by_law = 0;
}

/* Whether two bindings drive rows along the same axis of the same joint (a stop and a motor) and have the same mass:
 * given alike, or measured for both (a hard row measures none, so its NAN is not the other's mass). */
static int sharesRow(const JointBinding* a, const JointBinding* b) {
  int a_limit = a->param == SS_PARAM_STOP || a->param == SS_PARAM_MOTOR;
  int b_limit = b->param == SS_PARAM_STOP || b->param == SS_PARAM_MOTOR;
  return a->joint == b->joint && a->axis == b->axis && a_limit && b_limit && a->effective_mass == b->effective_mass &&
         !a->law.hard && !b->law.hard;
}

static int compareBodyCache(const void* a, const void* b) {
  uintptr_t x = (uintptr_t)((const BodyCache*)a)->body, y = (uintptr_t)((const BodyCache*)b)->body;
  return (x > y) - (x < y);
}

/* What Apply derives from the bindings, rebuilt when they change: the bound joints' bodies listed once each, with
 * every binding pointed at its bodies' slots (out of memory, every row computes its bodies itself), and the count of
 * rows with a load. */
static void rebuildApplyCache(ssRegistry* registry) {
  ssApplyMaterializeWritten(registry);
  registry->body_cache_revision = registry->revision;
  registry->body_cache_stale = 0;
  free(registry->body_cache);
  registry->body_cache = NULL;
  registry->body_cache_count = 0;
  size_t most = 2 * (size_t)registry->joint_count;
  BodyCache* cache = most > 0 ? malloc(most * sizeof *cache) : NULL;
  int count = 0;
  if (cache != NULL) {
    for (int i = 0; i < registry->joint_count; ++i)
      for (int side = 0; side < 2; ++side) {
        dBodyID body = dJointGetBody(registry->joints[i].joint, side);
        if (body != 0) cache[count++] = (BodyCache){.body = body, .stamp = 0};
      }
    qsort(cache, (size_t)count, sizeof *cache, compareBodyCache);
    int unique = 0;
    for (int i = 0; i < count; ++i)
      if (unique == 0 || cache[i].body != cache[unique - 1].body) cache[unique++] = cache[i];
    count = unique;
  }
  for (int i = 0; i < registry->joint_count; ++i)
    for (int side = 0; side < 2; ++side) {
      BodyCache key = {.body = dJointGetBody(registry->joints[i].joint, side)};
      const BodyCache* found =
          cache != NULL && key.body != 0 ? bsearch(&key, cache, (size_t)count, sizeof *cache, compareBodyCache) : NULL;
      registry->joints[i].body_slot[side] = found != NULL ? (int)(found - cache) : -1;
    }
  registry->body_cache = cache;
  registry->body_cache_count = count;
  registry->law_count = 0;
  for (int i = 0; i < registry->joint_count; ++i) {
    JointBinding* binding = &registry->joints[i];
    binding->law_slot = -1;
    for (int j = 0; j < registry->law_count && binding->law_slot < 0; ++j)
      if (sameLaw(&registry->laws[j], &binding->law)) binding->law_slot = j;
    if (binding->law_slot < 0 && registry->law_count < kLawTableSize) {
      registry->laws[registry->law_count] = binding->law;
      binding->law_slot = registry->law_count++;
    }
  }
  registry->rows_outside_laws = 0;
  for (int i = 0; i < registry->joint_count; ++i) registry->rows_outside_laws += registry->joints[i].law_slot < 0;
  registry->loaded_rows = 0;
  for (int i = 0; i < registry->joint_count; ++i) {
    JointBinding* binding = &registry->joints[i];
    registry->loaded_rows += binding->load != 0;
    binding->shares_previous_row = i > 0 && sharesRow(&registry->joints[i - 1], binding);
  }
  /* the hot rows by law (a counting sort, in binding order within a law) */
  int* next = registry->law_rows;
  memset(next, 0, sizeof registry->law_rows);
  for (int i = 0; i < registry->joint_count; ++i) {
    const JointBinding* binding = &registry->joints[i];
    if (binding->law_slot >= 0 && binding->writer.set != NULL) next[binding->law_slot + 1] += 1;
  }
  for (int j = 0; j < kLawTableSize; ++j) next[j + 1] += next[j];
  int placed[kLawTableSize];
  memcpy(placed, next, sizeof placed);
  for (int i = 0; i < registry->joint_count; ++i) {
    const JointBinding* binding = &registry->joints[i];
    if (binding->law_slot < 0 || binding->writer.set == NULL) continue;
    registry->hot_rows[placed[binding->law_slot]++] = (HotRow){.joint = binding->joint,
                                                               .set = binding->writer.set,
                                                               .erp_number = (int16_t)binding->writer.erp_number,
                                                               .cfm_number = (int16_t)binding->writer.cfm_number,
                                                               .binding = i};
  }
}

/* What the body opposes to its rows in this Apply: from the cache, computed on its first use in the Apply, or into
 * *local for a body the cache does not know (the joint was attached elsewhere since: the cache is rebuilt next). */
static const ssBodyInverse* bodyInverse(ssRegistry* registry, int slot, dBodyID body, ssBodyInverse* local) {
  if (registry->disabled_caches & SS_CACHE_BODIES) {
    ssBodyInverseOf(body, local);
    return local;
  }
  if (slot >= 0 && registry->body_cache[slot].body == body) {
    BodyCache* cached = &registry->body_cache[slot];
    if (cached->stamp != registry->apply_stamp) {
      ssBodyInverseOf(body, &cached->inverse);
      cached->stamp = registry->apply_stamp;
    }
    return &cached->inverse;
  }
  registry->body_cache_stale = 1;
  ssBodyInverseOf(body, local);
  return local;
}

/* The row's effective mass from its bodies (ssJointEffectiveMass's value, through the body cache); NAN when the row
 * has none to measure. */
static double rowMass(ssRegistry* registry, const JointBinding* binding) {
  dBodyID bodies[2] = {dJointGetBody(binding->joint, 0), 0};
  ssRowGeometry row;
  if (bodies[0] == 0) return NAN;
  if (binding->joint_type == dJointTypeHinge) { /* the commonest row, read directly: what ssJointRowGeometry reads */
    dVector3 axis;
    dJointGetHingeAxis(binding->joint, axis);
    row.direction[0] = axis[0], row.direction[1] = axis[1], row.direction[2] = axis[2];
    row.angular = 1;
    row.has_point = 0;
  } else if (!ssJointRowGeometry(binding->joint, binding->joint_type, binding->param, binding->axis, &row)) {
    return NAN;
  }
  bodies[1] = dJointGetBody(binding->joint, 1);
  ssBodyInverse local; /* for a body the cache does not know: one at a time */
  double inverse = ssRowInverseMass(bodyInverse(registry, binding->body_slot[0], bodies[0], &local), &row);
  if (bodies[1] != 0)
    inverse += ssRowInverseMass(bodyInverse(registry, binding->body_slot[1], bodies[1], &local), &row);
  double mass = inverse > 0 ? 1.0 / inverse : 0;
  return mass > 0 && isfinite(mass) ? mass : NAN;
}

/* The binding's mass for this Apply: given, or measured from the bodies when `measure` (every Apply of the accurate
 * mappings), or the last one (implicit Euler, which reads none).
 * NAN when the row has none (no dynamic body, or a transmission): the accurate mappings then hand the row to the
 * implicit-Euler mapping. */
static double bindingMass(ssRegistry* registry, const JointBinding* binding, const ssRowLaw* law, int measure) {
  if (binding->effective_mass > 0) return binding->effective_mass;
  if (law->hard) return NAN;
  return measure ? rowMass(registry, binding) : binding->mass;
}

/* Whether writing b over a would change nothing in ODE (as it stores them: in float, doubles that round alike are
 * one value): a row without an erp (a motor) holds only its cfm. */
static int sameWrite(int erp_number, const ssSoftness* a, const ssSoftness* b) {
  return ssSameInOde(a->cfm, b->cfm) && (erp_number < 0 || ssSameInOde(a->erp, b->erp));
}

/* The implicit-Euler softness of the laws in the table that rows of one Apply were handed to, each computed (and
 * checked) at its first use in the Apply. */
typedef struct LawFallbacks {
  unsigned char known[kLawTableSize];
  ssSoftness softness[kLawTableSize];
} LawFallbacks;

/* The softness ssRowSoftness gives a row an accurate mapping hands to implicit Euler: the law's implicit-Euler
 * softness, checked for ODE as every computed softness is. */
static ssStatus lawFallback(const ssRowLaw* law, int law_slot, double step_s, LawFallbacks* fallbacks,
                            ssSoftness* out) {
  if (law_slot >= 0 && fallbacks->known[law_slot]) {
    *out = fallbacks->softness[law_slot];
    return SS_OK;
  }
  ssStatus status = ssRowSoftness(law, SS_MAPPING_IMPLICIT_EULER, NAN, step_s, 0, 0, NULL, out);
  if (status == SS_OK) status = ssCheckSoftnessForOde("softness", out->erp, out->cfm);
  if (status == SS_OK && law_slot >= 0) {
    fallbacks->known[law_slot] = 1;
    fallbacks->softness[law_slot] = *out;
  }
  return status;
}

/* Apply's first pass in general: each row's mass and softness into pending, and the load corrections, all checked
 * before anything is written. */
static ssStatus computeRows(ssRegistry* registry, ssMapping mapping, double step_s, double previous_s, int measure,
                           ssApplyReport* counts, int* unwritten) {
  ssStatus status = SS_OK;
  /* Programs bind many rows to a few springs, and many rows move equal masses (identical links, wheels, stop and
   * motor on one axis): within one Apply the softness is a function of the law and (accurate mappings) the mass, so
   * each distinct pair is computed once and shared. */
  SharedTable shared;
  memset(shared.used, 0, sizeof shared.used);
  /* Rows of distinct masses (a ragdoll, links of their own masses) never share: after kSharedTrial computed rows
   * that found fewer than one in four shared, the rest of this Apply computes every row without the probes (the
   * softness is a pure function of law and mass, so the values are the same either way). */
  int sharing = !(registry->disabled_caches & SS_CACHE_SHARED), shared_hits = 0, shared_computed = 0;
  double last_mass = NAN;
  LawFallbacks fallbacks;
  memset(fallbacks.known, 0, sizeof fallbacks.known);
  const int same_axis = !(registry->disabled_caches & SS_CACHE_SAME_AXIS);
  const int reuse = mapping != SS_MAPPING_IMPLICIT_EULER && !(registry->disabled_caches & SS_CACHE_REUSE);
  const int sure_fallback = !(registry->disabled_caches & SS_CACHE_SURE_FALLBACK);
  const int any_load = registry->loaded_rows > 0;
  /* the rows and their count in locals: the calls into ODE could write *registry for all the compiler knows */
  JointBinding* const joints = registry->joints;
  const int count = registry->joint_count;
  for (int i = 0; i < count; ++i) {
    JointBinding* binding = &joints[i];
    PREFETCH_ROWS(joints, count, i, 2);
    const ssRowLaw* law = binding->law_slot >= 0 ? &registry->laws[binding->law_slot] : &binding->law;
    /* a stop and a motor on one axis move the same mass: computed once */
    int same_row = same_axis && binding->shares_previous_row;
    double mass = same_row ? last_mass : bindingMass(registry, binding, law, measure);
    last_mass = mass;
    /* the accurate mappings depend on the mass, the step and (exact) the step before, all of which often repeat
     * (constant steps, masses that a motion leaves unchanged): equal inputs, equal softness */
    if (reuse && binding->computed_step_s == step_s && binding->mass == mass && binding->computed_mapping == mapping &&
        binding->computed_previous_s == previous_s) { /* the step first: under varying steps it differs at once */
      countRow(&binding->computed_fallback, counts);
      *unwritten += !sameWrite(binding->writer.erp_number, &binding->pending, &binding->written);
      continue;
    }
    binding->mass = mass;
    /* a row's load lies on a line of its own that the rows of a program without loads leave unread */
    const int load_declared = any_load && binding->load != 0;
    int any_mass = mapping == SS_MAPPING_IMPLICIT_EULER || law->hard;
    const SharedSoftness* hit = NULL;
    unsigned slot = 0;
    if (sharing) {
      slot = sharedSlot(law, binding->law_slot, any_mass, mass, load_declared);
      hit = findShared(&shared, slot, law, binding->law_slot, any_mass, mass, load_declared);
    }
    if (hit != NULL) {
      binding->pending = hit->softness;
      binding->computed_fallback = hit->fallback;
      countRow(&hit->fallback, counts);
      shared_hits += 1;
    } else {
      if (!any_mass && sure_fallback && !(load_declared && law->spring.stiffness > 0) &&
          ssSurelyFailsStaticResponse(law->spring, mass, step_s)) {
        /* a row the rule surely hands to implicit Euler gets the law's implicit-Euler softness (checked), without
         * the accurate arithmetic whose only use would be to decide so (a declared load keeps the accurate
         * softness instead): what ssRowSoftness gives it, so it is shared like any other */
        status = lawFallback(law, binding->law_slot, step_s, &fallbacks, &binding->pending);
        binding->computed_fallback = (ssRowFallback){0, 1};
        countRow(&binding->computed_fallback, counts);
      } else {
        if (mapping != SS_MAPPING_IMPLICIT_EULER && damperServed(law, mass, step_s, &binding->pending)) {
          binding->computed_fallback = (ssRowFallback){0, 0};
          counts->rows.by_mapping += 1;
        } else {
          status = softnessFor(law, mapping, mass, step_s, previous_s, load_declared, counts,
                               &binding->computed_fallback, &binding->pending);
        }
        /* the boundary with ODE: nothing outside limits.h's ranges is ever written. An accurate mapping's own
         * softness passed a stricter check already (matched.c's finish: finite, |erp| <= SS_MAX_ERP, cfm in
         * [SS_MIN_POSITIVE_CFM, SS_MAX_CFM]); what implicit Euler or a hard law gave is checked here. */
        int checked =
            mapping != SS_MAPPING_IMPLICIT_EULER && !law->hard && !binding->computed_fallback.to_implicit_euler;
        if (status == SS_OK && !checked)
          status = ssCheckSoftnessForOde("softness", binding->pending.erp, binding->pending.cfm);
      }
      if (status != SS_OK) {
        binding->computed_step_s = NAN;
        return failBinding(status, binding);
      }
      if (sharing) {
        slot = sharedFreeSlot(&shared, slot);
        shared.entries[slot] = (SharedSoftness){law, binding->law_slot, mass, load_declared, binding->pending,
                                                binding->computed_fallback};
        shared.used[slot] = 1;
        if (++shared_computed >= kSharedTrial && 4 * shared_hits < shared_computed) sharing = 0;
      }
    }
    *unwritten += !sameWrite(binding->writer.erp_number, &binding->pending, &binding->written);
    binding->computed_mapping = mapping; /* implicit Euler: an accurate mapping never reuses this pending */
    if (mapping == SS_MAPPING_IMPLICIT_EULER) continue;
    binding->computed_step_s = step_s;
    binding->computed_previous_s = previous_s;
  }

  /* The load corrections, computed and bounded before anything is written. */
  if (mapping != SS_MAPPING_IMPLICIT_EULER && registry->loaded_rows > 0) {
    for (int i = 0; i < registry->joint_count; ++i) {
      JointBinding* binding = &registry->joints[i];
      binding->load_correction = 0;
      const ssSpring* spring = &binding->law.spring;
      if (binding->load == 0 || binding->law.hard || spring->stiffness == 0) continue;
      /* the step's static stiffness is k' = erp/(h·cfm): this force puts the rest position back at load/k */
      double static_stiffness = binding->pending.erp / (step_s * binding->pending.cfm);
      double correction = binding->load * (static_stiffness / spring->stiffness - 1);
      if (!(fabs(correction) <= SS_MAX_FORCE_N)) {
        /* an accurate softness this far from the spring's static stiffness cannot carry the load: implicit Euler,
         * whose static stiffness is k itself, serves the row (as for every row an accurate mapping cannot) */
        status = ssImplicitEulerSoftness(*spring, step_s, &binding->pending);
        if (status != SS_OK) return failBinding(status, binding);
        /* counted once: moved from who was to serve it */
        if (binding->computed_fallback.exact_to_matched) counts->rows.handed_to_matched -= 1;
        else counts->rows.by_mapping -= 1;
        counts->rows.handed_to_implicit_euler += 1;
        binding->computed_fallback = (ssRowFallback){0, 1};
        binding->computed_step_s = NAN; /* not reused: the next Apply decides again from the accurate softness */
        correction = 0;
      }
      binding->load_correction = correction;
    }
  }

  return SS_OK;
}

/* Apply's second pass in general: the rows whose softness changed, then the load forces. Returns the rows
 * written. */
static int writeRows(ssRegistry* registry, ssMapping mapping) {
  int writes = 0;
  JointBinding* const joints = registry->joints;
  const int count = registry->joint_count;
  for (int i = 0; i < count; ++i) {
    JointBinding* binding = &joints[i];
    /* nothing prefetched: the first pass has just read these lines of the bindings and of the joints */
    if (sameWrite(binding->writer.erp_number, &binding->pending, &binding->written)) continue;
    ssRowWrite(&binding->writer, binding->joint, binding->pending.erp, binding->pending.cfm);
    binding->written = binding->pending;
    writes += 1;
  }
  if (mapping != SS_MAPPING_IMPLICIT_EULER && registry->loaded_rows > 0) {
    for (int i = 0; i < registry->joint_count; ++i) {
      const JointBinding* binding = &registry->joints[i];
      if (binding->load_correction != 0)
        ssJointAddRowForce(binding->joint, binding->param, binding->axis, binding->load_correction);
    }
  }
  return writes;
}

/* Implicit Euler when every row's law is in the table: the softness of each law, checked (the only part that can
 * fail), so that the rows can then be counted and written in one pass. */
static ssStatus lawSoftnesses(ssRegistry* registry, double step_s, ssSoftness* softness) {
  for (int j = 0; j < registry->law_count; ++j) {
    const ssRowLaw* law = &registry->laws[j];
    if (!law->hard && step_s != law->tuned_step_s) { /* at its tuned step, a law gives its tuned numbers back */
      /* ssImplicitEulerSoftness's arithmetic without its checks, which every bound law passed for every step length
       * (ssCheckLawForEveryStep at bind time): cfm within ODE's range is all that is left to see */
      double hk_plus_c = step_s * law->spring.stiffness + law->spring.damping;
      softness[j] = (ssSoftness){.erp = step_s * law->spring.stiffness / hk_plus_c, .cfm = 1.0 / hk_plus_c};
      if (softness[j].cfm > 0 && softness[j].cfm <= SS_MAX_CFM) continue;
    }
    ssStatus status =
        ssRowSoftness(&registry->laws[j], SS_MAPPING_IMPLICIT_EULER, NAN, step_s, 0, 0, NULL, &softness[j]);
    if (status == SS_OK) status = ssCheckSoftnessForOde("softness", softness[j].erp, softness[j].cfm);
    if (status == SS_OK) continue;
    for (int i = 0; i < registry->joint_count; ++i)
      if (registry->joints[i].law_slot == j) return failBinding(status, &registry->joints[i]);
    return status;
  }
  return SS_OK;
}

/* Writes s into one packed row: its erp where it has one, and its cfm. */
static void writeHotRow(const HotRow* row, ssSoftness s) {
  if (row->erp_number >= 0) row->set(row->joint, row->erp_number, s.erp);
  row->set(row->joint, row->cfm_number, s.cfm);
}

/* A law's rows, from..end of the hot rows, written with its softness s: each row's erp where it has one, and its
 * cfm; with erp_rows_only (only the law's erp changed) only the rows that hold an erp (a motor's row holds only its
 * cfm). Returns the rows written. */
static int writeLawRows(const HotRow* from, const HotRow* end, const HotRow* hot_end, ssSoftness s,
                        int erp_rows_only) {
  int writes = 0;
  for (const HotRow* row = from; row < end; ++row) {
    if (erp_rows_only && row->erp_number < 0) continue;
#if defined(__GNUC__)
    if (row + kPrefetchAhead / 2 < hot_end) __builtin_prefetch(row[kPrefetchAhead / 2].joint);
#endif
    writeHotRow(row, s);
    writes += 1;
  }
  return writes;
}

/* The one pass of lawSoftnesses' case: each row's law's softness written where it changed. Nothing here can
 * fail. It reads the rows' hot records and nothing else: where every row of a law was written by the last such
 * pass, law_written says what ODE holds, and a law whose softness is what ODE holds has none of its rows read.
 * Returns the rows written. */
static int writeRowsByLaw(ssRegistry* registry, const ssSoftness* softness) {
  int writes = 0;
  const HotRow* hot = registry->hot_rows; /* NULL before any binding: no law then */
  const HotRow* hot_end = registry->law_count > 0 ? hot + registry->law_rows[registry->law_count] : hot;
  for (int j = 0; j < registry->law_count; ++j) {
    const HotRow *from = hot + registry->law_rows[j], *end = hot + registry->law_rows[j + 1];
    if (!registry->written_by_law) { /* each row holds its own written */
      for (const HotRow* row = from; row < end; ++row) {
        if (sameWrite(row->erp_number, &softness[j], &registry->joints[row->binding].written)) continue;
        writeHotRow(row, softness[j]);
        writes += 1;
      }
    } else if (!ssSameInOde(softness[j].cfm, registry->law_written[j].cfm)) {
      writes += writeLawRows(from, end, hot_end, softness[j], 0);
    } else if (!ssSameInOde(softness[j].erp, registry->law_written[j].erp)) {
      writes += writeLawRows(from, end, hot_end, softness[j], 1);
    }
  }
  for (int j = 0; j < registry->law_count; ++j) registry->law_written[j] = softness[j];
  registry->written_by_law = 1;
  return writes;
}

ssStatus ssRegistry_Apply(ssRegistry* registry, ssMapping mapping, double step_s, double previous_step_s,
                          ssApplyReport* report) {
  REQUIRE_REGISTRY(registry);
  ssStatus status = ssCheckStepLength("step_s", step_s);
  if (status == SS_OK && previous_step_s != 0) status = ssCheckStepLength("previous_step_s", previous_step_s);
  if (status != SS_OK) return status;
  if (ssMappingName(mapping) == NULL) return ssFail(SS_ERROR_UNSUPPORTED, "mapping = %d: unknown", (int)mapping);

  /* implicit Euler depends on h alone: a step as long as the last one, with nothing rebound since, has every row
   * written already (a program with constant frames pays nothing here) */
  if (mapping == SS_MAPPING_IMPLICIT_EULER && !(registry->disabled_caches & SS_CACHE_SAME_STEP) &&
      registry->applied_mapping == mapping &&
      registry->applied_step_s == step_s && registry->applied_revision == registry->revision) {
    if (report != NULL) *report = (ssApplyReport){registry->applied_counts.rows, 0};
    return SS_OK;
  }
  ssApplyReport counts = {{0, 0, 0}, 0};
  if (registry->body_cache_stale || registry->body_cache_revision != registry->revision) rebuildApplyCache(registry);
  if (++registry->apply_stamp == 0) { /* after 2^32 Applies: no cached body may look computed for this one */
    for (int i = 0; i < registry->body_cache_count; ++i) registry->body_cache[i].stamp = 0;
    registry->apply_stamp = 1;
  }
  if (registry->world_bound) {
    ssRowFallback fallback;
    status = softnessFor(&registry->world_law, mapping, registry->world_mass, step_s, previous_step_s, 0, &counts,
                         &fallback, &registry->world_pending);
    if (status == SS_OK)
      status = ssCheckSoftnessForOde("softness", registry->world_pending.erp, registry->world_pending.cfm);
    if (status != SS_OK) return failBinding(status, NULL);
  }
  int measure = mapping != SS_MAPPING_IMPLICIT_EULER; /* implicit Euler reads no mass */
  int by_law = mapping == SS_MAPPING_IMPLICIT_EULER && !(registry->disabled_caches & SS_CACHE_BY_LAW) &&
               registry->rows_outside_laws == 0;
  ssSoftness law_softness[kLawTableSize];
  if (!by_law) ssApplyMaterializeWritten(registry); /* computeRows and writeRows compare each row's own */
  int unwritten = 0; /* rows whose pending differs from what ODE holds: with none (constant steps), no second pass */
  status = by_law ? lawSoftnesses(registry, step_s, law_softness)
                  : computeRows(registry, mapping, step_s, mapping == SS_MAPPING_EXACT ? previous_step_s : 0,
                                measure, &counts, &unwritten);
  if (status != SS_OK) return status;

  /* Nothing below can fail. */
  if (registry->world_bound && (!ssSameInOde(dWorldGetERP(registry->world), registry->world_pending.erp) ||
                                !ssSameInOde(dWorldGetCFM(registry->world), registry->world_pending.cfm))) {
    dWorldSetERP(registry->world, registry->world_pending.erp);
    dWorldSetCFM(registry->world, registry->world_pending.cfm);
    counts.row_writes += 1;
  }
  if (registry->world_bound) registry->world_written = registry->world_pending;
  if (by_law) {
    counts.rows.by_mapping += registry->joint_count; /* implicit Euler serves every row */
    counts.row_writes += writeRowsByLaw(registry, law_softness);
  } else if (unwritten > 0 || (mapping != SS_MAPPING_IMPLICIT_EULER && registry->loaded_rows > 0)) {
    counts.row_writes += writeRows(registry, mapping);
  }
  ssRegistryWriteBodies(registry, step_s);
  registry->applied_mapping = mapping;
  registry->applied_step_s = step_s;
  registry->applied_revision = registry->revision;
  registry->applied_counts = counts;
  if (report != NULL) *report = counts;
  return SS_OK;
}

void ssRegistryDisableCaches(ssRegistry* registry, unsigned mask) {
  ssApplyMaterializeWritten(registry);
  registry->disabled_caches = mask;
  registry->revision += 1; /* the caches are rebuilt and nothing computed with others is reused */
}

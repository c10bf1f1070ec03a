/* The registry: bindings of springs and rates to ODE's per-step numbers, written for each step length.
 * Apply works in two passes, compute then write, so that an error leaves every ODE object as it was. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "array.h"
#include "error.h"
#include "ode_bounds.h"
#include "joint_rows.h"
#include "registry_internal.h"
#include "row_law.h"
#include "steadystep/adopt.h"
#include "steadystep/registry.h"

/* Laid out by use, one cache line a group (the array is aligned to lines): what every Apply reads for every row
 * (implicit Euler with its laws in the table reads nothing else, but every few Applies); what the other Applies'
 * first pass reads; what only rows outside the registry's law table and rows with a load read. */
typedef struct JointBinding {
  _Alignas(64) dJointID joint;
  ssRowWriter writer;    /* ODE's setter and parameter numbers for the row, resolved at bind time */
  ssSoftness written;    /* last written: the registry owns the row, so an unchanged value is not written again */
  ssJointParam param;
  int axis;
  int law_slot; /* the law in the registry's table; -1: not there, read law */
  /* the mass the last Apply of an accurate mapping gave the row (NAN: none), the input of its softness (implicit
   * Euler reads no mass) */
  double mass;

  ssSoftness pending; /* computed in the general first pass */
  double effective_mass; /* 0: computed from the bodies at each Apply */
  /* what pending was computed from besides the mass: the mappings are pure functions, so equal inputs reuse it */
  double computed_step_s, computed_previous_s;
  int body_slot[2]; /* the joint's bodies in the registry's body cache; -1: none or not known */
  int joint_type;   /* dJointGetType, resolved at bind time: a joint's type never changes */
  ssMapping computed_mapping;
  unsigned computed_epoch; /* the registry's reuse_epoch when computed: an implicit-Euler Apply since voids it */
  ssRowFallback computed_fallback;

  ssRowLaw law;
  double load; /* the steady force or torque the row carries (ssRegistry_SetJointLoad); 0 = none declared */
  double load_correction; /* the force this Apply adds along the row for the load (N or N·m) */
} JointBinding;

/* What implicit Euler's by-law pass reads of a row, packed apart from the bindings (rebuilt with the Apply cache):
 * after an ODE step has evicted the registry's arrays, it streams through 32 bytes a row instead of a binding's
 * first line. mass mirrors the binding's. */
typedef struct HotRow {
  dJointID joint;
  ssParamSetter set; /* the row's writer: NULL for a row without softness */
  int16_t erp_number, cfm_number; /* ODE's parameter numbers (below 0x400); erp_number -1: none */
  int16_t law_slot;
} HotRow;

/* A body's inverse mass and inertia, computed at most once per Apply for all the rows on it. */
typedef struct BodyCache {
  dBodyID body;
  unsigned stamp; /* the Apply it was computed for */
  ssBodyInverse inverse;
} BodyCache;

enum { kLawTableSize = 16 };

struct ssRegistry {
  dWorldID world;
  int world_bound;
  ssRowLaw world_law;
  double world_mass;
  ssSoftness world_pending;
  double tuned_step_s;      /* adoption's tuned step; 0 before any */
  ssSoftness tuned_world;   /* the world's ERP/CFM as adopted (contacts without soft modes stand for these) */
  JointBinding* joints;
  HotRow* hot_rows; /* joints' hot part, as many; valid while body_cache_revision == revision */
  int joint_count, joint_capacity;
  ssBodyBinding* bodies;
  int body_count, body_capacity;
  unsigned generation; /* changes whenever the set of bound joints or bodies does */
  unsigned revision;   /* changes whenever any binding does */
  /* the last Apply: under implicit Euler, the same step with the same bindings writes nothing new */
  unsigned applied_revision;
  double applied_step_s;
  ssMapping applied_mapping;
  ssApplyReport applied_counts;
  /* the bound joints' bodies, each once (sorted by address), for the effective masses; rebuilt on any rebinding, and
   * after a row found its joint attached to other bodies (dJointAttach) */
  BodyCache* body_cache;
  int body_cache_count;
  unsigned body_cache_revision;
  int body_cache_stale;
  unsigned apply_stamp;
  int loaded_rows; /* bindings with a load, counted with the body cache: Apply skips the load passes without */
  /* the distinct laws of the bindings (programs bind many rows to a few springs), rebuilt with the body cache */
  ssRowLaw laws[kLawTableSize];
  int law_count;
  int rows_outside_laws; /* bindings whose law did not fit in the table */
  unsigned reuse_epoch;  /* changes at every implicit-Euler Apply, which leaves the rows' pending behind */
  /* after a by-law pass, every row in the law table holds its law's softness in ODE: law_written stands for the
   * rows' written until the other passes (or a rebinding) need theirs back (materializeWritten) */
  int written_by_law;
  ssSoftness law_written[kLawTableSize];
};

#define REQUIRE_REGISTRY(registry) \
  if ((registry) == NULL) return ssFail(SS_ERROR_OUT_OF_RANGE, "registry = NULL: a registry is required")

ssRegistry* ssRegistry_Create(dWorldID world) {
  if (world == 0) {
    ssFail(SS_ERROR_OUT_OF_RANGE, "world = NULL: a world is required");
    return NULL;
  }
  ssRegistry* registry = calloc(1, sizeof *registry);
  if (registry == NULL) {
    ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory creating a registry");
    return NULL;
  }
  registry->world = world;
  registry->applied_step_s = NAN;
  registry->body_cache_stale = 1;
  return registry;
}

void ssRegistry_Destroy(ssRegistry* registry) {
  if (registry == NULL) return;
  free(registry->joints);
  free(registry->hot_rows);
  free(registry->bodies);
  free(registry->body_cache);
  free(registry);
}

void ssRegistryBindWorldLaw(ssRegistry* registry, ssRowLaw law, double effective_mass) {
  registry->revision += 1;
  registry->world_bound = 1;
  registry->world_law = law;
  registry->world_mass = effective_mass > 0 ? effective_mass : 1.0;
}

ssStatus ssRegistry_BindWorld(ssRegistry* registry, ssSpring spring, double effective_mass) {
  REQUIRE_REGISTRY(registry);
  ssRowLaw law = ssRowLawOfSpring(spring);
  ssStatus status = ssValidateSpring(spring);
  if (status == SS_OK) status = ssCheckLawForEveryStep("world", &law);
  if (status == SS_OK) status = ssCheckNonNegative("effective_mass", "kg", effective_mass);
  if (status != SS_OK) return status;
  ssRegistryBindWorldLaw(registry, law, effective_mass);
  return SS_OK;
}

/* After an ODE step the bindings are out of the cache and each row does little: the lines of a row a few ahead
 * are asked for while this one is worked on. */
enum { kPrefetchAhead = 8 };
#if defined(__GNUC__)
#define PREFETCH_ROWS(registry, i, lines)                                                  \
  do {                                                                                     \
    if ((i) + kPrefetchAhead < (registry)->joint_count) {                                  \
      const char* ahead = (const char*)&(registry)->joints[(i) + kPrefetchAhead];          \
      for (int line = 0; line < (lines); ++line) __builtin_prefetch(ahead + 64 * line, 1); \
    }                                                                                      \
    if ((i) + kPrefetchAhead / 2 < (registry)->joint_count) {                              \
      const char* joint = (const char*)(registry)->joints[(i) + kPrefetchAhead / 2].joint; \
      __builtin_prefetch(joint);                                                           \
      __builtin_prefetch(joint + 64);                                                      \
    }                                                                                      \
  } while (0)
#else
#define PREFETCH_ROWS(registry, i, lines) ((void)0)
#endif

/* Room for `more` joint bindings, in an array aligned to cache lines (JointBinding's groups are lines). */
static int reserveJoints(ssRegistry* registry, int more) {
  if (registry->joint_count + more <= registry->joint_capacity) return 1;
  int wanted = registry->joint_capacity ? 2 * registry->joint_capacity : 8;
  if (wanted < registry->joint_count + more) wanted = registry->joint_count + more;
  JointBinding* larger = aligned_alloc(_Alignof(JointBinding), (size_t)wanted * sizeof(JointBinding));
  HotRow* hot = aligned_alloc(64, ((size_t)wanted * sizeof(HotRow) + 63) / 64 * 64);
  if (larger == NULL || hot == NULL) {
    free(larger);
    free(hot);
    return 0;
  }
  if (registry->joint_count > 0) {
    memcpy(larger, registry->joints, (size_t)registry->joint_count * sizeof(JointBinding));
    memcpy(hot, registry->hot_rows, (size_t)registry->joint_count * sizeof(HotRow));
  }
  free(registry->joints);
  free(registry->hot_rows);
  registry->joints = larger;
  registry->hot_rows = hot;
  registry->joint_capacity = wanted;
  return 1;
}

static JointBinding* findJoint(ssRegistry* registry, dJointID joint, ssJointParam param, int axis) {
  for (int i = 0; i < registry->joint_count; ++i) {
    JointBinding* existing = &registry->joints[i];
    if (existing->joint == joint && existing->param == param && existing->axis == axis) return existing;
  }
  return NULL;
}

int ssRegistryHasJoint(const ssRegistry* registry, dJointID joint) {
  for (int i = 0; i < registry->joint_count; ++i)
    if (registry->joints[i].joint == joint) return 1;
  return 0;
}

int ssRegistryHasJointRow(ssRegistry* registry, dJointID joint, ssJointParam param, int axis) {
  return findJoint(registry, joint, param, axis) != NULL;
}

static void materializeWritten(ssRegistry* registry);

ssStatus ssRegistryBindJointLaw(ssRegistry* registry, dJointID joint, ssJointParam param, int axis, ssRowLaw law,
                                double effective_mass) {
  materializeWritten(registry); /* before the law slots or the rows move */
  registry->revision += 1;
  JointBinding binding = {.joint = joint,
                          .pending = {0, 0},
                          .written = {NAN, NAN},
                          .param = param,
                          .axis = axis,
                          .law = law,
                          .effective_mass = effective_mass,
                          .mass = NAN,
                          .computed_mapping = SS_MAPPING_IMPLICIT_EULER,
                          .computed_fallback = {0, 0},
                          .law_slot = -1,
                          .computed_step_s = NAN,
                          .computed_previous_s = NAN,
                          .load = 0,
                          .load_correction = 0,
                          .body_slot = {-1, -1},
                          .joint_type = dJointGetType(joint)};
  ssJointRowWriterOf(joint, param, axis, &binding.writer);
  JointBinding* existing = findJoint(registry, joint, param, axis);
  if (existing != NULL) {
    *existing = binding;
    return SS_OK;
  }
  if (!reserveJoints(registry, 1))
    return ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory binding a joint");
  registry->joints[registry->joint_count++] = binding;
  registry->generation += 1;
  return SS_OK;
}

ssStatus ssRegistry_BindJoint(ssRegistry* registry, dJointID joint, ssJointParam param, int axis, ssSpring spring,
                              double effective_mass) {
  REQUIRE_REGISTRY(registry);
  if (joint == 0) return ssFail(SS_ERROR_OUT_OF_RANGE, "joint = NULL: a joint is required");
  if (ssJointParamName(param) == NULL) return ssFail(SS_ERROR_UNSUPPORTED, "param = %d: unknown", (int)param);
  if (!ssJointSupports(joint, param, axis))
    return ssFail(SS_ERROR_UNSUPPORTED, "axis = %d: a %s joint has no %s parameters on it", axis,
                  ssJointTypeName(joint), ssJointParamName(param));
  ssRowLaw law = ssRowLawOfSpring(spring);
  ssStatus status = ssValidateSpring(spring);
  if (status == SS_OK) status = ssCheckLawForEveryStep("joint", &law);
  if (status == SS_OK) status = ssCheckNonNegative("effective_mass", "kg", effective_mass);
  if (status != SS_OK) return status;
  return ssRegistryBindJointLaw(registry, joint, param, axis, law, effective_mass);
}

ssStatus ssRegistry_SetJointLoad(ssRegistry* registry, dJointID joint, ssJointParam param, int axis, double load) {
  REQUIRE_REGISTRY(registry);
  ssStatus status = ssCheckFinite("load", "N or N·m", load);
  if (status == SS_OK && fabs(load) > SS_MAX_FORCE_N)
    status = ssFail(SS_ERROR_OUT_OF_RANGE, "load = %g N or N·m: must be at most SS_MAX_FORCE_N = %g in size", load,
                    SS_MAX_FORCE_N);
  if (status != SS_OK) return status;
  JointBinding* binding = findJoint(registry, joint, param, axis);
  if (binding == NULL)
    return ssFail(SS_ERROR_NOT_FOUND, "joint %p, param %d, axis %d: not bound", (void*)joint, (int)param, axis);
  if (!ssJointRowHasDirection(joint, param, axis))
    return ssFail(SS_ERROR_UNSUPPORTED, "a %s joint's %s rows have no single direction to carry a load",
                  ssJointTypeName(joint), ssJointParamName(param));
  binding->load = load;
  binding->computed_step_s = NAN; /* a softness the old load sent to implicit Euler is not reused */
  registry->revision += 1;
  return SS_OK;
}

ssStatus ssRegistry_UnbindJoint(ssRegistry* registry, dJointID joint) {
  REQUIRE_REGISTRY(registry);
  materializeWritten(registry);
  int kept = 0;
  for (int i = 0; i < registry->joint_count; ++i)
    if (registry->joints[i].joint != joint) registry->joints[kept++] = registry->joints[i];
  if (kept == registry->joint_count) return ssFail(SS_ERROR_NOT_FOUND, "joint %p: not bound", (void*)joint);
  registry->joint_count = kept;
  registry->generation += 1;
  registry->revision += 1;
  return SS_OK;
}

ssBodyBinding* ssRegistryFindBody(ssRegistry* registry, dBodyID body) {
  for (int i = 0; i < registry->body_count; ++i)
    if (registry->bodies[i].body == body) return &registry->bodies[i];
  return NULL;
}

int ssRegistryHasBody(ssRegistry* registry, dBodyID body) { return ssRegistryFindBody(registry, body) != NULL; }

/* The binding of body (0: the world's defaults), created empty if absent; NULL when out of memory. */
static ssBodyBinding* bodyBinding(ssRegistry* registry, dBodyID body) {
  ssBodyBinding* binding = ssRegistryFindBody(registry, body);
  if (binding != NULL) return binding;
  if (!ssReserveOne((void**)&registry->bodies, registry->body_count, &registry->body_capacity, sizeof(ssBodyBinding)))
    return NULL;
  binding = &registry->bodies[registry->body_count++];
  registry->generation += 1;
  registry->revision += 1;
  memset(binding, 0, sizeof *binding);
  binding->body = body;
  binding->written_step_s = NAN;
  return binding;
}

ssStatus ssRegistry_BindDamping(ssRegistry* registry, dBodyID body, double linear_rate_per_s,
                                double angular_rate_per_s) {
  REQUIRE_REGISTRY(registry);
  ssStatus status = ssCheckNonNegative("linear_rate_per_s", "1/s", linear_rate_per_s);
  if (status == SS_OK) status = ssCheckNonNegative("angular_rate_per_s", "1/s", angular_rate_per_s);
  if (status != SS_OK) return status;
  ssBodyBinding* binding = bodyBinding(registry, body);
  if (binding == NULL) return ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory binding damping");
  binding->has_damping = 1;
  binding->linear_rate_per_s = linear_rate_per_s;
  binding->angular_rate_per_s = angular_rate_per_s;
  binding->written_step_s = NAN;
  registry->revision += 1;
  return SS_OK;
}

ssStatus ssRegistry_BindAutoDisable(ssRegistry* registry, dBodyID body, double idle_time_s, double average_window_s) {
  REQUIRE_REGISTRY(registry);
  ssStatus status = ssCheckPositive("idle_time_s", "s", idle_time_s);
  if (status == SS_OK) status = ssCheckNonNegative("average_window_s", "s", average_window_s);
  if (status != SS_OK) return status;
  ssBodyBinding* binding = bodyBinding(registry, body);
  if (binding == NULL) return ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory binding auto-disable");
  binding->has_auto_disable = 1;
  binding->idle_time_s = idle_time_s;
  binding->average_window_s = average_window_s;
  binding->average_samples_written = 0;
  binding->written_step_s = NAN;
  registry->revision += 1;
  return SS_OK;
}

ssStatus ssRegistry_UnbindBody(ssRegistry* registry, dBodyID body) {
  REQUIRE_REGISTRY(registry);
  for (int i = 0; i < registry->body_count; ++i) {
    if (registry->bodies[i].body != body) continue;
    registry->bodies[i] = registry->bodies[--registry->body_count];
    registry->generation += 1;
    registry->revision += 1;
    return SS_OK;
  }
  return ssFail(SS_ERROR_NOT_FOUND, "body %p: not bound", (void*)body);
}

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
                            double previous_step_s, ssApplyReport* report, ssRowFallback* fallback,
                            ssSoftness* out) {
  ssStatus status = ssRowSoftness(law, mapping, mass, step_s, previous_step_s, fallback, out);
  countRow(fallback, report);
  return status;
}

/* One softness an Apply computed, for the rows with the same law and mass that follow. */
typedef struct SharedSoftness {
  const ssRowLaw* law;
  int law_slot;
  double mass; /* compared only where the mapping reads it */
  ssSoftness softness;
  ssRowFallback fallback;
} SharedSoftness;

static int sameLaw(const ssRowLaw* a, const ssRowLaw* b) {
  return a->hard == b->hard && a->spring.stiffness == b->spring.stiffness && a->spring.damping == b->spring.damping &&
         a->hard_rate_per_s == b->hard_rate_per_s;
}

/* Whether the row's law is the shared one's: by slot where both are in the law table (distinct there). */
static int sharedLaw(const SharedSoftness* shared, const ssRowLaw* law, int law_slot) {
  if (shared->law_slot >= 0 && law_slot >= 0) return shared->law_slot == law_slot;
  return sameLaw(shared->law, law);
}

/* Gives every row in the law table its written back from law_written: before a pass that reads the rows' own, and
 * before the rows or their law slots change. */
static void materializeWritten(ssRegistry* registry) {
  if (!registry->written_by_law) return;
  for (int i = 0; i < registry->joint_count; ++i) {
    JointBinding* binding = &registry->joints[i];
    if (binding->law_slot >= 0) binding->written = registry->law_written[binding->law_slot];
  }
  registry->written_by_law = 0;
}

static int compareBodyCache(const void* a, const void* b) {
  uintptr_t x = (uintptr_t)((const BodyCache*)a)->body, y = (uintptr_t)((const BodyCache*)b)->body;
  return (x > y) - (x < y);
}

/* What Apply derives from the bindings, rebuilt when they change: the bound joints' bodies listed once each, with
 * every binding pointed at its bodies' slots (out of memory, every row computes its bodies itself), and the count of
 * rows with a load. */
static void rebuildApplyCache(ssRegistry* registry) {
  materializeWritten(registry);
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
  for (int i = 0; i < registry->joint_count; ++i) registry->loaded_rows += registry->joints[i].load != 0;
  for (int i = 0; i < registry->joint_count; ++i) {
    const JointBinding* binding = &registry->joints[i];
    registry->hot_rows[i] = (HotRow){.joint = binding->joint,
                                     .set = binding->writer.set,
                                     .erp_number = (int16_t)binding->writer.erp_number,
                                     .cfm_number = (int16_t)binding->writer.cfm_number,
                                     .law_slot = (int16_t)binding->law_slot};
  }
}

/* What the body opposes to its rows in this Apply: from the cache, computed on its first use in the Apply, or into
 * *local for a body the cache does not know (the joint was attached elsewhere since: the cache is rebuilt next). */
static const ssBodyInverse* bodyInverse(ssRegistry* registry, int slot, dBodyID body, ssBodyInverse* local) {
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
  if (bodies[0] == 0 || !ssJointRowGeometry(binding->joint, binding->joint_type, binding->param, binding->axis, &row))
    return NAN;
  bodies[1] = dJointGetBody(binding->joint, 1);
  double inverse = 0;
  for (int side = 0; side < 2; ++side) {
    if (bodies[side] == 0) continue;
    ssBodyInverse local;
    inverse += ssRowInverseMass(bodyInverse(registry, binding->body_slot[side], bodies[side], &local), &row);
  }
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

/* Whether two bindings drive rows along the same axis of the same joint (a stop and a motor). */
static int sharesRow(const JointBinding* a, const JointBinding* b) {
  int a_limit = a->param == SS_PARAM_STOP || a->param == SS_PARAM_MOTOR;
  int b_limit = b->param == SS_PARAM_STOP || b->param == SS_PARAM_MOTOR;
  return a->joint == b->joint && a->axis == b->axis && a_limit && b_limit;
}

/* ODE counts steps: a count of seconds in steps of h, where a whole number of steps computed with rounding error
 * (10·(1/60)/(1/60) = 10.000000000000002) must not become one more. */
static double stepsIn(double seconds, double step_s) { return ceil(seconds / step_s - 1e-9); }

static void writeBody(ssBodyBinding* binding, dWorldID world, double step_s) {
  dBodyID body = binding->body;
  if (binding->has_damping) {
    /* ODE scales velocity by (1 - scale) once per step: this scale removes the same fraction per second */
    double linear = -expm1(-binding->linear_rate_per_s * step_s);
    double angular = -expm1(-binding->angular_rate_per_s * step_s);
    if (body) {
      dBodySetLinearDamping(body, linear);
      dBodySetAngularDamping(body, angular);
    } else {
      dWorldSetLinearDamping(world, linear);
      dWorldSetAngularDamping(world, angular);
    }
  }
  if (binding->has_auto_disable) {
    double steps = stepsIn(binding->idle_time_s, step_s);
    int idle_steps = steps < INT32_MAX ? (int)steps : INT32_MAX;
    double samples = fmax(1.0, stepsIn(binding->average_window_s, step_s));
    int average_samples = samples < 1e6 ? (int)samples : 1000000;
    if (body) {
      dBodySetAutoDisableSteps(body, idle_steps);
      dBodySetAutoDisableTime(body, binding->idle_time_s);
      if (average_samples != binding->average_samples_written)
        dBodySetAutoDisableAverageSamplesCount(body, (unsigned)average_samples);
    } else {
      dWorldSetAutoDisableSteps(world, idle_steps);
      dWorldSetAutoDisableTime(world, binding->idle_time_s);
      if (average_samples != binding->average_samples_written)
        dWorldSetAutoDisableAverageSamplesCount(world, (unsigned)average_samples);
    }
    binding->average_samples_written = average_samples;
  }
  binding->written_step_s = step_s;
}

static int sameSoftness(const ssSoftness* a, const ssSoftness* b) { return a->erp == b->erp && a->cfm == b->cfm; }

/* Apply's first pass in general: each row's mass and softness into pending, and the load corrections, all checked
 * before anything is written. */
static ssStatus computeRows(ssRegistry* registry, ssMapping mapping, double step_s, double previous_s, int measure,
                           ssApplyReport* counts, int* unwritten) {
  ssStatus status = SS_OK;
  /* Programs bind many rows to a few springs, and many rows move equal masses (identical links, wheels, stop and
   * motor on one axis): within one Apply the softness is a function of the law and (accurate mappings) the mass, so
   * each distinct pair is computed once and shared. */
  enum { kSharedSize = 8 };
  SharedSoftness shared[kSharedSize];
  int shared_count = 0, shared_next = 0;
  double last_mass = NAN;
  for (int i = 0; i < registry->joint_count; ++i) {
    JointBinding* binding = &registry->joints[i];
    PREFETCH_ROWS(registry, i, 2);
    const ssRowLaw* law = binding->law_slot >= 0 ? &registry->laws[binding->law_slot] : &binding->law;
    const JointBinding* before = i > 0 ? &registry->joints[i - 1] : NULL;
    /* a stop and a motor on one axis move the same mass: computed once */
    int same_row = before != NULL && sharesRow(before, binding) && binding->effective_mass == before->effective_mass;
    double mass = same_row ? last_mass : bindingMass(registry, binding, law, measure);
    last_mass = mass;
    /* the accurate mappings depend on the mass, the step and (exact) the step before, all of which often repeat
     * (constant steps, masses that a motion leaves unchanged): equal inputs, equal softness */
    if (mapping != SS_MAPPING_IMPLICIT_EULER && binding->computed_epoch == registry->reuse_epoch &&
        binding->computed_mapping == mapping && binding->mass == mass && binding->computed_step_s == step_s &&
        binding->computed_previous_s == previous_s) {
      countRow(&binding->computed_fallback, counts);
      *unwritten += !sameSoftness(&binding->pending, &binding->written);
      continue;
    }
    binding->mass = mass;
    int any_mass = mapping == SS_MAPPING_IMPLICIT_EULER || law->hard;
    const SharedSoftness* hit = NULL;
    for (int j = 0; j < shared_count && hit == NULL; ++j)
      if ((any_mass || shared[j].mass == mass) && sharedLaw(&shared[j], law, binding->law_slot)) hit = &shared[j];
    if (hit != NULL) {
      binding->pending = hit->softness;
      binding->computed_fallback = hit->fallback;
      countRow(&hit->fallback, counts);
    } else {
      status = softnessFor(law, mapping, mass, step_s, previous_s, counts, &binding->computed_fallback,
                           &binding->pending);
      /* the boundary with ODE: nothing outside limits.h's ranges is ever written */
      if (status == SS_OK) status = ssCheckSoftnessForOde("softness", binding->pending.erp, binding->pending.cfm);
      if (status != SS_OK) {
        binding->computed_step_s = NAN;
        return failBinding(status, binding);
      }
      shared[shared_next] =
          (SharedSoftness){law, binding->law_slot, mass, binding->pending, binding->computed_fallback};
      shared_next = (shared_next + 1) % kSharedSize;
      if (shared_count < kSharedSize) shared_count += 1;
    }
    *unwritten += !sameSoftness(&binding->pending, &binding->written);
    binding->computed_mapping = mapping; /* implicit Euler: an accurate mapping never reuses this pending */
    if (mapping == SS_MAPPING_IMPLICIT_EULER) continue;
    binding->computed_epoch = registry->reuse_epoch;
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
        status = ssSoftnessFromSpring(*spring, step_s, &binding->pending);
        if (status != SS_OK) return failBinding(status, binding);
        /* counted once: moved from who was to serve it */
        if (binding->computed_fallback.exact_to_matched) counts->rows.handed_to_matched -= 1;
        else counts->rows.by_mapping -= 1;
        counts->rows.handed_to_implicit_euler += 1;
        binding->computed_fallback = (ssRowFallback){0, 1};
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
  for (int i = 0; i < registry->joint_count; ++i) {
    JointBinding* binding = &registry->joints[i];
    PREFETCH_ROWS(registry, i, 2);
    if (sameSoftness(&binding->pending, &binding->written)) continue;
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
    ssStatus status = ssRowSoftness(&registry->laws[j], SS_MAPPING_IMPLICIT_EULER, NAN, step_s, 0, NULL, &softness[j]);
    if (status == SS_OK) status = ssCheckSoftnessForOde("softness", softness[j].erp, softness[j].cfm);
    if (status == SS_OK) continue;
    for (int i = 0; i < registry->joint_count; ++i)
      if (registry->joints[i].law_slot == j) return failBinding(status, &registry->joints[i]);
    return status;
  }
  return SS_OK;
}

/* The one pass of lawSoftnesses' case: each row's law's softness written where it changed. Nothing here can
 * fail. It reads the rows' hot records and nothing else: where every row of a law was written by the last such
 * pass, law_written says what ODE holds. Returns the rows written. */
static int writeRowsByLaw(ssRegistry* registry, const ssSoftness* softness) {
  int writes = 0;
  int by_law = registry->written_by_law;
  int changed[kLawTableSize];
  for (int j = 0; j < registry->law_count; ++j)
    changed[j] = softness[j].erp != registry->law_written[j].erp || softness[j].cfm != registry->law_written[j].cfm;
  HotRow* hot = registry->hot_rows;
  for (int i = 0; i < registry->joint_count; ++i) {
    HotRow* row = &hot[i];
#if defined(__GNUC__)
    if (i + kPrefetchAhead / 2 < registry->joint_count) __builtin_prefetch(hot[i + kPrefetchAhead / 2].joint);
#endif
    const ssSoftness* law_softness = &softness[row->law_slot];
    if (by_law) {
      if (!changed[row->law_slot]) continue;
    } else {
      const ssSoftness* written = &registry->joints[i].written;
      if (law_softness->erp == written->erp && law_softness->cfm == written->cfm) continue;
    }
    if (row->set == NULL) continue;
    if (row->erp_number >= 0) row->set(row->joint, row->erp_number, law_softness->erp);
    row->set(row->joint, row->cfm_number, law_softness->cfm);
    writes += 1;
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
  if (mapping == SS_MAPPING_IMPLICIT_EULER && registry->applied_mapping == mapping &&
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
    status = softnessFor(&registry->world_law, mapping, registry->world_mass, step_s, previous_step_s, &counts,
                         &fallback, &registry->world_pending);
    if (status == SS_OK)
      status = ssCheckSoftnessForOde("softness", registry->world_pending.erp, registry->world_pending.cfm);
    if (status != SS_OK) return failBinding(status, NULL);
  }
  int measure = mapping != SS_MAPPING_IMPLICIT_EULER; /* implicit Euler reads no mass */
  int by_law = mapping == SS_MAPPING_IMPLICIT_EULER && registry->rows_outside_laws == 0;
  ssSoftness law_softness[kLawTableSize];
  if (!by_law) materializeWritten(registry); /* computeRows and writeRows compare each row's own */
  int unwritten = 0; /* rows whose pending differs from what ODE holds: with none (constant steps), no second pass */
  status = by_law ? lawSoftnesses(registry, step_s, law_softness)
                  : computeRows(registry, mapping, step_s, mapping == SS_MAPPING_EXACT ? previous_step_s : 0,
                                measure, &counts, &unwritten);
  if (status != SS_OK) return status;

  /* Nothing below can fail. */
  if (mapping == SS_MAPPING_IMPLICIT_EULER) registry->reuse_epoch += 1;
  if (registry->world_bound && (dWorldGetERP(registry->world) != registry->world_pending.erp ||
                                dWorldGetCFM(registry->world) != registry->world_pending.cfm)) {
    dWorldSetERP(registry->world, registry->world_pending.erp);
    dWorldSetCFM(registry->world, registry->world_pending.cfm);
    counts.row_writes += 1;
  }
  if (by_law) {
    counts.rows.by_mapping += registry->joint_count; /* implicit Euler serves every row */
    counts.row_writes += writeRowsByLaw(registry, law_softness);
  } else if (unwritten > 0 || (mapping != SS_MAPPING_IMPLICIT_EULER && registry->loaded_rows > 0)) {
    counts.row_writes += writeRows(registry, mapping);
  }
  for (int i = 0; i < registry->body_count; ++i) {
    ssBodyBinding* binding = &registry->bodies[i];
    if (binding->written_step_s != step_s) writeBody(binding, registry->world, step_s);
  }
  registry->applied_mapping = mapping;
  registry->applied_step_s = step_s;
  registry->applied_revision = registry->revision;
  registry->applied_counts = counts;
  if (report != NULL) *report = counts;
  return SS_OK;
}

dWorldID ssRegistryWorld(const ssRegistry* registry) { return registry->world; }

static int reserve(void** items, int count, int more, int* capacity, size_t size) {
  if (count + more <= *capacity) return 1;
  int wanted = count + more;
  void* larger = realloc(*items, (size_t)wanted * size);
  if (larger == NULL) return 0;
  *items = larger;
  *capacity = wanted;
  return 1;
}

ssStatus ssRegistryReserve(ssRegistry* registry, int more_joints, int more_bodies) {
  if (!reserveJoints(registry, more_joints) ||
      !reserve((void**)&registry->bodies, registry->body_count, more_bodies, &registry->body_capacity,
               sizeof(ssBodyBinding)))
    return ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory reserving %d joint rows and %d bodies", more_joints,
                  more_bodies);
  return SS_OK;
}

double ssRegistry_TunedStep(const ssRegistry* registry) { return registry != NULL ? registry->tuned_step_s : 0; }

void ssRegistrySetTuned(ssRegistry* registry, double tuned_step_s, ssSoftness tuned_world) {
  registry->revision += 1;
  registry->tuned_step_s = tuned_step_s;
  registry->tuned_world = tuned_world;
}

void ssRegistryForgetWorldAdoption(ssRegistry* registry) {
  registry->revision += 1;
  registry->world_bound = 0;
  registry->tuned_step_s = 0;
  if (ssRegistryHasBody(registry, 0)) ssRegistry_UnbindBody(registry, 0);
}

ssSoftness ssRegistryTunedWorld(const ssRegistry* registry) { return registry->tuned_world; }

int ssRegistryWorldBound(const ssRegistry* registry, ssRowLaw* law) {
  if (registry->world_bound && law != NULL) *law = registry->world_law;
  return registry->world_bound;
}


int ssRegistry_JointBindingCount(const ssRegistry* registry) { return registry != NULL ? registry->joint_count : 0; }

int ssRegistryBodyBindingCount(const ssRegistry* registry) { return registry->body_count; }

unsigned ssRegistryGeneration(const ssRegistry* registry) { return registry->generation; }

/* Every bound body, with repeats, without allocating. */
static void visitBodiesRepeated(const ssRegistry* registry, void (*visit)(void* context, dBodyID body),
                                void* context) {
  for (int i = 0; i < registry->joint_count; ++i)
    for (int side = 0; side < 2; ++side) {
      dBodyID body = dJointGetBody(registry->joints[i].joint, side);
      if (body != 0) visit(context, body);
    }
  for (int i = 0; i < registry->body_count; ++i)
    if (registry->bodies[i].body != 0) visit(context, registry->bodies[i].body);
}

typedef struct BodyList {
  dBodyID* bodies;
  int count;
} BodyList;

static void appendBody(void* context, dBodyID body) {
  BodyList* list = context;
  list->bodies[list->count++] = body;
}

static int compareBodies(const void* a, const void* b) {
  uintptr_t x = (uintptr_t) * (const dBodyID*)a, y = (uintptr_t) * (const dBodyID*)b;
  return (x > y) - (x < y);
}

void ssRegistry_VisitBodies(const ssRegistry* registry, void (*visit)(void* context, dBodyID body), void* context) {
  if (registry == NULL || visit == NULL) return;
  size_t most = 2 * (size_t)registry->joint_count + (size_t)registry->body_count;
  BodyList list = {malloc((most ? most : 1) * sizeof(dBodyID)), 0};
  if (list.bodies == NULL) { /* rather a body twice than none */
    visitBodiesRepeated(registry, visit, context);
    return;
  }
  visitBodiesRepeated(registry, appendBody, &list);
  qsort(list.bodies, (size_t)list.count, sizeof(dBodyID), compareBodies);
  for (int i = 0; i < list.count; ++i)
    if (i == 0 || list.bodies[i] != list.bodies[i - 1]) visit(context, list.bodies[i]);
  free(list.bodies);
}

/* Internal: the registry's layout, shared by its two halves: the bindings (registry.c) and Apply (apply.c). Only
 * those two files read it; everything else goes through registry_internal.h. */
#ifndef STEADYSTEP_REGISTRY_LAYOUT_H
#define STEADYSTEP_REGISTRY_LAYOUT_H

#include <stdint.h>

#include "binding_index.h"
#include "joint_rows.h"
#include "registry_internal.h"
#include "row_law.h"

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
  uint8_t joint_type;       /* a dJointType (below 256), resolved at bind time: a joint's type never changes */
  uint8_t computed_mapping; /* an ssMapping */
  ssRowFallback computed_fallback;
  uint8_t shares_previous_row; /* sharesRow(the binding before, this one), with the Apply cache: its mass is reused */
  double load_correction; /* the force this Apply adds along the row for the load (N or N·m), with pending */

  ssRowLaw law;
  double load; /* the steady force or torque the row carries (ssRegistry_SetJointLoad); 0 = none declared */
} JointBinding;

/* Three lines a row: at 100,000 rows a fourth line would be 6 MB more memory first touched at binding (1,600 page
 * faults), and one more line evicted by each Apply. */
_Static_assert(sizeof(JointBinding) == 3 * 64, "a joint binding is three cache lines");

/* What implicit Euler's by-law pass reads of a row, packed apart from the bindings (rebuilt with the Apply cache):
 * after an ODE step has evicted the registry's arrays, it streams through 24 bytes a row instead of a binding's
 * first line. Only rows with a writer and a law in the table have one, grouped by law (law_rows), so that the rows
 * of a law whose softness did not change (a damper's, k = 0, at any step) are passed over without being read. */
typedef struct HotRow {
  dJointID joint;
  ssParamSetter set;              /* the row's writer */
  int16_t erp_number, cfm_number; /* ODE's parameter numbers (below 0x400); erp_number -1: none */
  int binding;                    /* the row's position in joints */
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
  ssSoftness world_written; /* what ODE holds since the last Apply (NAN before): follow.c compares it */
  double tuned_step_s;      /* adoption's tuned step; 0 before any */
  ssSoftness tuned_world;   /* the world's ERP/CFM as adopted (contacts without soft modes stand for these) */
  JointBinding* joints;
  HotRow* hot_rows; /* joints' hot part, as many; valid while body_cache_revision == revision */
  int joint_count, joint_capacity;
  ssBodyBinding* bodies;
  int body_count, body_capacity;
  ssBindingIndex joint_index; /* (joint, rowTag) -> position in joints */
  ssBindingIndex body_index;  /* (body, 0) -> position in bodies */
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
  int law_rows[kLawTableSize + 1]; /* hot_rows[law_rows[j] .. law_rows[j + 1]) are law j's rows with a writer */
  int rows_outside_laws; /* bindings whose law did not fit in the table */
  /* after a by-law pass, every row in the law table holds its law's softness in ODE: law_written stands for the
   * rows' written until the other passes (or a rebinding) need theirs back (materializeWritten) */
  int written_by_law;
  ssSoftness law_written[kLawTableSize];
  unsigned disabled_caches; /* SS_CACHE_* turned off, to measure what each buys (ssRegistryDisableCaches) */
};

#define REQUIRE_REGISTRY(registry) \
  if ((registry) == NULL) return ssFail(SS_ERROR_OUT_OF_RANGE, "registry = NULL: a registry is required")

/* apply.c: gives every row in the law table its written back from law_written, before the rows or their law slots
 * change (see the invariants at the top of apply.c). */
void ssApplyMaterializeWritten(ssRegistry* registry);

/* registry.c: writes every body binding whose values were written for another step than step_s. */
void ssRegistryWriteBodies(ssRegistry* registry, double step_s);

#endif

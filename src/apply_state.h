/* Private to Apply's room (apply.c, apply_state.c): what Apply derives from the registry's bindings and keeps
 * between Applies. Nothing outside the room reads it; the registry holds it as an attachment it never opens.
 *
 * Invariants (apply_state.c keeps them; apply.c relies on them):
 *  - The state is built for the registry's rows revision (revision: ssRegistryRowsRevision) and its rows are the
 *    bindings' in order (ssRegistryJointRowAt), each with a copy of what Apply reads of its binding. Built again on
 *    any change of the rows' or the world's bindings (a body's is none of the state's); what ODE holds by Apply's
 *    writes (written) is carried over to the rows whose stamp is unchanged.
 *  - rows[i].written is what ODE holds for the row as Apply last wrote it (NAN: bound since, written at the next
 *    Apply whatever ODE holds), except while written_by_law: a row with law_slot >= 0 then holds
 *    law_written[law_slot] (the by-law pass writes no row's own); materializeWritten puts those back before a row's
 *    own is read. A row without an erp (a motor's) holds only its cfm (sameWrite).
 *  - laws[0..law_count) are distinct; rows[i].law_slot is the slot of a law equal to rows[i].law, or -1 (the table
 *    was full; rows_outside_laws counts those). hot_rows[law_rows[j] .. law_rows[j + 1]) are the joint and writer of
 *    law j's rows that have a writer, with each row's position. loaded_rows counts the rows with a load.
 *  - hard_rows counts the rows in the table whose law is hard. For each spring law j: law_unsure[j], some row of it
 *    cannot be handed on by law (a declared load on a spring, which the accurate mappings serve whatever the rule;
 *    an angular motor's measured mass, whose Euler axes are no unit vectors for its bodies' bounds to hold);
 *    law_given_mass[j], the largest mass given at binding among its rows (0: none). bound_rows: the spring rows in the
 *    table whose mass is measured, by joint and kind of axis, built with the body cache.
 *  - The body cache, valid while !bodies_stale: bodies lists the rows' joints' bodies once each (sorted by address);
 *    rows[i].body_slot[side] is the slot of the body the joint had there, or -1. A row that finds its joint attached
 *    elsewhere computes that body itself and sets bodies_stale. A slot's inverse is the body's for this Apply when
 *    its stamp == apply_stamp.
 *  - rows[i].computed (and computed_fallback), where computed_mapping is an accurate mapping, is the law's softness
 *    for (computed_mapping, mass, computed_step_s, computed_previous_s): the mappings are pure functions of these.
 *  - The same-step shortcut: when the last Apply was implicit Euler at applied_step_s with applied_revision the
 *    registry's revision now (ssRegistryRevision: any binding, a body's too), ODE holds every value an
 *    implicit-Euler Apply at that step would write, and applied_counts is its report. */
#ifndef STEADYSTEP_APPLY_STATE_H
#define STEADYSTEP_APPLY_STATE_H

#include <stdint.h>

#include "apply_internal.h"
#include "joint_rows.h"
#include "ode_bounds.h"
#include "registry_internal.h"
#include "row_law.h"

enum { kLawTableSize = 16 };

typedef struct ApplyRow {
  dJointID joint;
  ssRowWriter writer;
  ssParamGetter get; /* reads the writer's numbers back (NULL: ODE cannot, or the row has no writer) */
  ssSoftness written;
  ssSoftness pending; /* this Apply's softness for the row, checked, after its load's fallback */
  ssSoftness computed;
  ssRowFallback computed_fallback;
  uint8_t computed_mapping;    /* an ssMapping */
  uint8_t shares_previous_row; /* a stop and a motor on one axis with rows[i - 1], the same mass (sharesRow) */
  int law_slot;
  int body_slot[2];
  double mass; /* the last mass measured or given (NAN: none) */
  double computed_step_s, computed_previous_s;
  double load_correction; /* the force this Apply adds along the row for its load (N or N·m) */
  ssJointRowBinding binding; /* the registry's binding, as it was at the build */
} ApplyRow;

/* What implicit Euler's by-law pass reads of a row, packed apart: 24 bytes a row, grouped by law. */
typedef struct HotRow {
  dJointID joint;
  ssParamSetter set;
  int16_t erp_number, cfm_number; /* ODE's parameter numbers; erp_number -1: none */
  int row;                        /* the row's position in rows */
} HotRow;

/* What bounds the mass of a joint's measured rows on one kind of axis (apply_handed.c), packed apart: the bodies
 * the joint had in the body cache when it was built, with where the cache keeps their bounds (0 and NULL for the
 * static world and for a body the cache could not hold: read then), and the laws of up to two rows (a stop and its
 * motor; -1: none). */
typedef struct BoundRow {
  dJointID joint;
  dBodyID body[2];
  const ssBodyInverseBound* bound[2];
  int16_t law_slot[2];
  uint8_t angular; /* ssJointRowIsAngular */
} BoundRow;

/* A body's inverse mass and inertia, computed at most once per Apply for all the rows on it. */
typedef struct BodyCache {
  dBodyID body;
  unsigned stamp; /* the Apply it was computed for */
  ssBodyInverse inverse;
  ssBodyInverseBound bound; /* read at each Apply that bounds the laws' masses (apply.c) */
} BodyCache;

typedef struct ApplyState {
  unsigned revision; /* the registry's rows revision, at the build */
  unsigned stamp;    /* the registry's last stamp, at the build */
  ApplyRow* rows;
  HotRow* hot_rows;
  int row_count;
  int loaded_rows;
  ssRowLaw laws[kLawTableSize];
  int law_count;
  int law_rows[kLawTableSize + 1];
  int rows_outside_laws;
  int hard_rows;
  unsigned char law_unsure[kLawTableSize];
  double law_given_mass[kLawTableSize];
  BoundRow* bound_rows;
  int bound_row_count;
  int handed_wait;   /* Applies before the laws' masses are bounded again (apply.c's everyLawHandedOn) */
  int handed_failed; /* the last bounds found a law served */
  int written_by_law;
  ssSoftness law_written[kLawTableSize];
  ssSoftness world_written;
  BodyCache* bodies;
  int body_count;
  int bodies_stale;
  unsigned apply_stamp;
  unsigned applied_revision; /* the same-step shortcut: the registry's revision at the last Apply */
  double applied_step_s;     /* NAN: none */
  ssMapping applied_mapping;
  ssApplyReport applied_counts;
#ifdef SS_APPLY_SWITCHES
  unsigned disabled; /* SS_APPLY_* turned off */
#endif
} ApplyState;

#ifdef SS_APPLY_SWITCHES
#define APPLY_CACHE_ON(state, cache) (!((state)->disabled & (cache)))
#else
#define APPLY_CACHE_ON(state, cache) ((void)(state), 1)
#endif

/* Apply's state for the registry's bindings as they are now, built or rebuilt as needed; NULL when out of memory. */
ApplyState* ssApplyStateOf(ssRegistry* registry);

/* Gives every row in the law table its written back from law_written (before a row's own is read). */
void ssApplyMaterializeRows(ApplyState* state);

/* Under an accurate mapping: whether every row in the table is surely handed to implicit Euler at every mass it can
 * have (apply_handed.c). Bounding the masses reads every body: after a law was found served, the next Applies do not
 * try for a while, and the one after probes a few rows first. */
int ssApplyEveryLawHandedOn(ApplyState* state, double step_s);

/* The body cache again, after a row found its joint attached elsewhere. */
void ssApplyRebuildBodies(ApplyState* state);

/* What the body opposes to its rows in this Apply: from the cache (computed on its first use in the Apply), or into
 * *local for a body the cache does not know (bodies_stale is then set). */
const ssBodyInverse* ssApplyBodyInverse(ApplyState* state, int slot, dBodyID body, ssBodyInverse* local);

/* Whether writing b over a would change nothing in ODE (as ODE stores them): a row without an erp holds its cfm. */
static inline int ssSameWrite(int erp_number, const ssSoftness* a, const ssSoftness* b) {
  return ssSameInOde(a->cfm, b->cfm) && (erp_number < 0 || ssSameInOde(a->erp, b->erp));
}

#endif

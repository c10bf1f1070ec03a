/* Apply's handed-on cache (apply.c): under an accurate mapping, whether the rule (ssSurelyFailsUpToMass) hands every
 * row in the table to implicit Euler at every mass it can have now, bounded from the masses and inertias of its
 * bodies (which no rotation changes) without measuring one, so that implicit Euler's by-law pass serves the Apply:
 * a program tuned near-rigid and adopted, where the accurate mappings serve nothing, pays for them about what reading
 * every body's mass costs. Hard laws are implicit Euler's under every mapping. */
#include <math.h>
#include <string.h>

#include "apply_state.h"

/* A bound on the effective mass of a BoundRow's rows from lower bounds of what its two sides oppose: rowMass' sum
 * is at least theirs, within SS_MASS_BOUND_MARGIN. 0: nothing opposes the row (it has no mass); NAN: no bound. */
static double boundedMass(const BoundRow* row, const ssBodyInverseBound* first, const ssBodyInverseBound* second) {
  const double inverse = row->angular ? first->angular + second->angular : first->linear + second->linear;
  return inverse > 0 ? (1.0 + SS_MASS_BOUND_MARGIN) / inverse : inverse == 0 ? 0 : NAN;
}

static void raiseBound(const BoundRow* row, double mass, double* bound) {
  for (int k = 0; k < 2 && row->law_slot[k] >= 0; ++k)
    if (!(mass <= bound[row->law_slot[k]])) bound[row->law_slot[k]] = mass; /* NAN too */
}

/* Each spring law's bound on the effective masses its rows can have now (ssSurelyFailsUpToMass): given, or from
 * the bounds of their bodies (ssBodyInverseBoundOf), read once per body; NAN where a row has none. With probe, from
 * the first kProbeRows bound rows only, each body read for itself: bounds that do not hand every law on with them
 * are not read for all. */
enum { kProbeRows = 8 };
static void lawMassBounds(ApplyState* state, int probe, double* bound) {
  memcpy(bound, state->law_given_mass, sizeof state->law_given_mass);
  if (probe) {
    for (int i = 0; i < state->bound_row_count && i < kProbeRows; ++i) {
      const BoundRow* row = &state->bound_rows[i];
      ssBodyInverseBound first = ssBodyInverseBoundOf(dJointGetBody(row->joint, 0));
      ssBodyInverseBound second = ssBodyInverseBoundOf(dJointGetBody(row->joint, 1));
      raiseBound(row, boundedMass(row, &first, &second), bound);
    }
    return;
  }
  static const ssBodyInverseBound kStatic = {0, 0};
  BodyCache* bodies = state->bodies;
  for (int b = 0; b < state->body_count; ++b) bodies[b].bound = ssBodyInverseBoundOf(bodies[b].body);
  for (const BoundRow *row = state->bound_rows, *end = row + state->bound_row_count; row < end; ++row) {
    ssBodyInverseBound found[2];
    const ssBodyInverseBound* side_bound[2];
    for (int side = 0; side < 2; ++side) {
      dBodyID body = dJointGetBody(row->joint, side);
      side_bound[side] = body == 0 ? &kStatic : body == row->body[side] ? row->bound[side] : NULL;
      if (side_bound[side] == NULL) { /* attached elsewhere since the cache was built, or a body it could not hold */
        found[side] = ssBodyInverseBoundOf(body);
        side_bound[side] = &found[side];
        state->bodies_stale |= bodies != NULL;
      }
    }
    raiseBound(row, boundedMass(row, side_bound[0], side_bound[1]), bound);
  }
}

/* Whether every spring law is handed on at every mass up to its bound. */
static int everyLawUpToItsBound(const ApplyState* state, const double* bound, double step_s) {
  for (int j = 0; j < state->law_count; ++j)
    if (!state->laws[j].hard && !ssSurelyFailsUpToMass(state->laws[j].spring, bound[j], step_s)) return 0;
  return 1;
}

enum { kHandedWait = 15 };
int ssApplyEveryLawHandedOn(ApplyState* state, double step_s) {
  int springs = 0;
  for (int j = 0; j < state->law_count; ++j) {
    if (state->law_unsure[j]) return 0;
    springs += !state->laws[j].hard;
  }
  if (springs == 0) return 1;
  if (state->handed_wait > 0) {
    state->handed_wait -= 1;
    return 0;
  }
  double bound[kLawTableSize];
  for (int probe = state->handed_failed; probe >= 0; --probe) {
    lawMassBounds(state, probe, bound);
    state->handed_failed = !everyLawUpToItsBound(state, bound, step_s);
    if (state->handed_failed) {
      state->handed_wait = kHandedWait;
      return 0;
    }
  }
  return 1;
}

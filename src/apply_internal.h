/* Internal: what Apply (apply.c) tells the rest of the core. Apply owns everything it derives from the registry's
 * bindings, what it last wrote into ODE included: the one place where a program's own writes since are noticed
 * (follow.c compares ODE's values with it). */
#ifndef STEADYSTEP_APPLY_INTERNAL_H
#define STEADYSTEP_APPLY_INTERNAL_H

#include "steadystep/registry.h"

/* What Apply last wrote into the world's ERP/CFM: {NAN, NAN} when nothing was written since the world was bound (or
 * Apply's state could not be built: out of memory, which the next Apply reports). */
ssSoftness ssApplyWorldLastWritten(ssRegistry* registry);

/* A row the program wrote over: i, its place among the bound joint rows (ssRegistryJointRowAt), and held, what ODE
 * holds (a row without an erp, a motor's: erp 0). A status other than SS_OK stops the pass and is returned. */
typedef ssStatus ssRowWrittenOver(void* context, int i, ssSoftness held);

/* Calls visit, in the rows' order, for each bound joint row adopted from the program's numbers (a spring the program
 * bound itself is its own to bind again) whose numbers in ODE differ from what Apply last wrote there: the program
 * wrote them since. A row bound since the last Apply, a row ODE cannot read back (plane-2D), and every row when
 * Apply's state cannot be built (out of memory, which the next Apply reports) are passed over. One pass over Apply's
 * own rows, which hold each row's writer and getter: nothing looked up a row. */
ssStatus ssApplyEachRowWrittenOver(ssRegistry* registry, ssRowWrittenOver* visit, void* context);

/* Records that the i-th row (i = -1: the world) holds held, as the program wrote it and follow.c took it: the next
 * Apply compares its softness with held and writes where they differ. */
void ssApplyTakeHeld(ssRegistry* registry, int i, ssSoftness held);

/* Built only into the tests' and benchmarks' copy of the core (SS_APPLY_SWITCHES): Apply's caches, to turn off one by
 * one; the values Apply writes are the same either way (the differential test requires it), only the time differs
 * (bench_apply). The shipped library has none of this. */
#ifdef SS_APPLY_SWITCHES
enum {
  SS_APPLY_SAME_STEP = 1 << 0, /* implicit Euler at the last step with nothing rebound: nothing to write */
  SS_APPLY_BY_LAW = 1 << 1,    /* implicit Euler: one softness per law, rows written by law */
  SS_APPLY_BODIES = 1 << 2,    /* each body's inverse mass and inertia computed once per Apply */
  SS_APPLY_SHARED = 1 << 3,    /* within an Apply, rows with the same law and mass share one softness */
  SS_APPLY_REUSE = 1 << 4,     /* accurate mappings: a row's softness kept while its inputs are the same */
  SS_APPLY_SAME_AXIS = 1 << 5, /* a stop and a motor on one axis share the mass measured for the first */
  SS_APPLY_SURE_FALLBACK = 1 << 6, /* accurate mappings: a row the rule surely hands on, without the arithmetic */
  SS_APPLY_HANDED_ON = 1 << 7, /* accurate mappings: laws the rule hands on at any mass their rows can have, by law */
  SS_APPLY_ALL = (1 << 8) - 1
};
/* Turns off the caches in mask (and on the others). */
void ssApplyDisableCaches(ssRegistry* registry, unsigned mask);
#endif

#endif

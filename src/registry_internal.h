/* Internal: what the stepper and soft contacts need from the registry beyond the public API. */
#ifndef STEADYSTEP_REGISTRY_INTERNAL_H
#define STEADYSTEP_REGISTRY_INTERNAL_H

#include "steadystep/registry.h"

/* A number that changes whenever a joint or body is bound or unbound: the stepper rebuilds its list on a change. */
unsigned ssRegistryGeneration(const ssRegistry* registry);

/* The number of bodies bound for damping or auto-disable (the world's defaults included). */
int ssRegistryBodyBindingCount(const ssRegistry* registry);

/* ssSoftnessFor, except that where SS_MAPPING_EXACT has no finite mapping for this pair of steps (and c > 0) it
 * uses the matched mapping, which keeps the exact poles and loses only the history correction; *fell_back says so.
 * The registry and soft contacts share this rule. */
ssStatus ssSoftnessOrMatched(ssMapping mapping, ssSpring spring, double mass, double step_s,
                             double previous_step_s, int* fell_back, ssSoftness* out);

#endif

/* Internal: what the stepper needs from the registry beyond the public API. */
#ifndef STEADYSTEP_REGISTRY_INTERNAL_H
#define STEADYSTEP_REGISTRY_INTERNAL_H

#include "steadystep/registry.h"

/* A number that changes whenever a joint or body is bound or unbound: the stepper rebuilds its list on a change. */
unsigned ssRegistryGeneration(const ssRegistry* registry);

/* The number of bodies bound for damping or auto-disable (the world's defaults included). */
int ssRegistryBodyBindingCount(const ssRegistry* registry);

#endif

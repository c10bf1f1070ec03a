/* Internal: what the stepper needs from the registry beyond the public API. */
#ifndef STEADYSTEP_REGISTRY_INTERNAL_H
#define STEADYSTEP_REGISTRY_INTERNAL_H

#include "steadystep/registry.h"

/* Like ssRegistry_VisitBodies, without removing repeats and without allocating: for checks that may repeat. */
void ssRegistryVisitBodiesRepeated(const ssRegistry* registry, void (*visit)(void* context, dBodyID body),
                                   void* context);

#endif

/* Internal: the accurate mappings for the registry's rows, which hand a row on to another mapping whenever these
 * refuse: SS_ERROR_NO_FINITE_MAPPING is returned without a message (ssLastError is left as it was), since building
 * one for every row at every step would cost more than the mapping. */
#ifndef STEADYSTEP_MATCHED_INTERNAL_H
#define STEADYSTEP_MATCHED_INTERNAL_H

#include "steadystep/spring.h"

/* ssMatchedSoftness without its argument checks, for rows whose spring, mass and step are already known to be valid
 * (c > 0, mass > 0 finite, step in range). */
ssStatus ssMatchedSoftnessUnchecked(ssSpring spring, double mass, double step_s, ssSoftness* out);

/* ssExactSoftness, its arguments checked (with messages) as there. */
ssStatus ssExactSoftnessQuiet(ssSpring spring, double mass, double step_s, double previous_step_s, ssSoftness* out);

#endif

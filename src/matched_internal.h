/* Internal: the matched mapping without its argument checks, for the registry's rows, whose spring, mass and step
 * are already known to be valid (c > 0, mass > 0 finite, step in range). */
#ifndef STEADYSTEP_MATCHED_INTERNAL_H
#define STEADYSTEP_MATCHED_INTERNAL_H

#include "steadystep/spring.h"

ssStatus ssMatchedSoftnessUnchecked(ssSpring spring, double mass, double step_s, ssSoftness* out);

#endif

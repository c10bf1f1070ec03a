/* Internal: the accurate mappings for the registry's rows, which hand a row on to another mapping whenever these
 * refuse: SS_ERROR_NO_FINITE_MAPPING is returned without a message (ssLastError is left as it was), since building
 * one for every row at every step would cost more than the mapping. */
#ifndef STEADYSTEP_MATCHED_INTERNAL_H
#define STEADYSTEP_MATCHED_INTERNAL_H

#include <math.h>

#include "steadystep/limits.h"
#include "steadystep/spring.h"

/* The matched softness of a pure damper (k = 0) of damping c > 0 N·s/m on mass m > 0 (finite) at a step of step_s:
 * its poles are 1 and P = d², d = e^(-c·h/2m), so erp = (1 + P - (1 + P))/(1 - P) = 0 exactly and cfm = a·h/m with
 * a = P/(1 - P), 1 - P computed as (1 - d)(1 + d) from expm1 (matchedSoftness's arithmetic, which calls this for
 * every damper). 1 with *out written when cfm is within ODE's range (SS_MIN_POSITIVE_CFM to SS_MAX_CFM); 0
 * otherwise, out untouched. Inline: Apply serves a program's motor rows with it at every step. */
static inline int ssMatchedDamper(double damping, double mass, double step_s, ssSoftness* out) {
  double sigma_h = damping / (2.0 * mass) * step_s;
  double one_minus_d = -expm1(-sigma_h);
  double d = sigma_h < 0.5 ? 1.0 - one_minus_d : exp(-sigma_h);
  double cfm = d * d / (one_minus_d * (1.0 + d)) * step_s / mass;
  if (!(cfm >= SS_MIN_POSITIVE_CFM && cfm <= SS_MAX_CFM)) return 0; /* NAN and infinities too */
  *out = (ssSoftness){.erp = 0.0, .cfm = cfm};
  return 1;
}

/* ssMatchedSoftness without its argument checks, for rows whose spring, mass and step are already known to be valid
 * (c > 0, mass > 0 finite, step in range). */
ssStatus ssMatchedSoftnessUnchecked(ssSpring spring, double mass, double step_s, ssSoftness* out);

/* ssExactSoftness, its arguments checked (with messages) as there. */
ssStatus ssExactSoftnessQuiet(ssSpring spring, double mass, double step_s, double previous_step_s, ssSoftness* out);

#endif

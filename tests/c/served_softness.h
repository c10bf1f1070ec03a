// Test support: the softness the registry serves a row with, from the public mappings and issue 15's rule as
// row_law.c states it: an accurate mapping serves a row of undeclared load only where the matched softness' static
// response is the spring's within 5 % (stiffness k' = erp/(h·cfm) against k; a pure damper's 1/cfm against c);
// elsewhere implicit Euler serves it. Exact refused for a pair of steps: matched.
#ifndef STEADYSTEP_TESTS_SERVED_SOFTNESS_H
#define STEADYSTEP_TESTS_SERVED_SOFTNESS_H

#include <cmath>

#include "steadystep/spring.h"

// Whether the matched softness of (spring, mass) at step_s keeps the static response within 5 %.
inline bool KeepsStaticResponse(ssSpring spring, double mass, double step_s) {
  ssSoftness matched;
  if (ssMatchedSoftness(spring, mass, step_s, &matched) != SS_OK) return false;
  double ratio = spring.stiffness > 0 ? spring.stiffness * step_s * matched.cfm / matched.erp
                                      : spring.damping * matched.cfm;
  return std::fabs(ratio - 1.0) <= 0.05;
}

inline ssStatus ServedSoftness(ssMapping mapping, ssSpring spring, double mass, double step_s, double previous_s,
                               ssSoftness* out) {
  if (mapping != SS_MAPPING_IMPLICIT_EULER && !KeepsStaticResponse(spring, mass, step_s))
    return ssImplicitEulerSoftness(spring, step_s, out);
  if (mapping == SS_MAPPING_EXACT && spring.stiffness == 0) mapping = SS_MAPPING_MATCHED;
  ssStatus status = ssSoftnessFor(mapping, spring, mass, step_s, mapping == SS_MAPPING_EXACT ? previous_s : 0, out);
  if (status == SS_ERROR_NO_FINITE_MAPPING && mapping == SS_MAPPING_EXACT)
    status = ssMatchedSoftness(spring, mass, step_s, out);
  return status;
}

#endif

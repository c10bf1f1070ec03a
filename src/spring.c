/* The article's mapping between a spring-damper and ODE's ERP/CFM, its inverse, and the frequency form.
 *
 * ODE solves each row as J v' = -(erp/h)·x - cfm·f with f the row's force (ode/src/step.cpp scales the row's rhs
 * and cfm by 1/h). With m(v' - v)/h = f for a lone body, erp = hk/(hk+c) and cfm = 1/(hk+c) turn that into
 * m(v' - v)/h = -k(x + h v') - c v': the implicit-Euler step of the spring. */
#include "steadystep/spring.h"

#include <math.h>
#include <stddef.h>

#include "error.h"

ssStatus ssValidateSpring(ssSpring spring) {
  ssStatus status = ssCheckNonNegative("k", "N/m", spring.stiffness);
  if (status == SS_OK) status = ssCheckNonNegative("c", "N*s/m", spring.damping);
  if (status != SS_OK) return status;
  if (spring.stiffness == 0 && spring.damping == 0)
    return ssFail(SS_ERROR_NO_SPRING, "k = 0 N/m and c = 0 N*s/m: a spring needs stiffness or damping");
  return SS_OK;
}

ssStatus ssSoftnessFromSpring(ssSpring spring, double step_s, ssSoftness* out) {
  ssStatus status = ssValidateSpring(spring);
  if (status == SS_OK) status = ssCheckPositive("step_s", "s", step_s);
  if (status != SS_OK) return status;
  double hk_plus_c = step_s * spring.stiffness + spring.damping;
  *out = (ssSoftness){.erp = step_s * spring.stiffness / hk_plus_c, .cfm = 1.0 / hk_plus_c};
  if (!isfinite(out->cfm))
    return ssFail(SS_ERROR_NO_FINITE_MAPPING, "h*k + c = %g: too small for a finite cfm", hk_plus_c);
  return SS_OK;
}

ssStatus ssSpringFromSoftness(ssSoftness softness, double step_s, ssSpring* out) {
  ssStatus status = ssCheckFinite("erp", "", softness.erp);
  if (status == SS_OK) status = ssCheckPositive("cfm", "", softness.cfm);
  if (status == SS_OK) status = ssCheckPositive("step_s", "s", step_s);
  if (status != SS_OK) return status;
  if (!(softness.erp > 0 && softness.erp <= 1))
    return ssFail(SS_ERROR_OUT_OF_RANGE, "erp = %g: must be in (0, 1] to stand for a spring", softness.erp);
  *out = (ssSpring){.stiffness = softness.erp / (step_s * softness.cfm),
                    .damping = (1.0 - softness.erp) / softness.cfm};
  return SS_OK;
}

ssStatus ssSpringFromFrequency(double frequency_hz, double damping_ratio, double mass, ssSpring* out) {
  ssStatus status = ssCheckPositive("frequency_hz", "Hz", frequency_hz);
  if (status == SS_OK) status = ssCheckNonNegative("damping_ratio", "", damping_ratio);
  if (status == SS_OK) status = ssCheckPositive("mass", "kg", mass);
  if (status != SS_OK) return status;
  double omega = 2.0 * M_PI * frequency_hz;
  *out = (ssSpring){.stiffness = mass * omega * omega, .damping = 2.0 * damping_ratio * mass * omega};
  return SS_OK;
}

ssStatus ssFrequencyFromSpring(ssSpring spring, double mass, double* frequency_hz, double* damping_ratio) {
  ssStatus status = ssValidateSpring(spring);
  if (status == SS_OK) status = ssCheckPositive("mass", "kg", mass);
  if (status != SS_OK) return status;
  double omega = sqrt(spring.stiffness / mass);
  *frequency_hz = omega / (2.0 * M_PI);
  *damping_ratio = spring.stiffness > 0 ? spring.damping / (2.0 * mass * omega) : INFINITY;
  return SS_OK;
}

const char* ssMappingName(ssMapping mapping) {
  switch (mapping) {
    case SS_MAPPING_SPRING: return "spring";
    case SS_MAPPING_MATCHED: return "matched";
    case SS_MAPPING_EXACT: return "exact";
  }
  return NULL;
}

ssStatus ssSoftnessFor(ssMapping mapping, ssSpring spring, double mass, double step_s, double previous_step_s,
                       ssSoftness* out) {
  switch (mapping) {
    case SS_MAPPING_SPRING: return ssSoftnessFromSpring(spring, step_s, out);
    case SS_MAPPING_MATCHED: return ssMatchedSoftness(spring, mass, step_s, out);
    case SS_MAPPING_EXACT: return ssExactSoftness(spring, mass, step_s, previous_step_s, out);
  }
  return ssFail(SS_ERROR_UNSUPPORTED, "mapping = %d: unknown (0 spring, 1 matched, 2 exact)", (int)mapping);
}

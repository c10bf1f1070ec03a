/* The article's mapping between a spring-damper and ODE's ERP/CFM, its inverse, and the frequency form.
 *
 * ODE solves each row as J v' = -(erp/h)·x - cfm·f with f the row's force (ode/src/step.cpp scales the row's rhs
 * and cfm by 1/h). With m(v' - v)/h = f for a lone body, erp = hk/(hk+c) and cfm = 1/(hk+c) turn that into
 * m(v' - v)/h = -k(x + h v') - c v': the implicit-Euler step of the spring. */
#include "steadystep/spring.h"

#include <math.h>
#include <stddef.h>

#include "error.h"
#include "ode_bounds.h"

ssStatus ssValidateSpring(ssSpring spring) {
  ssStatus status = ssCheckNonNegative("k", "N/m", spring.stiffness);
  if (status == SS_OK) status = ssCheckNonNegative("c", "N*s/m", spring.damping);
  if (status != SS_OK) return status;
  if (spring.stiffness == 0 && spring.damping == 0)
    return ssFail(SS_ERROR_NO_SPRING, "k = 0 N/m and c = 0 N*s/m: a spring needs stiffness or damping");
  return SS_OK;
}

/* The article's mapping without touching *out: every conversion checks its result before it writes. */
static ssStatus implicitEulerSoftness(ssSpring spring, double step_s, ssSoftness* result) {
  ssStatus status = ssValidateSpring(spring);
  if (status == SS_OK) status = ssCheckStepLength("step_s", step_s);
  if (status != SS_OK) return status;
  double hk_plus_c = step_s * spring.stiffness + spring.damping;
  if (!isfinite(hk_plus_c))
    return ssFail(SS_ERROR_NO_FINITE_MAPPING, "k = %g N/m, c = %g N*s/m at step_s = %g s: h*k + c overflows",
                  spring.stiffness, spring.damping, step_s);
  ssSoftness softness = {.erp = step_s * spring.stiffness / hk_plus_c, .cfm = 1.0 / hk_plus_c};
  if (!(softness.cfm <= SS_MAX_CFM))
    return ssFail(SS_ERROR_NO_FINITE_MAPPING,
                  "k = %g N/m, c = %g N*s/m at step_s = %g s: h*k + c = %g N*s/m gives cfm = %g, above %g", spring.stiffness,
                  spring.damping, step_s, hk_plus_c, softness.cfm, SS_MAX_CFM);
  status = ssCheckComputedSoftness("implicit-Euler mapping", softness);
  if (status != SS_OK) return status;
  *result = softness;
  return SS_OK;
}

ssStatus ssImplicitEulerSoftness(ssSpring spring, double step_s, ssSoftness* out) {
  if (out == NULL) return ssFail(SS_ERROR_OUT_OF_RANGE, "out = NULL: ssImplicitEulerSoftness needs somewhere to write");
  return implicitEulerSoftness(spring, step_s, out);
}

ssStatus ssSpringFromSoftness(ssSoftness softness, double step_s, ssSpring* out) {
  if (out == NULL) return ssFail(SS_ERROR_OUT_OF_RANGE, "out = NULL: ssSpringFromSoftness needs somewhere to write");
  ssStatus status = ssCheckFinite("erp", "", softness.erp);
  if (status == SS_OK) status = ssCheckFinite("cfm", "", softness.cfm);
  if (status == SS_OK) status = ssCheckStepLength("step_s", step_s);
  if (status != SS_OK) return status;
  if (!(softness.erp >= 0 && softness.erp <= 1))
    return ssFail(SS_ERROR_OUT_OF_RANGE, "erp = %g: must be in [0, 1] to stand for a spring", softness.erp);
  if (!(softness.cfm > 0 && softness.cfm <= SS_MAX_CFM))
    return ssFail(SS_ERROR_OUT_OF_RANGE, "cfm = %g: must be in (0, %g] to stand for a spring", softness.cfm,
                  SS_MAX_CFM);
  /* erp = 0 is a pure damper; writing 0 rather than erp/(h*cfm) keeps a -0 erp from giving k = -0. */
  ssSpring spring = {.stiffness = softness.erp > 0 ? softness.erp / (step_s * softness.cfm) : 0.0,
                     .damping = (1.0 - softness.erp) / softness.cfm};
  /* Denormal or extreme inputs overflow (k = inf) or underflow (k = c = 0): only a spring that converts back to
   * softness at this step is a result. */
  ssSoftness back;
  if (!(isfinite(spring.stiffness) && isfinite(spring.damping)) || ssValidateSpring(spring) != SS_OK ||
      implicitEulerSoftness(spring, step_s, &back) != SS_OK)
    return ssFail(SS_ERROR_NO_FINITE_MAPPING,
                  "erp = %g, cfm = %g at step_s = %g s: the spring (k = %g N/m, c = %g N*s/m) is not representable",
                  softness.erp, softness.cfm, step_s, spring.stiffness, spring.damping);
  *out = spring;
  return SS_OK;
}

/* The frequency form in both directions. Products like m·w² under- or overflow in double long before the result
 * does, so they are formed in long double (x86-64: 15-bit exponent) and rounded once. A result counts only when
 * every number is 0 or normal (a subnormal has lost its digits) and it converts back: a round trip at the edge of
 * the double range can round into a subnormal, and then neither direction answers. */
static int springFromFrequency(double frequency_hz, double damping_ratio, double mass, ssSpring* spring) {
  long double omega = 2.0L * 3.14159265358979323846264338327950288L * frequency_hz;
  double k = (double)((long double)mass * omega * omega);
  double c = (double)(2.0L * damping_ratio * mass * omega);
  if (!isnormal(frequency_hz) || !isnormal(mass) || !isnormal(k)) return 0;
  if (damping_ratio == 0 ? c != 0 : !(isnormal(damping_ratio) && isnormal(c))) return 0;
  *spring = (ssSpring){.stiffness = k, .damping = c};
  return 1;
}

static int frequencyFromSpring(ssSpring spring, double mass, double* frequency_hz, double* damping_ratio) {
  if (!isnormal(spring.stiffness) || !isnormal(mass) || (spring.damping != 0 && !isnormal(spring.damping))) return 0;
  long double omega = sqrtl((long double)spring.stiffness / mass);
  double hz = (double)(omega / (2.0L * 3.14159265358979323846264338327950288L));
  double ratio = (double)(spring.damping / (2.0L * sqrtl((long double)spring.stiffness * mass)));
  if (!isnormal(hz) || (spring.damping != 0 && !isnormal(ratio))) return 0;
  *frequency_hz = hz;
  *damping_ratio = ratio;
  return 1;
}

ssStatus ssSpringFromFrequency(double frequency_hz, double damping_ratio, double mass, ssSpring* out) {
  if (out == NULL) return ssFail(SS_ERROR_OUT_OF_RANGE, "out = NULL: ssSpringFromFrequency needs somewhere to write");
  ssStatus status = ssCheckPositive("frequency_hz", "Hz", frequency_hz);
  if (status == SS_OK) status = ssCheckNonNegative("damping_ratio", "", damping_ratio);
  if (status == SS_OK) status = ssCheckPositive("mass", "kg", mass);
  if (status != SS_OK) return status;
  ssSpring spring;
  double hz_back, ratio_back;
  if (!springFromFrequency(frequency_hz, damping_ratio, mass, &spring) ||
      !frequencyFromSpring(spring, mass, &hz_back, &ratio_back))
    return ssFail(SS_ERROR_NO_FINITE_MAPPING,
                  "frequency_hz = %g Hz, damping_ratio = %g, mass = %g kg: k = m*w^2 or c = 2*zeta*m*w is not "
                  "representable as a normal double",
                  frequency_hz, damping_ratio, mass);
  *out = spring;
  return SS_OK;
}

ssStatus ssFrequencyFromSpring(ssSpring spring, double mass, double* frequency_hz, double* damping_ratio) {
  if (frequency_hz == NULL || damping_ratio == NULL)
    return ssFail(SS_ERROR_OUT_OF_RANGE, "%s = NULL: ssFrequencyFromSpring needs somewhere to write",
                  frequency_hz == NULL ? "frequency_hz" : "damping_ratio");
  ssStatus status = ssValidateSpring(spring);
  if (status == SS_OK) status = ssCheckPositive("mass", "kg", mass);
  if (status != SS_OK) return status;
  if (spring.stiffness == 0)
    return ssFail(SS_ERROR_NO_FINITE_MAPPING,
                  "k = 0 N/m: a pure damper has no natural frequency (its damping ratio would be infinite)");
  double hz, ratio;
  ssSpring back;
  if (!frequencyFromSpring(spring, mass, &hz, &ratio) || !springFromFrequency(hz, ratio, mass, &back))
    return ssFail(SS_ERROR_NO_FINITE_MAPPING,
                  "k = %g N/m, c = %g N*s/m, mass = %g kg: the frequency or damping ratio is not representable as a "
                  "normal double",
                  spring.stiffness, spring.damping, mass);
  *frequency_hz = hz;
  *damping_ratio = ratio;
  return SS_OK;
}

const char* ssMappingName(ssMapping mapping) {
  switch (mapping) {
    case SS_MAPPING_IMPLICIT_EULER: return "implicit-euler";
    case SS_MAPPING_MATCHED: return "matched";
    case SS_MAPPING_EXACT: return "exact";
  }
  return NULL;
}

ssStatus ssSoftnessFor(ssMapping mapping, ssSpring spring, double mass, double step_s, double previous_step_s,
                       ssSoftness* out) {
  if (out == NULL) return ssFail(SS_ERROR_OUT_OF_RANGE, "out = NULL: ssSoftnessFor needs somewhere to write");
  switch (mapping) {
    case SS_MAPPING_IMPLICIT_EULER: return ssImplicitEulerSoftness(spring, step_s, out);
    case SS_MAPPING_MATCHED: return ssMatchedSoftness(spring, mass, step_s, out);
    case SS_MAPPING_EXACT: return ssExactSoftness(spring, mass, step_s, previous_step_s, out);
  }
  return ssFail(SS_ERROR_UNSUPPORTED, "mapping = %d: unknown (0 implicit-euler, 1 matched, 2 exact)", (int)mapping);
}

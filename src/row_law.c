/* Row laws: a spring or a hard row, and the one rule for when an accurate mapping hands a row to implicit Euler. */
#include "row_law.h"

#include <math.h>
#include <stddef.h>

#include "error.h"
#include "ode_bounds.h"
#include "steadystep/limits.h"
#include "matched_internal.h"

ssRowLaw ssRowLawOfSpring(ssSpring spring) {
  return (ssRowLaw){.spring = spring, .hard = 0, .hard_rate_per_s = 0, .tuned_step_s = 0, .tuned = {0, 0}};
}

ssStatus ssRowLawFromTuned(const char* what, double erp, double cfm, double tuned_step_s, ssRowLaw* out) {
  if (!isfinite(erp) || !isfinite(cfm))
    return ssFail(SS_ERROR_NOT_FINITE, "%s: erp = %g, cfm = %g: must be finite", what, erp, cfm);
  if (!(erp >= 0 && erp <= 1))
    return ssFail(SS_ERROR_OUT_OF_RANGE, "%s: erp = %g: must be in [0, 1] to stand for a spring", what, erp);
  if (cfm < 0) return ssFail(SS_ERROR_OUT_OF_RANGE, "%s: cfm = %g: must not be negative", what, cfm);
  ssStatus status = ssCheckStepLength("tuned_step_s", tuned_step_s);
  if (status != SS_OK) return status;
  /* k = erp/(h0·cfm), c = (1 - erp)/cfm; a cfm so small that they overflow is a hard row in all but name */
  double stiffness = erp / (tuned_step_s * cfm), damping = (1.0 - erp) / cfm;
  if (cfm > 0 && isfinite(stiffness) && isfinite(damping)) {
    if (stiffness == 0 && damping == 0) /* a cfm so large that k and c underflow: no constraint at all */
      return ssFail(SS_ERROR_OUT_OF_RANGE, "%s: erp = %g, cfm = %g at %g s: too soft to stand for a spring", what,
                    erp, cfm, tuned_step_s);
    *out = ssRowLawOfSpring((ssSpring){stiffness, damping});
    out->tuned_step_s = tuned_step_s;
    out->tuned = (ssSoftness){erp, cfm};
    return SS_OK;
  }
  /* hard: the error is corrected at r = k/c = erp/(h0·(1 - erp)) per second, which stays finite as cfm -> 0 */
  double rate = erp == 1 ? INFINITY : erp / (tuned_step_s * (1.0 - erp));
  *out = (ssRowLaw){
      .spring = {0, 0}, .hard = 1, .hard_rate_per_s = rate, .tuned_step_s = tuned_step_s, .tuned = {erp, cfm}};
  return SS_OK;
}

ssStatus ssCheckLawForEveryStep(const char* what, const ssRowLaw* law) {
  if (law->hard) return SS_OK;
  double k = law->spring.stiffness, c = law->spring.damping;
  /* cfm = 1/(h·k + c) is largest at the shortest step and smallest at the longest */
  if (!(SS_MAX_STEP_S * k + c <= 1.0 / SS_MIN_POSITIVE_CFM) || !(SS_MIN_STEP_S * k + c >= 1.0 / SS_MAX_CFM))
    return ssFail(SS_ERROR_NO_FINITE_MAPPING,
                  "%s: k = %g N/m, c = %g N*s/m: no softness ODE handles at every step from %g s to %g s "
                  "(h*k + c must stay within [1/SS_MAX_CFM, 1/SS_MIN_POSITIVE_CFM] = [%g, %g])",
                  what, k, c, SS_MIN_STEP_S, SS_MAX_STEP_S, 1.0 / SS_MAX_CFM, 1.0 / SS_MIN_POSITIVE_CFM);
  return SS_OK;
}

/* The implicit-Euler mapping of a law (a hard law's one rule): at the law's tuned step, its tuned numbers. */
static ssStatus implicitEuler(const ssRowLaw* law, double step_s, ssSoftness* out) {
  if (step_s == law->tuned_step_s) {
    *out = law->tuned;
    return SS_OK;
  }
  if (law->hard) {
    double rate_h = law->hard_rate_per_s * step_s;
    *out = (ssSoftness){.erp = isinf(rate_h) ? 1.0 : rate_h / (rate_h + 1.0), .cfm = 0};
    return SS_OK;
  }
  return ssSoftnessFromSpring(law->spring, step_s, out);
}

ssStatus ssRowSoftness(const ssRowLaw* law, ssMapping mapping, double mass, double step_s, double previous_step_s,
                       ssRowFallback* fallback, ssSoftness* out) {
  ssRowFallback local;
  if (fallback == NULL) fallback = &local;
  *fallback = (ssRowFallback){0, 0};
  if (law->hard) return implicitEuler(law, step_s, out);
  if (mapping == SS_MAPPING_MATCHED || mapping == SS_MAPPING_EXACT) {
    /* The accurate mappings need a mass, damping (c = 0 puts the poles on the unit circle) and a frequency the
     * step can sample: a near-rigid row above Nyquist has poles that no (erp, cfm) of this step reproduces. */
    int servable = mass > 0 && isfinite(mass) && law->spring.damping > 0 && !ssOverNyquist(law->spring, mass, step_s);
    if (servable) {
      /* A pure damper (k = 0) has no position to correct: its velocity decays by exp(-c·h/m) per step whatever the
       * steps before, which the matched mapping reproduces exactly; the exact mapping's history adds nothing. The
       * law, the mass and the step are valid here, so the matched mapping needs no second check. */
      int matched = mapping == SS_MAPPING_MATCHED || law->spring.stiffness == 0;
      ssStatus status = matched ? ssMatchedSoftnessUnchecked(law->spring, mass, step_s, out)
                                : ssExactSoftness(law->spring, mass, step_s, previous_step_s, out);
      if (status == SS_ERROR_NO_FINITE_MAPPING && !matched) {
        status = ssMatchedSoftnessUnchecked(law->spring, mass, step_s, out);
        fallback->exact_to_matched = status == SS_OK;
      }
      if (status == SS_OK) return SS_OK;
      if (status != SS_ERROR_NO_FINITE_MAPPING) return status;
    }
    fallback->exact_to_matched = 0;
    fallback->to_implicit_euler = 1;
  }
  return implicitEuler(law, step_s, out);
}

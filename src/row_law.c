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
  return ssImplicitEulerSoftness(law->spring, step_s, out);
}

/* When an accurate mapping may serve a row: the rule that keeps matched and exact from losing to implicit Euler.
 *
 * Both accurate mappings spend ODE's two free numbers (erp, cfm) on the poles of one row of effective mass m:
 * the homogeneous motion m x'' + c x' + k x = 0 is reproduced, and nothing else is. What a row carries besides
 * its own spring is not. ODE's row law is f = -(erp/(h·cfm))·x - (1/cfm)·v', so a constant load F along the row
 * rests at x = F/k' with the step's static stiffness
 *     k' = erp/(h·cfm) = m·(1 - z1)(1 - z2)/(h²·z1·z2)   (matched; z = e^(s·h), the poles)
 *        = k·((e^x - 1)² + 2·e^x·(1 - cos √w))/(x² + w)   (x = σh, σ = c/2m; w = q·h², q = k/m - σ²)
 *        ≈ k·(1 + σh)·sinc²(ω·h/2)                        (lightly damped; ω the frequency),
 * while implicit Euler (erp = hk/(hk + c), cfm = 1/(hk + c)) has k' = k exactly, at every step. A load the registry
 * knows (ssRegistry_SetJointLoad) is corrected: the registry adds F·(k'/k - 1) along the row, which moves the rest
 * back to F/k without touching the poles. A load it does not know is the weight a stacked contact carries, the
 * motor pressing a ram into its stop, the chassis on a suspension nobody declared: the row then rests at F/k'
 * where the spring rests at F/k, an error of F/k·|k/k' - 1| in every quantity the row holds up, which no accuracy
 * of the poles repays once the motion has settled (the lab's stack stood 4 mm too high, k'/k about 3).
 *
 * Where k' is far from k, h is not short against the row's own time scales (σh or ω·h of order 1: a contact of a
 * light box under a stiff, strongly damped law, a stop of a ram whose decay takes a fraction of a step), which is
 * also where the isolated row's effective mass describes the motion least: the mode of a box on four contact
 * points, or of a ram between its stop and its motor, is not one row's. So the rule, applied to every row whose
 * load is not declared (contacts, whose load is never known, go further: contact.c):
 *     an accurate softness serves the row only if |k/k' - 1| <= SS_STATIC_RESPONSE_TOLERANCE (5 %),
 *     otherwise implicit Euler serves it (counted in handed_to_implicit_euler);
 * a pure damper (k = 0, motors) likewise with its static damping 1/cfm against c (a load drives it at F·cfm where
 * the damper moves at F/c; matched's 1/cfm = m(e^(ch/m) - 1)/h). The rule keeps rows with σh up to about 0.05
 * and ω·h up to about 0.75 (eight steps a period): where one spring dominates one body at steps short against it
 * (the oscillator: σh = 0.008 at 1/60 s, 0.033 at 1/15 s; a suspension with its load declared) the accurate
 * mappings keep serving; elsewhere the row moves under implicit Euler, as it would without them. */
int ssKeepsStaticResponse(ssSpring spring, ssSoftness softness, double step_s) {
  if (spring.stiffness > 0) {
    double static_stiffness = softness.erp / (step_s * softness.cfm);
    return fabs(spring.stiffness / static_stiffness - 1.0) <= SS_STATIC_RESPONSE_TOLERANCE;
  }
  return ssDamperKeepsStaticResponse(spring.damping, softness.cfm);
}

ssStatus ssRowSoftness(const ssRowLaw* law, ssMapping mapping, double mass, double step_s, double previous_step_s,
                       int load_declared, ssRowFallback* fallback, ssSoftness* out) {
  ssRowFallback local;
  if (fallback == NULL) fallback = &local;
  *fallback = (ssRowFallback){0, 0};
  if (law->hard) return implicitEuler(law, step_s, out);
  if (mapping == SS_MAPPING_MATCHED || mapping == SS_MAPPING_EXACT) {
    /* The accurate mappings need a mass, damping (c = 0 puts the poles on the unit circle) and a frequency the
     * step can sample: a near-rigid row above Nyquist has poles that no (erp, cfm) of this step reproduces. */
    int servable = mass > 0 && isfinite(mass) && law->spring.damping > 0 && !ssOverNyquist(law->spring, mass, step_s);
    /* The matched softness first: it is the rule's measure (the static response of steady steps, which exact
     * equals at h = h_p; exact's own varies with h/h_p around it, and a row that changed mappings with h/h_p would
     * lose the history exact needs) and exact's fallback. The law, the mass and the step are valid here, so it
     * needs no second check. A declared load is corrected by the caller (pure dampers get no correction). */
    ssSoftness matched;
    ssStatus status = servable ? ssMatchedSoftnessUnchecked(law->spring, mass, step_s, &matched)
                               : SS_ERROR_NO_FINITE_MAPPING;
    int load_corrected = load_declared && law->spring.stiffness > 0;
    if (status == SS_OK && (load_corrected || ssKeepsStaticResponse(law->spring, matched, step_s))) {
      /* A pure damper (k = 0) has no position to correct: its velocity decays by exp(-c·h/m) per step whatever
       * the steps before, which the matched mapping reproduces exactly; the exact mapping's history adds nothing. */
      if (mapping == SS_MAPPING_MATCHED || law->spring.stiffness == 0) {
        *out = matched;
        return SS_OK;
      }
      status = ssExactSoftnessQuiet(law->spring, mass, step_s, previous_step_s, out);
      if (status == SS_OK) return SS_OK;
      if (status != SS_ERROR_NO_FINITE_MAPPING) return status;
      *out = matched;
      fallback->exact_to_matched = 1;
      return SS_OK;
    }
    if (status != SS_OK && status != SS_ERROR_NO_FINITE_MAPPING) return status;
    fallback->exact_to_matched = 0;
    fallback->to_implicit_euler = 1;
  }
  return implicitEuler(law, step_s, out);
}

/* Whether k'/k = g(x) = N/(r·x) > limit on every x of [from, to] along the under-damped part of the ray (0 < from,
 * to <= r, w = x·(r - x) in [0, π²]). With N = (e^x - 1)² + 4·e^x·sin²(√w/2),
 *     g = (e^x - 1)²/(r·x) + 4·e^x·S(w)·(r - x)/r,   S(w) = sin²(√w/2)/w,
 * whose first term grows with x and whose S falls as w grows (sinc² up to √w = 2π): on an interval g is at least
 * the first term at its left end plus e^x there times S at the interval's largest w (w is concave in x, largest at
 * r/2) times (r - x)/r at its right end. Intervals that do not decide are halved (geometrically: g moves with the
 * ratio of the ends), to depth levels. */
static int stifferOnRay(double from, double to, double r, double limit, int depth) {
  double w = r / 2 >= from && r / 2 <= to ? r * r / 4 : fmax(from * (r - from), to * (r - to));
  double s = sin(0.5 * sqrt(w));
  double sinc2 = w > 1e-12 ? s * s / w : 0.25 - w / 48.0; /* below S(w) = 1/4 - w/48 + w²/1440 - ... */
  double e = expm1(from);
  if (e * e / (r * from) + 4.0 * (1.0 + e) * sinc2 * (r - to) / r > limit) return 1;
  if (depth == 0) return 0;
  double middle = sqrt(from * to);
  return stifferOnRay(from, middle, r, limit, depth - 1) && stifferOnRay(middle, to, r, limit, depth - 1);
}

int ssSurelyFailsUpToMass(ssSpring spring, double mass_bound, double step_s) {
  const double k = spring.stiffness, c = spring.damping, h = step_s;
  if (mass_bound == 0 || c == 0) return 1;
  if (!(k >= 0 && k <= 1e150 && c >= 1e-150 && c <= 1e150 && mass_bound >= 1e-150 && mass_bound <= 1e150 &&
        h >= SS_MIN_STEP_S && h <= SS_MAX_STEP_S))
    return 0;
  const double x0 = 0.5 * c * h / mass_bound; /* the least x: at the largest mass */
  if (k == 0) return x0 >= 0.06;                /* ssSurelyFailsStaticResponse's damper bound */
  if (ssOverNyquist(spring, mass_bound, h)) return 1; /* and every lighter mass is (the comparison is monotone) */
  /* the matched softness loses up to about 1e-15/r of its digits to cancellation where over-damped (matched.c):
   * far below the margin for r >= 1e-3 */
  const double r = 2.0 * k * h / c, margin = 1e-6;
  if (!(r >= 1e-3)) return 0;
  const double limit = (1.0 + margin) / (1.0 - SS_STATIC_RESPONSE_TOLERANCE); /* k'/k above it fails the rule */
  const double nyquist_x = 9.869604401089358 / r * (1.0 + 1e-9); /* D = π², where the masses stop being served */
  /* over-damped, x > r: N = (e^a - 1)(e^b - 1) with a, b = x ± √(x² - D), so N >= a·b·(1 + a/2)(1 + b/2) >= D·(1 + x) */
  if (nyquist_x > r && !(1.0 + fmax(x0, r) > limit)) return 0;
  const double top = fmin(r, nyquist_x);
  return x0 >= top || stifferOnRay(x0, top, r, limit, 6);
}

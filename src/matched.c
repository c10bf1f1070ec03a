/* The matched and exact mappings (derivation: docs/exact-mappings.md).
 *
 * For one row of effective mass m, ODE's step with softness (erp, cfm) and a = cfm·m/h is
 *     v' = (a·v - (erp/h)·x) / (1 + a),   x' = x + h·v'.
 * The continuous spring m x'' + c x' + k x = 0 moves its state over a time t by
 *     x(t) = e^(-σt)·(C(t) + σ·S(t))·x0 + e^(-σt)·S(t)·v0,   σ = c/2m, q = k/m - σ²,
 * with C = cos(√q t), S = sin(√q t)/√q when q > 0 (cosh and sinh of √-q t when q < 0, 1 and t when q = 0).
 *  - matched: with v = (x_n - x_(n-1))/h, ODE's x obeys x_(n+1) = (1 + (a - erp)/(1+a))·x_n - a/(1+a)·x_(n-1).
 *    Equating the sum and the product of its roots with those of the exact poles, S_z = 2e^(-σh)C(h) and
 *    P_z = e^(-2σh), gives a = P_z/(1 - P_z) and erp = (1 + P_z - S_z)/(1 - P_z).
 *  - exact: v = (x_n - x_(n-1))/h_p and the exact solution gives x_(n+1) = α·x_n + β·x_(n-1) with
 *    α = e^(-σh)·(C(h) + S(h)·C(h_p)/S(h_p)) and β = -e^(-σ(h+h_p))·S(h)/S(h_p). With ρ = h/h_p, ODE's step gives
 *    x_(n+1) = (1 + (aρ - erp)/(1+a))·x_n - aρ/(1+a)·x_(n-1), so a = -β/(ρ + β), erp = aρ - (α - 1)(1 + a).
 *    Without history (h_p = 0) the step maps the true (x0, v0): a/(1+a) = e^(-σh)S(h)/h, erp = (1 - φ11)(1 + a). */
#include <math.h>
#include <stddef.h>

#include "error.h"
#include "ode_bounds.h"
#include "matched_internal.h"
#include "steadystep/spring.h"

/* e^(-σt)·C(t) and e^(-σt)·S(t), and C(t)/S(t), computed without overflow for strongly over-damped springs and
 * by series near critical damping, where √q·t is tiny and the closed forms lose their digits. */
typedef struct Propagator {
  double decayed_c; /* e^(-σt)·C(t) */
  double decayed_s; /* e^(-σt)·S(t), s */
  double c_over_s;  /* C(t)/S(t), 1/s */
} Propagator;

static Propagator propagate(double sigma, double q, double t) {
  double qt2 = q * t * t;
  double decay = exp(-sigma * t);
  if (fabs(qt2) < 1e-6) {
    double c = 1.0 - qt2 / 2.0 + qt2 * qt2 / 24.0;
    double s = t * (1.0 - qt2 / 6.0 + qt2 * qt2 / 120.0);
    return (Propagator){decay * c, decay * s, c / s};
  }
  if (q > 0) {
    double w = sqrt(q);
    double sine = sin(w * t), cosine = cos(w * t); /* one sincos */
    return (Propagator){decay * cosine, decay * sine / w, w * cosine / sine};
  }
  double mu = sqrt(-q);
  double slow = exp((mu - sigma) * t), fast = exp(-(mu + sigma) * t);
  return (Propagator){0.5 * (slow + fast), (slow - fast) / (2.0 * mu), mu * (slow + fast) / (slow - fast)};
}

static ssStatus validate(ssSpring spring, double mass, double step_s, const ssSoftness* out) {
  if (out == NULL) return ssFail(SS_ERROR_OUT_OF_RANGE, "out = NULL: the mapping needs somewhere to write");
  ssStatus status = ssValidateSpring(spring);
  if (status == SS_OK) status = ssCheckPositive("mass", "kg", mass);
  if (status == SS_OK) status = ssCheckStepLength("step_s", step_s);
  if (status != SS_OK) return status;
  if (spring.damping == 0)
    return ssFail(SS_ERROR_NO_FINITE_MAPPING,
                  "c = 0 N*s/m: an undamped spring has no finite matched softness (cfm would be infinite)");
  return SS_OK;
}

/* Every exit with a result passes here: NaN, infinities and values beyond ODE's range (limits.h) from any
 * intermediate overflow or underflow end as a refusal, never as output. quiet: refused without a message, for the
 * registry's rows, which a refusal hands on to another mapping at every step (formatting the message would cost
 * more than the mapping). */
static ssStatus finish(double a, double erp, double step_s, double mass, int quiet, ssSoftness* out) {
  double cfm = a * step_s / mass;
  if (isfinite(erp) && isfinite(cfm) && cfm >= SS_MIN_POSITIVE_CFM && cfm <= SS_MAX_CFM && fabs(erp) <= SS_MAX_ERP) {
    *out = (ssSoftness){.erp = erp, .cfm = cfm};
    return SS_OK;
  }
  if (quiet) return SS_ERROR_NO_FINITE_MAPPING;
  return ssFail(SS_ERROR_NO_FINITE_MAPPING,
                "step_s = %g s gives erp = %g, cfm = %g: not a usable softness (finite, |erp| <= %g, %g <= cfm <= %g)",
                step_s, erp, cfm, SS_MAX_ERP, SS_MIN_POSITIVE_CFM, SS_MAX_CFM);
}

/* With d = e^(-σh), P = d², the numerator of erp, 1 + P - 2·d·C(h), is written as (1 - d)² + 2·d·(1 - C(h)): both
 * terms are computed without cancellation, so erp keeps its digits at short steps (where it is O(h²)·k/c and the
 * closed form subtracts numbers near 1), and 1 - P = (1 - d)(1 + d) needs no second exponential. */
static ssStatus matchedSoftness(ssSpring spring, double mass, double step_s, int quiet, ssSoftness* out) {
  if (spring.stiffness == 0 && ssMatchedDamper(spring.damping, mass, step_s, out)) return SS_OK;
  double sigma = spring.damping / (2.0 * mass);
  double sigma_h = sigma * step_s;
  double one_minus_d = -expm1(-sigma_h);
  double d = sigma_h < 0.5 ? 1.0 - one_minus_d : exp(-sigma_h);
  double one_minus_product = one_minus_d * (1.0 + d);
  double product = d * d;
  double twice_d_one_minus_c; /* 2·d·(1 - C(h)) */
  if (spring.stiffness == 0) {
    twice_d_one_minus_c = -one_minus_d * one_minus_d; /* a damper's poles are 1 and P: erp is 0 */
  } else {
    double q = spring.stiffness / mass - sigma * sigma;
    double half_angle = 0.5 * sqrt(fabs(q)) * step_s;
    if (fabs(q) * step_s * step_s < 1e-6) {
      double qh2 = q * step_s * step_s;
      twice_d_one_minus_c = d * (qh2 - qh2 * qh2 / 12.0);
    } else if (q > 0) {
      double s = sin(half_angle);
      twice_d_one_minus_c = 4.0 * d * s * s;
    } else if (half_angle < 0.5) {
      double s = sinh(half_angle);
      twice_d_one_minus_c = -4.0 * d * s * s;
    } else { /* 2d - d(e^(μh) + e^(-μh)), in exponents that cannot overflow for a strongly over-damped spring */
      double mu_h = 2.0 * half_angle;
      twice_d_one_minus_c = 2.0 * d - exp(mu_h - sigma_h) - exp(-mu_h - sigma_h);
    }
  }
  double a = product / one_minus_product;
  double erp = (one_minus_d * one_minus_d + twice_d_one_minus_c) / one_minus_product;
  return finish(a, erp, step_s, mass, quiet, out);
}

ssStatus ssMatchedSoftnessUnchecked(ssSpring spring, double mass, double step_s, ssSoftness* out) {
  return matchedSoftness(spring, mass, step_s, 1, out);
}

ssStatus ssMatchedSoftness(ssSpring spring, double mass, double step_s, ssSoftness* out) {
  ssStatus status = validate(spring, mass, step_s, out);
  if (status != SS_OK) return status;
  return matchedSoftness(spring, mass, step_s, 0, out);
}

static ssStatus exactSoftness(ssSpring spring, double mass, double step_s, double previous_step_s, int quiet,
                              ssSoftness* out) {
  ssStatus status = validate(spring, mass, step_s, out);
  if (status == SS_OK) status = ssCheckNonNegative("previous_step_s", "s", previous_step_s);
  if (status == SS_OK && previous_step_s != 0) status = ssCheckStepLength("previous_step_s", previous_step_s);
  if (status != SS_OK) return status;
  double sigma = spring.damping / (2.0 * mass);
  double q = spring.stiffness / mass - sigma * sigma;
  Propagator now = propagate(sigma, q, step_s);
  if (previous_step_s == 0) {
    double gain = now.decayed_s / step_s; /* a/(1+a) */
    double a = gain / (1.0 - gain);
    double x_gain = now.decayed_c + sigma * now.decayed_s; /* φ11 */
    return finish(a, (1.0 - x_gain) * (1.0 + a), step_s, mass, quiet, out);
  }
  Propagator before = propagate(sigma, q, previous_step_s);
  /* e^(-σ h_p)/S(h_p) = e^(-2σ h_p)/decayed_s(h_p); decayed_s(h_p) = 0 (h_p at a half period) has no history. */
  double alpha = now.decayed_c + now.decayed_s * before.c_over_s;
  double beta = -now.decayed_s * exp(-2.0 * sigma * previous_step_s) / before.decayed_s;
  double ratio = step_s / previous_step_s;
  if (!(ratio + beta > 0 && beta < 0)) {
    if (quiet) return SS_ERROR_NO_FINITE_MAPPING;
    return ssFail(SS_ERROR_NO_FINITE_MAPPING,
                  "step_s = %g s after previous_step_s = %g s: the exact step would need cfm <= 0", step_s,
                  previous_step_s);
  }
  double a = -beta / (ratio + beta);
  return finish(a, a * ratio - (alpha - 1.0) * (1.0 + a), step_s, mass, quiet, out);
}

ssStatus ssExactSoftness(ssSpring spring, double mass, double step_s, double previous_step_s, ssSoftness* out) {
  return exactSoftness(spring, mass, step_s, previous_step_s, 0, out);
}

ssStatus ssExactSoftnessQuiet(ssSpring spring, double mass, double step_s, double previous_step_s, ssSoftness* out) {
  return exactSoftness(spring, mass, step_s, previous_step_s, 1, out);
}

/* steadystep: springs and softness, the pure math (no ODE types).
 *
 * A soft constraint row is a spring-damper: stiffness k and damping c. ODE wants it as ERP and CFM for the length h
 * of each step. These functions convert between the two and are usable by any engine with ODE's ERP/CFM
 * definitions (Bullet's contacts use the same ones). Units are SI; for an angular row read N·m/rad for N/m,
 * N·m·s/rad for N·s/m and kg·m² for kg.
 *
 * Three mappings from a spring to softness at step h:
 *  - SS_MAPPING_IMPLICIT_EULER, the article's: erp = hk/(hk+c), cfm = 1/(hk+c). ODE's step then solves exactly the
 *    implicit-Euler step of the spring, m(v'-v)/h = -k(x + h v') - c v', x' = x + h v', at any h: consistent
 *    stiffness and damping at every frame rate. Implicit Euler adds numerical damping of about h·k/2 per unit mass.
 *  - SS_MAPPING_MATCHED: for a row of effective mass m, the erp and cfm whose discrete poles equal exp(s·h) of the
 *    exact poles s of m x'' + c x' + k x = 0. At a constant h the sampled motion decays and oscillates exactly as
 *    the continuous spring does. erp is often above 1 (ODE accepts that). Needs c > 0.
 *  - SS_MAPPING_EXACT: like matched, and also uses the previous step length, because the velocity ODE carries into
 *    a step is the slope (x_n - x_(n-1))/h_prev over the previous step. The sampled motion of a lone linear
 *    spring-damper then equals the exact solution under any sequence of step lengths. See docs/exact-mappings.md.
 */
#ifndef STEADYSTEP_SPRING_H
#define STEADYSTEP_SPRING_H

#include "steadystep/export.h"
#include "steadystep/limits.h"
#include "steadystep/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A spring-damper. */
typedef struct ssSpring {
  double stiffness; /* k, N/m (N·m/rad for angular rows), >= 0 */
  double damping;   /* c, N·s/m (N·m·s/rad for angular rows), >= 0; k and c not both 0 */
} ssSpring;

/** ODE's softness of one constraint row for one step. */
typedef struct ssSoftness {
  double erp; /* error reduction parameter, non-dimensional; [0, 1] for the implicit-Euler mapping, may exceed 1 for the
               * others; |erp| <= SS_MAX_ERP (limits.h) */
  double cfm; /* constraint force mixing, m/(N·s) for a linear row (what ODE multiplies the force by),
               * in (0, SS_MAX_CFM] */
} ssSoftness;

/** How a spring becomes softness at a step. */
typedef enum ssMapping {
  SS_MAPPING_IMPLICIT_EULER = 0,  /* the article's mapping: implicit Euler of the spring */
  SS_MAPPING_MATCHED = 1, /* exact poles at a constant step; needs the row's effective mass and c > 0 */
  SS_MAPPING_EXACT = 2,   /* exact samples under varying steps; also needs the previous step length */
} ssMapping;

/** The article's mapping: erp = hk/(hk+c), cfm = 1/(hk+c) at step length step_s (s, in [SS_MIN_STEP_S,
 *  SS_MAX_STEP_S], limits.h). On success erp is in [0, 1] and cfm in (0, SS_MAX_CFM].
 *  Errors (out untouched): SS_ERROR_NOT_FINITE, SS_ERROR_OUT_OF_RANGE (k < 0, c < 0, step_s outside its range,
 *  out = NULL), SS_ERROR_NO_SPRING (k = c = 0), SS_ERROR_NO_FINITE_MAPPING (h·k + c overflows, or is below
 *  1/SS_MAX_CFM so that cfm would exceed SS_MAX_CFM). */
SS_API ssStatus ssImplicitEulerSoftness(ssSpring spring, double step_s, ssSoftness* out);

/** The inverse: the spring that erp, cfm tuned at a fixed step step_s stand for: k = erp/(h·cfm), c = (1-erp)/cfm.
 *  erp in [0, 1] (0 is a pure damper: k = 0, c = 1/cfm), cfm in (0, SS_MAX_CFM], step_s in [SS_MIN_STEP_S,
 *  SS_MAX_STEP_S]. On success k and c are finite, not both 0, and ssImplicitEulerSoftness(result, step_s) gives
 *  erp, cfm back.
 *  Errors (out untouched): SS_ERROR_NOT_FINITE, SS_ERROR_OUT_OF_RANGE (erp, cfm or step_s outside those ranges,
 *  out = NULL), SS_ERROR_NO_FINITE_MAPPING (extreme values whose k or c over- or underflows). */
SS_API ssStatus ssSpringFromSoftness(ssSoftness softness, double step_s, ssSpring* out);

/** A spring from its undamped natural frequency (Hz, > 0), damping ratio (>= 0, finite, 1 = critical) and the
 *  effective mass it moves (kg or kg·m², > 0): k = m·w², c = 2·zeta·m·w with w = 2π·f, as Jolt's SpringSettings
 *  does. On success k is a finite normal number and c is 0 exactly when zeta is.
 *  Errors (out untouched): SS_ERROR_NOT_FINITE, SS_ERROR_OUT_OF_RANGE (a value <= 0 or < 0, out = NULL),
 *  SS_ERROR_NO_FINITE_MAPPING (k or c over- or underflows, e.g. frequency_hz = 1e200). */
SS_API ssStatus ssSpringFromFrequency(double frequency_hz, double damping_ratio, double mass, ssSpring* out);

/** The undamped natural frequency (Hz) and damping ratio of a spring with k > 0 acting on mass (kg, > 0). On
 *  success both are finite and the frequency is > 0.
 *  Errors (outputs untouched): SS_ERROR_NOT_FINITE, SS_ERROR_OUT_OF_RANGE (mass <= 0, a NULL output),
 *  SS_ERROR_NO_SPRING, SS_ERROR_NO_FINITE_MAPPING (a pure damper, k = 0: no natural frequency and an infinite
 *  damping ratio; or a frequency or ratio that over- or underflows). */
SS_API ssStatus ssFrequencyFromSpring(ssSpring spring, double mass, double* frequency_hz, double* damping_ratio);

/** The matched mapping for a row of effective mass `mass` (kg or kg·m², > 0) at step_s. With the discrete poles
 *  z1, z2 = exp(s1·h), exp(s2·h): P = z1·z2 = exp(-c·h/m), S = z1 + z2, erp = (1 + P - S)/(1 - P),
 *  cfm = h·P/(m·(1 - P)). Under-, critically and over-damped springs are all handled.
 *  On success erp and cfm are finite, |erp| <= SS_MAX_ERP and 0 < cfm <= SS_MAX_CFM (limits.h).
 *  Errors (out untouched): as ssImplicitEulerSoftness, SS_ERROR_OUT_OF_RANGE for mass <= 0,
 *  SS_ERROR_NO_FINITE_MAPPING for c = 0 (an undamped spring has poles on the unit circle: cfm would be infinite)
 *  and for springs whose erp or cfm falls outside that range at this step. */
SS_API ssStatus ssMatchedSoftness(ssSpring spring, double mass, double step_s, ssSoftness* out);

/** The exact mapping: erp, cfm such that ODE's step from x_(n-1), x_n (previous step previous_step_s) lands on the
 *  exact solution's sample x_(n+1) after step_s. previous_step_s = 0 means there is no usable history (the first
 *  step, or after a teleport): then the step maps the body's true velocity exactly.
 *  Errors (out untouched): as ssMatchedSoftness; SS_ERROR_OUT_OF_RANGE for previous_step_s neither 0 nor in
 *  [SS_MIN_STEP_S, SS_MAX_STEP_S];
 *  SS_ERROR_NO_FINITE_MAPPING when this pair of step lengths would need cfm <= 0 (a much shorter step after a
 *  long one on a lightly damped spring): the caller may fall back to the matched mapping for that step. */
SS_API ssStatus ssExactSoftness(ssSpring spring, double mass, double step_s, double previous_step_s, ssSoftness* out);

/** One entry point for all mappings: mass is ignored by SS_MAPPING_IMPLICIT_EULER, previous_step_s by all but EXACT.
 *  Errors (out untouched): those of the chosen mapping, SS_ERROR_UNSUPPORTED for an unknown mapping value,
 *  SS_ERROR_OUT_OF_RANGE for out = NULL. */
SS_API ssStatus ssSoftnessFor(ssMapping mapping, ssSpring spring, double mass, double step_s, double previous_step_s,
                              ssSoftness* out);

/** The mapping's name: "implicit-euler", "matched", "exact"; NULL for an unknown value. */
SS_API const char* ssMappingName(ssMapping mapping);

/** Checks a spring: finite, k >= 0, c >= 0, not both 0. Errors as ssImplicitEulerSoftness. */
SS_API ssStatus ssValidateSpring(ssSpring spring);

#ifdef __cplusplus
}
#endif

#endif

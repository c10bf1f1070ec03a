/* Internal: what a soft row stands for, independently of the step: a spring, or a hard row whose error is corrected
 * at a rate per second. The registry, adoption and contacts share it, so the fallback rule of the accurate
 * mappings is written once. */
#ifndef STEADYSTEP_ROW_LAW_H
#define STEADYSTEP_ROW_LAW_H

#include <math.h>

#include "steadystep/spring.h"

typedef struct ssRowLaw {
  ssSpring spring;        /* when !hard */
  int hard;               /* tuned with cfm = 0: kept at cfm = 0 at every step */
  double hard_rate_per_s; /* hard rows: erp(h) = h·r/(h·r + 1); INFINITY keeps erp = 1 */
  /* > 0: the law was read from `tuned`, the erp/cfm a program set for steps of this length (s). The implicit-Euler
   * mapping at that very step gives them back as they were: in exact arithmetic it is the same numbers, but the
   * round trip through k and c moves them by a rounding, and a program adopted under naive must step bit for bit
   * as its own stepping. 0: a spring bound as such. */
  double tuned_step_s;
  ssSoftness tuned;
} ssRowLaw;

/* How a row's softness for one step was obtained, beyond the mapping asked for. */
typedef struct ssRowFallback {
  /* flags of one byte each: the registry keeps one of these in every binding's hot cache line */
  unsigned char exact_to_matched;  /* SS_MAPPING_EXACT had no finite softness for this pair of steps: matched used */
  unsigned char to_implicit_euler; /* an accurate mapping could not serve the row: the implicit-Euler mapping used */
} ssRowFallback;

/* A spring's law (the spring is not checked here: bind time does). */
ssRowLaw ssRowLawOfSpring(ssSpring spring);

/* What erp and cfm tuned at a fixed step tuned_step_s stand for: a spring (cfm > 0, erp in [0, 1]; erp = 0 is a
 * pure damper) or a hard row (cfm = 0), remembering erp and cfm themselves for that step. what names the row in
 * messages ("world", "hinge joint 0x.. stop axis 1").
 * Errors: SS_ERROR_NOT_FINITE, SS_ERROR_OUT_OF_RANGE (erp outside [0, 1], cfm < 0). */
ssStatus ssRowLawFromTuned(const char* what, double erp, double cfm, double tuned_step_s, ssRowLaw* out);

/* Whether the implicit-Euler mapping gives the law a softness ODE handles at every step length the library takes
 * ([SS_MIN_STEP_S, SS_MAX_STEP_S]): cfm = 1/(h·k + c) at least SS_MIN_POSITIVE_CFM at the longest step and
 * within SS_MAX_CFM at the shortest. Since every accurate mapping falls back to implicit Euler, a law that passes
 * can always be written, so Apply never fails in the middle of a frame. Hard laws pass. what names the row in the
 * message. Errors: SS_ERROR_NO_FINITE_MAPPING. */
ssStatus ssCheckLawForEveryStep(const char* what, const ssRowLaw* law);

/* The softness of the row for a step of step_s under mapping: for a tuned law at its tuned step under implicit Euler
 * (or a hard law, whose rule is the same under every mapping), the tuned erp/cfm themselves. mass (kg or kg·m²) is
 * read by the accurate mappings only; pass NAN when the row has none. load_declared: the program declared the
 * steady load the row carries (ssRegistry_SetJointLoad), and the caller adds the force that puts its rest back at
 * load/k. Where MATCHED or EXACT cannot serve the row the implicit-Euler mapping serves it and
 * fallback->to_implicit_euler says so: no mass, c = 0, natural frequency above the step's Nyquist frequency, no
 * finite softness, or (the rule of ssKeepsStaticResponse) a static response so far from the law's that an
 * undeclared load would rest elsewhere than under the spring. fallback may be NULL. Errors: those of
 * ssImplicitEulerSoftness. */
ssStatus ssRowSoftness(const ssRowLaw* law, ssMapping mapping, double mass, double step_s, double previous_step_s,
                       int load_declared, ssRowFallback* fallback, ssSoftness* out);

/* How far (relative) an accurate softness' static response may be from the spring's for the row to be served
 * with an undeclared load: the rest position is then within this fraction of the sag F/k that implicit Euler gives
 * exactly. Issue 15's tolerance (1.05 times implicit Euler's deviation) on the part of the motion a load sets. */
#define SS_STATIC_RESPONSE_TOLERANCE 0.05

/* Whether the softness, written for a step of step_s, responds to a constant load as the spring does, within
 * SS_STATIC_RESPONSE_TOLERANCE: the static stiffness k' = erp/(h·cfm) of ODE's step against k (a load F rests at
 * F/k' instead of F/k), or for a pure damper (k = 0) its static damping 1/cfm against c (a load drives it at F·cfm
 * instead of F/c). The implicit-Euler mapping keeps both exactly (k' = k, 1/cfm = h·k + c). */
int ssKeepsStaticResponse(ssSpring spring, ssSoftness softness, double step_s);

/* ssKeepsStaticResponse for a pure damper (k = 0) of damping c (N·s/m): its static damping 1/cfm against c. Inline:
 * Apply asks it of every motor row an accurate mapping serves. */
static inline int ssDamperKeepsStaticResponse(double damping, double cfm) {
  return fabs(damping * cfm - 1.0) <= SS_STATIC_RESPONSE_TOLERANCE;
}

/* Whether ssRowSoftness would hand the row to implicit Euler under an accurate mapping for its static response
 * alone, decided without the matched softness' arithmetic (no exp, sqrt or sin): 1 only when the matched
 * softness of (spring, mass, step_s), if it is finite, certainly fails ssKeepsStaticResponse, by bounds on the exact
 * value of its static stiffness (or a damper's static damping) that are a million times wider than the roundings
 * of computing it. 0 (undecided) outside the ranges the bounds are derived for (over-damped springs, σh > 1,
 * ω·h > 2, extreme values), and near the tolerance. A row that falls back has the implicit-Euler softness whatever
 * the reason, so where this says 1 the row's softness and fallback are those ssRowSoftness gives (for a row whose
 * load is not declared: a declared load keeps the accurate softness). Inline: Apply asks it of every unloaded row
 * at every step of an accurate mapping. */
static inline int ssSurelyFailsStaticResponse(ssSpring spring, double mass, double step_s) {
  /* In x = σh = c·h/2m and w = q·h² (q = k/m - σ², so x² + w = D = k·h²/m), the matched static stiffness is
   *     k'/k = g = ((e^x - 1)² + 2·e^x·(1 - cos √w)) / D      (row_law.c: the derivation)
   * and the row is kept iff 1/(1 + tol) <= g <= 1/(1 - tol). For 0 < x <= 1 and 0 <= w <= 4, e^x - 1 lies between
   * its Taylor sum to x⁵ and that plus x⁶/240 (Lagrange: e^ξ/720 < 1/240), and 1 - cos √w between its alternating
   * series' sums to w³ (above) and to w⁴ (below, still positive); the numerator grows with both. */
  const double k = spring.stiffness, c = spring.damping;
  if (!(k <= 1e150 && c >= 1e-150 && c <= 1e150 && mass >= 1e-150 && mass <= 1e150)) return 0;
  double h_over_m = step_s / mass, x = 0.5 * c * h_over_m; /* within roundings of the mapping's: the margin's */
  /* a damper (k = 0): matched's static damping is c·cfm = 2x/(e^(2x) - 1), below 1 - tol from x = 0.0513 on and
   * decreasing (0.9412 at x = 0.06): the motor rows of a program tuned at ODE's CFM 1e-10 are far beyond */
  if (k == 0) return x >= 0.06;
  if (!(k >= 1e-150)) return 0;
  double kh2_over_m = k * h_over_m * step_s;
  double w = kh2_over_m - x * x;
  if (!(x >= 1e-8 && x <= 1.0 && w >= 0.0 && w <= 4.0)) return 0;
  double x2 = x * x;
  const double margin = 1e-6; /* against this function's roundings and those of the softness and its check */
  const double upper = kh2_over_m * ((1.0 + margin) / (1.0 - SS_STATIC_RESPONSE_TOLERANCE));
  /* first a cruder lower bound of the numerator, which decides most rows the rule hands on (far too stiff: the
   * static stiffness grows as 1 + σh) in a third of the arithmetic: (e^x - 1)² >= (x + x²/2)² >= x² + x³,
   * e^x >= 1 + x, 1 - cos √w >= w/2 - w²/24 >= 0 (w <= 4). It is a lower bound as n_low is (and at most n_low):
   * a 1 here has the same guarantee, and is a row the full bounds below would hand on too. */
  if (x2 + x2 * x + (1.0 + x) * (w - w * w * (1.0 / 12.0)) > upper) return 1;
  double e_low = x * (1.0 + x * (0.5 + x * (1.0 / 6.0 + x * (1.0 / 24.0 + x * (1.0 / 120.0)))));
  double e_high = e_low + x2 * x2 * x2 * (1.0 / 240.0);
  double c_high = w * (0.5 - w * (1.0 / 24.0 - w * (1.0 / 720.0)));
  double c_low = c_high - w * w * w * w * (1.0 / 40320.0);
  double n_low = e_low * e_low + 2.0 * (1.0 + e_low) * c_low;
  double n_high = e_high * e_high + 2.0 * (1.0 + e_high) * c_high;
  return n_high < kh2_over_m * ((1.0 - margin) / (1.0 + SS_STATIC_RESPONSE_TOLERANCE)) || n_low > upper;
}

/* Whether ssRowSoftness hands the row to implicit Euler under an accurate mapping (load not declared) at every mass
 * in (0, mass_bound] (kg or kg·m²), for every row of a law at once: no row's mass is then measured. 1 for c = 0
 * (never servable) and for mass_bound 0 (no row with a mass); 0 (undecided) for a NAN bound, outside the ranges
 * below, and where some mass may be served. Masses below k·h²/π² are above Nyquist; above it, along the ray that
 * the masses trace in the rule's coordinates (x = c·h/2m, D = k·h²/m = r·x with r = 2k·h/c), the static stiffness
 * k'/k = N/D is bounded below: by 1 + x where the spring is over-damped (x > r), and on the under-damped part by
 * intervals of x, each with N's least value there (row_law.c). A damper is handed on from x = 0.06 up, as in
 * ssSurelyFailsStaticResponse, and x only grows as the mass falls. */
int ssSurelyFailsUpToMass(ssSpring spring, double mass_bound, double step_s);

/* w·h > π, i.e. k·h² > π²·m: the spring's natural frequency is above half the step rate. False for a NAN
 * mass. Inline: the registry asks it of every row at every Apply. */
static inline int ssOverNyquist(ssSpring spring, double mass, double step_s) {
  return spring.stiffness * step_s * step_s > 9.869604401089358 * mass; /* π² */
}

#endif

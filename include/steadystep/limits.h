/* steadystep: the ranges of values the library hands to ODE. (The lab's bounds on its profiles and runs are in
 * lab/include/steadystep/lab/profile.h and scene.h.)
 *
 * ODE has no error return for a bad number. Debian's libode8 2:0.16.2 (double precision, built with its internal
 * checks on) aborts the process (SIGABRT in `dxNormalize4` or `dMassCheck`) when a value overflows inside a step;
 * an ODE built with CMake in Release (dNODEBUG), as scripts/ode-single.sh builds 0.16.2 in single precision, has
 * those checks compiled out and goes non-finite instead. The library is the boundary: every step length, ERP, CFM,
 * mass and force it hands ODE lies in the ranges below, for the precision of the dReal it is built with, and
 * anything outside them is refused by name (SS_ERROR_OUT_OF_RANGE or SS_ERROR_NOT_FINITE) before ODE is touched.
 * The conversions themselves run in double; what is written into ODE is rounded once to dReal.
 *
 * How the ranges were found. ODE's step (ode/src/step.cpp, quickstep.cpp) divides by the step length h twice:
 * a row's right-hand side is (erp/h)·error scaled by 1/h, its diagonal gets cfm/h, and the integrator multiplies
 * velocities by h. So the numbers that overflow are erp·error/h², cfm/h and h·(speed, force/mass), and products of
 * a mass with a squared displacement. tests/c/ode_probe.c steps a small real world (a slider stop, a ball joint on
 * the world's ERP/CFM and a soft contact on three bodies, gravity, both solvers) in a child process and reports
 * whether it aborted or went non-finite. Each edge below was found with the other values at their bounds or,
 * where said, nominal (h = 1/60 s, erp 0.2, cfm 1e-5, 1 kg), 10 steps from near rest. tests/c/test_limits.cpp
 * runs the probe at every corner of the ranges of the build's precision (both solvers; h, erp, cfm and mass at
 * their bounds) and checks that ODE neither aborts nor loses finiteness: 10 steps from near rest, stopping as the
 * stepper does once a body is faster than SS_MAX_SAFE_SPEED (a runaway row, e.g. erp = 1e9 with cfm 0, grows by
 * about |erp| a step), and one step from SS_MAX_SAFE_SPEED with SS_MAX_FORCE_N on every body; and that ODE does
 * fail at h = 1e-200 s and at 1e300 kg, so the probe can fail.
 *
 * Double precision (Debian's libode8):
 *   step length   aborts at h <= 1e-156 s (nominal) and at h >= 1e100 s; finite from 1e-155 s to 1e50 s.
 *   cfm           aborts when cfm/h overflows (cfm = 1e300 at h = 1e-9 s; cfm = 1e307 at h = 1/60 s); dWorldStep
 *                 prints "LCP internal error" from there on. 0 (a hard row) and 1e-300 are handled.
 *   erp           aborts from 1e50 (the error grows by about erp per step, 10 steps overflow); -1e10 to 1e10
 *                 survive 10 steps. Neither solver needs erp <= 1.
 *   mass          aborts at 1e-320 kg (a denormal: its inverse is infinite) and from 1e140 to 1e160 kg depending
 *                 on h; finite from 1e-300 kg to 1e100 kg (inertia scaled alike).
 *   speed, force  one step from speeds of 1e80 is finite at all 64 corners; from 1e90, 16 of them abort.
 *   The bounds sit many orders of magnitude inside those edges, at values no physical program needs to pass, so
 *   that products with a state that has not (yet) blown up stay finite too.
 *
 * Single precision (ODE 0.16.2 from Debian's source package, CMake Release, -DODE_DOUBLE_PRECISION=OFF): float's
 * range (1.2e-38 to 3.4e38) leaves less room; the masses, speeds and forces are narrower, the rest is kept.
 *   step length   non-finite at h <= 1e-22 s and at h >= 1e10 s (nominal); finite from 1e-20 s to 1e6 s. Kept:
 *                 1e-9 s to an hour, finite at every corner below.
 *   cfm           non-finite when cfm/h overflows: from 1e30 at h = 1e-9 s (1e28 finite), 1e38 at h = 1/60 s.
 *                 Kept: 1e20.
 *   erp           without the runaway stop, 10 nominal steps survive erp 100, not 1e3 (float overflows within
 *                 10 steps of a row growing by |erp|); stopped at SS_MAX_SAFE_SPEED, every corner is finite up to
 *                 |erp| = 1e18 (the largest tried). Kept: 1e9.
 *   mass          non-finite at 1e-40 kg (a denormal), finite from 1e-38 kg (nominal). The heavy edge is a mass
 *                 times a squared displacement: one step from 1e5 m/s at h = 3600 s is finite to 1e5 kg, not at
 *                 3e5 kg (from 1e4 m/s: finite to 1e6 kg). Built with its asserts (CMake Debug), ODE aborts
 *                 in dxNormalize4 from a principal inertia of about 1e-13 kg·m². Bounds: 1e-6 kg to 1e4 kg.
 *   speed         one step at every corner (1e4 kg, h = 3600 s) is finite from 1e6 m/s, not from 1e7. Bound: 1e5,
 *                 above an hour's fall (3.5e4 m/s).
 *   force         one step from 1e5 m/s at every corner is finite with 1e18 N on every body, not with 1e21
 *                 (1e-12 kg, h = 3600 s). Bound: 1e12 N. Unlike double, one step of the largest force on the
 *                 lightest body can leave a speed above SS_MAX_SAFE_SPEED (finite: probed); the stepper's
 *                 runaway check then stops before the next step.
 */
#ifndef STEADYSTEP_LIMITS_H
#define STEADYSTEP_LIMITS_H

#include <float.h>
#include <ode/precision.h> /* dSINGLE or dDOUBLE: the precision of the ODE the program is compiled against */

#include "steadystep/ode_build.h" /* SS_ODE_DOUBLE_PRECISION: the precision the library was built against */

#if (SS_ODE_DOUBLE_PRECISION && !defined(dDOUBLE)) || (!SS_ODE_DOUBLE_PRECISION && !defined(dSINGLE))
#error "steadystep was built against ODE in the other precision than these ODE headers (dSINGLE/dDOUBLE): build the program and the library against one ODE"
#endif

/** The shortest step (s) the library hands to dWorldStep or dWorldQuickStep: a nanosecond, in both precisions.
 *  ODE aborts below about 1e-155 s in double (where (1/h)² overflows) and goes non-finite below about 1e-20 s in
 *  single. A frame shorter than this is carried over, never stepped. */
#define SS_MIN_STEP_S 1e-9

/** The longest step (s): an hour, the longest frame the stepper takes (SS_MAX_FRAME_S in stepper.h), which the
 *  naive policy steps whole; the same in both precisions. ODE keeps a falling world finite to about 1e50 s
 *  (double) and 1e6 s (single); a step is a product of h with speeds and forces, so the bound keeps a margin for
 *  states far from rest. */
#define SS_MAX_STEP_S 3600.0

/** The largest cfm (m/(N·s) for a linear row; what ODE multiplies the row force by) handed to ODE: 1e20 in both
 *  precisions, i.e. a spring with h·k + c of at least 1e-20 N·s/m. ODE fails when cfm/h overflows (cfm about
 *  1e299 in double, 1e29 in single, at SS_MIN_STEP_S). The smallest cfm is 0: a hard row, as programs tune it;
 *  every conversion returns cfm > 0. */
#define SS_MAX_CFM 1e20

/** The smallest positive cfm handed to ODE: the smallest normal dReal (FLT_MIN, 1.2e-38, in single precision;
 *  DBL_MIN, 2.2e-308, in double). A spring's cfm computed below it would reach ODE as 0 or a denormal: a hard row,
 *  or a softness that has lost its digits. A mapping that computes one has no softness in this precision and falls
 *  back as for any result ODE cannot take (exact to matched to implicit Euler, counted); a spring whose
 *  implicit-Euler cfm at SS_MAX_STEP_S would be below it (h·k + c above 8.5e37 N·s/m in single) is refused when it
 *  is bound. */
#if defined(dSINGLE)
#define SS_MIN_POSITIVE_CFM FLT_MIN
#else
#define SS_MIN_POSITIVE_CFM DBL_MIN
#endif

/** The largest |erp| (non-dimensional) handed to ODE: 1e9 in both precisions. The matched and exact mappings may
 *  exceed 1 (ODE accepts that; their cfm keeps the row stable). This bound keeps erp·error/h² finite at
 *  SS_MIN_STEP_S for any error below 1e270 m (double; 3e11 m in single). A row with erp far above 2 and a small
 *  cfm is unstable and grows by about |erp| a step: at erp = 1e9, cfm = 0 the probe aborts within 30 steps in
 *  double and goes non-finite within 5 in single, so a stepper must stop such a runaway while it is still finite
 *  (SS_MAX_SAFE_SPEED). ODE aborts from about erp = 1e50 within 10 steps in double. */
#define SS_MAX_ERP 1e9

#if defined(dSINGLE)
/** The lightest and heaviest body mass (kg) handed to ODE in single precision: 1e-6 kg to 1e4 kg. ODE goes
 *  non-finite on 1e-40 kg (a denormal float) and, one step from SS_MAX_SAFE_SPEED at an hour's step, from 3e5 kg;
 *  built with its asserts, it aborts (dxNormalize4 on the orientation) on a body whose principal inertia is about
 *  1e-13 kg·m² or less, at steps as long as 1/60 s (a sphere of 1e-12 kg, 0.1 m across). The bound leaves room for
 *  an inertia of mass times 1e-6 m², a body a millimetre across: probed at every corner (tests/c/test_limits.cpp). */
#define SS_MIN_MASS_KG 1e-6
#define SS_MAX_MASS_KG 1e4

/** The speed (m/s, rad/s) below which one step at any corner of the ranges above stays finite, in single
 *  precision: 1e5 (probed finite from 1e6, not from 1e7). A stepper that refuses to step once any body is faster
 *  than this never hands ODE a state it cannot step. */
#define SS_MAX_SAFE_SPEED 1e5

/** The largest force (N) or torque (N·m) handed to ODE in single precision: 1e12 (one step from SS_MAX_SAFE_SPEED
 *  at every corner is finite with 1e18 N, not with 1e21 N). */
#define SS_MAX_FORCE_N 1e12
#else
/** The lightest and heaviest body mass (kg) the library hands to ODE (dBodySetMass): 1e-12 kg to 1e12 kg. ODE aborts
 *  on 1e-320 kg (a denormal, whose inverse is infinite) and from about 1e140 kg (probed with inertia in kg·m² equal
 *  to the mass in kg). The margins, 1e288 below and 1e128 above, leave room for a body's inertia, mass times the
 *  square of its size. */
#define SS_MIN_MASS_KG 1e-12
#define SS_MAX_MASS_KG 1e12

/** The speed (m/s for a body's linear velocity, rad/s for its angular velocity) below which one step at any corner
 *  of the ranges above stays finite: 1e50. ODE aborts instead of returning a non-finite state (dxNormalize4 on
 *  the orientation), so a blow-up must be caught while the state is finite: a stepper that refuses to step once
 *  any body is faster than this never hands ODE a state it cannot step. Probed: one step from speeds of 1e80 is
 *  finite at all 64 corners (both solvers, h, erp, cfm and mass at their bounds); from 1e90, 16 of them abort. */
#define SS_MAX_SAFE_SPEED 1e50

/** The largest force (N) or torque (N·m) the library hands to ODE: 1e30, the program's frame forces that the
 *  stepper puts back before each substep and the load corrections of ssRegistry_SetJointLoad alike. With masses of
 *  at least SS_MIN_MASS_KG and steps of at most SS_MAX_STEP_S, one step changes a speed by at most 3.6e45, inside
 *  SS_MAX_SAFE_SPEED. */
#define SS_MAX_FORCE_N 1e30
#endif

/** The farthest a known body's centre may be from the origin along any axis (m): 1e6 (1000 km). ODE's collision
 *  spaces turn positions into cell indices: a hash space (dHashSpaceCreate, default levels -3 to 10) aborts the
 *  process (`aabbBound < dMaxIntExact`) once a geom's cell index leaves the int range, at 2^31 cells of its level.
 *  Probed with tests/c/space_probe.c (two touching boxes collided once, then stepped): boxes of 0.01 m abort from
 *  3e8 m (2^31 cells of 1/8 m), boxes of 100 m from 1e12 m; simple, quadtree and sweep-and-prune spaces collide
 *  and step finite up to 1e100 m. The bound sits 268 times inside the smallest default-level edge, and inside it
 *  too for a hash space whose smallest level a program lowered to -10 (2^21 m); a body beyond it is refused by name
 *  (SS_ERROR_POSITION_LIMIT) before its next step, and a step at max_speed below 1e4 m/s moves at most 3.6e7 m. */
#define SS_MAX_POSITION_M 1e6

/** The most auto-disable samples the registry writes into a body or the world's defaults: 1000. A window of S
 *  samples tuned at h0 lasts S·h0 seconds, which takes ceil(S·h0/h) samples at a step h, and ODE allocates two
 *  vectors a sample for every body (64 bytes in double, 32 in float): 5 samples tuned at 1/60 s stepped at
 *  SS_MIN_STEP_S would be 8·10^7 samples, 5 GB a body. 1000 samples are 64 kB a body. Beyond the bound (steps
 *  shorter than the window / 1000, e.g. under 83 µs for 5 samples at 1/60 s), the velocities are averaged over the
 *  last 1000 steps, a window shorter than the tuned one; the idle time still holds. A program's own count is written
 *  back as it was at the step it was tuned for (adopt.h), whatever its size. */
#define SS_MAX_AVERAGE_SAMPLES 1000

/** The largest turn (rad) of a body geared by a transmission joint in one physics step: pi/2. ODE 0.16's
 *  transmission joint tracks each gear's phase from step to step and aborts the process (`fabs(phase_hat - phase[i])
 *  < M_PI`, transmission.cpp) when a gear turns by pi or more between two steps: at 1/60 s that is 188 rad/s, far
 *  inside the speed guard. A stepper refuses the step (SS_ERROR_SPEED_LIMIT, named) once a geared body spins faster
 *  than this turn per step, before and after every step, with half of ODE's edge as the margin for the step that
 *  follows; the turn counts the spin and the sliding the body's force and torque can add in the step, and the swing
 *  of the line between the gears' anchors when they move relative to each other (ODE measures the phase towards the
 *  mesh between them: anchors that may pass each other in a step turn it by pi). What no spin shows (a step that failed a check, a rotation the program sets) is made good by
 *  ssStepper_Reset, which has ODE measure the gears afresh. */
#define SS_MAX_GEAR_TURN_RAD 1.5707963267948966

#endif

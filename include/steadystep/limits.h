/* steadystep: the ranges of values the library hands to ODE, and the bounds of the lab's profiles and runs.
 *
 * ODE 0.16 (Debian's libode8 2:0.16.2, built with its internal checks on) has no error return for a bad number:
 * a value that overflows inside a step ends in `dxNormalize4` or `dMassCheck` asserting, and the process aborts
 * (SIGABRT). The library is the boundary: every step length, ERP, CFM and mass it hands ODE lies in the ranges
 * below, and anything outside them is refused by name (SS_ERROR_OUT_OF_RANGE or SS_ERROR_NOT_FINITE) before ODE
 * is touched.
 *
 * How the ranges were found. ODE's step (ode/src/step.cpp, quickstep.cpp) divides by the step length h twice:
 * a row's right-hand side is (erp/h)·error scaled by 1/h, its diagonal gets cfm/h, and the integrator multiplies
 * velocities by h. So the numbers that overflow are erp·error/h², cfm/h and h·(speed, force/mass). tests/c/
 * ode_probe.c steps a small real world (a slider stop, a ball joint on the world's ERP/CFM and a soft contact on
 * three bodies, gravity, both solvers, 10 steps) in a child process and reports whether it aborted:
 *   step length   aborts at h <= 1e-156 s (with the default softness) and at h >= 1e100 s; finite from 1e-155 s
 *                 to 1e50 s.
 *   cfm           aborts when cfm/h overflows (cfm = 1e300 at h = 1e-9 s; cfm = 1e307 at h = 1/60 s); dWorldStep
 *                 prints "LCP internal error" from there on. 0 (a hard row) and 1e-300 are handled.
 *   erp           aborts from 1e50 (the error grows by about erp per step, 10 steps overflow); -1e10 to 1e10
 *                 survive 10 steps. Neither solver needs erp <= 1.
 *   mass          aborts at 1e-320 kg (a denormal: its inverse is infinite) and from 1e140 to 1e160 kg depending
 *                 on h; finite from 1e-300 kg to 1e100 kg (inertia scaled alike).
 * The bounds below sit many orders of magnitude inside those edges, at values no physical program needs to pass,
 * so that products with a state that has not (yet) blown up stay finite too. tests/c/test_limits.cpp runs the
 * probe at every corner of these ranges (10 steps from near rest, and one step from SS_MAX_SAFE_SPEED) and checks
 * that ODE neither aborts nor loses finiteness; and that it does abort at h = 1e-200 s, so the probe can fail.
 */
#ifndef STEADYSTEP_LIMITS_H
#define STEADYSTEP_LIMITS_H

/** The shortest step (s) the library hands to dWorldStep or dWorldQuickStep: a nanosecond. ODE aborts below about
 *  1e-155 s, where (1/h)² overflows. A frame shorter than this is carried over, never stepped. (stepper.h defines
 *  the same macro with the same tokens, which C allows; one of the two should go.) */
#define SS_MIN_STEP_S 1e-9

/** The longest step (s): an hour, the longest frame the stepper takes (SS_MAX_FRAME_S in stepper.h), which the
 *  naive policy steps whole. ODE keeps a falling world finite to about 1e50 s; a step is a product of h with
 *  speeds and forces, so the bound keeps a wide margin for states far from rest. */
#define SS_MAX_STEP_S 3600.0

/** The largest |erp| (non-dimensional) handed to ODE: 1e9. The matched and exact mappings may exceed 1 (ODE
 *  accepts that; their cfm keeps the row stable). This bound keeps erp·error/h² finite at SS_MIN_STEP_S for any
 *  error below 1e270 m. A row with erp far above 2 and a small cfm is unstable and grows by about |erp| a step:
 *  at erp = 1e9, cfm = 0 the probe aborts within 30 steps, so a stepper must stop such a runaway while it is still
 *  finite (SS_MAX_SAFE_SPEED). ODE aborts from about erp = 1e50 within 10 steps. */
#define SS_MAX_ERP 1e9

/** The largest cfm (m/(N·s) for a linear row; what ODE multiplies the row force by) handed to ODE: 1e20, i.e. a
 *  spring with h·k + c of at least 1e-20 N·s/m. ODE aborts when cfm/h overflows (cfm about 1e299 at
 *  SS_MIN_STEP_S). The smallest cfm is 0: a hard row, as programs tune it; every conversion returns cfm > 0. */
#define SS_MAX_CFM 1e20

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

/** The farthest a known body's centre may be from the origin along any axis (m): 1e6 (1000 km). ODE's collision
 *  spaces turn positions into cell indices: a hash space (dHashSpaceCreate, default levels -3 to 10) aborts the
 *  process (`aabbBound < dMaxIntExact`) once a geom's cell index leaves the int range, at 2^31 cells of its level.
 *  Probed with tests/c/space_probe.c (two touching boxes collided once, then stepped): boxes of 0.01 m abort from
 *  3e8 m (2^31 cells of 1/8 m), boxes of 100 m from 1e12 m; simple, quadtree and sweep-and-prune spaces collide
 *  and step finite up to 1e100 m. The bound sits 268 times inside the smallest default-level edge, and inside it
 *  too for a hash space whose smallest level a program lowered to -10 (2^21 m); a body beyond it is refused by name
 *  (SS_ERROR_POSITION_LIMIT) before its next step, and a step at max_speed below 1e4 m/s moves at most 3.6e7 m. */
#define SS_MAX_POSITION_M 1e6

/** The largest force (N) or torque (N·m) the library hands to ODE: 1e30, the program's frame forces that the
 *  stepper puts back before each substep and the load corrections of ssRegistry_SetJointLoad alike. With masses of
 *  at least SS_MIN_MASS_KG and steps of at most SS_MAX_STEP_S, one step changes a speed by at most 3.6e45, inside
 *  SS_MAX_SAFE_SPEED. */
#define SS_MAX_FORCE_N 1e30

/** The shortest and longest frame (s) a lab profile hands out (profile.h): 1e-12 s to SS_MAX_STEP_S. Frames
 *  shorter than SS_MIN_STEP_S are allowed on purpose, to exercise carrying a frame over. */
#define SS_MIN_PROFILE_FRAME_S 1e-12
#define SS_MAX_PROFILE_FRAME_S SS_MAX_STEP_S

/** A lab run (scene.h) takes at most this many frames and this many physics steps: 10^7 each. A run records 2 + 4
 *  doubles per step, so the largest run holds about 480 MB. A run expected to need more is refused before it
 *  starts; one that reaches the bound (a random profile's unlucky draw) stops with SS_ERROR_OUT_OF_RANGE. */
#define SS_MAX_RUN_FRAMES 10000000
#define SS_MAX_RUN_STEPS 10000000

/** The longest simulated duration (s) of a lab run: 10^6 s (about 11.6 days). */
#define SS_MAX_RUN_DURATION_S 1e6

#endif

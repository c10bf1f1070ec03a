/* steadystep: how frames become physics steps, as plain data (no ODE types), shared by the stepper (stepper.h), the
 * lab (scene.h) and the Python package.
 *
 * Two independent choices make a way of stepping:
 *  - the cut: how a frame's time becomes steps (one step of the whole frame; equal substeps no longer than
 *    max_step_s; or constant steps of fixed_step_s from an accumulator, "fix your timestep");
 *  - the mapping: how each bound spring becomes ODE's ERP/CFM for a step (spring.h: implicit Euler, matched,
 *    exact), for the step's own length, or frozen at one length as ODE programs usually do.
 * Every combination works. Eight of them have names, the stepping policies (ssSteppingForPolicy): a feature of the
 * core, for a program or tool that lets its user choose a way of stepping by name (the examples' --policy flag, a
 * settings file), and the names under which the lab reports its comparisons.
 */
#ifndef STEADYSTEP_STEPPING_H
#define STEADYSTEP_STEPPING_H

#include "steadystep/export.h"
#include "steadystep/spring.h"
#include "steadystep/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/** stepping.frozen_step_s: the softness frozen at the stepper's tuned step (the naive policy of an adopted program). */
#define SS_FROZEN_AT_TUNED_STEP (-1.0)

/** How a frame's time becomes physics steps. */
typedef enum ssFrameCut {
  SS_CUT_WHOLE_FRAME = 0, /* one step of the whole frame (what ODE programs usually do) */
  SS_CUT_SUBSTEPS = 1,    /* n = ceil(frame / max_step_s) equal substeps (the article: cap the step) */
  SS_CUT_FIXED = 2,       /* steps of fixed_step_s from an accumulator, at most max_steps_per_frame a frame, with an
                           * interpolation factor for rendering */
} ssFrameCut;

/** Which ODE step the stepper calls: the one the program calls. There is no default: a program says which, so that
 *  a dWorldStep program never silently becomes a dWorldQuickStep one (ssValidateStepping refuses UNSET). */
typedef enum ssSolver {
  SS_SOLVER_UNSET = 0, /* not said yet: refused */
  SS_SOLVER_QUICK = 1, /* dWorldQuickStep, iterative: the world's own iteration count and SOR w */
  SS_SOLVER_STEP = 2,  /* dWorldStep, the direct (big matrix) solver */
} ssSolver;

/** Everything about stepping that needs no ODE handle. Start from ssDefaultStepping(). */
typedef struct ssStepping {
  ssFrameCut cut;          /* default SS_CUT_SUBSTEPS */
  ssMapping mapping;       /* default SS_MAPPING_IMPLICIT_EULER */
  /* > 0: every step's softness is computed for this step length (s), whatever the step's own: fixed ERP/CFM, the
   * way ODE programs are usually tuned (the naive policy). SS_FROZEN_AT_TUNED_STEP (-1): at the stepper's tuned step
   * (ssStepperDef.tuned_step_s or the registry's), which is what adopted numbers mean. 0 (default): each step's own
   * length. A stepper with a tuned step refuses any other frozen step: the numbers a program tuned mean that
   * softness at one step only, so a second value could only disagree with it. */
  double frozen_step_s;
  ssSolver solver;         /* required: default SS_SOLVER_UNSET, which is refused */
  /* dWorldQuickStep iterations written into the world before each frame, >= 0; default 0: the world's own setting
   * is left as the program set it. The stepper writes no other solver setting. */
  int quick_iterations;
  /* SUBSTEPS: the longest substep (s), in [SS_MIN_STEP_S, SS_MAX_STEP_S]; default 0: the stepper's tuned step
   * (ssStepperDef.tuned_step_s, or the registry's), refused when it has none */
  double max_step_s;
  double fixed_step_s;     /* FIXED: the constant step (s), in the same range; default 0: the tuned step, as above */
  /* SUBSTEPS: a frame up to (1 + max_step_slack)·max_step_s long is one step; a longer one is cut into
   * n = ceil(frame / max_step_s) equal substeps as before, so no step is ever longer than that. In [0, 1]; default
   * 0.25: a 60 fps frame with ordinary jitter (a 2 ms spread), a 59 Hz vsync frame or a frame time kept in a float
   * (1/60 s as a float is 7e-10 s longer) takes one step of the tuned length's neighbourhood, not two; a frame a
   * quarter longer than the step a program was tuned for is well inside what ODE steps stably. 0: every frame longer
   * than max_step_s is split. */
  double max_step_slack;
  /* QuickStep's row order. >= 0: before every step ODE's global random generator (dRandSetSeed) is set to a value
   * derived from this seed and the step's simulated start time (ssStepInfo.time_s), and put back as it was after the
   * step, so that a step depends only on the world's state and its time: not on how many QuickSteps ran before it
   * (in this world or any other in the process), and the program's own dRand sequence is neither read nor advanced
   * by the stepper. Under SS_CUT_FIXED the n-th step has the same row order at every frame rate; each step's order
   * differs from the last, as QuickStep's shuffling means it to (one order for every step biases a resting stack). -1: ODE's generator is left alone, as a program's own
   * loop leaves it (the naive policy, the program's own stepping bit for bit). Default 0. */
  int step_seed;
  /* SUBSTEPS and FIXED: the most physics steps a frame takes, > 0, against the spiral of death and a long frame
   * (a breakpoint, a hitch): the frame's time beyond them is dropped and reported (ssFrameReport.dropped_s).
   * Default 32: 0.53 s of simulated time a frame at 1/60 s steps (no frame of the lab's profiles comes near: its
   * longest, hitch:60:30:0.1's 0.1 s, is 6 steps), 0.13 s at 1/240 s. Whole-frame steps take one step anyway. */
  int max_steps_per_frame;
  /* A known body faster than this after a step is a runaway (m/s, rad/s), in [0, SS_MAX_SAFE_SPEED]. Default
   * 1e4 m/s and 1e4 rad/s: far above anything a game moves, and a blow-up is stopped long before ODE 0.16 would
   * abort the process (a non-finite rotation fails an assertion inside the next step). Raise them for faster
   * bodies; 0 leaves only the guard ODE itself needs, SS_MAX_SAFE_SPEED (limits.h). */
  double max_speed;
  double max_angular_speed;
} ssStepping;

/** The defaults listed at each field. */
SS_API ssStepping ssDefaultStepping(void);

/** Checks every field, naming the first one out of range.
 *  max_step_s and fixed_step_s may be 0 (the tuned step, which only the stepper knows).
 *  Errors: SS_ERROR_OUT_OF_RANGE (NULL, or a field outside its range), SS_ERROR_NOT_FINITE, SS_ERROR_UNSUPPORTED
 *  (an unknown cut, mapping or solver, and SS_SOLVER_UNSET: "say which ODE step the program calls"). */
SS_API ssStatus ssValidateStepping(const ssStepping* stepping);

/** The cut's name: "whole-frame", "substeps", "fixed"; NULL for an unknown value. */
SS_API const char* ssFrameCutName(ssFrameCut cut);

/** The stepping policies: named presets of (cut, mapping, frozen step), in this order (the lab reports in it):
 *    naive           whole frame, implicit Euler frozen at the reference step: an ODE program as it is usually
 *                    written, the problem the article fixes
 *    substeps-frozen substeps, implicit Euler frozen at the reference step: the control (what the cut alone gives)
 *    implicit-euler  substeps, implicit Euler at each step's length: the article's method
 *    matched         substeps, matched
 *    exact           substeps, exact
 *    fixed           fixed steps, implicit Euler
 *    fixed-matched   fixed steps, matched
 *    fixed-exact     fixed steps, exact */
SS_API int ssSteppingPolicyCount(void);

/** The name of policy index (0 <= index < ssSteppingPolicyCount()), or NULL. */
SS_API const char* ssSteppingPolicyNameAt(int index);

/** Sets stepping's cut, mapping, frozen step and step_seed use to the policy's (the other fields are kept): naive
 *  sets step_seed to -1 (ODE's generator left alone, as the program's own loop leaves it); every other policy sets a
 *  negative step_seed to 0 and keeps a seed the caller chose. reference_step_s is the length naive and
 *  substeps-frozen freeze their softness at: 0 for the stepper's tuned step (SS_FROZEN_AT_TUNED_STEP, what an
 *  adopted program means; a stepper refuses any other), or a step (s, in the step range) for springs bound by
 *  hand.
 *  Errors, with stepping unchanged: SS_ERROR_PARSE for an unknown name (named, with the known ones);
 *  SS_ERROR_OUT_OF_RANGE for NULL or a reference_step_s neither 0 nor in range; SS_ERROR_NOT_FINITE. */
SS_API ssStatus ssSteppingForPolicy(const char* name, double reference_step_s, ssStepping* stepping);

/** The name of the policy stepping is (cut, mapping and whether the softness is frozen; step_seed is not looked at),
 *  or NULL when it is no preset (e.g. whole frame with matched). */
SS_API const char* ssSteppingPolicyName(const ssStepping* stepping);

#ifdef __cplusplus
}
#endif

#endif

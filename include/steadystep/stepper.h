/* steadystep: the stepper, one call per rendered frame instead of dWorldQuickStep.
 *
 * A frame of dt seconds becomes n = ceil(dt / max_step_s) equal substeps of h = dt / n (the article: "make sure to
 * specify a largest time step the simulation can handle"). Before each substep the registry rewrites every soft
 * thing for h, the program's collision callback runs (handed h), ODE steps, the contact group is emptied and the
 * watched bodies are checked for NaN, infinity and runaway speed.
 *
 *     ssStepperDef def = ssDefaultStepperDef();
 *     def.world = world; def.registry = registry; def.max_step_s = 1.0 / 60.0;
 *     def.collide = my_near_callback_driver; def.contact_group = contacts;
 *     ssStepper* stepper; ssStepper_Create(&def, &stepper);
 *     for (;;) { ssFrameReport report; if (ssStepper_Step(stepper, frame_seconds, &report) != SS_OK) ...; }
 */
#ifndef STEADYSTEP_STEPPER_H
#define STEADYSTEP_STEPPER_H

#include <ode/ode.h>

#include "steadystep/registry.h"

#ifdef __cplusplus
extern "C" {
#endif

/** What a frame does with its time. */
typedef enum ssPolicy {
  SS_POLICY_NAIVE = 0,   /* one step of dt; softness frozen at its value for reference_step_s: the problem itself */
  SS_POLICY_SPRING = 1,  /* substeps <= max_step_s, the article's mapping at each substep's h */
  SS_POLICY_MATCHED = 2, /* substeps <= max_step_s, the matched mapping: exact poles at each h */
  SS_POLICY_EXACT = 3,   /* substeps <= max_step_s, the exact mapping: exact samples under varying h */
  SS_POLICY_FIXED = 4,   /* constant steps of fixed_step_s from an accumulator ("fix your timestep"), spring
                          * mapping at that step, at most max_steps_per_frame a frame, with an interpolation factor */
} ssPolicy;

/** Which ODE solver a step calls. */
typedef enum ssSolver {
  SS_SOLVER_QUICK = 0, /* dWorldQuickStep, iterative (quick_iterations) */
  SS_SOLVER_STEP = 1,  /* dWorldStep, the direct (big matrix) solver */
} ssSolver;

/** Called before each physics step, after the registry has been applied: run collision detection here, create
 *  contact joints in the stepper's contact_group and soften them with ssContactSoften(contact, b1, b2, spring,
 *  mapping, step_s, previous_step_s). The arguments are the ones the registry was applied with: the policy's
 *  mapping, the step length the softness is for (SS_POLICY_NAIVE: reference_step_s, whatever the frame time) and
 *  the step before (0 if none). */
typedef void ssCollideFn(void* context, ssMapping mapping, double step_s, double previous_step_s);

/** Called after each physics step that passed the blow-up checks, with its length; for recording. */
typedef void ssStepDoneFn(void* context, double step_s);

/** How a stepper is made. Start from ssDefaultStepperDef(): new fields keep working defaults. */
typedef struct ssStepperDef {
  dWorldID world;               /* required */
  ssRegistry* registry;         /* may be NULL: nothing soft is rewritten */
  ssPolicy policy;              /* default SS_POLICY_SPRING */
  ssSolver solver;              /* default SS_SOLVER_QUICK */
  int quick_iterations;         /* dWorldQuickStep iterations, > 0; default 20 (ODE's default) */
  double max_step_s;            /* the longest substep (s), > 0; default 1/60 */
  double reference_step_s;      /* NAIVE: the step its softness was tuned at (s), > 0; default 1/30 */
  double fixed_step_s;          /* FIXED: the constant step (s), > 0; default 1/60 */
  int max_steps_per_frame;      /* FIXED: cap against the spiral of death (later time is dropped), > 0; default 8 */
  /* a watched body faster than this (m/s) is a blow-up; 0 = no limit; default 0. Set it: ODE 0.16 aborts the
   * program (dxNormalize4) when a step produces a non-finite rotation, so a runaway must be caught before NaN. */
  double max_speed;
  ssCollideFn* collide;         /* may be NULL */
  void* collide_context;
  ssStepDoneFn* step_done;      /* may be NULL */
  void* step_done_context;
  dJointGroupID contact_group;  /* emptied after every step when not 0 */
} ssStepperDef;

/** What one frame did. */
typedef struct ssFrameReport {
  int steps;                  /* physics steps taken */
  double step_s;              /* length of the last step taken (s); 0 when none */
  double simulated_s;         /* time simulated this frame (s) */
  double dropped_s;           /* FIXED: time dropped by max_steps_per_frame (s) */
  double interpolation;       /* FIXED: accumulator / fixed_step_s in [0, 1), to blend the last two states */
  ssApplyReport apply;        /* summed over the frame's steps */
  dBodyID failed_body;        /* the body that blew up or ran too fast, else 0 */
} ssFrameReport;

typedef struct ssStepper ssStepper;

/** The defaults listed at each field. */
ssStepperDef ssDefaultStepperDef(void);

/** Makes a stepper. The registry and the world are borrowed: they must outlive it.
 *  Errors: SS_ERROR_OUT_OF_RANGE (no world, or a field outside its range, named), SS_ERROR_NOT_FINITE,
 *  SS_ERROR_UNSUPPORTED (unknown policy or solver), SS_ERROR_OUT_OF_MEMORY. */
ssStatus ssStepper_Create(const ssStepperDef* def, ssStepper** out);

/** Destroys the stepper. NULL is a no-op. */
void ssStepper_Destroy(ssStepper* stepper);

/** Advances the world by one frame of frame_s seconds (>= 0; 0 does nothing). report may be NULL.
 *  Errors, with the world left as it was: SS_ERROR_NOT_FINITE or SS_ERROR_OUT_OF_RANGE for frame_s; errors of
 *  ssRegistry_Apply (checked before the first step touches the world).
 *  Errors after stepping: SS_ERROR_BLOWUP (a watched body's position or linear velocity is not finite) and
 *  SS_ERROR_SPEED_LIMIT (faster than max_speed): the frame stops at that step and report->failed_body names it. */
ssStatus ssStepper_Step(ssStepper* stepper, double frame_s, ssFrameReport* report);

/** Adds a body to the blow-up checks (bodies of bound joints and bound bodies are watched anyway).
 *  Errors: SS_ERROR_OUT_OF_MEMORY. */
ssStatus ssStepper_WatchBody(ssStepper* stepper, dBodyID body);

/** Stops watching a body; call it before dBodyDestroy. Errors: SS_ERROR_NOT_FOUND. */
ssStatus ssStepper_UnwatchBody(ssStepper* stepper, dBodyID body);

/** Forgets the previous step length, so the next step of SS_POLICY_EXACT maps the bodies' true velocities. Call it
 *  after teleporting a body or setting its velocity. */
void ssStepper_ResetHistory(ssStepper* stepper);

/** Changes the policy between frames (resets the history and the FIXED accumulator).
 *  Errors: SS_ERROR_UNSUPPORTED for an unknown policy. */
ssStatus ssStepper_SetPolicy(ssStepper* stepper, ssPolicy policy);

/** The policy's name: "naive", "spring", "matched", "exact", "fixed"; NULL for an unknown value. */
const char* ssPolicyName(ssPolicy policy);

/** Parses a policy name as ssPolicyName gives it. Errors: SS_ERROR_PARSE naming the text. */
ssStatus ssPolicyParse(const char* name, ssPolicy* out);

#ifdef __cplusplus
}
#endif

#endif

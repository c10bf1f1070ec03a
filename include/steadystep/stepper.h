/* steadystep: the stepper, one call per rendered frame instead of dWorldQuickStep.
 *
 * A frame of dt seconds becomes n = ceil(dt / max_step_s) equal substeps of h = dt / n (the article: "make sure to
 * specify a largest time step the simulation can handle"). Before each substep the stepper puts back the forces the
 * program added for the frame, the registry rewrites every soft thing for h, the program's callbacks run, ODE
 * steps with the program's own solver settings, the contact group is emptied and the known bodies are checked.
 *
 *     ssStepperDef def = ssDefaultStepperDef();
 *     def.world = world; def.registry = registry; def.max_step_s = 1.0 / 60.0;
 *     def.collide = collide; def.contact_group = contacts;   // collide calls dSpaceCollide(space, stepper, near)
 *     ssStepper* stepper; ssStepper_Create(&def, &stepper);
 *     for (;;) {
 *       add_forces();                                          // once a frame: they act for the whole frame
 *       ssFrameReport report;
 *       if (ssStepper_Step(stepper, frame_seconds, &report) != SS_OK) { ...repair or restore...;
 *                                                                        ssStepper_Reset(stepper); }
 *     }
 *
 * Threads. Each stepper's world may be stepped from its own thread, one thread per world, on ODE 0.16's terms:
 * every world shares one process-wide default threading implementation, and stepping two worlds with it at once
 * crashes the process. Before a world is stepped off the main thread, give it its own:
 *     impl = dThreadingAllocateSelfThreadedImplementation();
 *     dWorldSetStepThreadingImplementation(world, dThreadingImplementationGetFunctions(impl), impl);
 * and when done: dWorldSetStepThreadingImplementation(world, NULL, NULL), dWorldDestroy, dThreadingFreeImplementation.
 * Every thread that uses ODE calls dAllocateODEDataForThread(dAllocateMaskAll) first; dInitODE2 runs once, before
 * the threads start. dWorldQuickStep shuffles rows with ODE's one global generator, so concurrent QuickSteps are
 * not reproducible run to run; dWorldStep is. A stepper and its registry are used from one thread at a time.
 * tests/c/test_threads.cpp shows two worlds on two threads.
 *
 * Known bodies: the bodies of the registry (bound, adopted) and those given to ssStepper_WatchBody. They are the
 * ones whose forces are kept for the whole frame and whose state is checked after every step.
 */
#ifndef STEADYSTEP_STEPPER_H
#define STEADYSTEP_STEPPER_H

#include <ode/ode.h>

#include "steadystep/limits.h"
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
  SS_SOLVER_QUICK = 0, /* dWorldQuickStep, iterative: the world's own iteration count and SOR w */
  SS_SOLVER_STEP = 1,  /* dWorldStep, the direct (big matrix) solver */
} ssSolver;

typedef struct ssStepper ssStepper;

/** The physics step about to be taken, as ssStepper_CurrentStep gives it inside the callbacks. */
typedef struct ssStepInfo {
  ssMapping mapping;      /* the mapping this step's softness is written with */
  double step_s;          /* the length of the physics step about to be taken (s) */
  double softness_step_s; /* the step length the softness is for (s): step_s, except SS_POLICY_NAIVE's reference */
  double previous_step_s; /* the step before, for SS_MAPPING_EXACT (s); 0 when there is no usable history */
  int index;              /* 0-based index of this step within the frame */
  int count;              /* steps this frame takes */
} ssStepInfo;

/** A callback before each physics step; ssStepper_CurrentStep(stepper) tells the step. */
typedef void ssStepCallback(void* context, ssStepper* stepper);

/** Called after each physics step that passed the checks, with its length (s); for recording. */
typedef void ssStepDoneFn(void* context, double step_s);

/** How a stepper is made. Start from ssDefaultStepperDef(): new fields keep working defaults. */
typedef struct ssStepperDef {
  dWorldID world;               /* required */
  ssRegistry* registry;         /* may be NULL: nothing soft is rewritten, only watched bodies are known */
  ssPolicy policy;              /* default SS_POLICY_SPRING */
  ssSolver solver;              /* default SS_SOLVER_QUICK */
  /* dWorldQuickStep iterations written into the world before each frame, > 0; default 0: the world's own setting
   * (dWorldSetQuickStepNumIterations) is left as the program set it. The stepper writes no other solver setting. */
  int quick_iterations;
  double max_step_s;            /* the longest substep (s), > 0; default 1/60 */
  double reference_step_s;      /* NAIVE: the step its softness was tuned at (s), > 0; default 1/30 */
  double fixed_step_s;          /* FIXED: the constant step (s), > 0; default 1/60 */
  int max_steps_per_frame;      /* FIXED: cap against the spiral of death (later time is dropped), > 0; default 8 */
  /* A known body faster than this after a step is a runaway (m/s, rad/s), in [0, SS_MAX_SAFE_SPEED]. Default
   * 1e4 m/s and 1e4 rad/s: far above anything a game moves, and a blow-up is stopped long before ODE 0.16 would
   * abort the process (a non-finite rotation fails an assertion inside the next step). Raise them for faster
   * bodies; 0 leaves only the guard ODE itself needs, SS_MAX_SAFE_SPEED. */
  double max_speed;
  double max_angular_speed;
  /* Before each step, after the frame's forces were put back and the registry applied: add forces that depend on
   * the state (PD controllers, drag, buoyancy). Forces that are constant over a frame can simply be added before
   * ssStepper_Step. May be NULL. */
  ssStepCallback* before_step;
  void* before_step_context;
  /* Before each step, after before_step: run collision detection, e.g. dSpaceCollide(space, stepper, near), create
   * contacts in contact_group and soften each with ssStepper_SoftenContact. May be NULL. */
  ssStepCallback* collide;
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
  double carried_s;           /* time not simulated yet, carried to the next frame (s): FIXED's accumulator, or a
                               * frame shorter than SS_MIN_STEP_S */
  double dropped_s;           /* FIXED: time dropped by max_steps_per_frame (s) */
  double interpolation;       /* FIXED: accumulator / fixed_step_s in [0, 1), to blend the last two states */
  ssApplyReport apply;        /* summed over the frame's steps */
  int contacts_softened;      /* contacts softened with ssStepper_SoftenContact */
  int contacts_spring_fallback; /* of those, contacts the accurate mapping could not serve: spring mapping used */
  dBodyID failed_body;        /* the body that blew up or ran too fast, else 0 */
} ssFrameReport;

/** The longest frame ssStepper_Step takes (s): SS_MAX_STEP_S (limits.h), since SS_POLICY_NAIVE steps it whole.
 *  A frame shorter than SS_MIN_STEP_S is carried over to the next one, never stepped. */
#define SS_MAX_FRAME_S SS_MAX_STEP_S

/** The defaults listed at each field. */
ssStepperDef ssDefaultStepperDef(void);

/** Makes a stepper. The registry and the world are borrowed: they must outlive it.
 *  Errors: SS_ERROR_OUT_OF_RANGE (def or out NULL, no world, or a field outside its range, named),
 *  SS_ERROR_NOT_FINITE, SS_ERROR_UNSUPPORTED (unknown policy or solver), SS_ERROR_OUT_OF_MEMORY. */
ssStatus ssStepper_Create(const ssStepperDef* def, ssStepper** out);

/** Destroys the stepper. NULL is a no-op. */
void ssStepper_Destroy(ssStepper* stepper);

/** Advances the world by one frame of frame_s seconds (0 <= frame_s <= SS_MAX_FRAME_S; 0 does nothing). report may
 *  be NULL.
 *  Forces and torques that the program added to known bodies before this call act for the whole frame: they are
 *  put back before every substep (ODE clears them after each step), and under SS_POLICY_FIXED they are scaled so
 *  that the frame's steps deliver the momentum F·frame_s (carried to the next frame when this one takes no step).
 *  Errors, with the world left as it was: SS_ERROR_OUT_OF_RANGE (stepper NULL, frame_s out of range, a force or
 *  torque on a known body beyond SS_MAX_FORCE_N, named with its body), SS_ERROR_NOT_FINITE (frame_s, a force);
 *  errors of ssRegistry_Apply (checked before the first step touches the world);
 *  SS_ERROR_FAILED when an earlier frame failed and ssStepper_Reset has not been called.
 *  Errors after stepping: SS_ERROR_BLOWUP (a known body's position or velocity is not finite) and
 *  SS_ERROR_SPEED_LIMIT (faster than max_speed or max_angular_speed): the frame stops at that step,
 *  report->failed_body names the body, and the stepper refuses every later frame until ssStepper_Reset. */
ssStatus ssStepper_Step(ssStepper* stepper, double frame_s, ssFrameReport* report);

/** After a failure, once the program has repaired or restored its bodies: accepts frames again. Also forgets the
 *  step history, the FIXED accumulator and the momentum carried for the next frame. NULL is a no-op. */
void ssStepper_Reset(ssStepper* stepper);

/** The step about to be taken. Meaningful inside before_step and collide; between frames it describes the next
 *  step of the default length. stepper must not be NULL. */
ssStepInfo ssStepper_CurrentStep(const ssStepper* stepper);

/** In the program's near callback: turns the contact's tuned softness into the softness for the step about to be
 *  taken. The contact's soft_erp/soft_cfm (where surface.mode has dContactSoftERP/dContactSoftCFM), or else the
 *  world's ERP/CFM, as the program tuned them at the registry's tuned step (ssRegistry_Adopt), become a spring; it
 *  is written back as soft_erp/soft_cfm for this step's length and mapping, both mode bits set. body1 and body2
 *  (either may be 0 for the static world) give the effective mass along the normal for matched and exact; where
 *  those cannot serve the contact, the spring mapping does (counted in the frame report). A contact tuned with
 *  cfm = 0 stays hard (erp follows h as for adopted hard rows).
 *  Errors, with the contact unchanged: SS_ERROR_OUT_OF_RANGE (stepper or contact NULL, no tuned step: adopt
 *  first, or a tuned erp outside [0, 1] or cfm < 0); SS_ERROR_NOT_FINITE. */
ssStatus ssStepper_SoftenContact(ssStepper* stepper, dContact* contact, dBodyID body1, dBodyID body2);

/** Adds a body to the known bodies: forces kept for the whole frame and checks after each step.
 *  Errors: SS_ERROR_OUT_OF_RANGE (NULL), SS_ERROR_OUT_OF_MEMORY. */
ssStatus ssStepper_WatchBody(ssStepper* stepper, dBodyID body);

/** Stops watching a body; call it before dBodyDestroy. Errors: SS_ERROR_OUT_OF_RANGE (NULL), SS_ERROR_NOT_FOUND. */
ssStatus ssStepper_UnwatchBody(ssStepper* stepper, dBodyID body);

/** Destroys a body safely: stops watching it, removes its damping and auto-disable bindings from the registry,
 *  then calls dBodyDestroy. Use it instead of dBodyDestroy for any body the stepper knows: ODE gives no way to tell
 *  a destroyed body from a live one, so the stepper and the registry would read freed memory (a sanitizer build
 *  stops there with a report). The registry's bindings of the joints attached to it are removed too: ODE leaves
 *  those joints detached on one side, where some of its getters assert.
 *  Errors, with nothing destroyed: SS_ERROR_OUT_OF_RANGE (stepper or body NULL). */
ssStatus ssStepper_DestroyBody(ssStepper* stepper, dBodyID body);

/** Destroys a joint safely: removes its bindings from the registry, then calls dJointDestroy. Use it instead of
 *  dJointDestroy for a bound or adopted joint (contact joints in the contact group need nothing).
 *  Errors, with nothing destroyed: SS_ERROR_OUT_OF_RANGE (stepper or joint NULL). */
ssStatus ssStepper_DestroyJoint(ssStepper* stepper, dJointID joint);

/** Forgets the previous step length, so the next step of SS_POLICY_EXACT maps the bodies' true velocities. Call it
 *  after teleporting a body or setting its velocity. NULL is a no-op. */
void ssStepper_ResetHistory(ssStepper* stepper);

/** Changes the policy between frames (resets the history and the FIXED accumulator).
 *  Errors: SS_ERROR_OUT_OF_RANGE for a NULL stepper, SS_ERROR_UNSUPPORTED for an unknown policy. */
ssStatus ssStepper_SetPolicy(ssStepper* stepper, ssPolicy policy);

/** The policy's name: "naive", "spring", "matched", "exact", "fixed"; NULL for an unknown value. */
const char* ssPolicyName(ssPolicy policy);

/** Parses a policy name as ssPolicyName gives it. Errors: SS_ERROR_PARSE naming the text; SS_ERROR_OUT_OF_RANGE
 *  for a NULL out. */
ssStatus ssPolicyParse(const char* name, ssPolicy* out);

#ifdef __cplusplus
}
#endif

#endif

/* steadystep: the stepper, one call per rendered frame instead of dWorldQuickStep.
 *
 * A frame of dt seconds becomes n = ceil(dt / max_step_s) equal substeps of h = dt / n (the article: "make sure to
 * specify a largest time step the simulation can handle"), at most stepping.max_steps_per_frame; a frame at most
 * stepping.max_step_slack longer than max_step_s is one step. Under SS_CUT_FIXED it becomes steps of fixed_step_s
 * from an accumulator, the one way of stepping that makes motion identical at every frame rate. Before each
 * substep the stepper puts back the forces the program added for the frame, the registry rewrites every soft thing
 * for h, the program's callbacks run, the known bodies are checked, ODE steps with the ODE step the program named
 * and its own solver settings, the contact group is emptied and the known bodies are checked again.
 *
 *     ssStepperDef def = ssDefaultStepperDef();
 *     def.world = world; def.space = space; def.tuned_step_s = 1.0 / 60.0;   // the step the program was tuned for
 *     def.stepping.solver = SS_SOLVER_QUICK;                   // the ODE step the program calls
 *     def.collide = collide; def.contact_group = contacts;   // collide calls dSpaceCollide(space, stepper, near)
 *     ssStepper* stepper; ssStepper_Create(&def, &stepper);
 *     for (;;) {
 *       add_forces();                                          // once a frame: held until the next frame's
 *       ssFrameReport report;
 *       if (ssStepper_Step(stepper, frame_seconds, &report) != SS_OK) { ...repair or restore...;
 *                                                                        ssStepper_Reset(stepper); }
 *     }
 *
 * A near callback that already uses dSpaceCollide's `data` for its own context keeps it: put the stepper in that
 * context (struct { MyGame* game; ssStepper* stepper; }) and pass it as data; the stepper takes nothing over.
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
 * Known bodies: the bodies of the registry (bound, adopted), those given to ssStepper_WatchBody, and every body
 * reachable from those through joints other than contacts. They are the ones whose forces are kept for the whole
 * frame and whose state and forces are checked at every step. With def.space, bodies and joints made later are
 * found and adopted at the tuned step: before each frame and each step the stepper looks at the adopted spaces
 * (their geom count and first geom: a geom added to any of them, a nested space too), and before each frame at
 * every known body's first joint (ODE attaches a new joint at the head of its body's list), one read each, and
 * walks the spaces or the joints only when one changed. A body made in a callback is found before the next step; a
 * joint made in a callback, before the next frame. What nothing reaches the stepper cannot see: a body with no geom in
 * the space and no joint to a known body (a bob hung from the static world, a free projectile without a geom).
 * Its forces would act on the first substep only: make it known with ssStepper_WatchBody (or adopt it,
 * ssRegistry_AdoptBody, into the registry). ssStepper_Adopted and ssStepper_KnownBodyCount tell what was reached,
 * for a program to compare with the bodies it made.
 *
 * What the program destroys with ODE's own calls, between frames or in a callback, is forgotten before the stepper
 * reads it, found from what is alive: a joint attached to known bodies (dJointDestroy: an entity's joint rebuilt each
 * frame); a body destroyed together with its geoms in the adopted spaces (dGeomDestroy and dBodyDestroy: a prop
 * despawned); a nested space with its geoms (dSpaceDestroy: a level torn down). What ODE 0.16 gives no way to tell
 * from freed memory must go through the stepper: a body with no geom in the adopted spaces (a bob on a joint), and
 * any watched body, is destroyed with ssStepper_DestroyBody (or a watched one unwatched first, then destroyed). The world is destroyed
 * after its stepper: ssStepper_Destroy writes the program's own numbers back (see there).
 *
 * The boundary with ODE. ODE 0.16 aborts the process inside a step or a collision rather than return an error for
 * a state it cannot handle, so the stepper checks every known body before the frame (before any callback) and
 * again just before every physics step (after before_step and collide, whatever they did): position within
 * SS_MAX_POSITION_M, linear and angular velocity finite and within stepping.max_speed and max_angular_speed, force
 * and torque accumulators finite and within SS_MAX_FORCE_N (whatever added them: the program before the frame,
 * before_step or collide). After every step it checks the state again. A failure refuses the frame by name (the
 * body, the quantity, its value) with nothing of that step taken: the world as the previous step left it (the
 * step's contacts removed, the accumulators as the program left them for the frame, or empty after an earlier
 * step), report->failed_body set, and every later frame refused until ssStepper_Reset. A state set in before_step or
 * in the last step's step_done is checked again before collide runs (position and speeds: dSpaceCollide aborts on a
 * position far out of range), so no state the program set reaches its own collision unchecked. A body's bound on
 * its position is SS_MAX_POSITION_M less the farthest offset of its geoms from it (dGeomSetOffsetPosition), as
 * they were when the body became known.
 *
 * The program's own writes. A program may go on setting what it tuned (world ERP/CFM, a joint's parameters, a body's
 * damping or auto-disable) after adoption, from its settings or its entities. Before each frame, and before each
 * step that follows a callback, the stepper compares every adopted value it rewrites for each step with what it last
 * wrote: one that differs was the program's, and is taken as newly tuned at the tuned step (as adoption took the
 * first), so that every step length gets what the program's value means. (A spring bound by hand with the registry
 * is changed by binding it again: its rows are not read. Under a softness frozen at the tuned step, as naive's, a
 * body's damping and auto-disable are written for that step only and not read back: the program's value stays as it
 * wrote it, and is followed when the stepping changes.) report->program_writes counts them. A value no
 * spring stands for (an erp outside [0, 1], a cfm below 0, a damping scale of 1) refuses the frame by name, with
 * nothing stepped, until the program sets another.
 *
 * Callbacks (before_step, collide, step_done) may call, on their own stepper:
 *  - ssStepper_CurrentStep, ssStepper_SoftenContact(s), ssStepper_Stepping, ssStepper_ResetHistory, WatchBody,
 *    UnwatchBody: as between frames; the known list follows before the next check.
 *  - ssStepper_DestroyBody, ssStepper_DestroyJoint: the body or joint leaves the stepper and the registry at once
 *    (no later part of the frame reads it), then ODE destroys it.
 *  - ssStepper_Destroy: deferred. The frame stops where it is (from before_step or collide, that step is not taken
 *    and its contacts are removed; from step_done, no further step), ssStepper_Step fills the report and returns
 *    SS_OK, and then the stepper is freed: do not use it after that ssStepper_Step returns.
 *  - ssStepper_Step, ssStepper_SetStepping, ssStepper_Reset: refused with SS_ERROR_REENTERED, named (Reset, which
 *    returns nothing, records the message for ssLastError and does nothing).
 */
#ifndef STEADYSTEP_STEPPER_H
#define STEADYSTEP_STEPPER_H

#include <ode/ode.h>

#include "steadystep/adopt.h"
#include "steadystep/export.h"
#include "steadystep/limits.h"
#include "steadystep/registry.h"
#include "steadystep/stepping.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct ssStepper ssStepper;

/** The physics step about to be taken, as ssStepper_CurrentStep gives it inside the callbacks. */
typedef struct ssStepInfo {
  ssMapping mapping;      /* the mapping this step's softness is written with */
  double step_s;          /* the length of the physics step about to be taken (s) */
  double softness_step_s; /* the step length the softness is for (s): step_s, or stepping.frozen_step_s */
  double previous_step_s; /* the step before, for SS_MAPPING_EXACT (s); 0 when there is no usable history */
  int index;              /* 0-based index of this step within the frame */
  int count;              /* steps this frame takes */
  /* the simulated time at this step's start (s): every step the stepper took since ssStepper_Create, added in
   * order. Under SS_CUT_FIXED the n-th step starts at the same time, to the bit, whatever the frame rate: compute
   * inputs that change with time (a motor's target, a script, a controller's set point) from it in before_step */
  double time_s;
} ssStepInfo;

/** A callback before each physics step; ssStepper_CurrentStep(stepper) tells the step: its length (step_s) and the
 *  simulated time at its start (time_s). */
typedef void ssStepCallback(void* context, ssStepper* stepper);

/** Called after each physics step that passed the checks, with its length (s); for recording. */
typedef void ssStepDoneCallback(void* context, double step_s);

/** How a stepper is made. Start from ssDefaultStepperDef(): new fields keep working defaults. */
typedef struct ssStepperDef {
  dWorldID world;               /* required */
  /* Optional: the program's space. ssStepper_Create adopts the world and everything the space reaches as tuned at
   * tuned_step_s (ssRegistry_Adopt, adopt.h), into a registry it makes and owns (or into `registry` when given),
   * and before every step finds the bodies and joints added since. */
  dSpaceID space;
  /* The step (s) the program's ERP/CFM, damping and auto-disable were tuned for, in [SS_MIN_STEP_S, SS_MAX_STEP_S]:
   * required with space; 0 otherwise means ssRegistry_TunedStep(registry) (0 without a registry or adoption).
   * stepping.max_step_s and fixed_step_s default to it. */
  double tuned_step_s;
  /* Optional, borrowed (it must outlive the stepper): a registry of `world` for springs bound by hand. NULL
   * without space: nothing soft is rewritten, only watched bodies are known. */
  ssRegistry* registry;
  /* How frames become steps (stepping.h); default ssDefaultStepping(), whose solver must be set. */
  ssStepping stepping;
  /* Before each step, after the frame's forces were put back and the registry applied: the program's per-step logic.
   * Everything that depends on the state or on the simulated time belongs here (PD controllers, drag, buoyancy, a
   * motor's target, a scripted event, input applied at a time), computed from ssStepper_CurrentStep's time_s and
   * step_s: run once a frame instead, it makes the motion depend on the frame rate under every policy. Forces
   * constant over a frame may be added before ssStepper_Step instead: they are held (ssStepper_Step). May be NULL. */
  ssStepCallback* before_step;
  void* before_step_context;
  /* Before each step, after before_step: run collision detection, e.g. dSpaceCollide(space, stepper, near), create
   * contacts in contact_group and soften them with ssStepper_SoftenContacts (or each with ssStepper_SoftenContact).
   * May be NULL. */
  ssStepCallback* collide;
  void* collide_context;
  ssStepDoneCallback* step_done; /* may be NULL */
  void* step_done_context;
  dJointGroupID contact_group;  /* emptied after every step when not 0 */
} ssStepperDef;

/** What one frame did. */
typedef struct ssFrameReport {
  int steps;                  /* physics steps taken */
  double step_s;              /* length of the last step taken (s); 0 when none */
  double simulated_s;         /* time simulated this frame (s) */
  double time_s;              /* the stepper's simulated time after this frame (s): ssStepInfo.time_s of the next
                               * step. Under SS_CUT_FIXED the same bits after the same number of steps whatever
                               * the frame rate: the time to label a frame's state with */
  double carried_s;           /* time not simulated yet, carried to the next frame (s): FIXED's accumulator, or a
                               * frame shorter than SS_MIN_STEP_S */
  double dropped_s;           /* time dropped by stepping.max_steps_per_frame (s), never simulated */
  double interpolation;       /* FIXED: accumulator / fixed_step_s in [0, 1), to blend the last two states */
  ssServedCounts rows;        /* row-steps: every bound row (the world's included) counted once per physics step,
                               * by who served it (registry.h) */
  ssServedCounts contacts;    /* contacts softened with ssStepper_SoftenContact(s), by who served them */
  int row_writes;             /* parameter sets written into ODE, summed over the frame's Applies (implicit Euler
                               * applies once a frame of equal substeps, and writes only what changed) */
  int unsoftened_contact_steps; /* steps whose collision made contacts on known bodies but softened none with
                                 * ssStepper_SoftenContact (a near callback that forgot it: those contacts keep the
                                 * softness tuned for one step length); counted with def.space and def.contact_group */
  int program_writes;         /* values the program wrote into ODE since the stepper last looked (the world's
                               * ERP/CFM, a bound joint row, a body's damping or auto-disable), each taken as newly
                               * tuned at the tuned step (see "The program's own writes" at the top) */
  dBodyID failed_body;        /* the body that blew up or ran too fast, else 0 */
} ssFrameReport;

/** The longest frame ssStepper_Step takes (s): SS_MAX_STEP_S (limits.h), since SS_CUT_WHOLE_FRAME steps it whole.
 *  A frame shorter than SS_MIN_STEP_S is carried over to the next one, never stepped. */
#define SS_MAX_FRAME_S SS_MAX_STEP_S

/** The defaults listed at each field. */
SS_API ssStepperDef ssDefaultStepperDef(void);

/** Whether the ODE loaded at run time has the precision the library was built against (SS_ODE_DOUBLE_PRECISION,
 *  ode_build.h): a program and the library compiled against one ODE, then run with a libode of the other precision
 *  under the same name, would read and write every dReal wrongly. ssStepper_Create calls it; so does the Python
 *  package when it loads. Errors: SS_ERROR_UNSUPPORTED, naming both precisions. */
SS_API ssStatus ssCheckOdePrecision(void);

/** Makes a stepper. The world and a given registry are borrowed: they must outlive it. With def->space, the
 *  world and everything the space reaches are adopted as tuned at def->tuned_step_s (into def->registry when
 *  given, else into a registry the stepper makes and destroys with itself); nothing is made or adopted on an error.
 *  Errors: SS_ERROR_UNSUPPORTED (an ODE of the other precision loaded: ssCheckOdePrecision);
 *  SS_ERROR_OUT_OF_RANGE (def or out NULL, no world, a registry of another world, space without
 *  tuned_step_s, a field outside its range, stepping.max_step_s or fixed_step_s 0 with no tuned step, named),
 *  SS_ERROR_NOT_FINITE, SS_ERROR_UNSUPPORTED (those of ssValidateStepping, e.g. stepping.solver unset); those of
 *  ssRegistry_Adopt; SS_ERROR_OUT_OF_MEMORY. */
SS_API ssStatus ssStepper_Create(const ssStepperDef* def, ssStepper** out);

/** Destroys the stepper (and the registry it made for def.space). NULL is a no-op. From the stepper's own callback
 *  it is deferred to the end of that ssStepper_Step (see the top). A stepper that adopted (def.space) first writes
 *  back into ODE the program's own numbers, as tuned at the tuned step (or as the program wrote them since): the
 *  world is the program's again, and a stepper made on it next adopts what the program tuned, not what this one
 *  wrote for another step. So the world, its spaces and the bodies must still exist: destroy the stepper before
 *  them. */
SS_API void ssStepper_Destroy(ssStepper* stepper);

/** Advances the world by one frame of frame_s seconds (0 <= frame_s <= SS_MAX_FRAME_S; 0 takes no step). report may
 *  be NULL.
 *  Held forces. Forces and torques that the program added to known bodies before this call are its input for this
 *  frame's time, held like any input sampled once a frame (a zero-order hold): they act, unchanged, at every
 *  physics step until the next frame's forces replace them (ODE clears its accumulators after each step: the
 *  stepper puts them back). Time a frame leaves unstepped (FIXED's accumulator, a frame shorter than SS_MIN_STEP_S)
 *  carries its force with it, and the step that later covers that time gets it for that share of its length. So
 *  F·dt is exact over the run under every cut, frames with no step included, and a force added every frame with
 *  the same value acts as itself at every step: under SS_CUT_FIXED the motion is then the same, to the bit, at every
 *  frame rate. What this cannot hold is an input that varies within a frame (a force that follows the state or the
 *  time): compute it per step in before_step, from ssStepper_CurrentStep's time_s and step_s. A frame that takes
 *  no step clears the accumulators (its force is carried), so the program's next additions are not counted twice;
 *  a frame's first step with nothing carried leaves them as the program added them. Time beyond
 *  max_steps_per_frame steps is dropped (report->dropped_s) with its force.
 *  QuickStep's row order: unless stepping.step_seed is -1 (naive), each step starts from the same state of ODE's
 *  random generator (stepping.h), so a step depends only on the world.
 *  Errors, with the world left as it was: SS_ERROR_OUT_OF_RANGE (stepper NULL, frame_s out of range),
 *  SS_ERROR_NOT_FINITE (frame_s); SS_ERROR_REENTERED (called from one of its own callbacks; report untouched);
 *  errors of ssRegistry_Apply (found at the frame's first step: what can fail depends on the step length and the
 *  bound springs alone, and every row an accurate mapping cannot serve falls back to implicit Euler);
 *  SS_ERROR_FAILED when an earlier frame failed and ssStepper_Reset has not been called.
 *  Errors of the boundary (see the top), before the frame or before a step, named with the body and the value,
 *  nothing of that step taken: SS_ERROR_BLOWUP (a position or velocity not finite), SS_ERROR_POSITION_LIMIT,
 *  SS_ERROR_SPEED_LIMIT, SS_ERROR_NOT_FINITE (a force or torque), SS_ERROR_OUT_OF_RANGE (one beyond
 *  SS_MAX_FORCE_N); and after a step: SS_ERROR_BLOWUP, SS_ERROR_POSITION_LIMIT, SS_ERROR_SPEED_LIMIT. Each stops
 *  the frame, names the body in report->failed_body, and the stepper refuses every later frame until
 *  ssStepper_Reset. */
SS_API ssStatus ssStepper_Step(ssStepper* stepper, double frame_s, ssFrameReport* report);

/** After a failure, once the program has repaired or restored its bodies: accepts frames again. Also forgets the
 *  step history, the FIXED accumulator and the momentum carried for the next frame. NULL is a no-op. A body left as
 *  it failed (still too fast, or beyond a bound) is refused again, by name, before the next frame touches it.
 *  Every transmission joint on a known body is measured afresh at the next frame's first step: the gears' angles
 *  then are their phase 0 (ODE 0.16 predicts each gear's phase from its spin and aborts when the gear has turned
 *  otherwise by pi: a runaway step followed by a repair does that, and so does a program that turns a gear itself,
 *  which should call this before the next frame). The phase error the gears had is forgotten; each keeps its axis.
 *  From the stepper's own callback: does nothing, and records SS_ERROR_REENTERED's message for ssLastError. */
SS_API void ssStepper_Reset(ssStepper* stepper);

/** The step about to be taken. Meaningful inside before_step and collide; between frames it describes the next
 *  step of the default length. A NULL stepper gives an all-zero step and records SS_ERROR_OUT_OF_RANGE for
 *  ssLastError. */
SS_API ssStepInfo ssStepper_CurrentStep(const ssStepper* stepper);

/** In the program's near callback: turns the contact's tuned softness into the softness for the step about to be
 *  taken. The contact's soft_erp/soft_cfm (where surface.mode has dContactSoftERP/dContactSoftCFM), or else the
 *  world's ERP/CFM, as the program tuned them at the registry's tuned step (ssRegistry_Adopt), become a spring; it
 *  is written back as soft_erp/soft_cfm for this step's length, both mode bits set. Under every mapping the
 *  implicit-Euler softness serves it: matched and exact serve no contact (its load is never known; ssContactSoften),
 *  and count it in the frame report's contacts.handed_to_implicit_euler. body1 and body2 are not read. A contact
 *  tuned with cfm = 0 stays hard (erp follows h as for adopted hard rows).
 *  Errors, with the contact unchanged: SS_ERROR_OUT_OF_RANGE (stepper or contact NULL, no tuned step: adopt
 *  first, or a tuned erp outside [0, 1] or cfm < 0); SS_ERROR_NOT_FINITE (a tuned value, or the contact's position,
 *  normal or depth as the collider made it: ODE 0.16's sphere-cylinder collider makes such contacts; drop it instead
 *  of creating its joint). */
SS_API ssStatus ssStepper_SoftenContact(ssStepper* stepper, dContact* contact, dBodyID body1, dBodyID body2);

/** ssStepper_SoftenContact for the count contacts one dCollide call made, in the array it filled (&contacts[0].geom,
 *  stride sizeof(dContact)): one call a pair of geoms, where ODE's demos fill every contact's surface before
 *  dCollide and create the joints after it. Each contact is softened as ssStepper_SoftenContact softens it and
 *  counted the same way; count = 0 does nothing (contacts may then be NULL). A batch whose contacts all have the
 *  surface the last contact softened in this step had costs one comparison a contact and nothing else.
 *  Errors, with every contact of the batch unchanged: SS_ERROR_OUT_OF_RANGE (stepper NULL, contacts NULL with
 *  count > 0, count < 0, and ssStepper_SoftenContact's), SS_ERROR_NOT_FINITE (as ssStepper_SoftenContact, for the
 *  first contact that has one). */
SS_API ssStatus ssStepper_SoftenContacts(ssStepper* stepper, dContact* contacts, int count);

/** The most contacts ssStepper_CollideByRule asks dCollide for per pair of geoms. */
#define SS_MAX_RULE_CONTACTS 4096

/** A near callback as a rule (ssStepper_CollideByRule): the one of ODE's demos and PyODE's tutorials, applied in C.
 *  Start from ssDefaultContactRule(): new fields keep working defaults. */
typedef struct ssContactRule {
  dWorldID world;              /* the world the contact joints are made in: the stepper's. Required */
  dSpaceID space;              /* the space whose pairs of geoms are collided. Required */
  dJointGroupID contact_group; /* the group the contact joints are made in: the stepper's def.contact_group, which
                                * it empties after every step. Required */
  /* Required: every contact gets this contact's surface (mode, mu, bounce, soft_erp/soft_cfm as tuned at the
   * tuned step, ...) and fdir1; its geom is not read. mu, mu2, rho, rho2 and rhoN in [0, infinity], bounce in
   * [0, 1], bounce_vel, slip1 and slip2 finite and >= 0, motion1, motion2, motionN and fdir1 finite */
  const dContact* surface;
  int max_contacts;            /* contacts asked of dCollide per pair of geoms, in [1, SS_MAX_RULE_CONTACTS];
                                * default 4 (PyODE's ode.collide asks 150) */
  int skip_connected;          /* 1: no contact between two bodies that a joint other than a contact connects
                                * (dAreConnectedExcluding), as ODE's demos do; 0 (the default): every pair */
} ssContactRule;

/** What one ssStepper_CollideByRule made. */
typedef struct ssContactRuleReport {
  int pairs;    /* pairs of geoms dCollide was asked about (pairs of two static geoms are skipped) */
  int contacts; /* contact joints made, each softened (counted in the frame report's contacts) */
  int dropped;  /* contacts whose position, normal or depth was not finite, dropped without a joint (ODE 0.16's
                 * sphere-cylinder collider makes them) */
} ssContactRuleReport;

/** The defaults listed at each field (the required ones NULL). */
SS_API ssContactRule ssDefaultContactRule(void);

/** Checks a rule as ssStepper_CollideByRule does before it collides (its fields and its surface's values).
 *  Errors: SS_ERROR_OUT_OF_RANGE (rule or a required field NULL, max_contacts or skip_connected out of range, a
 *  surface value out of its range), SS_ERROR_NOT_FINITE (a surface value NaN), each named. */
SS_API ssStatus ssValidateContactRule(const ssContactRule* rule);

/** In the stepper's collide callback, instead of dSpaceCollide with a near callback: collides rule->space
 *  (dSpaceCollide; a nested space with its partner, dSpaceCollide2) and, for every pair of geoms not both static
 *  (nor connected by a joint, with skip_connected), asks dCollide for up to max_contacts contacts; each gets the
 *  rule's surface and fdir1, is softened for the step about to be taken (ssStepper_SoftenContact: the rule's
 *  soft_erp/soft_cfm where its mode has them, else the world's, as tuned) and becomes a contact joint in
 *  contact_group attached to the geoms' bodies, in the order dSpaceCollide gives the pairs: the joints a near
 *  callback that does the same would make, bit for bit, with no call into the program per contact. report may be
 *  NULL. Like ssStepper_SoftenContact it needs the stepper's adoption (a tuned step).
 *  Errors, with no joint made: SS_ERROR_OUT_OF_RANGE (stepper, rule or a required field NULL, max_contacts or
 *  skip_connected out of range, a surface value out of its range, a body in the space of another world than
 *  rule->world, and those of ssStepper_SoftenContact: no tuned step, a tuned erp outside [0, 1] or cfm < 0);
 *  SS_ERROR_NOT_FINITE (a surface value NaN, or a tuned value not finite); SS_ERROR_OUT_OF_MEMORY. */
SS_API ssStatus ssStepper_CollideByRule(ssStepper* stepper, const ssContactRule* rule, ssContactRuleReport* report);

/** Adds a body to the known bodies: forces kept for the whole frame and checks at each step.
 *  Errors: SS_ERROR_OUT_OF_RANGE (NULL, or a body of another world), SS_ERROR_OUT_OF_MEMORY. */
SS_API ssStatus ssStepper_WatchBody(ssStepper* stepper, dBodyID body);

/** Stops watching a body; call it before dBodyDestroy. Errors: SS_ERROR_OUT_OF_RANGE (NULL), SS_ERROR_NOT_FOUND. */
SS_API ssStatus ssStepper_UnwatchBody(ssStepper* stepper, dBodyID body);

/** Destroys a body safely: stops watching it, removes its damping and auto-disable bindings from the registry,
 *  then calls dBodyDestroy. Use it instead of dBodyDestroy for any body the stepper knows: ODE gives no way to tell
 *  a destroyed body from a live one, so the stepper and the registry would read freed memory (a sanitizer build
 *  stops there with a report). The registry's bindings of the joints attached to it are removed too: ODE leaves
 *  those joints detached on one side, where some of its getters assert.
 *  Errors, with nothing destroyed: SS_ERROR_OUT_OF_RANGE (stepper or body NULL). */
SS_API ssStatus ssStepper_DestroyBody(ssStepper* stepper, dBodyID body);

/** Destroys a joint safely: removes its bindings from the registry, then calls dJointDestroy. Use it instead of
 *  dJointDestroy for a bound or adopted joint (contact joints in the contact group need nothing).
 *  Errors, with nothing destroyed: SS_ERROR_OUT_OF_RANGE (stepper or joint NULL). */
SS_API ssStatus ssStepper_DestroyJoint(ssStepper* stepper, dJointID joint);

/** Forgets the previous step length, so the next step of SS_MAPPING_EXACT maps the bodies' true velocities. Call it
 *  after teleporting a body or setting its velocity. NULL is a no-op. */
SS_API void ssStepper_ResetHistory(ssStepper* stepper);

/** Changes how frames become steps, between frames (resets the history and the FIXED accumulator). max_step_s and
 *  fixed_step_s of 0 are the stepper's tuned step.
 *  Errors, with nothing changed: those of ssValidateStepping; SS_ERROR_OUT_OF_RANGE for a NULL stepper or a step of
 *  0 with no tuned step; SS_ERROR_REENTERED from the stepper's own callback. */
SS_API ssStatus ssStepper_SetStepping(ssStepper* stepper, const ssStepping* stepping);

/** What the stepper's own adoption reached (def.space): at ssStepper_Create and since, summed (ssAdoptReport,
 *  adopt.h; all zero without a space). A NULL stepper gives all zero and records SS_ERROR_OUT_OF_RANGE. */
SS_API ssAdoptReport ssStepper_Adopted(const ssStepper* stepper);

/** How many bodies the stepper knows now (see the top): compare it with the bodies the program made to find one
 *  nothing reaches. -1 for a NULL stepper (SS_ERROR_OUT_OF_RANGE recorded) or when out of memory listing them. */
SS_API int ssStepper_KnownBodyCount(ssStepper* stepper);

/** The stepper's stepping. A NULL stepper gives ssDefaultStepping() and records SS_ERROR_OUT_OF_RANGE for
 *  ssLastError. */
SS_API ssStepping ssStepper_Stepping(const ssStepper* stepper);

#ifdef __cplusplus
}
#endif

#endif

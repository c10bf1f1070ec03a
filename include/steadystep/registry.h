/* steadystep: the registry of what is soft in an ODE world, rewritten for each step length.
 *
 * Register each soft thing once with its spring (or rate, in 1/s); before each step call ssRegistry_Apply with
 * that step's length and the registry writes ODE's per-step numbers: the world's ERP/CFM, every bound joint
 * parameter, body damping scales and auto-disable sample counts. ssStepper (stepper.h) does this for you.
 *
 * ODE copies the world's ERP/CFM into ball, fixed, double-ball, double-hinge and transmission joints (and hinge-2
 * suspension) when they are created, so a later dWorldSetERP does not reach them: bind each one. Hinge, slider,
 * universal, PR, PU and piston joints read the world's ERP/CFM at every step for their non-limit rows.
 *
 * Bindings hold ODE handles. A program that destroys a joint or a body must unbind it first. A bound parameter
 * belongs to the registry, which writes it only when its value changes: a program that sets one itself binds it
 * again to have it rewritten at the next Apply.
 */
#ifndef STEADYSTEP_REGISTRY_H
#define STEADYSTEP_REGISTRY_H

#include <ode/ode.h>

#include "steadystep/export.h"
#include "steadystep/spring.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct ssRegistry ssRegistry;

/** Which of a joint's soft parameter sets a binding drives. */
typedef enum ssJointParam {
  /* dParamERP + dParamCFM: the joint's own rows. Ball, fixed, double ball, double hinge, transmission. */
  SS_PARAM_JOINT = 0,
  /* dParamStopERP + dParamStopCFM: a joint limit (stop) on one axis. Hinge, slider, universal, hinge-2, PR, PU,
   * piston, angular motor, linear motor, plane-2D. A stop with dParamLoStop = dParamHiStop is a bilateral spring. */
  SS_PARAM_STOP = 1,
  /* dParamCFM of a limit/motor axis: the softness of the motor row away from the stops. A motor row has no
   * position error, so only cfm = 1/(h·k + c) is written (with k = 0: a damper of c toward the motor's velocity,
   * the same at every step length). Same joint types as SS_PARAM_STOP. */
  SS_PARAM_MOTOR = 2,
  /* dParamSuspensionERP + dParamSuspensionCFM: hinge-2 suspension along axis 1. */
  SS_PARAM_SUSPENSION = 3,
} ssJointParam;

/** Who served the rows or contacts of a step (or of a frame, summed over its steps). Each row or contact is counted
 *  once, in one of the three. */
typedef struct ssServedCounts {
  int by_mapping;               /* served by the stepping's own mapping (every one under implicit Euler) */
  int handed_to_matched;        /* exact only: served by matched (this step length gave exact no finite softness) */
  int handed_to_implicit_euler; /* matched/exact only: served by implicit Euler (above the step's Nyquist
                                 * frequency, undamped, no effective mass, a static stiffness off by more than
                                 * 5 % with no load declared, no finite softness; every contact) */
} ssServedCounts;

/** What one Apply did. */
typedef struct ssApplyReport {
  ssServedCounts rows; /* every bound row, the world's included, once */
  int row_writes;      /* parameter sets actually written into ODE (unchanged values are skipped) */
} ssApplyReport;

/** Creates an empty registry for world. Returns NULL when out of memory. */
SS_API ssRegistry* ssRegistry_Create(dWorldID world);

/** Destroys the registry. ODE objects are left as they are. NULL is a no-op. */
SS_API void ssRegistry_Destroy(ssRegistry* registry);

/** Binds the world's ERP and CFM (they soften the non-limit rows of hinge-like joints, and contacts that have no
 *  soft mode). effective_mass (kg, > 0) is needed only by the matched and exact mappings; pass 0 to use 1 kg.
 *  Errors: those of ssValidateSpring; SS_ERROR_NO_FINITE_MAPPING when implicit Euler gives the spring no softness
 *  ODE handles at some step in [SS_MIN_STEP_S, SS_MAX_STEP_S] (every mapping falls back to it, so a bound spring can
 *  always be written); SS_ERROR_OUT_OF_RANGE for a negative or non-finite effective_mass. */
SS_API ssStatus ssRegistry_BindWorld(ssRegistry* registry, ssSpring spring, double effective_mass);

/** Binds one soft parameter set of a joint on one axis (1, 2 or 3, as ODE's dParamGroup1..3; SS_PARAM_JOINT and
 *  SS_PARAM_SUSPENSION have axis 1 only). Binding the same joint, param and axis again replaces the first binding.
 *  effective_mass (kg, or kg·m² for an angular row) is what the matched and exact mappings need; pass 0 to have it
 *  computed at each Apply from the joint's bodies (ssJointEffectiveMass).
 *  Errors: SS_ERROR_UNSUPPORTED when the joint's type has no such parameter on that axis (ODE itself would ignore
 *  it silently), or for an unknown param; those of ssValidateSpring; SS_ERROR_NO_FINITE_MAPPING as
 *  ssRegistry_BindWorld; SS_ERROR_OUT_OF_RANGE for effective_mass < 0, a NULL registry or joint, or a joint
 *  attached to a body of another world than the registry's; SS_ERROR_OUT_OF_MEMORY. */
SS_API ssStatus ssRegistry_BindJoint(ssRegistry* registry, dJointID joint, ssJointParam param, int axis,
                                     ssSpring spring, double effective_mass);

/** Declares the steady load a bound row carries: a force (N) along a linear row or a torque (N·m) about an angular
 *  one, as it acts on the joint's first body in the axis' positive direction (a 1 kg body hanging on an upward
 *  slider: -9.81 N; a quarter of a chassis' weight on a hinge-2 suspension whose axis 1 points up: -m·g/4).
 *  Why: the matched and exact mappings choose erp and cfm for the right poles, which makes the row's static stiffness
 *  k' = erp/(h·cfm) differ from k, so under a load the rest position would be load/k' instead of load/k. With the
 *  load declared, every Apply under those mappings adds load·(k'/k - 1) along the row (the opposite to the second
 *  body) for the coming step, which puts the rest position back at load/k; for a lone spring under a constant load
 *  the exact mapping's samples are then exact again. The implicit-Euler mapping needs nothing (its k' is k). Call Apply
 *  once per step (the stepper does), since the force is added each time. Binding the row again clears the load.
 *  Errors: SS_ERROR_NOT_FINITE; SS_ERROR_OUT_OF_RANGE for |load| > SS_MAX_FORCE_N (limits.h), or a NULL registry;
 *  SS_ERROR_NOT_FOUND when that row is not bound; SS_ERROR_UNSUPPORTED for SS_PARAM_JOINT rows, which have no
 *  single direction. A row whose correction would exceed SS_MAX_FORCE_N at some step gets implicit Euler there
 *  (static stiffness k, no correction), counted as a fallback. */
SS_API ssStatus ssRegistry_SetJointLoad(ssRegistry* registry, dJointID joint, ssJointParam param, int axis,
                                        double load);

/** Removes every binding of joint. Call it before dJointDestroy. Errors: SS_ERROR_NOT_FOUND. */
SS_API ssStatus ssRegistry_UnbindJoint(ssRegistry* registry, dJointID joint);

/** Binds velocity damping as rates (1/s, >= 0): ODE multiplies velocity by (1 - scale) once per step, so the
 *  registry writes scale = 1 - exp(-rate·h), which removes the same fraction of velocity per second at every step
 *  length. body = NULL binds the world's default damping (dWorldSetLinearDamping/AngularDamping), which ODE copies
 *  into a body when the body is created: bind existing bodies one by one.
 *  Errors: SS_ERROR_NOT_FINITE, SS_ERROR_OUT_OF_RANGE (also a body of another world than the registry's),
 *  SS_ERROR_OUT_OF_MEMORY. */
SS_API ssStatus ssRegistry_BindDamping(ssRegistry* registry, dBodyID body, double linear_rate_per_s,
                                       double angular_rate_per_s);

/** Binds auto-disable in seconds: a body at rest for idle_time_s (> 0) is disabled, with its velocity averaged over
 *  average_window_s (>= 0; 0 = the current step only). ODE counts steps, so the registry writes
 *  AutoDisableSteps = ceil(idle/h), AutoDisableTime = idle and AverageSamplesCount = max(1, ceil(window/h)), at most
 *  SS_MAX_AVERAGE_SAMPLES (limits.h: ODE allocates the samples for every body).
 *  body = NULL binds the world's defaults (copied into bodies when they are created). The sample count is written
 *  only when it changes, because ODE restarts a body's velocity average whenever it is set. Enabling auto-disable
 *  and its thresholds stay the program's own choice.
 *  Errors: SS_ERROR_NOT_FINITE, SS_ERROR_OUT_OF_RANGE (also a body of another world than the registry's),
 *  SS_ERROR_OUT_OF_MEMORY. */
SS_API ssStatus ssRegistry_BindAutoDisable(ssRegistry* registry, dBodyID body, double idle_time_s,
                                           double average_window_s);

/** Removes the damping and auto-disable bindings of body. Call it before dBodyDestroy. Errors: SS_ERROR_NOT_FOUND. */
SS_API ssStatus ssRegistry_UnbindBody(ssRegistry* registry, dBodyID body);

/** Writes every binding for a step of step_s (s, in [SS_MIN_STEP_S, SS_MAX_STEP_S]) with the mapping.
 *  previous_step_s is the length of the step before (0 when there is none or after a teleport); only
 *  SS_MAPPING_EXACT reads it. A row that matched or exact cannot serve at this step (no effective mass, c = 0, a
 *  natural frequency above the step's Nyquist frequency, no finite softness, a load correction beyond
 *  SS_MAX_FORCE_N, or, with no load declared (ssRegistry_SetJointLoad), a matched static stiffness
 *  erp/(step_s·cfm) more than 5 % from k, or a pure damper's 1/cfm more than 5 % from c: an undeclared load would
 *  rest elsewhere than the spring puts it; docs/exact-mappings.md) is written with implicit Euler and counted.
 *  Either everything is written or, on an error, nothing is. report may be NULL. A sleeping body's damping and
 *  auto-disable are passed over (ODE steps none of it): a stepper writes them before the step the body wakes for;
 *  called directly, Apply writes them at its first call for another step length once the body is awake.
 *  Errors: SS_ERROR_NOT_FINITE, SS_ERROR_OUT_OF_RANGE (registry NULL, step_s, previous_step_s);
 *  SS_ERROR_UNSUPPORTED for an unknown mapping. */
SS_API ssStatus ssRegistry_Apply(ssRegistry* registry, ssMapping mapping, double step_s, double previous_step_s,
                                 ssApplyReport* report);

/** Number of bound joint parameter sets (not counting the world). */
SS_API int ssRegistry_JointBindingCount(const ssRegistry* registry);

/** Calls visit for every distinct body attached to a bound joint or bound for damping/auto-disable. */
SS_API void ssRegistry_VisitBodies(const ssRegistry* registry, void (*visit)(void* context, dBodyID body),
                                   void* context);

/** Whether the joint's type has that parameter set on that axis in ODE 0.16. */
SS_API int ssJointSupports(dJointID joint, ssJointParam param, int axis);

/** The effective mass (kg) or inertia (kg·m²) of a joint row: 1 / (J M⁻¹ Jᵀ) from the attached bodies' current
 *  mass and world-frame inertia, for the row that param/axis drives (slider and piston: translation along the axis;
 *  hinge, universal, angular motor: rotation about the axis; hinge-2 suspension: translation along axis 1).
 *  Errors: SS_ERROR_UNSUPPORTED (as ssRegistry_BindJoint), SS_ERROR_OUT_OF_RANGE when no dynamic body is attached. */
SS_API ssStatus ssJointEffectiveMass(dJointID joint, ssJointParam param, int axis, double* mass);

/** Fills contact->surface.soft_erp and soft_cfm from spring for a step of step_s and sets dContactSoftERP and
 *  dContactSoftCFM in surface.mode. Every mapping writes the implicit-Euler softness: matched and exact serve no
 *  contact, whose load is never known (a contact is made anew each step), whose bodies carry other contacts, and
 *  which exists only while it penetrates (docs/exact-mappings.md); body1, body2 (either may be 0 for the static
 *  world) and previous_step_s are therefore not read. Call it in the near callback that ssStepper hands the step
 *  length to.
 *  Errors: those of ssImplicitEulerSoftness; SS_ERROR_OUT_OF_RANGE (contact NULL, step_s or previous_step_s),
 *  SS_ERROR_UNSUPPORTED (unknown mapping), SS_ERROR_NOT_FINITE (the contact's position, normal or depth, as a
 *  collider made it: drop such a contact). On error contact is unchanged. */
SS_API ssStatus ssContactSoften(dContact* contact, dBodyID body1, dBodyID body2, ssSpring spring, ssMapping mapping,
                                double step_s, double previous_step_s);

#ifdef __cplusplus
}
#endif

#endif

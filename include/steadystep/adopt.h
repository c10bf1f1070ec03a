/* steadystep: adoption, a program's tuned ERP/CFM, damping and auto-disable taken over as they are.
 *
 * A program tuned its numbers at one step length (say 1/60 s). ssRegistry_Adopt reads them back from ODE, as the
 * program set them or as ODE's defaults left them (a double build's world CFM is 1e-10, its ERP 0.2), turns each
 * into what it stands for at that step, and binds it so that every later step of any length gets the same spring:
 *  - a row with erp in [0, 1] and cfm > 0 is the spring k = erp/(h0·cfm), c = (1 - erp)/cfm (erp = 0: a damper);
 *  - a row with cfm = 0 is hard, and stays hard: erp(h) = h·r/(h·r + 1) with r = erp/(h0·(1 - erp)), so its error
 *    is still corrected at the same rate per second (erp = 1 stays 1, erp = 0 stays 0);
 *  - a damping scale s (ODE removes the fraction s of a body's velocity every step) is the rate -ln(1 - s)/h0 per s;
 *  - auto-disable after N idle steps and T idle seconds is idle time max(N·h0, T); an average over S > 1 samples is
 *    a window of S·h0 seconds (at most SS_MAX_AVERAGE_SAMPLES samples are written, limits.h). A body that never
 *    samples (S = 0, which ODE never puts to sleep) or that sleeps at once (N = 0, T = 0) is so at every step: its
 *    auto-disable is left as it is.
 * At h0 itself (the implicit-Euler mapping at h0, as the naive policy frozen at the tuned step writes at every step;
 * hard rows and bodies under every mapping), the registry writes back the program's own numbers bit for bit: the
 * tuned erp/cfm, damping scales, idle steps, idle time (0 stays 0) and sample count, and ssStepper_SoftenContact
 * gives a contact the program's own soft_erp/soft_cfm (or the world's ERP). Adopted under naive, a program steps as
 * its own stepping does, to the last bit, at every frame rate.
 * What is adopted: the world's ERP/CFM (hinge, slider, universal, PR, PU and piston read them at every step, and
 * contacts without soft modes use them), the world's damping and auto-disable defaults, and for every joint
 * reachable from the space's geoms through bodies and joints: ball, fixed, double-ball, double-hinge and
 * transmission rows (dParamERP/CFM), every axis' stop (dParamStopERP/StopCFM) and motor (dParamCFM), and hinge-2
 * suspension. Every reachable body becomes known to the stepper (its forces are kept over a frame, its state is
 * checked), with its damping and auto-disable bound in seconds. Contact joints are transient and left alone (soften
 * contacts with ssStepper_SoftenContact); null joints have nothing soft; plane-2D joints cannot be read back in
 * ODE 0.16 (no getter), so they are counted as skipped: bind them with ssRegistry_BindJoint.
 *
 * Adopting is idempotent: a row or body already bound keeps its binding. Adopt objects created later one by one
 * (ssRegistry_AdoptBody, ssRegistry_AdoptJoint), or the whole space again. ODE copies the world's current ERP/CFM,
 * damping and auto-disable into a joint or body when it is created; since the registry rewrites those for each
 * step, a later object whose value is still the world's current one adopts the world's tuned spring or rate.
 */
#ifndef STEADYSTEP_ADOPT_H
#define STEADYSTEP_ADOPT_H

#include <ode/ode.h>

#include "steadystep/export.h"
#include "steadystep/registry.h"

#ifdef __cplusplus
extern "C" {
#endif

/** What an adoption call bound, by kind. Adoption calls add to the counts already in the report. */
typedef struct ssAdoptReport {
  int world;              /* 1 when the world's ERP/CFM were adopted */
  int joints;             /* joints adopted (at least one row bound, or nothing soft but known) */
  int joint_rows;         /* SS_PARAM_JOINT sets (ball, fixed, double ball, double hinge, transmission) */
  int stop_rows;          /* SS_PARAM_STOP sets, one per axis */
  int motor_rows;         /* SS_PARAM_MOTOR sets, one per axis */
  int suspension_rows;    /* SS_PARAM_SUSPENSION sets */
  int hard_rows;          /* of all rows above (world included), those tuned with cfm = 0, kept hard */
  int bodies;             /* bodies adopted: known to the stepper, damping and auto-disable bound in seconds */
  int skipped_joints;     /* contact, null and plane-2D joints */
} ssAdoptReport;

/** Adopts the world's ERP/CFM and its damping and auto-disable defaults, as tuned at tuned_step_s (s, in
 *  [SS_MIN_STEP_S, SS_MAX_STEP_S]), and everything reachable from space (nested spaces included): the one call a
 *  program makes after building its world. Sets the registry's tuned step, which later adoption calls and
 *  ssStepper_SoftenContact use. report may be NULL. Either everything is bound or, on an error, nothing is: every
 *  binding made before (by hand or by an earlier adoption, the world's included) is left as it was.
 *  Errors: SS_ERROR_OUT_OF_RANGE (registry or space NULL, tuned_step_s out of range, a tuned value outside its range,
 *  named with its joint or body, e.g. erp > 1, cfm < 0 or a cfm too large to stand for a spring, a tuned step
 *  different from an earlier adoption's, or a body reached, or a joint's body, of another world than the
 *  registry's); SS_ERROR_NO_FINITE_MAPPING (a tuned row that implicit Euler cannot
 *  write at every step length, see ssRegistry_BindWorld);
 *  SS_ERROR_NOT_FINITE; SS_ERROR_UNSUPPORTED (a joint of a type ODE 0.16 does not know); SS_ERROR_OUT_OF_MEMORY. */
SS_API ssStatus ssRegistry_Adopt(ssRegistry* registry, double tuned_step_s, dSpaceID space, ssAdoptReport* report);

/** Adopts the world's ERP/CFM and its damping and auto-disable defaults only (a program without a space, whose
 *  bodies are then adopted with ssRegistry_AdoptBody). Errors as ssRegistry_Adopt. */
SS_API ssStatus ssRegistry_AdoptWorld(ssRegistry* registry, double tuned_step_s, ssAdoptReport* report);

/** Adopts everything reachable from space, at the registry's tuned step.
 *  Errors as ssRegistry_Adopt; SS_ERROR_OUT_OF_RANGE when the world was not adopted first. */
SS_API ssStatus ssRegistry_AdoptSpace(ssRegistry* registry, dSpaceID space, ssAdoptReport* report);

/** Adopts a body and everything reachable from it through joints, at the registry's tuned step.
 *  Errors as ssRegistry_AdoptSpace. */
SS_API ssStatus ssRegistry_AdoptBody(ssRegistry* registry, dBodyID body, ssAdoptReport* report);

/** Adopts one joint's soft rows and its bodies (not what lies beyond them), at the registry's tuned step.
 *  Errors as ssRegistry_AdoptSpace. */
SS_API ssStatus ssRegistry_AdoptJoint(ssRegistry* registry, dJointID joint, ssAdoptReport* report);

/** The step length the registry's adopted values were tuned at (s); 0 before any adoption. */
SS_API double ssRegistry_TunedStep(const ssRegistry* registry);

#ifdef __cplusplus
}
#endif

#endif

/* Internal: what the stepper, Apply, soft contacts, adoption and following need from the registry beyond the public
 * API. The registry's layout is registry.c's alone. */
#ifndef STEADYSTEP_REGISTRY_INTERNAL_H
#define STEADYSTEP_REGISTRY_INTERNAL_H

#include <math.h>
#include <stdint.h>

#include "pointer_set.h"
#include "row_law.h"
#include "steadystep/limits.h"
#include "steadystep/registry.h"

#define REQUIRE_REGISTRY(registry) \
  if ((registry) == NULL) return ssFail(SS_ERROR_OUT_OF_RANGE, "registry = NULL: a registry is required")

/* What a program had set on a body (or as the world's defaults), read back by adoption: at the step they were tuned
 * for the registry writes these numbers as they were, since the rates and seconds that stand for them at every other
 * step give them back only to a rounding (and an idle time the program never set). */
typedef struct ssBodyTuned {
  double damping_step_s; /* > 0: the damping scales were read for steps of this length (s); 0: bound by hand */
  double linear_scale, angular_scale;
  double auto_disable_step_s; /* > 0: the auto-disable numbers were read for steps of this length (s) */
  double idle_time_s;
  int idle_steps;
  int average_samples;
} ssBodyTuned;

/* The numbers the registry writes into a body binding's body (or the world's defaults) for a step of step_s. */
typedef struct ssBodyWritten {
  double linear_scale, angular_scale; /* has_damping */
  double idle_time_s;                 /* has_auto_disable, with the two below */
  int idle_steps;
  int average_samples;
} ssBodyWritten;

/* A body's damping and auto-disable, given in seconds. body 0 holds the world's defaults. Laid out without padding
 * (136 bytes): adoption holds two of these a body, the plan's and the registry's. */
typedef struct ssBodyBinding {
  dBodyID body;
  double linear_rate_per_s, angular_rate_per_s;
  double idle_time_s, average_window_s;
  double written_step_s;       /* the step the values were last written for; NAN after a (re)binding */
  ssBodyWritten written;       /* what was written then, as computed (follow.c compares ODE's numbers with it) */
  ssBodyTuned tuned;           /* cleared by ssRegistry_BindDamping and ssRegistry_BindAutoDisable */
  int average_samples_written; /* ODE restarts its average whenever the count is set: write it only on change */
  unsigned char has_damping, has_auto_disable;
} ssBodyBinding;

/* What body's damping and auto-disable numbers in ODE (body 0: world's defaults) stand for when tuned at
 * tuned_step_s, as adoption binds them (adopt.c). what names the body in messages. Errors: those of adoption
 * (SS_ERROR_NOT_FINITE, SS_ERROR_OUT_OF_RANGE: a damping scale outside [0, 1), a negative idle time). */
ssStatus ssBodyValuesAsTuned(const char* what, dWorldID world, dBodyID body, double tuned_step_s, ssBodyBinding* out);

/* ODE counts steps: a count of seconds in steps of h, where a whole number of steps computed with rounding error
 * (10·(1/60)/(1/60) = 10.000000000000002) must not become one more. */
static inline double ssStepsIn(double seconds, double step_s) { return ceil(seconds / step_s - 1e-9); }

/* At the tuned step they are the tuned numbers. */
static inline void ssBodyWrittenFor(const ssBodyBinding* binding, double step_s, ssBodyWritten* out) {
  const ssBodyTuned* tuned = &binding->tuned;
  *out = (ssBodyWritten){0, 0, 0, 0, 0};
  if (binding->has_damping) {
    /* ODE scales velocity by (1 - scale) once per step: this scale removes the same fraction per second */
    int as_tuned = step_s == tuned->damping_step_s;
    out->linear_scale = as_tuned ? tuned->linear_scale : -expm1(-binding->linear_rate_per_s * step_s);
    out->angular_scale = as_tuned ? tuned->angular_scale : -expm1(-binding->angular_rate_per_s * step_s);
  }
  if (!binding->has_auto_disable) return;
  if (step_s == tuned->auto_disable_step_s) {
    out->idle_steps = tuned->idle_steps;
    out->idle_time_s = tuned->idle_time_s;
    out->average_samples = tuned->average_samples;
    return;
  }
  double steps = ssStepsIn(binding->idle_time_s, step_s);
  out->idle_steps = steps < INT32_MAX ? (int)steps : INT32_MAX;
  out->idle_time_s = binding->idle_time_s;
  /* ODE allocates two vectors a sample for every body: bounded, see SS_MAX_AVERAGE_SAMPLES */
  double samples = fmax(1.0, ssStepsIn(binding->average_window_s, step_s));
  out->average_samples = samples < SS_MAX_AVERAGE_SAMPLES ? (int)samples : SS_MAX_AVERAGE_SAMPLES;
}

/* The program stays in charge (follow.c): every adopted value the registry writes for each step (the world's
 * ERP/CFM, each joint row, each body's damping and auto-disable, as adoption read them or as followed since) that ODE
 * holds otherwise than the registry last wrote it was written by the program since, and is taken as newly tuned at
 * the registry's tuned step: bound again as what it stands for, so that every step length writes what the program's
 * value means. A spring the program bound itself (ssRegistry_BindJoint, ...) it changes by binding again: not read. *followed (may be NULL) counts the values taken. Nothing is changed on an error.
 * Errors, naming the value: those of adoption for a value no spring stands for (erp outside [0, 1], cfm < 0, a
 * damping scale outside [0, 1), ...), SS_ERROR_NO_FINITE_MAPPING. with_bodies = 0 leaves the bodies' numbers
 * unread: where every Apply writes for the tuned step (a softness frozen there), what ODE holds is the tuned numbers
 * or the program's, both meant for that step, and Apply rewrites neither; a later Apply for another step follows
 * first. */
ssStatus ssRegistryFollowProgram(ssRegistry* registry, int with_bodies, int* followed);

/* ssRegistryFollowProgram for the bodies of woken[count] that just woke (the others are passed over): a damping or
 * auto-disable the program set while one slept, which neither Apply nor the follow of every frame reads, is taken as
 * newly tuned before the body is written for its step (ssRegistryWriteWoken). *followed counts them. Errors, with
 * nothing changed: those of ssRegistryFollowProgram. */
ssStatus ssRegistryFollowWoken(ssRegistry* registry, const dBodyID* woken, int count, int* followed);

/* A number that changes whenever a joint or body is bound or unbound: the stepper rebuilds its list on a change. */
unsigned ssRegistryGeneration(const ssRegistry* registry);

/* The number of bodies bound for damping or auto-disable (the world's defaults included). */
int ssRegistryBodyBindingCount(const ssRegistry* registry);

/* Binds the world's rows, or one joint row, to a law (checked by the caller). */
void ssRegistryBindWorldLaw(ssRegistry* registry, ssRowLaw law, double effective_mass);
ssStatus ssRegistryBindJointLaw(ssRegistry* registry, dJointID joint, ssJointParam param, int axis, ssRowLaw law,
                                double effective_mass);
/* Adoption's commit, after ssRegistryReserve made the room: appends a row or a body known not to be bound (the
 * joint's type read already, the body's binding whole), without looking either up again. */
void ssRegistryAppendJointLaw(ssRegistry* registry, dJointID joint, int joint_type, ssJointParam param, int axis,
                              ssRowLaw law);
void ssRegistryAppendBody(ssRegistry* registry, const ssBodyBinding* binding);
int ssRegistryHasJoint(const ssRegistry* registry, dJointID joint);
/* Unbinds every joint row whose joint is not in alive, reading none of them (a joint the program destroyed with
 * dJointDestroy is freed memory); returns the rows unbound. */
int ssRegistryUnbindJointsNotIn(ssRegistry* registry, const ssPointerSet* alive);
int ssRegistryHasJointRow(ssRegistry* registry, dJointID joint, ssJointParam param, int axis);

/* The body's binding (0: the world's defaults), or NULL. */
ssBodyBinding* ssRegistryFindBody(ssRegistry* registry, dBodyID body);
int ssRegistryHasBody(ssRegistry* registry, dBodyID body);

/* The world's law, when bound. */
int ssRegistryWorldBound(const ssRegistry* registry, ssRowLaw* law);

/* The registry's world. */
dWorldID ssRegistryWorld(const ssRegistry* registry);

/* Makes room for more bindings, so that adoption binds all or nothing. Errors: SS_ERROR_OUT_OF_MEMORY. */
ssStatus ssRegistryReserve(ssRegistry* registry, int more_joints, int more_bodies);

/* Adoption's tuned step and the world's ERP/CFM as adopted. */
void ssRegistrySetTuned(ssRegistry* registry, double tuned_step_s, ssSoftness tuned_world);
ssSoftness ssRegistryTunedWorld(const ssRegistry* registry);

/* One bound joint row as the program (or adoption) bound it: all the registry keeps of a row. What Apply derives
 * from it (what it wrote, masses, softnesses, its caches) is Apply's own (apply.c). */
typedef struct ssJointRowBinding {
  dJointID joint;
  ssRowLaw law;
  double effective_mass; /* 0: measured from the bodies */
  double load;           /* 0: none declared */
  /* changes whenever the row is bound (again): a row bound after an Apply is written at the next one whatever ODE
   * holds; never 0, and larger than every stamp given before (ssRegistryLastStamp) */
  unsigned stamp;
  int joint_type; /* dJointGetType at bind time: a joint's type never changes */
  ssJointParam param;
  int axis;
} ssJointRowBinding;

/* The i-th bound joint row (0 <= i < ssRegistry_JointBindingCount), in the order Apply writes them. Binding keeps the
 * order of the rows it does not touch: rows bound anew are appended, rebound in place, unbound ones removed. */
const ssJointRowBinding* ssRegistryJointRowAt(const ssRegistry* registry, int i);

/* The largest stamp given to a binding so far (0: none). */
unsigned ssRegistryLastStamp(const ssRegistry* registry);

/* A number that changes whenever any binding does (a row, its load, the world, a body, the tuned step): an Apply at
 * the step it last wrote writes again after a change. */
unsigned ssRegistryRevision(const ssRegistry* registry);

/* A number that changes whenever a joint row's or the world's binding does (a row, its load, the world, the tuned
 * step), not a body's: Apply's rows, built from these, are built again on a change. */
unsigned ssRegistryRowsRevision(const ssRegistry* registry);

/* The i-th row takes law as the program's newly tuned one (follow.c): not a new binding (what Apply last wrote stays
 * what it compares with), but a change of the bindings. */
void ssRegistryFollowJointLaw(ssRegistry* registry, int i, ssRowLaw law);
/* The world's rows take law, the world's ERP/CFM as the program wrote them (contacts without soft modes too). */
void ssRegistryFollowWorldLaw(ssRegistry* registry, ssRowLaw law);
/* The i-th body binding becomes binding, as adoption read it from what the program set. */
void ssRegistryFollowBody(ssRegistry* registry, int i, const ssBodyBinding* binding);

/* The i-th body binding (0 <= i < ssRegistryBodyBindingCount). */
ssBodyBinding* ssRegistryBodyAt(ssRegistry* registry, int i);

/* The effective mass the world's rows are bound with (kg; 1 when none was given). */
double ssRegistryWorldMass(const ssRegistry* registry);

/* Writes every body binding whose values were written for another step than step_s (Apply's last part). */
void ssRegistryWriteBodies(ssRegistry* registry, double step_s);

/* Writes, for a step of step_s, the bindings of those of bodies[count] that are bound and written for another step:
 * bodies that woke since Apply last wrote, or that ODE wakes in this step through a joint (ssRegistryWriteBodies
 * leaves a sleeping body as it is, and Apply writes nothing at a step it wrote already). A body not bound is passed
 * over. */
void ssRegistryWriteWoken(ssRegistry* registry, const dBodyID* bodies, int count, double step_s);

/* What another room derives from the bindings and keeps with the registry (Apply's state, apply.c): the registry
 * holds it, frees it with free_state when it is destroyed, and never reads it. */
typedef struct ssRegistryAttachment {
  void* state;
  void (*free_state)(void* state);
} ssRegistryAttachment;
ssRegistryAttachment* ssRegistryApplyAttachment(ssRegistry* registry);

/* The last contact's softness, for the contacts that follow with the same numbers. A program softens every contact
 * of a step with one or a few surfaces: a contact whose tuned erp/cfm, tuned step, mapping and step are the last
 * one's reuses its law and its softness (which depends on the step alone: every mapping serves a contact with
 * implicit Euler, contact.c), with no conversion and no check repeated: they were made, and passed, for the same
 * inputs. */
typedef struct ssContactCache {
  double tuned_erp, tuned_cfm, tuned_step_s; /* NAN: empty */
  ssRowLaw law;
  ssMapping mapping;
  double step_s;
  int has_softness;
  ssSoftness softness;
  ssRowFallback handed_on;
} ssContactCache;

/* An empty cache. */
ssContactCache ssContactCacheEmpty(void);

/* Softens contact as the law that tuned_erp and tuned_cfm stand for at tuned_step_s (ssRowLawFromTuned), for a step
 * of step_s under mapping, through the cache; *handed_on (may be NULL) says whether an accurate mapping handed the
 * contact on to implicit Euler (it always does: exact_to_matched is never set). No contact's softness depends on its
 * bodies or on the step before (contact.c). Errors, with contact unchanged: those of ssRowLawFromTuned and
 * ssContactSoften. */
ssStatus ssContactSoftenCached(ssContactCache* cache, dContact* contact, double tuned_erp, double tuned_cfm,
                               double tuned_step_s, ssMapping mapping, double step_s, ssRowFallback* handed_on);

#endif

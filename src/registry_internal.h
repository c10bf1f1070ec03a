/* Internal: what the stepper, soft contacts and adoption need from the registry beyond the public API. */
#ifndef STEADYSTEP_REGISTRY_INTERNAL_H
#define STEADYSTEP_REGISTRY_INTERNAL_H

#include "row_law.h"
#include "steadystep/registry.h"

/* A body's damping and auto-disable, given in seconds. body 0 holds the world's defaults. */
typedef struct ssBodyBinding {
  dBodyID body;
  int has_damping;
  double linear_rate_per_s, angular_rate_per_s;
  int has_auto_disable;
  double idle_time_s, average_window_s;
  int average_samples_written; /* ODE restarts its average whenever the count is set: write it only on change */
  double written_step_s;       /* the step the values were last written for; NAN after a (re)binding */
} ssBodyBinding;

/* A number that changes whenever a joint or body is bound or unbound: the stepper rebuilds its list on a change. */
unsigned ssRegistryGeneration(const ssRegistry* registry);

/* The number of bodies bound for damping or auto-disable (the world's defaults included). */
int ssRegistryBodyBindingCount(const ssRegistry* registry);

/* Binds the world's rows, or one joint row, to a law (checked by the caller). */
void ssRegistryBindWorldLaw(ssRegistry* registry, ssRowLaw law, double effective_mass);
ssStatus ssRegistryBindJointLaw(ssRegistry* registry, dJointID joint, ssJointParam param, int axis, ssRowLaw law,
                                double effective_mass);
int ssRegistryHasJoint(const ssRegistry* registry, dJointID joint);
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
/* Undoes ssRegistry_AdoptWorld, when the rest of an adoption failed. */
void ssRegistryForgetWorldAdoption(ssRegistry* registry);

/* ssContactSoften for a law, without checking its arguments; *fallback (may be NULL) says whether the accurate
 * mapping handed the contact on (to matched, or to implicit Euler). */
ssStatus ssContactSoftenLaw(dContact* contact, dBodyID body1, dBodyID body2, const ssRowLaw* law, ssMapping mapping,
                            double step_s, double previous_step_s, ssRowFallback* fallback);

#endif

/* Soft contacts: a contact's normal row as a spring, softened for each step in the near callback. */
#include <math.h>

#include "error.h"
#include "joint_rows.h"
#include "registry_internal.h"
#include "steadystep/registry.h"

ssStatus ssContactSoften(dContact* contact, dBodyID body1, dBodyID body2, ssSpring spring, ssMapping mapping,
                         double step_s, double previous_step_s) {
  if (contact == NULL) return ssFail(SS_ERROR_OUT_OF_RANGE, "contact = NULL: a contact is required");
  double mass = 1.0; /* unused by the spring mapping */
  if (mapping != SS_MAPPING_SPRING) {
    const dContactGeom* geom = &contact->geom;
    mass = ssRowEffectiveMass(body1, body2, geom->normal, geom->pos, 0);
    if (!(mass > 0) || !isfinite(mass))
      return ssFail(SS_ERROR_OUT_OF_RANGE, "contact at (%g, %g, %g): no dynamic body, so no effective mass",
                    geom->pos[0], geom->pos[1], geom->pos[2]);
  }
  ssSoftness softness;
  int fell_back;
  ssStatus status = ssSoftnessOrMatched(mapping, spring, mass, step_s, previous_step_s, &fell_back, &softness);
  if (status != SS_OK) return status;
  contact->surface.mode |= dContactSoftERP | dContactSoftCFM;
  contact->surface.soft_erp = softness.erp;
  contact->surface.soft_cfm = softness.cfm;
  return SS_OK;
}

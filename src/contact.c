/* Soft contacts: a contact's normal row as a spring, softened for each step in the near callback. */
#include <math.h>

#include "error.h"
#include "ode_bounds.h"
#include "joint_rows.h"
#include "registry_internal.h"
#include "row_law.h"
#include "steadystep/registry.h"

/* The effective mass along the contact normal; NAN when no dynamic body touches it. */
static double contactMass(const dContact* contact, dBodyID body1, dBodyID body2) {
  double mass = ssRowEffectiveMass(body1, body2, contact->geom.normal, contact->geom.pos, 0);
  return mass > 0 && isfinite(mass) ? mass : NAN;
}

ssStatus ssContactSoftenLaw(dContact* contact, dBodyID body1, dBodyID body2, const ssRowLaw* law, ssMapping mapping,
                            double step_s, double previous_step_s, ssRowFallback* handed_on) {
  double mass = mapping == SS_MAPPING_IMPLICIT_EULER || law->hard ? NAN : contactMass(contact, body1, body2);
  ssSoftness softness;
  ssRowFallback fallback;
  ssStatus status = ssRowSoftness(law, mapping, mass, step_s, previous_step_s, &fallback, &softness);
  if (status == SS_OK) status = ssCheckSoftnessForOde("contact", softness.erp, softness.cfm);
  if (status != SS_OK) return status;
  contact->surface.mode |= dContactSoftERP | dContactSoftCFM;
  contact->surface.soft_erp = softness.erp;
  contact->surface.soft_cfm = softness.cfm;
  if (handed_on != NULL) *handed_on = fallback;
  return SS_OK;
}

ssStatus ssContactSoften(dContact* contact, dBodyID body1, dBodyID body2, ssSpring spring, ssMapping mapping,
                         double step_s, double previous_step_s) {
  if (contact == NULL) return ssFail(SS_ERROR_OUT_OF_RANGE, "contact = NULL: a contact is required");
  if (ssMappingName(mapping) == NULL) return ssFail(SS_ERROR_UNSUPPORTED, "mapping = %d: unknown", (int)mapping);
  ssStatus status = ssValidateSpring(spring);
  if (status == SS_OK) status = ssCheckStepLength("step_s", step_s);
  if (status == SS_OK && previous_step_s != 0) status = ssCheckStepLength("previous_step_s", previous_step_s);
  if (status != SS_OK) return status;
  ssRowLaw law = ssRowLawOfSpring(spring);
  return ssContactSoftenLaw(contact, body1, body2, &law, mapping, step_s, previous_step_s, NULL);
}

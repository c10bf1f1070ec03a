/* Soft contacts: a contact's normal row as a spring, softened for each step in the near callback. */
#include <math.h>
#include <string.h>

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

/* The softness of a law for one contact whose mass (NAN where the mapping does not read it) is known: computed and
 * checked against what ODE takes; *handed_on says whether the accurate mapping handed it on. */
static ssStatus contactSoftness(const ssRowLaw* law, ssMapping mapping, double mass, double step_s,
                                double previous_step_s, ssSoftness* softness, ssRowFallback* handed_on) {
  ssStatus status = ssRowSoftness(law, mapping, mass, step_s, previous_step_s, handed_on, softness);
  if (status == SS_OK) status = ssCheckSoftnessForOde("contact", softness->erp, softness->cfm);
  return status;
}

static void writeSoftness(dContact* contact, ssSoftness softness) {
  contact->surface.mode |= dContactSoftERP | dContactSoftCFM;
  contact->surface.soft_erp = softness.erp;
  contact->surface.soft_cfm = softness.cfm;
}

/* Whether the softness of law under mapping reads the contact's effective mass. */
static int readsMass(const ssRowLaw* law, ssMapping mapping) {
  return mapping != SS_MAPPING_IMPLICIT_EULER && !law->hard;
}

/* ssContactSoften for a law, its arguments checked. */
static ssStatus softenByLaw(dContact* contact, dBodyID body1, dBodyID body2, const ssRowLaw* law, ssMapping mapping,
                            double step_s, double previous_step_s) {
  double mass = readsMass(law, mapping) ? contactMass(contact, body1, body2) : NAN;
  ssSoftness softness;
  ssRowFallback fallback;
  ssStatus status = contactSoftness(law, mapping, mass, step_s, previous_step_s, &softness, &fallback);
  if (status != SS_OK) return status;
  writeSoftness(contact, softness);
  return SS_OK;
}

ssContactCache ssContactCacheEmpty(void) {
  ssContactCache cache;
  memset(&cache, 0, sizeof cache);
  cache.tuned_erp = cache.tuned_cfm = cache.tuned_step_s = NAN;
  return cache;
}

ssStatus ssContactSoftenCached(ssContactCache* cache, dContact* contact, dBodyID body1, dBodyID body2,
                               double tuned_erp, double tuned_cfm, double tuned_step_s, ssMapping mapping,
                               double step_s, double previous_step_s, ssRowFallback* handed_on) {
  if (tuned_erp != cache->tuned_erp || tuned_cfm != cache->tuned_cfm || tuned_step_s != cache->tuned_step_s) {
    ssRowLaw law;
    ssStatus status = ssRowLawFromTuned("contact", tuned_erp, tuned_cfm, tuned_step_s, &law);
    if (status != SS_OK) return status;
    *cache = ssContactCacheEmpty();
    cache->tuned_erp = tuned_erp;
    cache->tuned_cfm = tuned_cfm;
    cache->tuned_step_s = tuned_step_s;
    cache->law = law;
  }
  if (mapping != SS_MAPPING_EXACT) previous_step_s = 0; /* read by the exact mapping alone */
  double mass = readsMass(&cache->law, mapping) ? contactMass(contact, body1, body2) : NAN;
  /* NAN == NAN is false: a mass is compared only where it is read */
  int same = cache->has_softness && mapping == cache->mapping && step_s == cache->step_s &&
             previous_step_s == cache->previous_step_s && (isnan(mass) ? isnan(cache->mass) : mass == cache->mass);
  if (!same) {
    ssSoftness softness;
    ssRowFallback fallback;
    ssStatus status = contactSoftness(&cache->law, mapping, mass, step_s, previous_step_s, &softness, &fallback);
    if (status != SS_OK) return status;
    cache->has_softness = 1;
    cache->mapping = mapping;
    cache->step_s = step_s;
    cache->previous_step_s = previous_step_s;
    cache->mass = mass;
    cache->softness = softness;
    cache->handed_on = fallback;
  }
  writeSoftness(contact, cache->softness);
  if (handed_on != NULL) *handed_on = cache->handed_on;
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
  return softenByLaw(contact, body1, body2, &law, mapping, step_s, previous_step_s);
}

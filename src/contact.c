/* Soft contacts: a contact's normal row as a spring, softened for each step in the near callback. */
#include <math.h>
#include <string.h>

#include "error.h"
#include "ode_bounds.h"
#include "registry_internal.h"
#include "row_law.h"
#include "steadystep/registry.h"

/* Why the accurate mappings serve no contact (the rule of row_law.c, applied to contacts).
 *
 * matched and exact reproduce one row's homogeneous motion; a load the row carries rests at F/k' instead of F/k
 * unless it is declared and corrected, and the motion is the row's own only where its effective mass is the mass
 * of the mode. A contact meets neither condition in the programs that have contacts:
 *  - its load is never known. ODE makes every contact anew each step, so nothing can be declared for it, and no
 *    joint feedback of the previous step belongs to it (the program creates the joint after this call; contacts
 *    have no identity from one step to the next to carry a measured force over). A resting contact carries the
 *    weight above it: under the accurate mappings the lab's stack stood 4 mm higher than F/k puts it.
 *  - it is never alone. A box stands on four points, a brick in a wall touches its neighbours, a ball lands on
 *    the floor while it pushes bricks: the contacts share bodies, and one point's effective mass (with its angular
 *    terms) is not the mass of the mode they move together. The exact mapping's history (the slope of the last
 *    step as the row's own velocity) breaks at every impact, where a contact appears.
 *  - a contact row is one-sided and exists only while it penetrates: the linear motion both mappings reproduce
 *    holds for part of a bounce at most.
 * And a scene of many contacts is chaotic enough (a wall knocked over, a stack's stick-slip) that serving even a
 * few contacts otherwise than implicit Euler moves every quantity by as much as the mapping could gain: in the
 * lab's wall, serving the ball's landing (26 contact-steps of 35 000, each with k'/k within 4 %) made the wall's
 * displacement 1.06 and the ball's x 1.15 times implicit Euler's deviation at fixed:60. So under MATCHED and
 * EXACT every contact is served by implicit Euler and counted as handed to it (no effective mass is measured,
 * and the softness depends on the step alone, which the cache below reuses); the accurate mappings keep the
 * rows where one spring dominates one body (row_law.c's rule). */

/* The softness of a law for one contact: implicit Euler's for this step under every mapping, computed and checked
 * against what ODE takes; *handed_on says whether an accurate mapping was asked for and handed the contact on. */
static ssStatus contactSoftness(const ssRowLaw* law, ssMapping mapping, double step_s, ssSoftness* softness,
                                ssRowFallback* handed_on) {
  ssStatus status = ssRowSoftness(law, SS_MAPPING_IMPLICIT_EULER, NAN, step_s, 0, 0, NULL, softness);
  if (status == SS_OK) status = ssCheckSoftnessForOde("contact", softness->erp, softness->cfm);
  *handed_on = (ssRowFallback){0, 0};
  handed_on->to_implicit_euler = !law->hard && (mapping == SS_MAPPING_MATCHED || mapping == SS_MAPPING_EXACT);
  return status;
}

static void writeSoftness(dContact* contact, ssSoftness softness) {
  contact->surface.mode |= dContactSoftERP | dContactSoftCFM;
  contact->surface.soft_erp = softness.erp;
  contact->surface.soft_cfm = softness.cfm;
}

/* A contact ODE's own colliders made, checked before it becomes a joint: a contact whose position, normal or depth is
 * not finite (ODE 0.16's sphere-cylinder collider makes one) would carry the NaN into the step. */
static ssStatus checkContactGeometry(const dContact* contact) {
  const dContactGeom* geom = &contact->geom;
  const char* bad = NULL;
  for (int i = 0; i < 3 && bad == NULL; ++i)
    bad = !isfinite(geom->pos[i]) ? "position" : !isfinite(geom->normal[i]) ? "normal" : NULL;
  if (bad == NULL && !isfinite(geom->depth)) bad = "depth";
  if (bad == NULL) return SS_OK;
  return ssFail(SS_ERROR_NOT_FINITE, "contact between geoms %p and %p: %s not finite (position (%g, %g, %g) m, "
                "normal (%g, %g, %g), depth %g m): drop it instead of creating its joint",
                (void*)geom->g1, (void*)geom->g2, bad, geom->pos[0], geom->pos[1], geom->pos[2], geom->normal[0],
                geom->normal[1], geom->normal[2], geom->depth);
}

/* ssContactSoften for a law, its arguments checked. */
static ssStatus softenByLaw(dContact* contact, const ssRowLaw* law, ssMapping mapping, double step_s) {
  ssSoftness softness;
  ssRowFallback fallback;
  ssStatus status = contactSoftness(law, mapping, step_s, &softness, &fallback);
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

ssStatus ssContactSoftenCached(ssContactCache* cache, dContact* contact, double tuned_erp, double tuned_cfm,
                               double tuned_step_s, ssMapping mapping, double step_s, ssRowFallback* handed_on) {
  ssStatus checked = checkContactGeometry(contact);
  if (checked != SS_OK) return checked;
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
  int same = cache->has_softness && mapping == cache->mapping && step_s == cache->step_s;
  if (!same) {
    ssSoftness softness;
    ssRowFallback fallback;
    ssStatus status = contactSoftness(&cache->law, mapping, step_s, &softness, &fallback);
    if (status != SS_OK) return status;
    cache->has_softness = 1;
    cache->mapping = mapping;
    cache->step_s = step_s;
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
  if (status == SS_OK) status = checkContactGeometry(contact);
  if (status != SS_OK) return status;
  ssRowLaw law = ssRowLawOfSpring(spring);
  (void)body1, (void)body2;
  return softenByLaw(contact, &law, mapping, step_s);
}

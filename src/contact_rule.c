/* A program's near callback as a rule applied in C (ssStepper_CollideByRule): every contact of a step made, softened
 * and joined without a call into the program per contact, which is what a Python program's contacts cost.
 *
 * One call collides the rule's space in two passes. The first runs dSpaceCollide and keeps every contact dCollide
 * makes, with its bodies, in a buffer, and checks what the rule cannot take (a body of another world); the second
 * softens each contact for the step (ssStepper_SoftenContact, which counts it in the frame's report) and makes its
 * joint, in the order of the first pass: the order a near callback that makes each joint at once would give. So
 * every refusal comes before the first joint. The softness of a contact depends on the rule's surface, the world's
 * tuned numbers and the step alone, the same for every contact of the call: if the first contact is softened, all
 * are (the stepper's cache gives the same softness); only a contact's geometry differs, which is checked first. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "error.h"
#include "steadystep/stepper.h"

/* A contact dCollide made, with the bodies of its geoms. */
typedef struct RuleContact {
  dContact contact;
  dBodyID body1, body2;
} RuleContact;

typedef struct RulePass {
  const ssContactRule* rule;
  RuleContact* contacts;
  int count, capacity;
  int pairs;
  ssStatus status; /* the first failure: the rest of the pass does nothing */
} RulePass;

ssContactRule ssDefaultContactRule(void) {
  ssContactRule rule;
  memset(&rule, 0, sizeof rule);
  rule.max_contacts = 4;
  return rule;
}

static int finiteGeometry(const dContactGeom* geom) {
  for (int i = 0; i < 3; ++i)
    if (!isfinite(geom->pos[i]) || !isfinite(geom->normal[i])) return 0;
  return isfinite(geom->depth);
}

/* A friction-like coefficient: in [0, infinity] (dInfinity is ODE's rigid friction). */
static ssStatus checkCoefficient(const char* name, double value) {
  if (isnan(value) || value < 0)
    return ssFail(isnan(value) ? SS_ERROR_NOT_FINITE : SS_ERROR_OUT_OF_RANGE,
                  "rule surface.%s = %g: must be in [0, infinity]", name, value);
  return SS_OK;
}

static ssStatus checkSurface(const dContact* surface_contact) {
  const dSurfaceParameters* surface = &surface_contact->surface;
  const struct {
    const char* name;
    double value;
  } coefficients[] = {{"mu", surface->mu}, {"mu2", surface->mu2}, {"rho", surface->rho}, {"rho2", surface->rho2},
                      {"rhoN", surface->rhoN}};
  for (size_t i = 0; i < sizeof coefficients / sizeof coefficients[0]; ++i) {
    ssStatus status = checkCoefficient(coefficients[i].name, coefficients[i].value);
    if (status != SS_OK) return status;
  }
  if (isnan(surface->bounce) || surface->bounce < 0 || surface->bounce > 1)
    return ssFail(isnan(surface->bounce) ? SS_ERROR_NOT_FINITE : SS_ERROR_OUT_OF_RANGE,
                  "rule surface.bounce = %g: must be in [0, 1]", surface->bounce);
  ssStatus status = ssCheckNonNegative("rule surface.bounce_vel", "m/s", surface->bounce_vel);
  if (status == SS_OK) status = ssCheckNonNegative("rule surface.slip1", "s/kg", surface->slip1);
  if (status == SS_OK) status = ssCheckNonNegative("rule surface.slip2", "s/kg", surface->slip2);
  if (status == SS_OK) status = ssCheckFinite("rule surface.motion1", "m/s", surface->motion1);
  if (status == SS_OK) status = ssCheckFinite("rule surface.motion2", "m/s", surface->motion2);
  if (status == SS_OK) status = ssCheckFinite("rule surface.motionN", "m/s", surface->motionN);
  for (int i = 0; i < 3 && status == SS_OK; ++i)
    status = ssCheckFinite("rule surface's fdir1", "", surface_contact->fdir1[i]);
  return status;
}

ssStatus ssValidateContactRule(const ssContactRule* rule) {
  if (rule == NULL) return ssFail(SS_ERROR_OUT_OF_RANGE, "rule = NULL: a rule is required");
  const char* missing = rule->world == 0           ? "world"
                        : rule->space == 0         ? "space"
                        : rule->contact_group == 0 ? "contact_group"
                        : rule->surface == NULL    ? "surface"
                                                   : NULL;
  if (missing != NULL) return ssFail(SS_ERROR_OUT_OF_RANGE, "rule.%s = NULL: required", missing);
  if (rule->max_contacts < 1 || rule->max_contacts > SS_MAX_RULE_CONTACTS)
    return ssFail(SS_ERROR_OUT_OF_RANGE, "rule.max_contacts = %d: must be in [1, %d]", rule->max_contacts,
                  SS_MAX_RULE_CONTACTS);
  if (rule->skip_connected != 0 && rule->skip_connected != 1)
    return ssFail(SS_ERROR_OUT_OF_RANGE, "rule.skip_connected = %d: must be 0 or 1", rule->skip_connected);
  return checkSurface(rule->surface);
}

/* Room for `more` contacts after the pass's count. */
static ssStatus reserve(RulePass* pass, int more) {
  if (pass->capacity - pass->count >= more) return SS_OK;
  int capacity = pass->capacity > 0 ? pass->capacity : 64;
  while (capacity - pass->count < more) {
    if (capacity > (1 << 24)) return ssFail(SS_ERROR_OUT_OF_MEMORY, "a step of more than %d contacts", 1 << 24);
    capacity *= 2;
  }
  RuleContact* grown = realloc(pass->contacts, (size_t)capacity * sizeof *grown);
  if (grown == NULL) return ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory for %d contacts", capacity);
  pass->contacts = grown;
  pass->capacity = capacity;
  return SS_OK;
}

static ssStatus checkBodyWorld(const ssContactRule* rule, dBodyID body) {
  if (body == 0 || dBodyGetWorld(body) == rule->world) return SS_OK;
  return ssFail(SS_ERROR_OUT_OF_RANGE, "body %p of world %p in rule.space: not of rule.world = %p", (void*)body,
                (void*)dBodyGetWorld(body), (void*)rule->world);
}

/* The first pass's near callback: a nested space is collided with its partner, a pair of geoms keeps its contacts. */
static void keepContacts(void* data, dGeomID geom1, dGeomID geom2) {
  RulePass* pass = data;
  if (pass->status != SS_OK) return;
  if (dGeomIsSpace(geom1) || dGeomIsSpace(geom2)) {
    dSpaceCollide2(geom1, geom2, data, keepContacts);
    return;
  }
  const ssContactRule* rule = pass->rule;
  dBodyID body1 = dGeomGetBody(geom1), body2 = dGeomGetBody(geom2);
  if (body1 == 0 && body2 == 0) return; /* two static geoms: a contact joint would join nothing */
  if ((pass->status = checkBodyWorld(rule, body1)) != SS_OK || (pass->status = checkBodyWorld(rule, body2)) != SS_OK)
    return;
  if (rule->skip_connected && body1 != 0 && body2 != 0 && dAreConnectedExcluding(body1, body2, dJointTypeContact))
    return;
  if ((pass->status = reserve(pass, rule->max_contacts)) != SS_OK) return;
  pass->pairs += 1;
  RuleContact* first = &pass->contacts[pass->count];
  int made = dCollide(geom1, geom2, rule->max_contacts, &first->contact.geom, (int)sizeof *first);
  for (int i = 0; i < made; ++i) {
    RuleContact* kept = &first[i];
    kept->contact.surface = rule->surface->surface;
    memcpy(kept->contact.fdir1, rule->surface->fdir1, sizeof kept->contact.fdir1);
    kept->body1 = body1;
    kept->body2 = body2;
  }
  pass->count += made;
}

ssStatus ssStepper_CollideByRule(ssStepper* stepper, const ssContactRule* rule, ssContactRuleReport* report) {
  if (report != NULL) memset(report, 0, sizeof *report);
  if (stepper == NULL) return ssFail(SS_ERROR_OUT_OF_RANGE, "stepper = NULL: a stepper is required");
  ssStatus status = ssValidateContactRule(rule);
  if (status != SS_OK) return status;
  RulePass pass = {rule, NULL, 0, 0, 0, SS_OK};
  dSpaceCollide(rule->space, &pass, keepContacts);
  status = pass.status;
  int made = 0, dropped = 0;
  for (int i = 0; i < pass.count && status == SS_OK; ++i) {
    RuleContact* kept = &pass.contacts[i];
    if (!finiteGeometry(&kept->contact.geom)) { /* ODE 0.16's sphere-cylinder collider makes such contacts */
      dropped += 1;
      continue;
    }
    /* fails, if at all, at the first contact (see the top): before any joint is made */
    status = ssStepper_SoftenContact(stepper, &kept->contact, kept->body1, kept->body2);
    if (status != SS_OK) break;
    dJointID joint = dJointCreateContact(rule->world, rule->contact_group, &kept->contact);
    dJointAttach(joint, kept->body1, kept->body2);
    made += 1;
  }
  if (report != NULL && status == SS_OK) *report = (ssContactRuleReport){pass.pairs, made, dropped};
  free(pass.contacts);
  return status;
}

/* The near callback shared by the scenes that touch the ground: every contact is softened by one spring for the
 * step the stepper is about to take, so contact softness follows the policy like every other soft row. */

#include <stdio.h>

#include "scene_internal.h"

typedef struct CollideCall {
  ssContactRecipe* recipe;
  ssStepInfo step;
} CollideCall;

static void nearCallback(void* data, dGeomID geom1, dGeomID geom2) {
  CollideCall* call = data;
  ssContactRecipe* recipe = call->recipe;
  dBodyID body1 = dGeomGetBody(geom1), body2 = dGeomGetBody(geom2);
  if (body1 == 0 && body2 == 0) return;  /* static against static: the ground and its bumps */
  /* Bodies held together by a joint (a wheel and its chassis) overlap by design. */
  if (body1 != 0 && body2 != 0 && dAreConnectedExcluding(body1, body2, dJointTypeContact)) return;

  dContact contacts[SS_MAX_PAIR_CONTACTS];
  int count = dCollide(geom1, geom2, recipe->max_contacts, &contacts[0].geom, sizeof contacts[0]);
  for (int i = 0; i < count; ++i) {
    dContact* contact = &contacts[i];
    contact->surface.mode = recipe->surface_mode;
    contact->surface.mu = recipe->mu;
    /* A contact ssContactSoften refuses (a spring ODE cannot take at this step, a collider's non-finite point) is
     * dropped and counted, never made: left as it is, its surface would be a hard contact, harder than the spring. */
    const ssStepInfo* step = &call->step;
    ssStatus status = ssContactSoften(contact, body1, body2, recipe->spring, step->mapping, step->softness_step_s,
                                      step->previous_step_s);
    if (status != SS_OK) {
      if (recipe->refused_count++ == 0)
        snprintf(recipe->refused_message, sizeof recipe->refused_message, "%s", ssLastError());
      continue;
    }
    if (contact->geom.depth > recipe->deepest_m) recipe->deepest_m = contact->geom.depth;
    dJointID joint = dJointCreateContact(recipe->world, recipe->contacts, contact);
    dJointAttach(joint, body1, body2);
    ++recipe->contact_count;
  }
}

void ssContactCollide(ssContactRecipe* recipe, const ssStepper* stepper) {
  recipe->deepest_m = 0;
  recipe->contact_count = 0;
  CollideCall call = {recipe, ssStepper_CurrentStep(stepper)};
  dSpaceCollide(recipe->space, &call, nearCallback);
}

/* The near callback of the scenes written as ODE programs: the surface as the program tuned it at 60 fps, then
 * ssStepper_SoftenContact turns it into the softness for the step about to be taken, as an adopted program does. */
typedef struct TunedCall {
  ssTunedContacts* recipe;
  ssStepper* stepper;
} TunedCall;

static void tunedNearCallback(void* data, dGeomID geom1, dGeomID geom2) {
  TunedCall* call = data;
  ssTunedContacts* recipe = call->recipe;
  dBodyID body1 = dGeomGetBody(geom1), body2 = dGeomGetBody(geom2);
  if ((body1 == 0 || !dBodyIsEnabled(body1)) && (body2 == 0 || !dBodyIsEnabled(body2))) return; /* both asleep */
  if (body1 != 0 && body2 != 0 && dAreConnectedExcluding(body1, body2, dJointTypeContact)) return;
  dContact contacts[SS_MAX_PAIR_CONTACTS];
  int count = dCollide(geom1, geom2, recipe->max_contacts, &contacts[0].geom, sizeof contacts[0]);
  for (int i = 0; i < count; ++i) {
    dContact* contact = &contacts[i];
    contact->surface.mode = recipe->surface_mode;
    contact->surface.mu = recipe->mu;
    contact->surface.soft_erp = recipe->soft_erp;
    contact->surface.soft_cfm = recipe->soft_cfm;
    /* The tuned values come from a validated spring and the registry was adopted: softening cannot fail. */
    ssStepper_SoftenContact(call->stepper, contact, body1, body2);
    dJointAttach(dJointCreateContact(recipe->world, recipe->contacts, contact), body1, body2);
  }
}

void ssTunedContactsCollide(ssTunedContacts* recipe, ssStepper* stepper) {
  TunedCall call = {recipe, stepper};
  dSpaceCollide(recipe->space, &call, tunedNearCallback);
}

double ssContactRefusedCheck(const ssContactRecipe* recipe, char* worst, size_t size) {
  if (recipe->refused_count == 0) return 0;
  ssBoundMessage(worst, size, "%d contacts refused by ssContactSoften, dropped; the first: %s", recipe->refused_count,
                 recipe->refused_message);
  return SS_CONTACT_REFUSED_BOUND_USE;
}

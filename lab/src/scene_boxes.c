/* Boxes of one size on a ground plane with soft contacts: what the drop and pile scenes share. They differ only in
 * where the boxes start and what they sample.
 *
 * Their sanity bound, a box's lowest corner below the floor, is checked here; each scene gives its depth bound (as a
 * fraction of the box's half side) and the reason for it. */
#include <math.h>
#include <stdlib.h>

#include "lab_error.h"
#include "scene_internal.h"

ssStatus ssBoxesCreate(const ssSceneWorld* world, const ssSceneParams* params, const char* scene, ssBoxes** out) {
  ssBoxes* boxes = calloc(1, sizeof *boxes);
  dBodyID* bodies = calloc((size_t)params->body_count, sizeof *bodies);
  if (boxes == NULL || bodies == NULL) {
    free(boxes);
    free(bodies);
    return ssLabFail(SS_ERROR_OUT_OF_MEMORY, "%s: out of memory for %d boxes", scene, params->body_count);
  }
  boxes->bodies = bodies;
  dWorldSetGravity(world->world, 0, 0, -params->gravity);
  dCreatePlane(world->space, 0, 0, 1, 0);
  boxes->recipe = (ssContactRecipe){.world = world->world,
                                    .space = world->space,
                                    .contacts = world->contacts,
                                    .spring = params->spring,
                                    .max_contacts = 4,
                                    .surface_mode = dContactApprox1,
                                    .mu = 0.5};
  *out = boxes;
  return SS_OK;
}

void ssBoxesAdd(ssBoxes* boxes, const ssSceneWorld* world, double mass_kg, double side_m, double x, double y,
                 double z) {
  dBodyID box = dBodyCreate(world->world);
  dMass mass;
  dMassSetBoxTotal(&mass, mass_kg, side_m, side_m, side_m);
  dBodySetMass(box, &mass);
  dBodySetPosition(box, x, y, z);
  dGeomID geom = dCreateBox(world->space, side_m, side_m, side_m);
  dGeomSetBody(geom, box);
  boxes->bodies[boxes->count++] = box;
}

ssStatus ssBoxesWatch(void* state, ssStepper* stepper) {
  ssBoxes* boxes = state;
  for (int i = 0; i < boxes->count; ++i) {
    ssStatus status = ssStepper_WatchBody(stepper, boxes->bodies[i]);
    if (status != SS_OK) return status;
  }
  return SS_OK;
}

void ssBoxesCollide(void* context, ssStepper* stepper) {
  ssBoxes* boxes = context;
  ssContactCollide(&boxes->recipe, stepper);
}

void ssBoxesDestroy(void* state) {
  ssBoxes* boxes = state;
  free(boxes->bodies);
  free(boxes);
}

double ssBoxDepth(dBodyID box, double side_m) {
  const dReal* position = dBodyGetPosition(box);
  const dReal* rotation = dBodyGetRotation(box);
  /* The half extents projected on world z: the third row of the rotation, weighted by the half side. */
  return 0.5 * side_m * (fabs(rotation[8]) + fabs(rotation[9]) + fabs(rotation[10])) - position[2];
}

double ssBoxesCheck(const ssBoxes* boxes, double side_m, double of_half_side, char* worst, size_t size) {
  double refused = ssContactRefusedCheck(&boxes->recipe, worst, size);
  if (refused > 0) return refused;
  const double bound_m = of_half_side * 0.5 * side_m;
  double deepest_m = -INFINITY;
  int deepest = 0;
  for (int i = 0; i < boxes->count; ++i) {
    double depth_m = ssBoxDepth(boxes->bodies[i], side_m);
    if (depth_m > deepest_m) {
      deepest_m = depth_m;
      deepest = i;
    }
  }
  if (boxes->count == 0) return 0;
  ssBoundMessage(worst, size, "box %d: lowest corner %.6g m below the floor, bound %g m (%g times its %g m half side)",
           deepest, deepest_m, bound_m, of_half_side, 0.5 * side_m);
  return deepest_m / bound_m;
}

/* Boxes dropped flat onto the ground from a few centimetres: their contacts are the scene's soft constraint.
 *
 * The drops are low on purpose. From high up, how deep a box is when its first contact is found depends on where
 * the step boundaries fall (speed times step length), whatever the softness; from low, the penetration a run
 * shows is the contact spring's own sag and rebound, which is what the policies differ in. */
#include <math.h>

#include "scene_internal.h"

#define DROP_SIDE_M 0.2         /* box edge */
#define DROP_SPACING_M 0.5      /* between box centres along x */
#define DROP_LOWEST_GAP_M 0.02  /* the first box's bottom above the ground */
#define DROP_GAP_STEP_M 0.03    /* each next box starts this much higher: they land one after another */

static ssStatus build(const ssSceneWorld* world, const ssSceneParams* params, void** state) {
  ssBoxes* boxes;
  ssStatus status = ssBoxesCreate(world, params, "drop", &boxes);
  if (status != SS_OK) return status;
  for (int i = 0; i < params->body_count; ++i) {
    double bottom_m = DROP_LOWEST_GAP_M + DROP_GAP_STEP_M * i;
    ssBoxesAdd(boxes, world, params->mass, DROP_SIDE_M, DROP_SPACING_M * i, 0, bottom_m + 0.5 * DROP_SIDE_M);
  }
  *state = boxes;
  return SS_OK;
}

static void sample(const void* state, double* out) {
  const ssBoxes* boxes = state;
  double penetration_m = 0;
  for (int i = 0; i < boxes->count; ++i) penetration_m = fmax(penetration_m, ssBoxDepth(boxes->bodies[i], DROP_SIDE_M));
  out[0] = penetration_m;
  out[1] = dBodyGetPosition(boxes->bodies[0])[2];
}

/* Sanity bound: no box's lowest corner more than half its half side (0.05 m) below the floor. A correct contact
 * sinks by its spring's sag and rebound, and by the distance a box falls in the step before its first contact is
 * found: the boxes land at 1.5 m/s at most, 2.5 cm in a 1/60 s step. The fine-step reference sinks 1 cm, the mapped
 * policies up to 2 cm (test_bounds.cpp); a box sunk a quarter of its side has gone through the floor
 * (policy naive at 30 fps, its contacts far too soft for the steps it is given). */
#define DROP_MAX_DEPTH_OF_HALF_SIDE 0.5

static double check(const void* state, char* worst, size_t size) {
  return ssBoxesCheck(state, DROP_SIDE_M, DROP_MAX_DEPTH_OF_HALF_SIDE, worst, size);
}

const ssSceneDesc ssDropScene = {
    .info = {.name = "drop",
             .description = "boxes dropped onto the ground; their contacts are soft with the spring",
             .quantity_count = 2,
             .quantity_names = {"penetration", "height"},
             .quantity_units = {"m", "m"}},
    /* Per contact point; a flat box rests on four, 1e4 N/m on 1 kg: 16 Hz, damping ratio 0.4, so it rebounds. */
    .defaults = {.spring = {.stiffness = 2500, .damping = 20}, .mass = 1, .x0 = 0, .gravity = 9.81, .body_count = 4},
    .max_body_count = 1000,
    .build = build,
    .watch = ssBoxesWatch,
    .collide = ssBoxesCollide,
    .sample = sample,
    .check = check,
    .destroy = ssBoxesDestroy,
};

/* Many boxes falling into a heap: the scene for timing, where collision and the solver dominate a step.
 *
 * Boxes start in layers of a square grid; every other layer is shifted by half a cell, so boxes land on the edges
 * of the ones below and topple into a heap instead of stacking into tidy columns. */
#include "scene_internal.h"

#define PILE_SIDE_M 0.2
#define PILE_CELL_M 0.25       /* grid spacing within a layer */
#define PILE_LAYER_M 0.3       /* height between layers */
#define PILE_PER_ROW 10        /* boxes along each side of a layer */

static ssStatus build(const ssSceneWorld* world, const ssSceneParams* params, void** state) {
  ssBoxes* boxes;
  ssStatus status = ssBoxesCreate(world, params, "pile", &boxes);
  if (status != SS_OK) return status;
  const int per_layer = PILE_PER_ROW * PILE_PER_ROW;
  for (int i = 0; i < params->body_count; ++i) {
    int layer = i / per_layer, row = (i % per_layer) / PILE_PER_ROW, column = i % PILE_PER_ROW;
    double shift_m = (layer % 2) * 0.5 * PILE_CELL_M;
    ssBoxesAdd(boxes, world, params->mass, PILE_SIDE_M, column * PILE_CELL_M + shift_m, row * PILE_CELL_M + shift_m,
                0.5 * PILE_SIDE_M + 0.05 + layer * PILE_LAYER_M);
  }
  *state = boxes;
  return SS_OK;
}

static void sample(const void* state, double* out) {
  const ssBoxes* boxes = state;
  double sum_m = 0;
  for (int i = 0; i < boxes->count; ++i) sum_m += dBodyGetPosition(boxes->bodies[i])[2];
  out[0] = sum_m / boxes->count;
}

/* Sanity bound: no box's lowest corner more than its half side (0.1 m) below the floor, i.e. no flat box with its
 * centre under the floor. Wider than drop's: boxes of the upper layers fall through the gaps from up to 1.35 m and
 * land at up to 5 m/s, so a step of 1/60 s finds a box's first contact up to 8.6 cm deep. That is where discrete
 * collision finds contacts, whatever the softness; the mapped policies reach 6.6 cm at 30 fps, the fine-step reference
 * 1.2 cm (test_bounds.cpp). A box half through the floor is beyond anything a contact gives back. */
#define PILE_MAX_DEPTH_OF_HALF_SIDE 1.0

static double check(const void* state, char* worst, size_t size) {
  return ssBoxesCheck(state, PILE_SIDE_M, PILE_MAX_DEPTH_OF_HALF_SIDE, worst, size);
}

const ssSceneDesc ssPileScene = {
    .info = {.name = "pile",
             .description = "many boxes falling into a heap, for timing",
             .quantity_count = 1,
             .quantity_names = {"mean height"},
             .quantity_units = {"m"}},
    /* Stiffer than drop's: a heap puts several boxes' weight on the bottom contacts. */
    .defaults = {.spring = {.stiffness = 20000, .damping = 200}, .mass = 1, .x0 = 0, .gravity = 9.81,
                 .body_count = 500},
    .max_body_count = 100000,
    .build = build,
    .watch = ssBoxesWatch,
    .collide = ssBoxesCollide,
    .sample = sample,
    .check = check,
    .destroy = ssBoxesDestroy,
};

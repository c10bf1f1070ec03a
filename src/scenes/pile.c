/* Many boxes falling into a heap: the scene for timing, where collision and the solver dominate a step.
 *
 * Boxes start in layers of a square grid; every other layer is shifted by half a cell, so boxes land on the edges
 * of the ones below and topple into a heap instead of stacking into tidy columns. */
#include <stdlib.h>

#include "error.h"
#include "scene_internal.h"

#define PILE_SIDE_M 0.2
#define PILE_CELL_M 0.25       /* grid spacing within a layer */
#define PILE_LAYER_M 0.3       /* height between layers */
#define PILE_PER_ROW 10        /* boxes along each side of a layer */

typedef struct Pile {
  int count;
  dBodyID* boxes;
  ssContactRecipe recipe;
} Pile;

static void destroy(void* state) {
  Pile* pile = state;
  free(pile->boxes);
  free(pile);
}

static ssStatus build(const ssSceneWorld* world, const ssSceneParams* params, void** state) {
  Pile* pile = calloc(1, sizeof *pile);
  dBodyID* boxes = calloc((size_t)params->body_count, sizeof *boxes);
  if (pile == NULL || boxes == NULL) {
    free(pile);
    free(boxes);
    return ssFail(SS_ERROR_OUT_OF_MEMORY, "pile: out of memory for %d boxes", params->body_count);
  }
  pile->count = params->body_count;
  pile->boxes = boxes;
  dWorldSetGravity(world->world, 0, 0, -params->gravity);
  dCreatePlane(world->space, 0, 0, 1, 0);
  const int per_layer = PILE_PER_ROW * PILE_PER_ROW;
  for (int i = 0; i < pile->count; ++i) {
    int layer = i / per_layer, row = (i % per_layer) / PILE_PER_ROW, column = i % PILE_PER_ROW;
    double shift_m = (layer % 2) * 0.5 * PILE_CELL_M;
    dBodyID box = dBodyCreate(world->world);
    dMass mass;
    dMassSetBoxTotal(&mass, params->mass, PILE_SIDE_M, PILE_SIDE_M, PILE_SIDE_M);
    dBodySetMass(box, &mass);
    dBodySetPosition(box, column * PILE_CELL_M + shift_m, row * PILE_CELL_M + shift_m,
                     0.5 * PILE_SIDE_M + 0.05 + layer * PILE_LAYER_M);
    dGeomID geom = dCreateBox(world->space, PILE_SIDE_M, PILE_SIDE_M, PILE_SIDE_M);
    dGeomSetBody(geom, box);
    boxes[i] = box;
  }
  pile->recipe = (ssContactRecipe){.world = world->world,
                                   .space = world->space,
                                   .contacts = world->contacts,
                                   .spring = params->spring,
                                   .max_contacts = 4,
                                   .surface_mode = dContactApprox1,
                                   .mu = 0.5};
  *state = pile;
  return SS_OK;
}

static ssStatus watch(void* state, ssStepper* stepper) {
  Pile* pile = state;
  for (int i = 0; i < pile->count; ++i) {
    ssStatus status = ssStepper_WatchBody(stepper, pile->boxes[i]);
    if (status != SS_OK) return status;
  }
  return SS_OK;
}

static void collide(void* context, ssMapping mapping, double step_s, double previous_step_s) {
  Pile* pile = context;
  ssContactCollide(&pile->recipe, mapping, step_s, previous_step_s);
}

static void sample(const void* state, double* out) {
  const Pile* pile = state;
  double sum_m = 0;
  for (int i = 0; i < pile->count; ++i) sum_m += dBodyGetPosition(pile->boxes[i])[2];
  out[0] = sum_m / pile->count;
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
    .watch = watch,
    .collide = collide,
    .sample = sample,
    .destroy = destroy,
};

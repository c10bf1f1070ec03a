/* A tower of boxes whose masses differ by 200 times, written as ODE programs write a stack (after reading ODE's
 * demo_boxstack): numbers tuned at 60 fps, contacts softened by a soft CFM alone so that their ERP is the world's,
 * body damping and auto-disable counted in steps, 40 QuickStep iterations because heavy boxes rest on light ones;
 * then adopted (ssRegistry_Adopt) and each contact softened for its step by ssStepper_SoftenContact.
 *
 * The boxes start a few millimetres apart and settle; the top box is pushed sideways by a force added before every
 * step for the first three seconds, which rocks the tower on its contacts (below the force that would slide or tip
 * a box, worked out at stack_masses), and then the tower comes to rest and falls asleep.
 *
 * params.spring is the contacts' spring: the program's world ERP and soft CFM are what it stands for at 1/60 s
 * (the default, k 12000 N/m and c 800 N*s/m per contact point, is ERP 0.2 and CFM 1e-3). params.mass is the
 * lightest box's mass; the others are the multiples in stack_masses. */
#include <math.h>
#include <stdlib.h>

#include "lab_error.h"
#include "scene_internal.h"

#define STACK_MAX_CONTACTS 4
#define STACK_GAP_M 0.005        /* between boxes at the start: the tower settles onto its contacts */
#define STACK_PUSH_OF_WEIGHT 0.4 /* amplitude of the push on the top box, in its weights */
#define STACK_PUSH_PERIOD_S 1.5
#define STACK_PUSH_UNTIL_S 3.0
#define STACK_WORLD_CFM 1e-5     /* as demo_boxstack; no joint reads it, contacts have their own soft CFM */
#define STACK_ITERATIONS 40
#define STACK_MU 0.8

/* Bottom to top: side (m) and mass in multiples of params.mass; at the default 0.1 kg, 20, 2, 0.2, 0.6, 0.1 and
 * 0.3 kg, 200 times apart (body_count < 6 stacks the first ones; more would put the 20 kg box on a 0.3 kg one). Heavier boxes stand on lighter ones (box 3 on box 2, box 5 on box 4, three times their
 * mass; box 2's contacts carry five times its weight). The push on the top box, 0.4 of its weight, is below what
 * slides it (mu = 0.8 of its weight) or tips it over the box beneath (its whole weight, for a cube pushed at its
 * centre), and the 1.0 N m it puts on the three boxes above box 2 is below the 1.5 N m their weight holds them with. */
static const double stack_sides_m[] = {0.6, 0.5, 0.3, 0.4, 0.3, 0.3};
static const double stack_masses[] = {200, 20, 2, 6, 1, 3};
enum { STACK_MAX_BOXES = sizeof stack_masses / sizeof stack_masses[0] };

/* Sanity bounds, measured in test_bounds.cpp. (1) Two neighbours overlap (the lower box's top above the upper box's
 * bottom, from their z extents) by at most 0.07 m, a quarter of the smallest side. Between boxes the contacts sag
 * by a millimetre or less (under box 1, 3.2 kg on four contacts of 12000 N/m: 0.65 mm, at default mass and
 * spring), and a rocking box's z extent, taken from its corners, grows by a centimetre or so as it tilts (the mapped
 * policies reach 1.5 cm); 7 cm is a box pushed into the one below. (2) Each box's centre at most a third of its
 * side, horizontally, from the centre of the box below: the push is below what slides or tips a box, so a box that
 * far out has slid off or the tower fell. */
#define STACK_MAX_OVERLAP_M 0.07
#define STACK_MAX_OFFSET_OF_SIDE (1.0 / 3.0)

typedef struct Stack {
  int count;
  dBodyID* boxes;
  double* sides_m;
  ssTunedContacts recipe;
  double push_n;  /* the push's amplitude (N) */
  double time_s;  /* the time of the step about to be taken: the push follows simulated time */
} Stack;

static void destroy(void* state) {
  Stack* stack = state;
  free(stack->boxes);
  free(stack->sides_m);
  free(stack);
}

static ssStatus build(const ssSceneWorld* world, const ssSceneParams* params, void** state) {
  Stack* stack = calloc(1, sizeof *stack);
  dBodyID* boxes = calloc((size_t)params->body_count, sizeof *boxes);
  double* sides = calloc((size_t)params->body_count, sizeof *sides);
  if (stack == NULL || boxes == NULL || sides == NULL) {
    free(stack);
    free(boxes);
    free(sides);
    return ssLabFail(SS_ERROR_OUT_OF_MEMORY, "stack: out of memory for %d boxes", params->body_count);
  }
  *stack = (Stack){.count = params->body_count, .boxes = boxes, .sides_m = sides};
  *state = stack;
  /* What the program tuned at 60 fps: the contacts' spring as world ERP (which contacts without a soft ERP use)
   * and the contacts' soft CFM. */
  ssSoftness tuned;
  ssStatus status = ssImplicitEulerSoftness(params->spring, SS_PROGRAM_TUNED_STEP_S, &tuned);
  if (status != SS_OK) {
    destroy(stack);
    *state = NULL;
    return status;
  }
  stack->recipe = (ssTunedContacts){.world = world->world, .space = world->space, .contacts = world->contacts,
                                    .max_contacts = STACK_MAX_CONTACTS, .surface_mode = dContactSoftCFM | dContactApprox1,
                                    .mu = STACK_MU, .soft_cfm = tuned.cfm};
  dWorldSetGravity(world->world, 0, 0, -params->gravity);
  dWorldSetERP(world->world, tuned.erp);
  dWorldSetCFM(world->world, STACK_WORLD_CFM);
  dWorldSetQuickStepNumIterations(world->world, STACK_ITERATIONS);
  dWorldSetLinearDamping(world->world, 0.001); /* per step, at 60 fps */
  dWorldSetAngularDamping(world->world, 0.005);
  dWorldSetAutoDisableFlag(world->world, 1);
  dWorldSetAutoDisableSteps(world->world, 20); /* idle for 20 steps, speeds averaged over 10 */
  dWorldSetAutoDisableAverageSamplesCount(world->world, 10);
  dCreatePlane(world->space, 0, 0, 1, 0);

  double bottom_m = 0;
  for (int i = 0; i < stack->count; ++i) {
    double side_m = stack_sides_m[i];
    dBodyID box = dBodyCreate(world->world);
    dMass mass;
    dMassSetBoxTotal(&mass, params->mass * stack_masses[i], side_m, side_m, side_m);
    dBodySetMass(box, &mass);
    dBodySetPosition(box, 0, 0, bottom_m + 0.5 * side_m);
    dGeomSetBody(dCreateBox(world->space, side_m, side_m, side_m), box);
    bottom_m += side_m + STACK_GAP_M;
    boxes[i] = box;
    sides[i] = side_m;
  }
  stack->push_n = STACK_PUSH_OF_WEIGHT * params->gravity * params->mass * stack_masses[stack->count - 1];
  status = ssRegistry_Adopt(world->registry, SS_PROGRAM_TUNED_STEP_S, world->space, NULL);
  if (status != SS_OK) {
    destroy(stack);
    *state = NULL;
  }
  return status;
}

static void collide(void* context, ssStepper* stepper) {
  Stack* stack = context;
  ssTunedContactsCollide(&stack->recipe, stepper);
}

/* Before every step: the push on the top box at the time the step starts, then that time moves on by the step. */
static void drive(void* state, double step_s) {
  Stack* stack = state;
  if (stack->time_s < STACK_PUSH_UNTIL_S)
    dBodyAddForce(stack->boxes[stack->count - 1],
                  stack->push_n * sin(2 * M_PI * stack->time_s / STACK_PUSH_PERIOD_S), 0, 0);
  stack->time_s += step_s;
}

/* How far above its centre a box reaches along world z (m): its half extents projected on z. */
static double halfHeight(dBodyID box, double side_m) {
  const dReal* rotation = dBodyGetRotation(box);
  return 0.5 * side_m * (fabs(rotation[8]) + fabs(rotation[9]) + fabs(rotation[10]));
}

static void sample(const void* state, double* out) {
  const Stack* stack = state;
  const dReal* top = dBodyGetPosition(stack->boxes[stack->count - 1]);
  double kinetic_j = 0;
  for (int i = 0; i < stack->count; ++i) {
    dMass mass;
    dBodyGetMass(stack->boxes[i], &mass);
    const dReal* v = dBodyGetLinearVel(stack->boxes[i]);
    const dReal* w = dBodyGetAngularVel(stack->boxes[i]);
    /* A cube's inertia is isotropic, so it is the same in the world frame: (1/2) I |w|^2. */
    kinetic_j += 0.5 * mass.mass * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) +
                 0.5 * mass.I[0] * (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
  }
  out[0] = top[0];
  out[1] = top[2];
  out[2] = kinetic_j;
}

static double check(const void* state, char* worst, size_t size) {
  const Stack* stack = state;
  double use = 0;
  for (int i = 1; i < stack->count; ++i) {
    const dReal* lower = dBodyGetPosition(stack->boxes[i - 1]);
    const dReal* upper = dBodyGetPosition(stack->boxes[i]);
    double overlap_m = (lower[2] + halfHeight(stack->boxes[i - 1], stack->sides_m[i - 1])) -
                       (upper[2] - halfHeight(stack->boxes[i], stack->sides_m[i]));
    double offset_m = hypot(upper[0] - lower[0], upper[1] - lower[1]);
    double offset_bound_m = STACK_MAX_OFFSET_OF_SIDE * stack->sides_m[i];
    if (overlap_m / STACK_MAX_OVERLAP_M > use) {
      use = overlap_m / STACK_MAX_OVERLAP_M;
      ssBoundMessage(worst, size, "box %d: %.6g m into box %d below it, bound %g m (a quarter of the smallest "
                     "side)", i, overlap_m, i - 1, STACK_MAX_OVERLAP_M);
    }
    if (offset_m / offset_bound_m > use) {
      use = offset_m / offset_bound_m;
      ssBoundMessage(worst, size, "box %d: centre %.6g m across from box %d's below it, bound %g m (a third of its "
                     "side: slid off or fallen)", i, offset_m, i - 1, offset_bound_m);
    }
  }
  return use;
}

const ssSceneDesc ssStackScene = {
    .info = {.name = "stack",
             .description = "a tower of boxes whose masses differ by 200 times, tuned as ODE programs are, pushed",
             .quantity_count = 3,
             .quantity_names = {"top x", "top z", "kinetic energy"},
             .quantity_units = {"m", "m", "J"}},
    /* ERP 0.2 and soft CFM 1e-3 at 1/60 s, per contact point. */
    .defaults = {.spring = {.stiffness = 12000, .damping = 800}, .mass = 0.1, .x0 = 0, .gravity = 9.81,
                 .body_count = 6},
    .max_body_count = STACK_MAX_BOXES,
    .build = build,
    .drive = drive,
    .collide = collide,
    .sample = sample,
    .check = check,
    .destroy = destroy,
};

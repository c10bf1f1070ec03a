/* A wall of boxes knocked over by a heavy ball, written as ODE programs write one (after reading ODE's demo_crash):
 * a wall of bricks in offset courses on the ground, a cannon ball ten times a brick's mass fired into it, contacts
 * with a soft ERP and a soft CFM tuned at 60 fps, the world's ERP/CFM set as the demo sets them, auto-disable
 * counted in steps (what comes to rest sleeps until something hits it); then adopted
 * (ssRegistry_Adopt) and each contact softened for its step by ssStepper_SoftenContact. Standing, the wall rests on
 * four contacts a brick (276 at the default 69, six courses); falling, it makes hundreds more between bricks.
 *
 * params.spring is the contacts' spring: the soft ERP and soft CFM are what it stands for at 1/60 s (the default,
 * k 3000 N/m and c 50 N*s/m per contact point, is soft ERP 0.5 and soft CFM 0.01: demo_crash's CFM, and a lower ERP
 * than its 0.8, with which the accurate mappings throw the standing wall apart, scene.h). params.mass is a brick's
 * mass; params.body_count the bricks, laid course by course. */
#include <math.h>
#include <stdlib.h>

#include "lab_error.h"
#include "scene_internal.h"

#define WALL_SIDE_M 0.4           /* bricks are cubes */
#define WALL_GAP_M 0.002          /* between bricks at the start, so that a standing wall has no side contacts */
#define WALL_PER_COURSE 12
#define WALL_BALL_RADIUS_M 0.25
#define WALL_BALL_MASS_OF_BRICKS 10.0
#define WALL_BALL_START_X_M (-3.0)  /* the wall stands at x = 0 */
#define WALL_BALL_START_Z_M 1.0
#define WALL_BALL_SPEED_M_PER_S 12.0  /* along +x, and WALL_BALL_CLIMB_M_PER_S up */
#define WALL_BALL_CLIMB_M_PER_S 1.5
#define WALL_MAX_CONTACTS 4
#define WALL_MU 0.6
#define WALL_WORLD_ERP 0.8        /* as demo_crash; no joint reads them, contacts have their own soft ERP/CFM */
#define WALL_WORLD_CFM 1e-5

/* Sanity bounds, measured in test_bounds.cpp. (1) The energy above the lowest state (every brick and the ball
 * resting on the ground), kinetic plus potential, at most twice its value at the start: gravity is conservative,
 * nothing drives anything after the launch, and contacts, friction and damping only take energy away, so doubling
 * is energy made by the contacts (bricks shot apart). A run starts at half this bound. Without gravity pulling
 * down (params.gravity <= 0) there is no resting state to measure from, and this bound is not checked. (2) No brick's lowest corner
 * more than its half side (0.2 m) below the floor, its centre not under it: bricks of the top course fall 2 m and
 * land at up to 6.3 m/s, 10.5 cm in a 1/60 s step before their first contact is found (where discrete collision
 * finds it, whatever the softness), while the standing wall sags by millimetres (five bricks on a bottom brick's
 * four contacts of 3000 N/m: 4 mm). A brick centred below the floor has gone through it. */
#define WALL_MAX_ENERGY_GAIN 2.0
#define WALL_MAX_DEPTH_OF_HALF_SIDE 1.0

typedef struct Wall {
  int count;
  dBodyID* bricks;
  dVector3* starts;      /* each brick's centre at the start */
  dBodyID ball;
  ssTunedContacts recipe;
  double gravity;
  double energy_start_j; /* the energy above the lowest state at the start */
} Wall;

static void destroy(void* state) {
  Wall* wall = state;
  free(wall->bricks);
  free(wall->starts);
  free(wall);
}

static dBodyID makeBody(const ssSceneWorld* world, const dMass* mass, dGeomID geom, double x, double y, double z) {
  dBodyID body = dBodyCreate(world->world);
  dBodySetMass(body, mass);
  dBodySetPosition(body, x, y, z);
  dGeomSetBody(geom, body);
  return body;
}

/* Kinetic energy plus potential energy above the lowest state (J). Bricks and ball are isotropic (cubes, a
 * sphere), so (1/2) I |w|^2 holds in the world frame. */
static double energy(const Wall* wall) {
  double total_j = 0;
  for (int i = 0; i <= wall->count; ++i) {
    dBodyID body = i < wall->count ? wall->bricks[i] : wall->ball;
    double lowest_z_m = i < wall->count ? 0.5 * WALL_SIDE_M : WALL_BALL_RADIUS_M;
    dMass mass;
    dBodyGetMass(body, &mass);
    const dReal* v = dBodyGetLinearVel(body);
    const dReal* w = dBodyGetAngularVel(body);
    total_j += 0.5 * mass.mass * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) +
               0.5 * mass.I[0] * (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]) +
               mass.mass * wall->gravity * (dBodyGetPosition(body)[2] - lowest_z_m);
  }
  return total_j;
}

static ssStatus build(const ssSceneWorld* world, const ssSceneParams* params, void** state) {
  Wall* wall = calloc(1, sizeof *wall);
  dBodyID* bricks = calloc((size_t)params->body_count, sizeof *bricks);
  dVector3* starts = calloc((size_t)params->body_count, sizeof *starts);
  if (wall == NULL || bricks == NULL || starts == NULL) {
    free(wall);
    free(bricks);
    free(starts);
    return ssLabFail(SS_ERROR_OUT_OF_MEMORY, "wall: out of memory for %d bricks", params->body_count);
  }
  *wall = (Wall){.count = params->body_count, .bricks = bricks, .starts = starts, .gravity = params->gravity};
  *state = wall;
  ssSoftness tuned;
  ssStatus status = ssImplicitEulerSoftness(params->spring, SS_PROGRAM_TUNED_STEP_S, &tuned);
  if (status != SS_OK) {
    destroy(wall);
    *state = NULL;
    return status;
  }
  wall->recipe = (ssTunedContacts){.world = world->world, .space = world->space, .contacts = world->contacts,
                                   .max_contacts = WALL_MAX_CONTACTS,
                                   .surface_mode = dContactSoftERP | dContactSoftCFM | dContactApprox1,
                                   .mu = WALL_MU, .soft_erp = tuned.erp, .soft_cfm = tuned.cfm};
  dWorldSetGravity(world->world, 0, 0, -params->gravity);
  dWorldSetERP(world->world, WALL_WORLD_ERP);
  dWorldSetCFM(world->world, WALL_WORLD_CFM);
  dWorldSetAutoDisableFlag(world->world, 1);
  dWorldSetAutoDisableSteps(world->world, 10); /* as demo_crash: idle for 10 steps */
  dCreatePlane(world->space, 0, 0, 1, 0);

  dMass mass;
  dMassSetBoxTotal(&mass, params->mass, WALL_SIDE_M, WALL_SIDE_M, WALL_SIDE_M);
  const double cell_m = WALL_SIDE_M + WALL_GAP_M;
  /* Courses of WALL_PER_COURSE bricks and WALL_PER_COURSE - 1 in turn, each of the shorter ones shifted by half a
   * brick: every brick of an upper course stands on two below it, none overhangs the end. */
  for (int i = 0, course = 0, place = 0; i < wall->count; ++i, ++place) {
    int in_course = WALL_PER_COURSE - course % 2;
    if (place == in_course) {
      ++course;
      place = 0;
      in_course = WALL_PER_COURSE - course % 2;
    }
    double y_m = (place - 0.5 * (in_course - 1)) * cell_m;
    double z_m = 0.5 * WALL_SIDE_M + course * cell_m;
    dGeomID geom = dCreateBox(world->space, WALL_SIDE_M, WALL_SIDE_M, WALL_SIDE_M);
    bricks[i] = makeBody(world, &mass, geom, 0, y_m, z_m);
    starts[i][0] = 0, starts[i][1] = y_m, starts[i][2] = z_m;
  }
  dMassSetSphereTotal(&mass, WALL_BALL_MASS_OF_BRICKS * params->mass, WALL_BALL_RADIUS_M);
  wall->ball = makeBody(world, &mass, dCreateSphere(world->space, WALL_BALL_RADIUS_M), WALL_BALL_START_X_M, 0,
                         WALL_BALL_START_Z_M);
  dBodySetLinearVel(wall->ball, WALL_BALL_SPEED_M_PER_S, 0, WALL_BALL_CLIMB_M_PER_S);
  wall->energy_start_j = energy(wall);
  status = ssRegistry_Adopt(world->registry, SS_PROGRAM_TUNED_STEP_S, world->space, NULL);
  if (status != SS_OK) {
    destroy(wall);
    *state = NULL;
  }
  return status;
}

static void collide(void* context, ssStepper* stepper) {
  Wall* wall = context;
  ssTunedContactsCollide(&wall->recipe, stepper);
}

static void sample(const void* state, double* out) {
  const Wall* wall = state;
  double sum_m = 0;
  for (int i = 0; i < wall->count; ++i) {
    const dReal* at = dBodyGetPosition(wall->bricks[i]);
    sum_m += sqrt((at[0] - wall->starts[i][0]) * (at[0] - wall->starts[i][0]) +
                  (at[1] - wall->starts[i][1]) * (at[1] - wall->starts[i][1]) +
                  (at[2] - wall->starts[i][2]) * (at[2] - wall->starts[i][2]));
  }
  const dReal* ball = dBodyGetPosition(wall->ball);
  out[0] = wall->count > 0 ? sum_m / wall->count : 0;
  out[1] = ball[0];
  out[2] = ball[2];
}

static double check(const void* state, char* worst, size_t size) {
  const Wall* wall = state;
  double use = 0;
  if (wall->gravity > 0) {
    double energy_bound_j = WALL_MAX_ENERGY_GAIN * wall->energy_start_j;
    double energy_j = energy(wall);
    use = energy_j / energy_bound_j;
    ssBoundMessage(worst, size, "energy %.6g J above the resting state, bound %g J (twice its %g J at the start)",
                   energy_j, energy_bound_j, wall->energy_start_j);
  }
  const double depth_bound_m = WALL_MAX_DEPTH_OF_HALF_SIDE * 0.5 * WALL_SIDE_M;
  for (int i = 0; i < wall->count; ++i) {
    double depth_m = ssBoxDepth(wall->bricks[i], WALL_SIDE_M);
    if (depth_m / depth_bound_m > use) {
      use = depth_m / depth_bound_m;
      ssBoundMessage(worst, size, "brick %d: lowest corner %.6g m below the floor, bound %g m (its half side: "
                     "its centre under the floor)", i, depth_m, depth_bound_m);
    }
  }
  return use;
}

const ssSceneDesc ssWallScene = {
    .info = {.name = "wall",
             .description = "a wall of boxes knocked over by a heavy ball, tuned as ODE programs are",
             .quantity_count = 3,
             .quantity_names = {"wall mean displacement", "ball x", "ball z"},
             .quantity_units = {"m", "m", "m"}},
    /* Soft ERP 0.5 and soft CFM 0.01 at 1/60 s, per contact point (scene.h: why not demo_crash's ERP 0.8). */
    .defaults = {.spring = {.stiffness = 3000, .damping = 50}, .mass = 1, .x0 = 0, .gravity = 9.81,
                 .body_count = 69},
    .max_body_count = 2000,
    .build = build,
    .collide = collide,
    .sample = sample,
    .check = check,
    .destroy = destroy,
};

/* A four-wheeled car driving forward over a few bumps: its suspension is the spring.
 *
 * Each wheel hangs on a hinge-2 joint: axis 1 vertical (steering, and the suspension slides along it), axis 2 the
 * wheel's spin axis, driven by a motor. Steering is locked with lo = hi = 0 stops on axis 1. Every soft thing is
 * bound: the suspension to the scene's spring, the ground contacts to a stiff spring, and the world's ERP/CFM
 * (the hinge-2 rigid rows) to a stiff spring too, so that policy naive freezes all of them and policy implicit-euler
 * maps all of them; nothing is left with a fixed ERP/CFM that would blur the comparison. */
#include <math.h>
#include <stdlib.h>

#include "lab_error.h"
#include "scene_internal.h"

#define BUGGY_LENGTH_M 0.7
#define BUGGY_WIDTH_M 0.5
#define BUGGY_HEIGHT_M 0.2
#define BUGGY_WHEEL_RADIUS_M 0.18
#define BUGGY_WHEEL_MASS_KG 0.2
#define BUGGY_AXLE_X_M 0.3         /* wheels at +-this along the car */
#define BUGGY_TRACK_Y_M 0.32       /* wheels at +-this across the car */
#define BUGGY_CHASSIS_Z_M 0.36     /* chassis centre at the start */
#define BUGGY_SPEED_M_PER_S 1.5    /* the motors aim for this ground speed */
#define BUGGY_MOTOR_TORQUE_NM 0.6  /* dParamFMax2 of each wheel motor */
#define BUGGY_BUMP_COUNT 3

/* Sanity bounds. The chassis rides about 0.2 m above the ground and never touches it in a correct run: its lowest
 * corner more than half its half height (0.05 m) below the ground is a car sunk through the road. A wheel's hinge-2
 * anchors move apart along axis 1 by the suspension's travel: the sag is 0.04 m, and the pitch of the start and
 * the bumps take it to about 0.12 m in the fine-step reference. More than 0.28 m (the wheel centre's start 0.18 m
 * below the chassis centre, plus the chassis' half height) is a wheel gone up through the chassis' roof, or as far
 * down. Across axis 1 the rigid rows hold them together; more than a quarter of the wheel radius (0.045 m) is a
 * wheel torn off. The margins of correct runs are measured in test_bounds.cpp. */
#define BUGGY_MAX_SINK_OF_HALF_HEIGHT 0.5
#define BUGGY_MAX_TRAVEL_M (BUGGY_CHASSIS_Z_M - BUGGY_WHEEL_RADIUS_M + 0.5 * BUGGY_HEIGHT_M)
#define BUGGY_MAX_GAP_OF_RADIUS 0.25

/* Ground contacts: stiff next to the suspension (about 50 Hz on a 0.2 kg wheel), well damped. */
static const ssSpring buggy_ground_spring = {.stiffness = 2e4, .damping = 200};
/* The hinge-2 rigid rows, as in chain.c: stiff and critically damped per kg. */
static const ssSpring buggy_world_spring = {.stiffness = 1e5, .damping = 630};

/* Bumps across the path: x of the centre, length along x, height (m). */
static const double bumps[BUGGY_BUMP_COUNT][3] = {{1.0, 0.3, 0.05}, {2.0, 0.2, 0.07}, {3.0, 0.4, 0.04}};

typedef struct Buggy {
  dBodyID chassis;
  dBodyID wheels[4];
  dJointID hinges[4];
  ssContactRecipe recipe;
} Buggy;

static dBodyID makeWheel(const ssSceneWorld* world, double x, double y, double z) {
  dBodyID wheel = dBodyCreate(world->world);
  dMass mass;
  dMassSetSphereTotal(&mass, BUGGY_WHEEL_MASS_KG, BUGGY_WHEEL_RADIUS_M);
  dBodySetMass(wheel, &mass);
  dBodySetPosition(wheel, x, y, z);
  dGeomID geom = dCreateSphere(world->space, BUGGY_WHEEL_RADIUS_M);
  dGeomSetBody(geom, wheel);
  return wheel;
}

static ssStatus attachWheel(const ssSceneWorld* world, const ssSceneParams* params, dBodyID chassis,
                             dBodyID wheel, dJointID* out) {
  const dReal* at = dBodyGetPosition(wheel);
  dJointID joint = dJointCreateHinge2(world->world, 0);
  dJointAttach(joint, chassis, wheel);
  *out = joint;
  dJointSetHinge2Anchor(joint, at[0], at[1], at[2]);
  const dReal steer_axis[3] = {0, 0, 1}, spin_axis[3] = {0, 1, 0};
  dJointSetHinge2Axes(joint, steer_axis, spin_axis);
  dJointSetHinge2Param(joint, dParamLoStop, 0);
  dJointSetHinge2Param(joint, dParamHiStop, 0);
  /* Rolling forward (+x) spins the wheel about +y, which hinge-2 reports as a negative axis-2 rate (its rate is of
   * body 1, the chassis, relative to body 2): a positive motor velocity drives the car backwards. */
  dJointSetHinge2Param(joint, dParamVel2, -BUGGY_SPEED_M_PER_S / BUGGY_WHEEL_RADIUS_M);
  dJointSetHinge2Param(joint, dParamFMax2, BUGGY_MOTOR_TORQUE_NM);
  ssStatus status = ssRegistry_BindJoint(world->registry, joint, SS_PARAM_SUSPENSION, 1, params->spring, 0);
  /* Each suspension carries a quarter of the chassis' weight, down along axis 1 on the chassis (body 1): declared,
   * so that the matched and exact mappings keep the sag of k instead of that of their own static stiffness. */
  if (status == SS_OK)
    status = ssRegistry_SetJointLoad(world->registry, joint, SS_PARAM_SUSPENSION, 1, -params->mass * params->gravity / 4);
  return status;
}

static ssStatus build(const ssSceneWorld* world, const ssSceneParams* params, void** state) {
  Buggy* buggy = calloc(1, sizeof *buggy);
  if (buggy == NULL) return ssLabFail(SS_ERROR_OUT_OF_MEMORY, "buggy: out of memory");
  dWorldSetGravity(world->world, 0, 0, -params->gravity);
  ssStatus status = ssRegistry_BindWorld(world->registry, buggy_world_spring, params->mass);

  dCreatePlane(world->space, 0, 0, 1, 0);
  for (int i = 0; i < BUGGY_BUMP_COUNT; ++i) {
    dGeomID bump = dCreateBox(world->space, bumps[i][1], 4.0, 2.0 * bumps[i][2]);
    dGeomSetPosition(bump, bumps[i][0], 0, 0);  /* half buried: its top is bumps[i][2] above the ground */
  }

  buggy->chassis = dBodyCreate(world->world);
  dMass mass;
  dMassSetBoxTotal(&mass, params->mass, BUGGY_LENGTH_M, BUGGY_WIDTH_M, BUGGY_HEIGHT_M);
  dBodySetMass(buggy->chassis, &mass);
  dBodySetPosition(buggy->chassis, 0, 0, BUGGY_CHASSIS_Z_M);
  dGeomID body_geom = dCreateBox(world->space, BUGGY_LENGTH_M, BUGGY_WIDTH_M, BUGGY_HEIGHT_M);
  dGeomSetBody(body_geom, buggy->chassis);

  /* Wheels start touching the ground; the suspension then settles under the car's weight. */
  for (int i = 0; status == SS_OK && i < 4; ++i) {
    double x = (i < 2 ? 1 : -1) * BUGGY_AXLE_X_M, y = (i % 2 == 0 ? 1 : -1) * BUGGY_TRACK_Y_M;
    buggy->wheels[i] = makeWheel(world, x, y, BUGGY_WHEEL_RADIUS_M);
    status = attachWheel(world, params, buggy->chassis, buggy->wheels[i], &buggy->hinges[i]);
  }
  if (status != SS_OK) {
    free(buggy);
    return status;
  }
  buggy->recipe = (ssContactRecipe){.world = world->world,
                                    .space = world->space,
                                    .contacts = world->contacts,
                                    .spring = buggy_ground_spring,
                                    .max_contacts = 4,
                                    .surface_mode = dContactApprox1,
                                    .mu = 1.0};
  *state = buggy;
  return SS_OK;
}

static ssStatus watch(void* state, ssStepper* stepper) {
  Buggy* buggy = state;
  return ssStepper_WatchBody(stepper, buggy->chassis);
}

static void collide(void* context, ssStepper* stepper) {
  Buggy* buggy = context;
  ssContactCollide(&buggy->recipe, stepper);
}

static void sample(const void* state, double* out) {
  const Buggy* buggy = state;
  const dReal* rotation = dBodyGetRotation(buggy->chassis);
  out[0] = dBodyGetPosition(buggy->chassis)[2];
  /* The chassis' forward axis in world coordinates is (R[0], R[4], R[8]): its climb is the pitch, nose up > 0. */
  out[1] = atan2(rotation[8], hypot(rotation[0], rotation[4]));
}

/* The largest of the three bounds' ratios; worst names the part that reached it. */
static double check(const void* state, char* worst, size_t size) {
  const Buggy* buggy = state;
  double refused = ssContactRefusedCheck(&buggy->recipe, worst, size);
  if (refused > 0) return refused;
  const dReal* position = dBodyGetPosition(buggy->chassis);
  const dReal* rotation = dBodyGetRotation(buggy->chassis);
  double sink_m = 0.5 * (BUGGY_LENGTH_M * fabs(rotation[8]) + BUGGY_WIDTH_M * fabs(rotation[9]) +
                         BUGGY_HEIGHT_M * fabs(rotation[10])) - position[2];
  double sink_bound_m = BUGGY_MAX_SINK_OF_HALF_HEIGHT * 0.5 * BUGGY_HEIGHT_M;
  double use = sink_m / sink_bound_m;
  ssBoundMessage(worst, size, "chassis: lowest corner %.6g m below the ground, bound %g m (half of its %g m half height)",
           sink_m, sink_bound_m, 0.5 * BUGGY_HEIGHT_M);
  const double travel_bound_m = BUGGY_MAX_TRAVEL_M;
  const double gap_bound_m = BUGGY_MAX_GAP_OF_RADIUS * BUGGY_WHEEL_RADIUS_M;
  for (int i = 0; i < 4; ++i) {
    dVector3 on_chassis, on_wheel, axis;
    dJointGetHinge2Anchor(buggy->hinges[i], on_chassis);
    dJointGetHinge2Anchor2(buggy->hinges[i], on_wheel);
    dJointGetHinge2Axis1(buggy->hinges[i], axis);
    double d[3] = {on_wheel[0] - on_chassis[0], on_wheel[1] - on_chassis[1], on_wheel[2] - on_chassis[2]};
    double travel_m = d[0] * axis[0] + d[1] * axis[1] + d[2] * axis[2];
    double across[3] = {d[0] - travel_m * axis[0], d[1] - travel_m * axis[1], d[2] - travel_m * axis[2]};
    double gap_m = sqrt(across[0] * across[0] + across[1] * across[1] + across[2] * across[2]);
    if (fabs(travel_m) / travel_bound_m > use) {
      use = fabs(travel_m) / travel_bound_m;
      ssBoundMessage(worst, size, "wheel %d hinge-2: anchors %.6g m apart along the suspension axis, bound %g m (the wheel "
               "through the chassis)", i, fabs(travel_m), travel_bound_m);
    }
    if (gap_m / gap_bound_m > use) {
      use = gap_m / gap_bound_m;
      ssBoundMessage(worst, size, "wheel %d hinge-2: anchors %.6g m apart across the suspension axis, bound %g m (%g of "
               "the wheel radius)", i, gap_m, gap_bound_m, BUGGY_MAX_GAP_OF_RADIUS);
    }
  }
  return use;
}

static void destroy(void* state) { free(state); }

const ssSceneDesc ssBuggyScene = {
    .info = {.name = "buggy",
             .description = "a four-wheeled car on hinge-2 spring suspension driving over bumps",
             .quantity_count = 2,
             .quantity_names = {"chassis height", "chassis pitch"},
             .quantity_units = {"m", "rad"}},
    /* Per wheel: 2.5 Hz on a quarter of the 1 kg chassis, damping ratio 0.13, so the bumps set it rocking and its
     * sag (4 cm) is large enough for the frame-time dependence of fixed ERP/CFM to show in the ride height. Stiffer
     * (k = 150) the height moved mostly with the bumps' geometry, which every policy resolves alike. */
    .defaults = {.spring = {.stiffness = 60, .damping = 1}, .mass = 1, .x0 = 0, .gravity = 9.81, .body_count = 0},
    .max_body_count = 0,
    .build = build,
    .watch = watch,
    .collide = collide,
    .sample = sample,
    .check = check,
    .destroy = destroy,
};

/* Fuzz support for the world-stepping targets: one ODE world per process, restored before every input, holding a
 * few islands of the ODE 0.16 joint types that the input chooses.
 *
 * Speed is what lets a fuzzer find anything: a world built and destroyed per input spent most of its time in the
 * kernel zeroing the fresh pages of ODE's step memory, and stepping seventeen islands at once cost seventeen times
 * one. So the world, its space, the ground and the contact group are made at the first input and kept; before each
 * input the world's settings (everything the registry, the stepper or an input may write: ERP, CFM, damping,
 * auto-disable, solver iterations, ...) are put back as saved, and ODE's generator is seeded again, so that an
 * input runs the same whether it is the process's first or its millionth (a reproducer is one input in a fresh
 * process). An input's first byte picks one to three islands, together covering every joint type over the corpus;
 * the registry, the stepper and the islands are made for the input and destroyed after it. An input takes at most
 * STEP_BUDGET physics steps: a frame that would take more is not stepped.
 *
 * An island is one body (two for hinge-2, the transmission and the contact boxes) held to the static world by one
 * joint type; the contact boxes fall on the ground plane. The soft rows come either from adoption (adopt.h: the
 * world's and the joints' ERP/CFM as ODE holds them, tuned at a fuzzed step, and fuzzed tuned values on rebuilt
 * joints) or from binding every supported row to a default spring (registry.h). */
#ifndef STEADYSTEP_FUZZ_WORLD_H
#define STEADYSTEP_FUZZ_WORLD_H

#include <ode/ode.h>

#include "fuzz_input.h"
#include "steadystep/adopt.h"
#include "steadystep/stepper.h"

enum {
  JOINT_BALL, JOINT_HINGE, JOINT_SLIDER, JOINT_UNIVERSAL, JOINT_HINGE2, JOINT_FIXED, JOINT_NULL, JOINT_AMOTOR,
  JOINT_LMOTOR, JOINT_PLANE2D, JOINT_PR, JOINT_PU, JOINT_PISTON, JOINT_DBALL, JOINT_DHINGE, JOINT_TRANSMISSION,
  CONTACT_BOXES, ISLAND_COUNT
};
enum { MAX_ISLAND_BODIES = 2, MAX_ISLAND_JOINTS = 3, MAX_ISLANDS_PER_INPUT = 3, STEP_BUDGET = 48 };

typedef struct Island {
  int present;               /* chosen by the input's first byte (and not destroyed for good) */
  dBodyID bodies[MAX_ISLAND_BODIES];
  dGeomID geoms[MAX_ISLAND_BODIES];
  dVector3 built_at[MAX_ISLAND_BODIES]; /* the bodies' positions as built: the island's layout */
  int body_count;
  dJointID joints[MAX_ISLAND_JOINTS];
  int joint_count;
} Island;

/* Everything of a dWorld that the library or an input may change, as ODE's getters give it. */
typedef struct WorldSettings {
  dVector3 gravity;
  dReal erp, cfm, quick_w, max_correcting_vel, surface_layer;
  int quick_iterations;
  int auto_disable_flag, auto_disable_steps;
  unsigned auto_disable_samples;
  dReal auto_disable_linear, auto_disable_angular, auto_disable_time;
  dReal linear_damping, angular_damping, linear_damping_threshold, angular_damping_threshold, max_angular_speed;
} WorldSettings;

/* The process's ODE objects, made at the first input. */
typedef struct Scene {
  dWorldID world;
  dSpaceID space;
  dJointGroupID contacts;
  WorldSettings settings;
} Scene;

typedef struct World {
  dWorldID world;
  dSpaceID space;
  dJointGroupID contacts;
  ssRegistry* registry;
  ssStepper* stepper;
  Island islands[ISLAND_COUNT];
  ssSpring contact_spring;         /* bind mode: the spring ssContactSoften gets */
  double contact_erp, contact_cfm; /* adopt mode: the contact's tuned soft_erp/soft_cfm for ssStepper_SoftenContact */
  int adopt;                       /* soft rows come from adoption rather than from binding */
  ssStepping stepping;             /* the stepper's, as last accepted */
  int steps_left;                  /* of STEP_BUDGET */
  /* fuzz_stepper's before_step in the next frame: at step `at`, `what` (0 nothing) with `value` on island `kind` */
  struct {
    int what, at, kind;
    double value;
  } plan;
} World;

typedef struct BodyState {
  dReal position[3], quaternion[4], linear[3], angular[3];
} BodyState;

/* A name for printing, whatever the enum value. */
#define NAME_OR_UNKNOWN(name) ((name) != NULL ? (name) : "unknown")

/* STEADYSTEP_FUZZ_VERBOSE=1 in the environment prints every operation: to read what a reproducer does. */
static int verbose = 0;

/* The world of the input being run: the near callback's way back to it (its data is the stepper). */
static World* current_world = NULL;

static const ssSpring DEFAULT_SPRING = {40.0, 0.5};

/* ---- the process's world ---- */

static inline WorldSettings readSettings(dWorldID world) {
  WorldSettings s;
  memset(&s, 0, sizeof s);
  dWorldGetGravity(world, s.gravity);
  s.erp = dWorldGetERP(world);
  s.cfm = dWorldGetCFM(world);
  s.quick_w = dWorldGetQuickStepW(world);
  s.quick_iterations = dWorldGetQuickStepNumIterations(world);
  s.max_correcting_vel = dWorldGetContactMaxCorrectingVel(world);
  s.surface_layer = dWorldGetContactSurfaceLayer(world);
  s.auto_disable_flag = dWorldGetAutoDisableFlag(world);
  s.auto_disable_steps = dWorldGetAutoDisableSteps(world);
  s.auto_disable_samples = (unsigned)dWorldGetAutoDisableAverageSamplesCount(world);
  s.auto_disable_linear = dWorldGetAutoDisableLinearThreshold(world);
  s.auto_disable_angular = dWorldGetAutoDisableAngularThreshold(world);
  s.auto_disable_time = dWorldGetAutoDisableTime(world);
  s.linear_damping = dWorldGetLinearDamping(world);
  s.angular_damping = dWorldGetAngularDamping(world);
  s.linear_damping_threshold = dWorldGetLinearDampingThreshold(world);
  s.angular_damping_threshold = dWorldGetAngularDampingThreshold(world);
  s.max_angular_speed = dWorldGetMaxAngularSpeed(world);
  return s;
}

static inline void writeSettings(dWorldID world, const WorldSettings* s) {
  dWorldSetGravity(world, s->gravity[0], s->gravity[1], s->gravity[2]);
  dWorldSetERP(world, s->erp);
  dWorldSetCFM(world, s->cfm);
  dWorldSetQuickStepW(world, s->quick_w);
  dWorldSetQuickStepNumIterations(world, s->quick_iterations);
  dWorldSetContactMaxCorrectingVel(world, s->max_correcting_vel);
  dWorldSetContactSurfaceLayer(world, s->surface_layer);
  dWorldSetAutoDisableFlag(world, s->auto_disable_flag);
  dWorldSetAutoDisableSteps(world, s->auto_disable_steps);
  dWorldSetAutoDisableAverageSamplesCount(world, s->auto_disable_samples);
  dWorldSetAutoDisableLinearThreshold(world, s->auto_disable_linear);
  dWorldSetAutoDisableAngularThreshold(world, s->auto_disable_angular);
  dWorldSetAutoDisableTime(world, s->auto_disable_time);
  dWorldSetDamping(world, s->linear_damping, s->angular_damping);
  dWorldSetLinearDampingThreshold(world, s->linear_damping_threshold);
  dWorldSetAngularDampingThreshold(world, s->angular_damping_threshold);
  dWorldSetMaxAngularSpeed(world, s->max_angular_speed);
}

/* The process's world as saved: made at the first call, its settings put back at every later one. */
static inline const Scene* sceneForInput(void) {
  static Scene scene;
  if (scene.world == 0) {
    dInitODE2(0);
    verbose = getenv("STEADYSTEP_FUZZ_VERBOSE") != NULL;
    scene.world = dWorldCreate();
    dWorldSetGravity(scene.world, 0, 0, -9.81);
    scene.space = dSimpleSpaceCreate(0);
    dCreatePlane(scene.space, 0, 0, 1, 0);
    scene.contacts = dJointGroupCreate(0);
    scene.settings = readSettings(scene.world);
  } else {
    writeSettings(scene.world, &scene.settings);
    WorldSettings now = readSettings(scene.world);
    FUZZ_REQUIRE(memcmp(&now, &scene.settings, sizeof now) == 0, "the world's settings were not restored");
  }
  dJointGroupEmpty(scene.contacts);
  dRandSetSeed(1); /* dWorldQuickStep shuffles rows with ODE's generator: every input runs the same way */
  return &scene;
}

/* ---- islands ---- */

static inline dBodyID makeBody(World* w, double x, double z) {
  dBodyID body = dBodyCreate(w->world);
  dMass mass;
  dMassSetBoxTotal(&mass, 1.0, 0.2, 0.2, 0.2);
  dBodySetMass(body, &mass);
  dBodySetPosition(body, x, 0, z);
  return body;
}

/* ODE has one parameter setter per joint type. */
static inline void setParam(dJointID joint, int parameter, double value) {
  switch (dJointGetType(joint)) {
    case dJointTypeHinge: dJointSetHingeParam(joint, parameter, value); break;
    case dJointTypeSlider: dJointSetSliderParam(joint, parameter, value); break;
    case dJointTypeUniversal: dJointSetUniversalParam(joint, parameter, value); break;
    case dJointTypeHinge2: dJointSetHinge2Param(joint, parameter, value); break;
    case dJointTypeAMotor: dJointSetAMotorParam(joint, parameter, value); break;
    case dJointTypeLMotor: dJointSetLMotorParam(joint, parameter, value); break;
    case dJointTypePR: dJointSetPRParam(joint, parameter, value); break;
    case dJointTypePU: dJointSetPUParam(joint, parameter, value); break;
    case dJointTypePiston: dJointSetPistonParam(joint, parameter, value); break;
    case dJointTypeBall: dJointSetBallParam(joint, parameter, value); break;
    case dJointTypeFixed: dJointSetFixedParam(joint, parameter, value); break;
    case dJointTypeDBall: dJointSetDBallParam(joint, parameter, value); break;
    case dJointTypeDHinge: dJointSetDHingeParam(joint, parameter, value); break;
    case dJointTypeTransmission: dJointSetTransmissionParam(joint, parameter, value); break;
    case dJointTypePlane2D: dJointSetPlane2DXParam(joint, parameter, value); break;
    default: break; /* null: nothing to set */
  }
}

static inline void setStops(dJointID joint, int axis_group, double lo, double hi) {
  setParam(joint, dParamLoStop + axis_group, lo);
  setParam(joint, dParamHiStop + axis_group, hi);
}

static inline void setMotor(dJointID joint, int axis_group) {
  setParam(joint, dParamVel + axis_group, 0.5);
  setParam(joint, dParamFMax + axis_group, 10.0);
}

/* Binds every (param, axis) the joint supports to the default spring. */
static inline void bindDefaults(World* w, dJointID joint) {
  if (joint == 0) return;
  for (int param = SS_PARAM_JOINT; param <= SS_PARAM_SUSPENSION; ++param)
    for (int axis = 1; axis <= 3; ++axis)
      if (ssJointSupports(joint, (ssJointParam)param, axis)) {
        /* Rows whose effective mass the library cannot compute get 1 kg, so that matched and exact can run. */
        double mass = 0;
        if (ssJointEffectiveMass(joint, (ssJointParam)param, axis, &mass) != SS_OK) mass = 1.0;
        FUZZ_REQUIRE(ssRegistry_BindJoint(w->registry, joint, (ssJointParam)param, axis, DEFAULT_SPRING, mass) ==
                         SS_OK, "binding a supported row failed: %s", ssLastError());
      }
}

/* Makes the island's bodies and joints. When tuned is given (adopt mode), the main joint's first soft row gets those
 * tuned ERP/CFM before adoption: values the program set, which adoption must either take or refuse by name. */
static inline void buildIsland(World* w, int kind, const double* tuned) {
  Island* island = &w->islands[kind];
  memset(island, 0, sizeof *island);
  island->present = 1;
  double x = 2.0 * kind, z = 1.0;
  dBodyID body = makeBody(w, x, z);
  island->bodies[island->body_count++] = body;
  dJointID joint = 0;
  switch (kind) {
    case JOINT_BALL:
      joint = dJointCreateBall(w->world, 0);
      dJointAttach(joint, body, 0);
      dJointSetBallAnchor(joint, x, 0, z + 0.5);
      break;
    case JOINT_HINGE:
      joint = dJointCreateHinge(w->world, 0);
      dJointAttach(joint, body, 0);
      dJointSetHingeAnchor(joint, x + 0.5, 0, z);
      dJointSetHingeAxis(joint, 0, 1, 0);
      setStops(joint, dParamGroup1, -0.4, 0.4);
      break;
    case JOINT_SLIDER:
      joint = dJointCreateSlider(w->world, 0);
      dJointAttach(joint, body, 0);
      dJointSetSliderAxis(joint, 0, 0, 1);
      setStops(joint, dParamGroup1, 0, 0);
      break;
    case JOINT_UNIVERSAL:
      joint = dJointCreateUniversal(w->world, 0);
      dJointAttach(joint, body, 0);
      dJointSetUniversalAnchor(joint, x, 0, z + 0.5);
      dJointSetUniversalAxis1(joint, 1, 0, 0);
      dJointSetUniversalAxis2(joint, 0, 1, 0);
      setStops(joint, dParamGroup1, -0.4, 0.4);
      setStops(joint, dParamGroup2, -0.4, 0.4);
      break;
    case JOINT_HINGE2: {
      /* A chassis on a ball to the world and a wheel on hinge-2 with a spring suspension. */
      dJointID hold = dJointCreateBall(w->world, 0);
      dJointAttach(hold, body, 0);
      dJointSetBallAnchor(hold, x, 0, z + 0.3);
      island->joints[island->joint_count++] = hold;
      dBodyID wheel = makeBody(w, x + 0.4, z - 0.2);
      island->bodies[island->body_count++] = wheel;
      joint = dJointCreateHinge2(w->world, 0);
      dJointAttach(joint, body, wheel);
      dJointSetHinge2Anchor(joint, x + 0.4, 0, z - 0.2);
      const dReal up[3] = {0, 0, 1}, side[3] = {0, 1, 0};
      dJointSetHinge2Axes(joint, up, side);
      setStops(joint, dParamGroup1, -0.3, 0.3);
      setMotor(joint, dParamGroup2);
      break;
    }
    case JOINT_FIXED:
      joint = dJointCreateFixed(w->world, 0);
      dJointAttach(joint, body, 0);
      dJointSetFixed(joint);
      break;
    case JOINT_NULL:
      joint = dJointCreateNull(w->world, 0);
      dJointAttach(joint, body, 0);
      break;
    case JOINT_AMOTOR:
      joint = dJointCreateAMotor(w->world, 0);
      dJointAttach(joint, body, 0);
      dJointSetAMotorMode(joint, dAMotorUser);
      dJointSetAMotorNumAxes(joint, 3);
      dJointSetAMotorAxis(joint, 0, 1, 1, 0, 0);
      dJointSetAMotorAxis(joint, 1, 1, 0, 1, 0);
      dJointSetAMotorAxis(joint, 2, 1, 0, 0, 1);
      setMotor(joint, dParamGroup1);
      setStops(joint, dParamGroup2, 0.1, 0.5); /* the angle is 0: this stop is active */
      setMotor(joint, dParamGroup3);
      break;
    case JOINT_LMOTOR:
      joint = dJointCreateLMotor(w->world, 0);
      dJointAttach(joint, body, 0);
      dJointSetLMotorNumAxes(joint, 3);
      dJointSetLMotorAxis(joint, 0, 0, 1, 0, 0);
      dJointSetLMotorAxis(joint, 1, 0, 0, 1, 0);
      dJointSetLMotorAxis(joint, 2, 0, 0, 0, 1);
      for (int group = 0; group < 3; ++group) setMotor(joint, group * dParamGroup2);
      break;
    case JOINT_PLANE2D:
      joint = dJointCreatePlane2D(w->world, 0);
      dJointAttach(joint, body, 0);
      dJointSetPlane2DXParam(joint, dParamFMax, 5.0);
      dJointSetPlane2DXParam(joint, dParamVel, 0.2);
      break;
    case JOINT_PR:
      joint = dJointCreatePR(w->world, 0);
      dJointAttach(joint, body, 0);
      dJointSetPRAnchor(joint, x, 0, z + 0.5);
      dJointSetPRAxis1(joint, 0, 0, 1);
      dJointSetPRAxis2(joint, 1, 0, 0);
      setStops(joint, dParamGroup1, -0.1, 0.1);
      setStops(joint, dParamGroup2, -0.4, 0.4);
      break;
    case JOINT_PU:
      joint = dJointCreatePU(w->world, 0);
      dJointAttach(joint, body, 0);
      dJointSetPUAnchor(joint, x, 0, z + 0.5);
      dJointSetPUAxis1(joint, 1, 0, 0);
      dJointSetPUAxis2(joint, 0, 1, 0);
      dJointSetPUAxisP(joint, 0, 0, 1);
      setStops(joint, dParamGroup1, -0.4, 0.4);
      setStops(joint, dParamGroup3, -0.1, 0.1);
      break;
    case JOINT_PISTON:
      joint = dJointCreatePiston(w->world, 0);
      dJointAttach(joint, body, 0);
      dJointSetPistonAnchor(joint, x, 0, z + 0.5);
      dJointSetPistonAxis(joint, 0, 0, 1);
      setStops(joint, dParamGroup1, 0, 0);
      setStops(joint, dParamGroup2, -0.4, 0.4);
      break;
    case JOINT_DBALL:
      joint = dJointCreateDBall(w->world, 0);
      dJointAttach(joint, body, 0);
      dJointSetDBallAnchor1(joint, x, 0, z + 0.1);
      dJointSetDBallAnchor2(joint, x, 0, z + 0.6);
      break;
    case JOINT_DHINGE:
      joint = dJointCreateDHinge(w->world, 0);
      dJointAttach(joint, body, 0);
      dJointSetDHingeAxis(joint, 0, 1, 0);
      dJointSetDHingeAnchor1(joint, x, 0, z + 0.1);
      dJointSetDHingeAnchor2(joint, x, 0, z + 0.6);
      break;
    case JOINT_TRANSMISSION: {
      /* Two gears, each on a hinge to the world, meshed by a transmission. */
      dBodyID gear = makeBody(w, x + 0.6, z);
      island->bodies[island->body_count++] = gear;
      for (int i = 0; i < 2; ++i) {
        dJointID hinge = dJointCreateHinge(w->world, 0);
        dJointAttach(hinge, island->bodies[i], 0);
        dJointSetHingeAnchor(hinge, x + 0.6 * i, 0, z);
        dJointSetHingeAxis(hinge, 0, 1, 0);
        island->joints[island->joint_count++] = hinge;
      }
      dBodySetAngularVel(body, 0, 1, 0);
      joint = dJointCreateTransmission(w->world, 0);
      dJointAttach(joint, body, gear);
      dJointSetTransmissionMode(joint, dTransmissionParallelAxes);
      dJointSetTransmissionAxis(joint, 0, 1, 0);
      dJointSetTransmissionAnchor1(joint, x, 0, z);
      dJointSetTransmissionAnchor2(joint, x + 0.6, 0, z);
      dJointSetTransmissionRatio(joint, 2.0);
      break;
    }
    case CONTACT_BOXES: {
      dBodySetPosition(body, x, 0, 0.3);
      dBodyID other = makeBody(w, x + 0.05, 0.65);
      island->bodies[island->body_count++] = other;
      for (int i = 0; i < 2; ++i) {
        island->geoms[i] = dCreateBox(w->space, 0.2, 0.2, 0.2);
        dGeomSetBody(island->geoms[i], island->bodies[i]);
      }
      break;
    }
  }
  if (joint != 0) island->joints[island->joint_count++] = joint;
  for (int i = 0; i < island->body_count; ++i) memcpy(island->built_at[i], dBodyGetPosition(island->bodies[i]),
                                                       sizeof island->built_at[i]);
  if (!w->adopt) {
    for (int i = 0; i < island->joint_count; ++i) bindDefaults(w, island->joints[i]);
  } else {
    if (tuned != NULL && joint != 0) {
      int stop = ssJointSupports(joint, SS_PARAM_STOP, 1);
      setParam(joint, stop ? dParamStopERP : dParamERP, tuned[0]);
      setParam(joint, stop ? dParamStopCFM : dParamCFM, tuned[1]);
    }
    int bindings = ssRegistry_JointBindingCount(w->registry);
    ssStatus status = ssRegistry_AdoptBody(w->registry, body, NULL);
    if (verbose && tuned != NULL)
      fprintf(stderr, "  AdoptBody(island %d, tuned erp %.17g, cfm %.17g) = %s %s\n", kind, tuned[0], tuned[1],
              ssStatusName(status), status == SS_OK ? "" : ssLastError());
    if (status != SS_OK) {
      FUZZ_REQUIRE(ssLastError()[0] != '\0' && ssRegistry_JointBindingCount(w->registry) == bindings,
                   "AdoptBody refused (%s) but bound something or said nothing", ssStatusName(status));
      if (tuned != NULL) {
        /* Put ODE's defaults back, as a program would after the refusal, and adopt those. */
        int stop = ssJointSupports(joint, SS_PARAM_STOP, 1);
        setParam(joint, stop ? dParamStopERP : dParamERP, 0.2);
        setParam(joint, stop ? dParamStopCFM : dParamCFM, 1e-5);
        status = ssRegistry_AdoptBody(w->registry, body, NULL);
        FUZZ_REQUIRE(status == SS_OK || (ssLastError()[0] != '\0' && ssRegistry_JointBindingCount(w->registry) ==
                                         bindings), "AdoptBody refused (%s) but bound something or said nothing",
                     ssStatusName(status));
      }
      /* Still refused: a row took the world's CFM, which the input fuzzed (ODE copies it into every new joint).
       * The program binds the island's rows by hand. */
      if (status != SS_OK)
        for (int i = 0; i < island->joint_count; ++i) bindDefaults(w, island->joints[i]);
    }
  }
  for (int i = 0; i < island->body_count; ++i)
    FUZZ_REQUIRE(ssStepper_WatchBody(w->stepper, island->bodies[i]) == SS_OK, "watch: %s", ssLastError());
}

/* The documented way to destroy what the stepper knows: ssStepper_DestroyJoint for the island's joints, or
 * ssStepper_DestroyBody for its bodies (their geoms first). Joints first or bodies first are both valid (ODE then
 * detaches the joints, which stay bound until destroyed). */
static inline void destroyIslandJoints(World* w, int kind) {
  Island* island = &w->islands[kind];
  for (int i = 0; i < island->joint_count; ++i)
    FUZZ_REQUIRE(ssStepper_DestroyJoint(w->stepper, island->joints[i]) == SS_OK, "DestroyJoint: %s", ssLastError());
  island->joint_count = 0;
}

static inline void destroyIslandBodies(World* w, int kind) {
  Island* island = &w->islands[kind];
  for (int i = 0; i < island->body_count; ++i) {
    if (island->geoms[i] != 0) dGeomDestroy(island->geoms[i]);
    FUZZ_REQUIRE(ssStepper_DestroyBody(w->stepper, island->bodies[i]) == SS_OK, "DestroyBody: %s", ssLastError());
  }
  island->body_count = 0;
}

/* ---- contacts ---- */

static inline void nearCallback(void* data, dGeomID geom1, dGeomID geom2) {
  ssStepper* stepper = data;
  World* w = current_world;
  dBodyID body1 = dGeomGetBody(geom1), body2 = dGeomGetBody(geom2);
  ssStepInfo step = ssStepper_CurrentStep(stepper);
  dContact contacts[4];
  int count = dCollide(geom1, geom2, 4, &contacts[0].geom, sizeof contacts[0]);
  for (int i = 0; i < count; ++i) {
    contacts[i].surface.mode = dContactApprox1;
    contacts[i].surface.mu = 0.8;
    if (w->adopt) {
      contacts[i].surface.mode |= dContactSoftERP | dContactSoftCFM;
      contacts[i].surface.soft_erp = w->contact_erp;
      contacts[i].surface.soft_cfm = w->contact_cfm;
    }
  }
  /* the batch, on a copy: softened as each contact alone is below, or refused whole and left as given */
  dContact batch[4], given[4];
  memcpy(batch, contacts, sizeof batch);
  memcpy(given, contacts, sizeof given);
  ssStatus batch_status = w->adopt ? ssStepper_SoftenContacts(stepper, batch, count) : SS_OK;
  int all_softened = 1;
  for (int i = 0; i < count; ++i) {
    dContact before = contacts[i];
    ssStatus status = w->adopt ? ssStepper_SoftenContact(stepper, &contacts[i], body1, body2)
                               : ssContactSoften(&contacts[i], body1, body2, w->contact_spring, step.mapping,
                                                 step.softness_step_s, step.previous_step_s);
    if (status != SS_OK) {
      FUZZ_REQUIRE(ssLastError()[0] != '\0', "softening a contact refused (%s) without a message",
                   ssStatusName(status));
      FUZZ_REQUIRE(memcmp(&before, &contacts[i], sizeof before) == 0, "softening a contact refused (%s) but changed "
                   "the contact", ssLastError());
      /* The program's choice when a contact cannot be softened: keep it with ODE's defaults (rigid). */
      contacts[i].surface.mode = dContactApprox1;
      all_softened = 0;
    } else {
      FUZZ_REQUIRE(isfinite(contacts[i].surface.soft_erp) && isfinite(contacts[i].surface.soft_cfm) &&
                       contacts[i].surface.soft_cfm >= 0,
                   "contact softened OK with erp %g cfm %g", contacts[i].surface.soft_erp,
                   contacts[i].surface.soft_cfm);
    }
    if (w->adopt && all_softened)
      FUZZ_REQUIRE(memcmp(&batch[i].surface, &contacts[i].surface, sizeof batch[i].surface) == 0,
                   "the batch softened contact %d of %d otherwise than alone", i, count);
    dJointID joint = dJointCreateContact(w->world, w->contacts, &contacts[i]);
    dJointAttach(joint, body1, body2);
  }
  if (!w->adopt) return;
  FUZZ_REQUIRE((batch_status == SS_OK) == all_softened, "the batch %s (%s) where each contact alone %s",
               batch_status == SS_OK ? "passed" : "was refused", ssStatusName(batch_status),
               all_softened ? "passed" : "was refused once");
  if (batch_status != SS_OK)
    FUZZ_REQUIRE(memcmp(batch, given, sizeof batch) == 0, "the batch was refused but changed its contacts");
}

static inline void collideAll(World* w, ssStepper* stepper) { dSpaceCollide(w->space, stepper, nearCallback); }

/* ---- states ---- */

enum { STATE_CAPACITY = MAX_ISLANDS_PER_INPUT * MAX_ISLAND_BODIES };

static inline int snapshot(const World* w, BodyState* out) {
  int count = 0;
  for (int k = 0; k < ISLAND_COUNT; ++k)
    for (int i = 0; i < w->islands[k].body_count && count < STATE_CAPACITY; ++i, ++count) {
      dBodyID body = w->islands[k].bodies[i];
      BodyState* s = &out[count];
      memset(s, 0, sizeof *s);
      memcpy(s->position, dBodyGetPosition(body), sizeof s->position);
      memcpy(s->quaternion, dBodyGetQuaternion(body), sizeof s->quaternion);
      memcpy(s->linear, dBodyGetLinearVel(body), sizeof s->linear);
      memcpy(s->angular, dBodyGetAngularVel(body), sizeof s->angular);
    }
  return count;
}

static inline int allFinite(const BodyState* states, int count, int* which) {
  for (int i = 0; i < count; ++i) {
    const dReal* values = states[i].position;
    for (size_t j = 0; j < sizeof states[i] / sizeof(dReal); ++j)
      if (!isfinite(values[j])) {
        *which = i;
        return 0;
      }
  }
  return 1;
}

/* ---- choosing ---- */

/* Physics steps the frame would take (an upper bound, to within the FIXED accumulator's one step). */
static inline double stepsFor(const World* w, double frame_s) {
  if (!(frame_s > 0) || !isfinite(frame_s)) return 0;
  switch (w->stepping.cut) {
    case SS_CUT_WHOLE_FRAME: return 1;
    case SS_CUT_FIXED:
      return fmin(ceil(frame_s / w->stepping.fixed_step_s) + 1, w->stepping.max_steps_per_frame);
    default: return fmin(ceil(frame_s / w->stepping.max_step_s), w->stepping.max_steps_per_frame);
  }
}

/* Whether the frame fits in what is left of the input's step budget. */
static inline int withinBudget(const World* w, double frame_s) { return stepsFor(w, frame_s) <= w->steps_left; }

static inline const char* jointTypeName(dJointID joint) {
  static const char* names[] = {"none", "ball", "hinge", "slider", "contact", "universal", "hinge2", "fixed", "null",
                                "amotor", "lmotor", "plane2d", "pr", "pu", "piston", "dball", "dhinge",
                                "transmission"};
  if (joint == 0) return "no";
  int type = dJointGetType(joint);
  return type >= 0 && type < (int)(sizeof names / sizeof names[0]) ? names[type] : "?";
}

/* One of the input's joints, or 0 when it has none (which the library must refuse by name). */
static inline dJointID pickJoint(World* w, uint8_t byte) {
  int count = 0;
  for (int k = 0; k < ISLAND_COUNT; ++k) count += w->islands[k].joint_count;
  if (count == 0) return 0;
  int index = byte % count;
  for (int k = 0; k < ISLAND_COUNT; ++k) {
    if (index < w->islands[k].joint_count) return w->islands[k].joints[index];
    index -= w->islands[k].joint_count;
  }
  return 0;
}

/* One of the input's bodies; 0xFF (or no body left) stands for the world's defaults. */
static inline dBodyID pickBody(World* w, uint8_t byte) {
  if (byte == 0xFF) return 0;
  int count = 0;
  for (int k = 0; k < ISLAND_COUNT; ++k) count += w->islands[k].body_count;
  if (count == 0) return 0;
  int index = byte % count;
  for (int k = 0; k < ISLAND_COUNT; ++k) {
    if (index < w->islands[k].body_count) return w->islands[k].bodies[index];
    index -= w->islands[k].body_count;
  }
  return 0;
}

/* The island kind the byte names among those the input has, or -1. */
static inline int pickIsland(const World* w, uint8_t byte) {
  int count = 0;
  for (int k = 0; k < ISLAND_COUNT; ++k) count += w->islands[k].present;
  if (count == 0) return -1;
  int index = byte % count;
  for (int k = 0; k < ISLAND_COUNT; ++k)
    if (w->islands[k].present && index-- == 0) return k;
  return -1;
}

/* A teleport the way a program moves an assembly: the body to (x, y, z) and the rest of its island in the layout it
 * was built in around it. Moving one gear of a transmission alone onto its mate makes ODE assert inside the step
 * ("radii[i] > 0", transmission.cpp): a precondition of the program's own joint geometry that plain ODE has too.
 * (Offsets from the current positions would not do: at 1e185 m the gears' 0.6 m apart is lost, and moved back they
 * coincide.) */
static inline void teleport(World* w, dBodyID body, double x, double y, double z) {
  for (int k = 0; k < ISLAND_COUNT; ++k) {
    Island* island = &w->islands[k];
    for (int i = 0; i < island->body_count; ++i)
      if (island->bodies[i] == body) {
        for (int j = 0; j < island->body_count; ++j)
          dBodySetPosition(island->bodies[j], x + island->built_at[j][0] - island->built_at[i][0],
                           y + island->built_at[j][1] - island->built_at[i][1],
                           z + island->built_at[j][2] - island->built_at[i][2]);
        dBodySetPosition(body, x, y, z); /* exactly as asked, whatever the sums above rounded */
        return;
      }
  }
  dBodySetPosition(body, x, y, z);
}

/* ---- checks ---- */

/* A refused registry call names something and keeps the bindings as they were. */
static inline void checkRegistryCall(World* w, ssStatus status, int bindings_before, const char* what) {
  if (status == SS_OK) return;
  FUZZ_REQUIRE(ssLastError()[0] != '\0', "%s refused (%s) without a message", what, ssStatusName(status));
  FUZZ_REQUIRE(ssRegistry_JointBindingCount(w->registry) == bindings_before, "%s refused (%s) but the binding count "
               "went from %d to %d", what, ssLastError(), bindings_before, ssRegistry_JointBindingCount(w->registry));
}

static inline int sameDouble(double a, double b) { return memcmp(&a, &b, sizeof a) == 0; }

/* Whether the stepper holds the stepping it was given: every field as given, except that a speed limit of 0 stands
 * for the guard ODE itself needs (stepping.h), and a step length of 0 for the tuned step, which the stepper fills
 * in. Field by field: padding is no state. */
static inline int holdsStepping(const ssStepping* held, const ssStepping* given) {
  double max_step_s = given->max_step_s == 0 ? held->max_step_s : given->max_step_s;
  double fixed_step_s = given->fixed_step_s == 0 ? held->fixed_step_s : given->fixed_step_s;
  double max_speed = given->max_speed == 0 ? held->max_speed : given->max_speed;
  double max_angular_speed = given->max_angular_speed == 0 ? held->max_angular_speed : given->max_angular_speed;
  return held->cut == given->cut && held->mapping == given->mapping &&
         sameDouble(held->frozen_step_s, given->frozen_step_s) && held->solver == given->solver &&
         held->quick_iterations == given->quick_iterations && sameDouble(held->max_step_s, max_step_s) &&
         sameDouble(held->fixed_step_s, fixed_step_s) &&
         held->max_steps_per_frame == given->max_steps_per_frame && held->max_speed > 0 &&
         held->max_angular_speed > 0 && sameDouble(held->max_speed, max_speed) &&
         sameDouble(held->max_angular_speed, max_angular_speed);
}

/* ---- the input's world ---- */

/* Reads the input's header (islands, the stepper's fields, adoption) and makes its registry, stepper and islands in
 * the process's world. def_template gives the callbacks; the world, registry, collide and contact group are set
 * here. The header: [islands] [cut, mapping, solver] [fields] [the fields' values...]. */
static inline void makeWorld(World* w, FuzzInput* in, const ssStepperDef* def_template) {
  const Scene* scene = sceneForInput();
  memset(w, 0, sizeof *w);
  current_world = w;
  w->world = scene->world;
  w->space = scene->space;
  w->contacts = scene->contacts;
  w->steps_left = STEP_BUDGET;
  w->registry = ssRegistry_Create(w->world);
  FUZZ_REQUIRE(w->registry != NULL, "out of memory");
  w->contact_spring = DEFAULT_SPRING;

  /* Islands: first % ISLAND_COUNT and the next ones, 1 + (byte / ISLAND_COUNT) % 3 of them. */
  uint8_t islands = fuzz_byte(in);
  int first = islands % ISLAND_COUNT, count = 1 + (islands / ISLAND_COUNT) % MAX_ISLANDS_PER_INPUT;

  /* The stepper's fields, fuzzed: a refused definition must say why, then the defaults run the world. */
  ssStepperDef def = *def_template;
  def.world = w->world;
  def.registry = w->registry;
  def.contact_group = w->contacts;
  uint8_t how = fuzz_byte(in);
  def.stepping.cut = (ssFrameCut)(how % 4);           /* 3 is unknown */
  def.stepping.mapping = (ssMapping)((how >> 2) % 4); /* 3 is unknown */
  def.stepping.solver = (ssSolver)((how >> 4) % 4);   /* 0 is unset, 3 unknown */
  /* The steps the program's tuned for, unless fuzzed: 0 (the tuned step) is refused, the registry has none yet. */
  def.stepping.max_step_s = def.stepping.fixed_step_s = 1.0 / 60;
  uint8_t fields = fuzz_byte(in);
  if (fields & 1) def.stepping.max_step_s = fuzzDouble(in);
  if (fields & 2) def.stepping.fixed_step_s = fuzzDouble(in);
  if (fields & 4) def.stepping.frozen_step_s = fuzzDouble(in);
  if (fields & 8) def.stepping.max_steps_per_frame = (int8_t)fuzz_byte(in);
  if (fields & 16) def.stepping.quick_iterations = (int8_t)fuzz_byte(in);
  w->adopt = (fields & 32) != 0;
  double world_erp = fields & 64 ? fuzzDouble(in) : 0.2, world_cfm = fields & 64 ? fuzzDouble(in) : 1e-10;
  double tuned_step_s = fields & 128 ? fuzzDouble(in) : 1.0 / 60;
  w->contact_erp = 0.2;
  w->contact_cfm = 1e-5;
  ssStepper* const canary = (ssStepper*)w;
  w->stepper = canary;
  ssStatus status = ssStepper_Create(&def, &w->stepper);
  if (status != SS_OK) {
    FUZZ_REQUIRE(ssLastError()[0] != '\0' && w->stepper == canary, "ssStepper_Create refused (%s) without a message "
                 "or wrote its output", ssStatusName(status));
    ssStepperDef fallback = ssDefaultStepperDef();
    fallback.world = def.world;
    fallback.registry = def.registry;
    fallback.before_step = def.before_step;
    fallback.before_step_context = def.before_step_context;
    fallback.collide = def.collide;
    fallback.collide_context = def.collide_context;
    fallback.step_done = def.step_done;
    fallback.step_done_context = def.step_done_context;
    fallback.contact_group = def.contact_group;
    fallback.stepping.solver = SS_SOLVER_QUICK;
    fallback.stepping.max_step_s = fallback.stepping.fixed_step_s = 1.0 / 60;
    def = fallback;
    FUZZ_REQUIRE(ssStepper_Create(&def, &w->stepper) == SS_OK, "default stepper: %s", ssLastError());
  }
  w->stepping = ssStepper_Stepping(w->stepper);
  FUZZ_REQUIRE(holdsStepping(&w->stepping, &def.stepping), "the stepper's stepping is not the one it was made with");
  if (w->adopt) {
    /* The program tuned the world (maybe badly) at a step (maybe bad): adopted, or refused by name with nothing
     * bound; then ODE's defaults at 1/60 s. */
    dWorldSetERP(w->world, world_erp);
    dWorldSetCFM(w->world, world_cfm);
    status = ssRegistry_AdoptWorld(w->registry, tuned_step_s, NULL);
    if (verbose)
      fprintf(stderr, "AdoptWorld(erp %.17g, cfm %.17g, tuned %.17g s) = %s %s\n", world_erp, world_cfm,
              tuned_step_s, ssStatusName(status), status == SS_OK ? "" : ssLastError());
    if (status != SS_OK) {
      FUZZ_REQUIRE(ssLastError()[0] != '\0' && ssRegistry_TunedStep(w->registry) == 0,
                   "AdoptWorld refused (%s) without a message or with a tuned step", ssStatusName(status));
      dWorldSetERP(w->world, 0.2);
      dWorldSetCFM(w->world, 1e-10);
      FUZZ_REQUIRE(ssRegistry_AdoptWorld(w->registry, 1.0 / 60, NULL) == SS_OK, "AdoptWorld: %s", ssLastError());
    }
  }
  for (int i = 0; i < count; ++i) buildIsland(w, (first + i) % ISLAND_COUNT, NULL);
  if (verbose) fprintf(stderr, "islands %d to %d\n", first, (first + count - 1) % ISLAND_COUNT);
}

/* Destroys what the input made, leaving the process's world empty for the next one. */
static inline void destroyWorld(World* w) {
  for (int k = 0; k < ISLAND_COUNT; ++k) {
    destroyIslandJoints(w, k);
    destroyIslandBodies(w, k);
  }
  ssStepper_Destroy(w->stepper);
  ssRegistry_Destroy(w->registry);
  dJointGroupEmpty(w->contacts);
  current_world = NULL;
}

#endif

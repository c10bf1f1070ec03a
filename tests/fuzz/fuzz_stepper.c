/* Fuzz target: the registry and the stepper on a small world holding every ODE 0.16 joint type and contacts.
 *
 * The world is a row of islands, each one body (two for hinge-2 and the transmission) held to the static world by
 * one joint type, plus two free boxes that fall on a ground plane. The soft rows come either from adoption
 * (adopt.h: the world's and the joints' ERP/CFM as ODE holds them, tuned at a fuzzed step, and fuzzed tuned values
 * on rebuilt joints) or from binding every supported row to a default spring (registry.h). The input then drives a
 * sequence of operations: frames of any length (NaN, infinities, negative, denormal, huge), stepping changes (lab
 * policies, or cut, mapping, frozen step and limits fuzzed, valid or not), rebinding rows with fuzzed springs and
 * effective masses, loads, damping, auto-disable, the world's ERP/CFM, the contact softness, body masses, resets,
 * and destroying an island through the stepper (ssStepper_DestroyJoint/DestroyBody, in either order, with a frame in
 * between or not) and building it again; states and forces the program sets between frames (fuzzed numbers on a
 * body's position, velocities, force, torque); and callbacks that, at a fuzzed step of the next frame, add a fuzzed
 * force or torque, set a state, destroy an island, or call ssStepper_Step, SetStepping and Reset again.
 *
 * Promises checked: the process never aborts; a refusal names something (ssLastError) and changes nothing (binding
 * count, body states for frame refusals); a frame reported OK leaves every body's state finite; a blow-up names the
 * body, and the stepper then refuses frames until ssStepper_Reset; so does a state or force refused at the boundary
 * (before the frame or a step), by name; re-entering is refused with SS_ERROR_REENTERED. Masses stay within [1e-3, 1e3]
 * kg: the program, not the library, hands them to ODE. */
#include <ode/ode.h>

#include "fuzz_input.h"
#include "steadystep/adopt.h"
#include "steadystep/stepper.h"

enum {
  JOINT_BALL, JOINT_HINGE, JOINT_SLIDER, JOINT_UNIVERSAL, JOINT_HINGE2, JOINT_FIXED, JOINT_NULL, JOINT_AMOTOR,
  JOINT_LMOTOR, JOINT_PLANE2D, JOINT_PR, JOINT_PU, JOINT_PISTON, JOINT_DBALL, JOINT_DHINGE, JOINT_TRANSMISSION,
  CONTACT_BOXES, ISLAND_COUNT
};
enum { MAX_ISLAND_BODIES = 2, MAX_ISLAND_JOINTS = 3, MAX_OPS = 48, MAX_STEPS_PER_FRAME = 256 };

typedef struct Island {
  dBodyID bodies[MAX_ISLAND_BODIES];
  dGeomID geoms[MAX_ISLAND_BODIES];
  int body_count;
  dJointID joints[MAX_ISLAND_JOINTS];
  int joint_count;
} Island;

typedef struct World World;
struct World {
  dWorldID world;
  dSpaceID space;
  dJointGroupID contacts;
  ssRegistry* registry;
  ssStepper* stepper;
  Island islands[ISLAND_COUNT];
  ssSpring contact_spring;   /* bind mode: the spring ssContactSoften gets */
  double contact_erp, contact_cfm; /* adopt mode: the contact's tuned soft_erp/soft_cfm for ssStepper_SoftenContact */
  int adopt;                 /* soft rows come from adoption rather than from binding */
  struct World* self;        /* what the geoms' data points at, so that the near callback finds the world */
  ssStepping stepping;       /* the stepper's, as last accepted */
  /* what before_step does in the next frame: at step `at`, `what` (0 nothing) with `value` on island `kind` */
  struct {
    int what, at, kind;
    double value;
  } plan;
};

typedef struct BodyState {
  dReal position[3], quaternion[4], linear[3], angular[3];
} BodyState;

/* A name for printing, whatever the enum value. */
#define NAME_OR_UNKNOWN(name) ((name) != NULL ? (name) : "unknown")

/* STEADYSTEP_FUZZ_VERBOSE=1 in the environment prints every operation: to read what a reproducer does. */
static int verbose = -1;

static const ssSpring DEFAULT_SPRING = {40.0, 0.5};

static dBodyID make_body(World* w, double x, double z) {
  dBodyID body = dBodyCreate(w->world);
  dMass mass;
  dMassSetBoxTotal(&mass, 1.0, 0.2, 0.2, 0.2);
  dBodySetMass(body, &mass);
  dBodySetPosition(body, x, 0, z);
  return body;
}

/* ODE has one parameter setter per joint type. */
static void set_param(dJointID joint, int parameter, double value) {
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

static void set_stops(dJointID joint, int axis_group, double lo, double hi) {
  set_param(joint, dParamLoStop + axis_group, lo);
  set_param(joint, dParamHiStop + axis_group, hi);
}

static void set_motor(dJointID joint, int axis_group) {
  set_param(joint, dParamVel + axis_group, 0.5);
  set_param(joint, dParamFMax + axis_group, 10.0);
}

/* Binds every (param, axis) the joint supports to the default spring. */
static void bind_defaults(World* w, dJointID joint) {
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
static void build_island(World* w, int kind, const double* tuned) {
  Island* island = &w->islands[kind];
  memset(island, 0, sizeof *island);
  double x = 2.0 * kind, z = 1.0;
  dBodyID body = make_body(w, x, z);
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
      set_stops(joint, dParamGroup1, -0.4, 0.4);
      break;
    case JOINT_SLIDER:
      joint = dJointCreateSlider(w->world, 0);
      dJointAttach(joint, body, 0);
      dJointSetSliderAxis(joint, 0, 0, 1);
      set_stops(joint, dParamGroup1, 0, 0);
      break;
    case JOINT_UNIVERSAL:
      joint = dJointCreateUniversal(w->world, 0);
      dJointAttach(joint, body, 0);
      dJointSetUniversalAnchor(joint, x, 0, z + 0.5);
      dJointSetUniversalAxis1(joint, 1, 0, 0);
      dJointSetUniversalAxis2(joint, 0, 1, 0);
      set_stops(joint, dParamGroup1, -0.4, 0.4);
      set_stops(joint, dParamGroup2, -0.4, 0.4);
      break;
    case JOINT_HINGE2: {
      /* A chassis on a ball to the world and a wheel on hinge-2 with a spring suspension. */
      dJointID hold = dJointCreateBall(w->world, 0);
      dJointAttach(hold, body, 0);
      dJointSetBallAnchor(hold, x, 0, z + 0.3);
      island->joints[island->joint_count++] = hold;
      dBodyID wheel = make_body(w, x + 0.4, z - 0.2);
      island->bodies[island->body_count++] = wheel;
      joint = dJointCreateHinge2(w->world, 0);
      dJointAttach(joint, body, wheel);
      dJointSetHinge2Anchor(joint, x + 0.4, 0, z - 0.2);
      const dReal up[3] = {0, 0, 1}, side[3] = {0, 1, 0};
      dJointSetHinge2Axes(joint, up, side);
      set_stops(joint, dParamGroup1, -0.3, 0.3);
      set_motor(joint, dParamGroup2);
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
      set_motor(joint, dParamGroup1);
      set_stops(joint, dParamGroup2, 0.1, 0.5); /* the angle is 0: this stop is active */
      set_motor(joint, dParamGroup3);
      break;
    case JOINT_LMOTOR:
      joint = dJointCreateLMotor(w->world, 0);
      dJointAttach(joint, body, 0);
      dJointSetLMotorNumAxes(joint, 3);
      dJointSetLMotorAxis(joint, 0, 0, 1, 0, 0);
      dJointSetLMotorAxis(joint, 1, 0, 0, 1, 0);
      dJointSetLMotorAxis(joint, 2, 0, 0, 0, 1);
      for (int group = 0; group < 3; ++group) set_motor(joint, group * dParamGroup2);
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
      set_stops(joint, dParamGroup1, -0.1, 0.1);
      set_stops(joint, dParamGroup2, -0.4, 0.4);
      break;
    case JOINT_PU:
      joint = dJointCreatePU(w->world, 0);
      dJointAttach(joint, body, 0);
      dJointSetPUAnchor(joint, x, 0, z + 0.5);
      dJointSetPUAxis1(joint, 1, 0, 0);
      dJointSetPUAxis2(joint, 0, 1, 0);
      dJointSetPUAxisP(joint, 0, 0, 1);
      set_stops(joint, dParamGroup1, -0.4, 0.4);
      set_stops(joint, dParamGroup3, -0.1, 0.1);
      break;
    case JOINT_PISTON:
      joint = dJointCreatePiston(w->world, 0);
      dJointAttach(joint, body, 0);
      dJointSetPistonAnchor(joint, x, 0, z + 0.5);
      dJointSetPistonAxis(joint, 0, 0, 1);
      set_stops(joint, dParamGroup1, 0, 0);
      set_stops(joint, dParamGroup2, -0.4, 0.4);
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
      dBodyID gear = make_body(w, x + 0.6, z);
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
      dBodyID other = make_body(w, x + 0.05, 0.65);
      island->bodies[island->body_count++] = other;
      for (int i = 0; i < 2; ++i) {
        island->geoms[i] = dCreateBox(w->space, 0.2, 0.2, 0.2);
        dGeomSetBody(island->geoms[i], island->bodies[i]);
        dGeomSetData(island->geoms[i], &w->self);
      }
      break;
    }
  }
  if (joint != 0) island->joints[island->joint_count++] = joint;
  if (!w->adopt) {
    for (int i = 0; i < island->joint_count; ++i) bind_defaults(w, island->joints[i]);
  } else {
    if (tuned != NULL && joint != 0) {
      int stop = ssJointSupports(joint, SS_PARAM_STOP, 1);
      set_param(joint, stop ? dParamStopERP : dParamERP, tuned[0]);
      set_param(joint, stop ? dParamStopCFM : dParamCFM, tuned[1]);
    }
    int bindings = ssRegistry_JointBindingCount(w->registry);
    ssStatus status = ssRegistry_AdoptBody(w->registry, body, NULL);
    if (verbose && tuned != NULL)
      fprintf(stderr, "  AdoptBody(island %d, tuned erp %.17g, cfm %.17g) = %s %s\n", kind, tuned[0], tuned[1],
              ssStatusName(status), status == SS_OK ? "" : ssLastError());
    if (status != SS_OK) {
      FUZZ_REQUIRE(tuned != NULL, "adopting island %d with ODE's own values: %s", kind, ssLastError());
      FUZZ_REQUIRE(ssLastError()[0] != '\0' && ssRegistry_JointBindingCount(w->registry) == bindings,
                   "AdoptBody refused (%s) but bound something or said nothing", ssStatusName(status));
      /* Put ODE's defaults back, as a program would after the refusal, and adopt those. */
      int stop = ssJointSupports(joint, SS_PARAM_STOP, 1);
      set_param(joint, stop ? dParamStopERP : dParamERP, 0.2);
      set_param(joint, stop ? dParamStopCFM : dParamCFM, 1e-5);
      FUZZ_REQUIRE(ssRegistry_AdoptBody(w->registry, body, NULL) == SS_OK, "adopting defaults: %s", ssLastError());
    }
  }
  for (int i = 0; i < island->body_count; ++i)
    FUZZ_REQUIRE(ssStepper_WatchBody(w->stepper, island->bodies[i]) == SS_OK, "watch: %s", ssLastError());
}

static int frame(World* w, double frame_s, int op);

/* The documented way: ssStepper_DestroyJoint and ssStepper_DestroyBody, joints first or bodies first (ODE then
 * detaches the joints, which stay bound until destroyed), with a frame in between when asked. */
static int destroy_island(World* w, int kind, int bodies_first, int frame_between) {
  Island* island = &w->islands[kind];
  int alive = 1;
  for (int pass = 0; pass < 2; ++pass) {
    if ((pass == 0) != (bodies_first != 0)) {
      for (int i = 0; i < island->joint_count; ++i)
        FUZZ_REQUIRE(ssStepper_DestroyJoint(w->stepper, island->joints[i]) == SS_OK, "DestroyJoint: %s",
                     ssLastError());
      island->joint_count = 0;
    } else {
      for (int i = 0; i < island->body_count; ++i) {
        if (island->geoms[i] != 0) dGeomDestroy(island->geoms[i]);
        FUZZ_REQUIRE(ssStepper_DestroyBody(w->stepper, island->bodies[i]) == SS_OK, "DestroyBody: %s",
                     ssLastError());
      }
      island->body_count = 0;
    }
    if (pass == 0 && frame_between) alive = frame(w, 1.0 / 60, -1);
  }
  memset(island, 0, sizeof *island);
  return alive;
}

/* ---- contacts ---- */

static void near_callback(void* data, dGeomID geom1, dGeomID geom2) {
  ssStepper* stepper = data;
  World* w = *(World**)dGeomGetData(geom1);
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
    } else {
      FUZZ_REQUIRE(isfinite(contacts[i].surface.soft_erp) && isfinite(contacts[i].surface.soft_cfm) &&
                       contacts[i].surface.soft_cfm >= 0,
                   "contact softened OK with erp %g cfm %g", contacts[i].surface.soft_erp,
                   contacts[i].surface.soft_cfm);
    }
    dJointID joint = dJointCreateContact(w->world, w->contacts, &contacts[i]);
    dJointAttach(joint, body1, body2);
  }
}

static void collide(void* context, ssStepper* stepper) {
  World* w = context;
  dSpaceCollide(w->space, stepper, near_callback);
}

static int destroy_island(World* w, int kind, int bodies_first, int frame_between);
static void build_island(World* w, int kind, const double* tuned);

/* A program's before_step doing what the plan says, once. */
static void before_step(void* context, ssStepper* stepper) {
  World* w = context;
  if (w->plan.what == 0 || ssStepper_CurrentStep(stepper).index != w->plan.at) return;
  int what = w->plan.what;
  w->plan.what = 0;
  Island* island = &w->islands[w->plan.kind];
  dBodyID body = island->body_count > 0 ? island->bodies[0] : 0;
  double v = w->plan.value;
  if (verbose) fprintf(stderr, "  before_step %d: plan %d, island %d, %.17g\n", w->plan.at, what, w->plan.kind, v);
  switch (what) {
    case 1: if (body) dBodyAddTorque(body, v, 0, 0); break; /* a PD controller's torque, NaN included */
    case 2: if (body) dBodyAddForce(body, 0, v, 0); break;
    case 3: if (body) dBodySetAngularVel(body, 0, 0, v); break;
    case 4: if (body) dBodySetPosition(body, v, 0, 0.5); break;
    case 5: /* destroyed and built again inside the frame: the stepper must forget the one and find the other */
      destroy_island(w, w->plan.kind, v > 0, 0);
      build_island(w, w->plan.kind, NULL);
      break;
    default: {
      ssFrameReport inner;
      FUZZ_REQUIRE(ssStepper_Step(stepper, 1.0 / 60, &inner) == SS_ERROR_REENTERED, "Step from before_step: %s",
                   ssLastError());
      ssStepping stepping = ssStepper_Stepping(stepper);
      FUZZ_REQUIRE(ssStepper_SetStepping(stepper, &stepping) == SS_ERROR_REENTERED, "SetStepping from before_step");
      ssStepper_Reset(stepper);
      FUZZ_REQUIRE(strstr(ssLastError(), "ssStepper_Reset: called from a callback") != NULL, "Reset from before_step");
    }
  }
}

/* ---- states ---- */

static int snapshot(const World* w, BodyState* out, int capacity) {
  int count = 0;
  for (int k = 0; k < ISLAND_COUNT; ++k)
    for (int i = 0; i < w->islands[k].body_count && count < capacity; ++i, ++count) {
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

static int all_finite(const BodyState* states, int count, int* which) {
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

/* ---- operations ---- */

/* Physics steps the frame would take; frames that would take more are not stepped (they test the machine). */
static double steps_for(const World* w, double frame_s) {
  if (!(frame_s > 0) || !isfinite(frame_s)) return 0;
  switch (w->stepping.cut) {
    case SS_CUT_WHOLE_FRAME: return 1;
    case SS_CUT_FIXED: return fmin(ceil(frame_s / w->stepping.fixed_step_s), w->stepping.max_steps_per_frame);
    default: return fmin(ceil(frame_s / w->stepping.max_step_s), w->stepping.max_steps_per_frame);
  }
}


/* One frame; returns 0 when the run must end (the world blew up). */
static int frame(World* w, double frame_s, int op) {
  if (steps_for(w, frame_s) > MAX_STEPS_PER_FRAME) return 1;
  enum { CAPACITY = ISLAND_COUNT * MAX_ISLAND_BODIES };
  BodyState before[CAPACITY], after[CAPACITY];
  int count = snapshot(w, before, CAPACITY);
  int planned_destroy = w->plan.what == 5; /* bodies replaced in the frame: states are not compared */
  ssFrameReport report;
  if (verbose) fprintf(stderr, "op %d: stepping %.17g s\n", op, frame_s);
  ssStatus status = ssStepper_Step(w->stepper, frame_s, &report);
  if (snapshot(w, after, CAPACITY) != count || planned_destroy) count = snapshot(w, before, CAPACITY);
  if (verbose)
    fprintf(stderr, "op %d: %s/%s frame %.17g s: %s, %d steps, %s\n", op,
            NAME_OR_UNKNOWN(ssFrameCutName(w->stepping.cut)), NAME_OR_UNKNOWN(ssMappingName(w->stepping.mapping)),
            frame_s, ssStatusName(status), report.steps, status == SS_OK ? "" : ssLastError());
  int which = -1;
  switch (status) {
    case SS_OK:
      FUZZ_REQUIRE(all_finite(after, count, &which), "op %d: frame %.17g s under %s reported OK but body %d is not "
                   "finite", op, frame_s, NAME_OR_UNKNOWN(ssMappingName(w->stepping.mapping)), which);
      FUZZ_REQUIRE(isfinite(report.simulated_s) && report.simulated_s >= 0 && report.steps >= 0,
                   "op %d: frame %.17g s: report simulated %g s in %d steps", op, frame_s, report.simulated_s,
                   report.steps);
      return 1;
    case SS_ERROR_BLOWUP:
    case SS_ERROR_SPEED_LIMIT:
    case SS_ERROR_POSITION_LIMIT:
    latched: {
      FUZZ_REQUIRE(ssLastError()[0] != '\0' && report.failed_body != 0, "op %d: %s without a message or a body", op,
                   ssStatusName(status));
      /* Latched: the next frame is refused and changes nothing. The run ends: the world is the program's to repair. */
      snapshot(w, before, CAPACITY);
      status = ssStepper_Step(w->stepper, 1.0 / 60, &report);
      snapshot(w, after, CAPACITY);
      FUZZ_REQUIRE(status == SS_ERROR_FAILED && memcmp(before, after, count * sizeof before[0]) == 0,
                   "op %d: the frame after a blow-up returned %s", op, ssStatusName(status));
      return 0;
    }
    default:
      if (report.failed_body != 0) goto latched; /* a force refused at the boundary, named with its body */
      FUZZ_REQUIRE(ssLastError()[0] != '\0', "op %d: frame %.17g s refused (%s) without a message", op, frame_s,
                   ssStatusName(status));
      FUZZ_REQUIRE(memcmp(before, after, count * sizeof before[0]) == 0,
                   "op %d: frame %.17g s refused (%s: %s) but the world moved", op, frame_s, ssStatusName(status),
                   ssLastError());
      return 1;
  }
}

/* A refused registry call names something and keeps the bindings as they were. */
static void check_registry_call(World* w, ssStatus status, int bindings_before, const char* what) {
  if (status == SS_OK) return;
  FUZZ_REQUIRE(ssLastError()[0] != '\0', "%s refused (%s) without a message", what, ssStatusName(status));
  FUZZ_REQUIRE(ssRegistry_JointBindingCount(w->registry) == bindings_before, "%s refused (%s) but the binding count "
               "went from %d to %d", what, ssLastError(), bindings_before, ssRegistry_JointBindingCount(w->registry));
}

static const char* joint_type_name(dJointID joint) {
  static const char* names[] = {"none", "ball", "hinge", "slider", "contact", "universal", "hinge2", "fixed", "null",
                                "amotor", "lmotor", "plane2d", "pr", "pu", "piston", "dball", "dhinge",
                                "transmission"};
  int type = dJointGetType(joint);
  return type >= 0 && type < (int)(sizeof names / sizeof names[0]) ? names[type] : "?";
}

static dJointID pick_joint(World* w, uint8_t byte) {
  int count = 0;
  for (int k = 0; k < ISLAND_COUNT; ++k) count += w->islands[k].joint_count;
  int index = byte % count;
  for (int k = 0; k < ISLAND_COUNT; ++k) {
    if (index < w->islands[k].joint_count) return w->islands[k].joints[index];
    index -= w->islands[k].joint_count;
  }
  return 0;
}

static dBodyID pick_body(World* w, uint8_t byte) {
  if (byte == 0xFF) return 0; /* the world's defaults */
  int count = 0;
  for (int k = 0; k < ISLAND_COUNT; ++k) count += w->islands[k].body_count;
  int index = byte % count;
  for (int k = 0; k < ISLAND_COUNT; ++k) {
    if (index < w->islands[k].body_count) return w->islands[k].bodies[index];
    index -= w->islands[k].body_count;
  }
  return 0;
}

static int same_double(double a, double b) { return memcmp(&a, &b, sizeof a) == 0; }

/* Whether the stepper holds the stepping it was given: every field as given, except that a speed limit of 0 stands
 * for the guard ODE itself needs (stepping.h), and a step length of 0 for the tuned step, which the stepper fills
 * in. Field by field: padding is no state. */
static int holds_stepping(const ssStepping* held, const ssStepping* given) {
  double max_step_s = given->max_step_s == 0 ? held->max_step_s : given->max_step_s;
  double fixed_step_s = given->fixed_step_s == 0 ? held->fixed_step_s : given->fixed_step_s;
  double max_speed = given->max_speed == 0 ? held->max_speed : given->max_speed;
  double max_angular_speed = given->max_angular_speed == 0 ? held->max_angular_speed : given->max_angular_speed;
  return held->cut == given->cut && held->mapping == given->mapping &&
         same_double(held->frozen_step_s, given->frozen_step_s) && held->solver == given->solver &&
         held->quick_iterations == given->quick_iterations && same_double(held->max_step_s, max_step_s) &&
         same_double(held->fixed_step_s, fixed_step_s) &&
         held->max_steps_per_frame == given->max_steps_per_frame && held->max_speed > 0 &&
         held->max_angular_speed > 0 && same_double(held->max_speed, max_speed) &&
         same_double(held->max_angular_speed, max_angular_speed);
}

static void make_world(World* w, FuzzInput* in) {
  memset(w, 0, sizeof *w);
  w->world = dWorldCreate();
  dWorldSetGravity(w->world, 0, 0, -9.81);
  w->space = dSimpleSpaceCreate(0);
  w->self = w;
  dGeomSetData(dCreatePlane(w->space, 0, 0, 1, 0), &w->self);
  w->contacts = dJointGroupCreate(0);
  w->registry = ssRegistry_Create(w->world);
  FUZZ_REQUIRE(w->registry != NULL, "out of memory");
  w->contact_spring = DEFAULT_SPRING;

  /* The stepper's fields, fuzzed: a refused definition must say why, then the defaults run the world. */
  ssStepperDef def = ssDefaultStepperDef();
  def.world = w->world;
  def.registry = w->registry;
  def.collide = collide;
  def.collide_context = w;
  def.before_step = before_step;
  def.before_step_context = w;
  def.contact_group = w->contacts;
  uint8_t how = fuzz_byte(in);
  def.stepping.cut = (ssFrameCut)(how % 4);           /* 3 is unknown */
  def.stepping.mapping = (ssMapping)((how >> 2) % 4); /* 3 is unknown */
  def.stepping.solver = (ssSolver)((how >> 4) % 4);   /* 0 is unset, 3 unknown */
  uint8_t fields = fuzz_byte(in);
  if (fields & 1) def.stepping.max_step_s = fuzz_double(in);
  if (fields & 2) def.stepping.fixed_step_s = fuzz_double(in);
  if (fields & 4) def.stepping.frozen_step_s = fuzz_double(in);
  if (fields & 8) def.stepping.max_steps_per_frame = (int8_t)fuzz_byte(in);
  if (fields & 16) def.stepping.quick_iterations = (int8_t)fuzz_byte(in);
  w->adopt = (fields & 32) != 0;
  double world_erp = fields & 64 ? fuzz_double(in) : 0.2, world_cfm = fields & 64 ? fuzz_double(in) : 1e-10;
  double tuned_step_s = fields & 128 ? fuzz_double(in) : 1.0 / 60;
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
    fallback.collide = def.collide;
    fallback.collide_context = def.collide_context;
    fallback.before_step = def.before_step;
    fallback.before_step_context = def.before_step_context;
    fallback.contact_group = def.contact_group;
    fallback.stepping.solver = SS_SOLVER_QUICK;
    fallback.stepping.max_step_s = fallback.stepping.fixed_step_s = 1.0 / 60;
    def = fallback;
    FUZZ_REQUIRE(ssStepper_Create(&def, &w->stepper) == SS_OK, "default stepper: %s", ssLastError());
  }
  w->stepping = ssStepper_Stepping(w->stepper);
  FUZZ_REQUIRE(holds_stepping(&w->stepping, &def.stepping), "the stepper's stepping is not the one it was made with");
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
  for (int kind = 0; kind < ISLAND_COUNT; ++kind) build_island(w, kind, NULL);
}

static void destroy_world(World* w) {
  ssStepper_Destroy(w->stepper);
  ssRegistry_Destroy(w->registry);
  dJointGroupDestroy(w->contacts);
  dSpaceDestroy(w->space);
  dWorldDestroy(w->world);
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static int initialised = 0;
  if (!initialised) {
    dInitODE2(0);
    verbose = getenv("STEADYSTEP_FUZZ_VERBOSE") != NULL;
    initialised = 1;
  }
  dRandSetSeed(1); /* dWorldQuickStep shuffles rows with ODE's generator: every input runs the same way */
  FuzzInput in = {data, size};
  World w;
  make_world(&w, &in);
  for (int op = 0; op < MAX_OPS && !fuzz_empty(&in); ++op) {
    uint8_t code = fuzz_byte(&in);
    if (verbose) fprintf(stderr, "op %d: code %d\n", op, code % 16);
    int bindings = ssRegistry_JointBindingCount(w.registry);
    switch (code % 16) {
      case 14: {
        /* A state or force the program sets between frames (a corrupt save, a teleport, a huge spin). */
        dBodyID body = pick_body(&w, fuzz_byte(&in) & 0x7F);
        uint8_t which = fuzz_byte(&in);
        double v = fuzz_double(&in);
        if (verbose) fprintf(stderr, "  set %d to %.17g\n", which % 5, v);
        switch (which % 5) {
          case 0: dBodySetPosition(body, v, 0, 0.5); break;
          case 1: dBodySetLinearVel(body, 0, v, 0); break;
          case 2: dBodySetAngularVel(body, v, 0, 0); break;
          case 3: dBodyAddForce(body, 0, 0, v); break;
          default: dBodyAddTorque(body, 0, v, 0); break;
        }
        break;
      }
      case 15: {
        /* What before_step does in the next frame. */
        w.plan.what = 1 + fuzz_byte(&in) % 6;
        w.plan.at = fuzz_byte(&in) % 4;
        w.plan.kind = fuzz_byte(&in) % ISLAND_COUNT;
        w.plan.value = fuzz_double(&in);
        break;
      }
      case 0:
        if (!frame(&w, fuzz_double(&in), op)) goto done;
        break;
      case 1: {
        int repeat = 1 + fuzz_byte(&in) % 16;
        double frame_s = fuzz_double(&in);
        for (int i = 0; i < repeat; ++i)
          if (!frame(&w, frame_s, op)) goto done;
        break;
      }
      case 2: {
        /* A new stepping: a lab policy by index (0x80 clear) or fields fuzzed one by one. */
        uint8_t which = fuzz_byte(&in);
        ssStepping stepping = w.stepping;
        if (!(which & 0x80)) {
          const char* name = ssPolicyNameAt(which % (ssPolicyCount() + 1)); /* one past the end: NULL */
          ssStatus status = ssSteppingForPolicy(name, fuzz_double(&in), &stepping);
          if (status != SS_OK) {
            FUZZ_REQUIRE(ssLastError()[0] != '\0' && holds_stepping(&stepping, &w.stepping),
                         "ssSteppingForPolicy(%s) refused (%s) without a message or changed the stepping",
                         name ? name : "NULL", ssStatusName(status));
            break;
          }
        } else {
          stepping.cut = (ssFrameCut)(int8_t)fuzz_byte(&in);
          stepping.mapping = (ssMapping)(int8_t)fuzz_byte(&in);
          stepping.frozen_step_s = which & 1 ? fuzz_double(&in) : 0;
          if (which & 2) stepping.max_step_s = fuzz_double(&in);
          if (which & 4) stepping.fixed_step_s = fuzz_double(&in);
          if (which & 8) stepping.max_speed = fuzz_double(&in);
          if (which & 16) stepping.max_angular_speed = fuzz_double(&in);
        }
        ssStatus status = ssStepper_SetStepping(w.stepper, &stepping);
        ssStepping now = ssStepper_Stepping(w.stepper);
        if (status == SS_OK) {
          FUZZ_REQUIRE(holds_stepping(&now, &stepping), "SetStepping OK but the stepping differs");
          w.stepping = now;
        } else {
          FUZZ_REQUIRE(ssLastError()[0] != '\0' && holds_stepping(&now, &w.stepping),
                       "SetStepping refused (%s) without a message or changed the stepping", ssStatusName(status));
        }
        if (verbose)
          fprintf(stderr, "  SetStepping(%s/%s frozen %.17g) = %s %s\n", NAME_OR_UNKNOWN(ssFrameCutName(stepping.cut)),
                  NAME_OR_UNKNOWN(ssMappingName(stepping.mapping)), stepping.frozen_step_s, ssStatusName(status),
                  status == SS_OK ? "" : ssLastError());
        break;
      }
      case 3: {
        /* Rebind a row: a supported one (high bit clear) or any param and axis. */
        uint8_t how = fuzz_byte(&in);
        dJointID joint = pick_joint(&w, fuzz_byte(&in));
        int param = how & 0x80 ? (int8_t)fuzz_byte(&in) : how % 4;
        int axis = how & 0x80 ? (int8_t)fuzz_byte(&in) : 1 + (how >> 2) % 3;
        ssSpring spring = {fuzz_double(&in), fuzz_double(&in)};
        double mass = how & 0x40 ? fuzz_double(&in) : 0;
        ssStatus status = ssRegistry_BindJoint(w.registry, joint, (ssJointParam)param, axis, spring, mass);
        if (verbose)
          fprintf(stderr, "  BindJoint(%s joint, param %d, axis %d, {%.17g, %.17g}, mass %.17g) = %s\n",
                  joint_type_name(joint), param, axis, spring.stiffness, spring.damping, mass, ssStatusName(status));
        check_registry_call(&w, status, bindings, "ssRegistry_BindJoint");
        break;
      }
      case 4: {
        uint8_t how = fuzz_byte(&in);
        dJointID joint = pick_joint(&w, fuzz_byte(&in));
        double load = fuzz_double(&in);
        ssStatus status = ssRegistry_SetJointLoad(w.registry, joint, (ssJointParam)(how % 4), 1 + (how >> 2) % 3, load);
        if (verbose)
          fprintf(stderr, "  SetJointLoad(%s joint, param %d, axis %d, %.17g) = %s\n", joint_type_name(joint), how % 4,
                  1 + (how >> 2) % 3, load, ssStatusName(status));
        check_registry_call(&w, status, bindings, "ssRegistry_SetJointLoad");
        break;
      }
      case 5: {
        uint8_t how = fuzz_byte(&in);
        int kind = how % ISLAND_COUNT;
        double tuned[2] = {0.2, 1e-5};
        if (how & 0x80) {
          tuned[0] = fuzz_double(&in);
          tuned[1] = fuzz_double(&in);
        }
        if (!destroy_island(&w, kind, how & 0x20, how & 0x40)) goto done;
        build_island(&w, kind, how & 0x80 ? tuned : NULL);
        break;
      }
      case 6: {
        dBodyID body = pick_body(&w, fuzz_byte(&in));
        double linear = fuzz_double(&in), angular = fuzz_double(&in);
        ssStatus status = ssRegistry_BindDamping(w.registry, body, linear, angular);
        if (verbose) fprintf(stderr, "  BindDamping(%.17g, %.17g) = %s\n", linear, angular, ssStatusName(status));
        check_registry_call(&w, status, bindings, "ssRegistry_BindDamping");
        break;
      }
      case 7: {
        uint8_t flags = fuzz_byte(&in);
        dBodyID body = pick_body(&w, fuzz_byte(&in));
        double idle = fuzz_double(&in), window = fuzz_double(&in);
        ssStatus status = ssRegistry_BindAutoDisable(w.registry, body, idle, window);
        if (verbose) fprintf(stderr, "  BindAutoDisable(%.17g, %.17g) = %s\n", idle, window, ssStatusName(status));
        check_registry_call(&w, status, bindings, "ssRegistry_BindAutoDisable");
        dWorldSetAutoDisableFlag(w.world, flags & 1);
        if (body != 0) dBodySetAutoDisableFlag(body, flags & 2);
        break;
      }
      case 8: {
        ssSpring spring = {fuzz_double(&in), fuzz_double(&in)};
        double mass = fuzz_double(&in);
        ssStatus status = ssRegistry_BindWorld(w.registry, spring, mass);
        if (verbose)
          fprintf(stderr, "  BindWorld({%.17g, %.17g}, %.17g) = %s\n", spring.stiffness, spring.damping, mass,
                  ssStatusName(status));
        check_registry_call(&w, status, bindings, "ssRegistry_BindWorld");
        break;
      }
      case 9: {
        double a = fuzz_double(&in), b = fuzz_double(&in);
        if (w.adopt) {
          w.contact_erp = a;
          w.contact_cfm = b;
        } else {
          w.contact_spring.stiffness = a;
          w.contact_spring.damping = b;
        }
        if (verbose) fprintf(stderr, "  contact %s {%.17g, %.17g}\n", w.adopt ? "erp, cfm" : "spring", a, b);
        break;
      }
      case 10:
        ssStepper_ResetHistory(w.stepper);
        break;
      case 13:
        ssStepper_Reset(w.stepper);
        break;
      case 11: {
        dBodyID body = pick_body(&w, fuzz_byte(&in));
        if (body == 0) break;
        dMass mass;
        double kg = fuzz_log_range(&in, 1e-3, 1e3);
        if (verbose) fprintf(stderr, "  mass %.17g kg\n", kg);
        dMassSetBoxTotal(&mass, kg, 0.2, 0.2, 0.2);
        dBodySetMass(body, &mass);
        break;
      }
      case 12: {
        /* Unbind a joint and bind its supported rows again with the default spring. */
        dJointID joint = pick_joint(&w, fuzz_byte(&in));
        ssRegistry_UnbindJoint(w.registry, joint);
        bind_defaults(&w, joint);
        break;
      }
    }
  }
done:
  destroy_world(&w);
  return 0;
}

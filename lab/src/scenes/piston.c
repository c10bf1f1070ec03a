/* A ram driven by a motor between the stops of its slider, carrying an arm on a hinge whose stops it swings into,
 * written as ODE programs write a jointed mechanism (after reading ODE's demo_piston, demo_slider and demo_hinge):
 * world ERP/CFM tuned at 60 fps, the stops softened by their own StopERP/StopCFM like rubber buffers, the slider's
 * motor given a target speed and a force limit, whose direction the program reverses every second; then adopted
 * (ssRegistry_Adopt), which binds the world's rows, both joints' stops and motors.
 *
 * The motor runs the ram into each stop and keeps pushing it there with its whole force until it reverses, so each
 * stop is hit as a limit and then carries a steady load; the arm swings when the ram starts and stops, and hits its
 * own stops.
 *
 * params.spring is the slider's stops (N/m, N*s/m): their StopERP and StopCFM are what it stands for at 1/60 s
 * (the default, k 18000 N/m and c 700 N*s/m, is StopERP 0.3, StopCFM 1e-3); params.mass is the ram's mass. */
#include <math.h>
#include <stdlib.h>

#include "lab_error.h"
#include "scene_internal.h"

#define PISTON_HEIGHT_M 1.0          /* the slider's axis: x, at this height */
#define PISTON_RAM_SIDES_M 0.3, 0.15, 0.15
#define PISTON_STOP_M 0.25           /* the slider's stops at +-this from the start */
#define PISTON_SPEED_M_PER_S 0.8     /* the motor's target speed: it reaches a stop 0.31 s after each reversal */
#define PISTON_FORCE_N 40.0          /* the motor's force limit (dParamFMax) */
#define PISTON_REVERSE_S 1.0         /* the program reverses the motor this often */
#define PISTON_ARM_M 0.4             /* the arm hangs this far below its hinge */
#define PISTON_ARM_THICK_M 0.04
#define PISTON_ARM_MASS_OF_RAM 0.25
#define PISTON_ARM_STOP_RAD 0.35
/* The arm's stops, tuned by hand at 60 fps: k 180 N*m/rad, c 7 N*m*s/rad. */
#define PISTON_ARM_STOP_ERP 0.3
#define PISTON_ARM_STOP_CFM 0.1
#define PISTON_WORLD_ERP 0.2
#define PISTON_WORLD_CFM 1e-5

/* Sanity bounds, measured in test_bounds.cpp. (1) The ram at most 0.06 m beyond a stop: a stop holds the motor's
 * 40 N with a sag of F/k (2.2 mm at the default spring), and it acts only from the step that finds the ram past it:
 * at 0.8 m/s a 1/15 s step passes it by up to 5.3 cm. Farther is a ram through its stop. (2) The arm at most 0.25 rad beyond its stops
 * (it swings into them at up to about 4 rad/s, which k and c stop within 0.05 rad). (3) The rigid rows: the ram's
 * centre at most 0.01 m off the slider's axis, and the hinge's two anchors at most 0.01 m apart (the world's rows,
 * k 1.2e6 N/m, open by well under a millimetre); beyond, a joint torn open. */
#define PISTON_MAX_OVERRUN_M 0.06
#define PISTON_MAX_ARM_OVERRUN_RAD 0.25
#define PISTON_MAX_GAP_M 0.01

typedef struct Piston {
  dBodyID ram, arm;
  dJointID slider, hinge;
  double time_s; /* the time of the step about to be taken: the program reverses the motor by simulated time */
} Piston;

static void destroy(void* state) { free(state); }

static ssStatus build(const ssSceneWorld* world, const ssSceneParams* params, void** state) {
  ssSoftness stop;
  ssStatus status = ssImplicitEulerSoftness(params->spring, SS_PROGRAM_TUNED_STEP_S, &stop);
  if (status != SS_OK) return status;
  Piston* piston = calloc(1, sizeof *piston);
  if (piston == NULL) return ssLabFail(SS_ERROR_OUT_OF_MEMORY, "piston: out of memory");
  *state = piston;
  dWorldSetGravity(world->world, 0, 0, -params->gravity);
  dWorldSetERP(world->world, PISTON_WORLD_ERP);
  dWorldSetCFM(world->world, PISTON_WORLD_CFM);

  dMass mass;
  piston->ram = dBodyCreate(world->world);
  dMassSetBoxTotal(&mass, params->mass, PISTON_RAM_SIDES_M);
  dBodySetMass(piston->ram, &mass);
  dBodySetPosition(piston->ram, 0, 0, PISTON_HEIGHT_M);
  dGeomSetBody(dCreateBox(world->space, PISTON_RAM_SIDES_M), piston->ram);
  piston->slider = dJointCreateSlider(world->world, 0);
  dJointAttach(piston->slider, piston->ram, 0);
  dJointSetSliderAxis(piston->slider, 1, 0, 0);
  dJointSetSliderParam(piston->slider, dParamLoStop, -PISTON_STOP_M);
  dJointSetSliderParam(piston->slider, dParamHiStop, PISTON_STOP_M);
  dJointSetSliderParam(piston->slider, dParamStopERP, stop.erp);
  dJointSetSliderParam(piston->slider, dParamStopCFM, stop.cfm);
  dJointSetSliderParam(piston->slider, dParamVel, PISTON_SPEED_M_PER_S);
  dJointSetSliderParam(piston->slider, dParamFMax, PISTON_FORCE_N);

  piston->arm = dBodyCreate(world->world);
  dMassSetBoxTotal(&mass, PISTON_ARM_MASS_OF_RAM * params->mass, PISTON_ARM_THICK_M, PISTON_ARM_THICK_M,
                   PISTON_ARM_M);
  dBodySetMass(piston->arm, &mass);
  dBodySetPosition(piston->arm, 0, 0, PISTON_HEIGHT_M - 0.5 * PISTON_ARM_M);
  dGeomSetBody(dCreateBox(world->space, PISTON_ARM_THICK_M, PISTON_ARM_THICK_M, PISTON_ARM_M), piston->arm);
  piston->hinge = dJointCreateHinge(world->world, 0);
  dJointAttach(piston->hinge, piston->arm, piston->ram);
  dJointSetHingeAnchor(piston->hinge, 0, 0, PISTON_HEIGHT_M);
  dJointSetHingeAxis(piston->hinge, 0, 1, 0);
  dJointSetHingeParam(piston->hinge, dParamLoStop, -PISTON_ARM_STOP_RAD);
  dJointSetHingeParam(piston->hinge, dParamHiStop, PISTON_ARM_STOP_RAD);
  dJointSetHingeParam(piston->hinge, dParamStopERP, PISTON_ARM_STOP_ERP);
  dJointSetHingeParam(piston->hinge, dParamStopCFM, PISTON_ARM_STOP_CFM);

  status = ssRegistry_Adopt(world->registry, SS_PROGRAM_TUNED_STEP_S, world->space, NULL);
  if (status != SS_OK) {
    destroy(piston);
    *state = NULL;
  }
  return status;
}

/* Before every step: the motor's direction for the time the step starts, then that time moves on by the step. */
static void drive(void* state, double step_s) {
  Piston* piston = state;
  int forward = (int)floor(piston->time_s / PISTON_REVERSE_S) % 2 == 0;
  dJointSetSliderParam(piston->slider, dParamVel, forward ? PISTON_SPEED_M_PER_S : -PISTON_SPEED_M_PER_S);
  piston->time_s += step_s;
}

static void sample(const void* state, double* out) {
  const Piston* piston = state;
  out[0] = dJointGetSliderPosition(piston->slider);
  out[1] = dJointGetSliderPositionRate(piston->slider);
  out[2] = dJointGetHingeAngle(piston->hinge);
}

static double check(const void* state, char* worst, size_t size) {
  const Piston* piston = state;
  double overrun_m = fabs(dJointGetSliderPosition(piston->slider)) - PISTON_STOP_M;
  double use = overrun_m / PISTON_MAX_OVERRUN_M;
  ssBoundMessage(worst, size, "slider: ram %.6g m beyond its stop, bound %g m (what a 1/15 s step at the motor's "
                 "speed passes it by, and more)", overrun_m, PISTON_MAX_OVERRUN_M);
  double arm_overrun_rad = fabs(dJointGetHingeAngle(piston->hinge)) - PISTON_ARM_STOP_RAD;
  if (arm_overrun_rad / PISTON_MAX_ARM_OVERRUN_RAD > use) {
    use = arm_overrun_rad / PISTON_MAX_ARM_OVERRUN_RAD;
    ssBoundMessage(worst, size, "hinge: arm %.6g rad beyond its stop, bound %g rad", arm_overrun_rad,
                   PISTON_MAX_ARM_OVERRUN_RAD);
  }
  const dReal* ram = dBodyGetPosition(piston->ram);
  double off_axis_m = hypot(ram[1], ram[2] - PISTON_HEIGHT_M);
  if (off_axis_m / PISTON_MAX_GAP_M > use) {
    use = off_axis_m / PISTON_MAX_GAP_M;
    ssBoundMessage(worst, size, "slider: ram %.6g m off its axis, bound %g m", off_axis_m, PISTON_MAX_GAP_M);
  }
  dVector3 on_arm, on_ram;
  dJointGetHingeAnchor(piston->hinge, on_arm);
  dJointGetHingeAnchor2(piston->hinge, on_ram);
  double gap_m = sqrt((on_arm[0] - on_ram[0]) * (on_arm[0] - on_ram[0]) + (on_arm[1] - on_ram[1]) * (on_arm[1] - on_ram[1]) +
                      (on_arm[2] - on_ram[2]) * (on_arm[2] - on_ram[2]));
  if (gap_m / PISTON_MAX_GAP_M > use) {
    use = gap_m / PISTON_MAX_GAP_M;
    ssBoundMessage(worst, size, "hinge: anchors %.6g m apart, bound %g m", gap_m, PISTON_MAX_GAP_M);
  }
  return use;
}

const ssSceneDesc ssPistonScene = {
    .info = {.name = "piston",
             .description = "a ram driven by a motor into the stops of its slider, with an arm swinging into its "
                            "hinge's stops",
             .quantity_count = 3,
             .quantity_names = {"ram x", "ram v", "arm angle"},
             .quantity_units = {"m", "m/s", "rad"}},
    /* StopERP 0.3, StopCFM 1e-3 at 1/60 s. */
    .defaults = {.spring = {.stiffness = 18000, .damping = 700}, .mass = 2, .x0 = 0, .gravity = 9.81,
                 .body_count = 0},
    .max_body_count = 0,
    .build = build,
    .drive = drive,
    .sample = sample,
    .check = check,
    .destroy = destroy,
};

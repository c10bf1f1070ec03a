/* The article's case: one body on a slider whose stop, with lo = hi = 0, is a bilateral spring-damper along x.
 *
 * ODE's slider position is measured from where the body was when the axis was set, so the body is created at the
 * origin, attached, given its axis and only then moved to x0: the stop then sees an extension of exactly x0. The
 * slider's other five rows are rigid and have no motion to soften, so the world's ERP/CFM are left alone. */
#include <stdlib.h>

#include "error.h"
#include "scene_internal.h"

typedef struct Oscillator {
  dBodyID body;
  dJointID slider;
} Oscillator;

static ssStatus build(const ssSceneWorld* world, const ssSceneParams* params, void** state) {
  Oscillator* osc = calloc(1, sizeof *osc);
  if (osc == NULL) return ssFail(SS_ERROR_OUT_OF_MEMORY, "oscillator: out of memory");
  /* "down" is -x, along the slider: gravity then shifts the spring's rest point to -m g / k. */
  dWorldSetGravity(world->world, -params->gravity, 0, 0);

  osc->body = dBodyCreate(world->world);
  dMass mass;
  dMassSetSphereTotal(&mass, params->mass, 0.1);
  dBodySetMass(osc->body, &mass);
  dBodySetPosition(osc->body, 0, 0, 0);

  osc->slider = dJointCreateSlider(world->world, 0);
  dJointAttach(osc->slider, osc->body, 0);
  dJointSetSliderAxis(osc->slider, 1, 0, 0);
  dJointSetSliderParam(osc->slider, dParamLoStop, 0);
  dJointSetSliderParam(osc->slider, dParamHiStop, 0);
  dBodySetPosition(osc->body, params->x0, 0, 0);
  dBodySetLinearVel(osc->body, 0, 0, 0);

  /* The row moves the body alone along x: its effective mass is the body's mass. */
  ssStatus status = ssRegistry_BindJoint(world->registry, osc->slider, SS_PARAM_STOP, 1, params->spring, params->mass);
  if (status != SS_OK) {
    free(osc);
    return status;
  }
  *state = osc;
  return SS_OK;
}

static void sample(const void* state, double* out) {
  const Oscillator* osc = state;
  out[0] = dJointGetSliderPosition(osc->slider);
  out[1] = dJointGetSliderPositionRate(osc->slider);
  out[2] = dJointGetSliderParam(osc->slider, dParamStopERP);
  out[3] = dJointGetSliderParam(osc->slider, dParamStopCFM);
}

static void destroy(void* state) { free(state); }

const ssSceneDesc ssOscillatorScene = {
    .info = {.name = "oscillator",
             .description = "one body on a slider whose stop (lo = hi = 0) is the spring: the article's case",
             .quantity_count = 4,
             .quantity_names = {"x", "v", "erp", "cfm"},
             .quantity_units = {"m", "m/s", "", "m/(N*s)"}},
    /* The article's constants: k = 40 N/m, c = 1 N*s/m on 1 kg, released at rest from 0.5 m. */
    .defaults = {.spring = {.stiffness = 40, .damping = 1}, .mass = 1, .x0 = 0.5, .gravity = 0, .body_count = 0},
    .max_body_count = 0,
    .build = build,
    .sample = sample,
    .destroy = destroy,
};

/* Stepping as data: defaults, the one validator, and the stepping policies (named presets). */
#include "steadystep/stepping.h"

#include <stddef.h>
#include <string.h>

#include "error.h"
#include "ode_bounds.h"

ssStepping ssDefaultStepping(void) {
  return (ssStepping){
      .cut = SS_CUT_SUBSTEPS,
      .mapping = SS_MAPPING_IMPLICIT_EULER,
      .frozen_step_s = 0,
      .solver = SS_SOLVER_UNSET,
      .quick_iterations = 0,
      .max_step_s = 0,
      .fixed_step_s = 0,
      .max_step_slack = 0.25,
      .step_seed = 0,
      .max_steps_per_frame = 32,
      .max_speed = 1e4,
      .max_angular_speed = 1e4,
  };
}

const char* ssFrameCutName(ssFrameCut cut) {
  switch (cut) {
    case SS_CUT_WHOLE_FRAME: return "whole-frame";
    case SS_CUT_SUBSTEPS: return "substeps";
    case SS_CUT_FIXED: return "fixed";
  }
  return NULL;
}

static ssStatus checkSpeed(const char* name, const char* unit, double value) {
  ssStatus status = ssCheckNonNegative(name, unit, value);
  if (status == SS_OK && value > SS_MAX_SAFE_SPEED)
    status = ssFail(SS_ERROR_OUT_OF_RANGE, "%s = %g %s: must be at most SS_MAX_SAFE_SPEED = %g (0 = that bound)",
                    name, value, unit, SS_MAX_SAFE_SPEED);
  return status;
}

ssStatus ssValidateStepping(const ssStepping* stepping) {
  if (stepping == NULL) return ssFail(SS_ERROR_OUT_OF_RANGE, "stepping = NULL: a stepping is required");
  if (ssFrameCutName(stepping->cut) == NULL)
    return ssFail(SS_ERROR_UNSUPPORTED, "stepping.cut = %d: unknown (0 whole-frame, 1 substeps, 2 fixed)",
                  (int)stepping->cut);
  if (ssMappingName(stepping->mapping) == NULL)
    return ssFail(SS_ERROR_UNSUPPORTED, "stepping.mapping = %d: unknown (0 implicit-euler, 1 matched, 2 exact)",
                  (int)stepping->mapping);
  if (stepping->solver == SS_SOLVER_UNSET)
    return ssFail(SS_ERROR_UNSUPPORTED, "stepping.solver = unset: say which ODE step the program calls "
                                        "(SS_SOLVER_QUICK for dWorldQuickStep, SS_SOLVER_STEP for dWorldStep)");
  if (stepping->solver != SS_SOLVER_QUICK && stepping->solver != SS_SOLVER_STEP)
    return ssFail(SS_ERROR_UNSUPPORTED, "stepping.solver = %d: unknown (1 quick, 2 step)", (int)stepping->solver);
  if (stepping->quick_iterations < 0)
    return ssFail(SS_ERROR_OUT_OF_RANGE, "stepping.quick_iterations = %d: must not be negative (0 = the world's own)",
                  stepping->quick_iterations);
  if (stepping->max_steps_per_frame <= 0)
    return ssFail(SS_ERROR_OUT_OF_RANGE, "stepping.max_steps_per_frame = %d: must be positive",
                  stepping->max_steps_per_frame);
  if (stepping->step_seed < -1)
    return ssFail(SS_ERROR_OUT_OF_RANGE, "stepping.step_seed = %d: must be >= 0 (a seed) or -1 (ODE's generator left "
                  "alone)", stepping->step_seed);
  ssStatus status = ssCheckNonNegative("stepping.max_step_slack", "(a fraction of max_step_s)", stepping->max_step_slack);
  if (status == SS_OK && stepping->max_step_slack > 1)
    status = ssFail(SS_ERROR_OUT_OF_RANGE, "stepping.max_step_slack = %g: must be at most 1 (a step at most twice "
                    "max_step_s)", stepping->max_step_slack);
  if (status != SS_OK) return status;
  /* 0: the tuned step, resolved (or refused) by the stepper */
  if (stepping->max_step_s != 0) status = ssCheckStepLength("stepping.max_step_s", stepping->max_step_s);
  if (status == SS_OK && stepping->fixed_step_s != 0)
    status = ssCheckStepLength("stepping.fixed_step_s", stepping->fixed_step_s);
  if (status == SS_OK && stepping->frozen_step_s != 0 && stepping->frozen_step_s != SS_FROZEN_AT_TUNED_STEP)
    status = ssCheckStepLength("stepping.frozen_step_s", stepping->frozen_step_s);
  if (status == SS_OK) status = checkSpeed("stepping.max_speed", "m/s", stepping->max_speed);
  if (status == SS_OK) status = checkSpeed("stepping.max_angular_speed", "rad/s", stepping->max_angular_speed);
  return status;
}

typedef struct Policy {
  const char* name;
  ssFrameCut cut;
  ssMapping mapping;
  int frozen;
} Policy;

static const Policy policies[] = {
    {"naive", SS_CUT_WHOLE_FRAME, SS_MAPPING_IMPLICIT_EULER, 1},
    /* The control: naive's frozen softness, but the frame cut as implicit-euler cuts it, so that a comparison
     * separates what cutting the frame gives (naive -> substeps-frozen) from what the mapping adds. */
    {"substeps-frozen", SS_CUT_SUBSTEPS, SS_MAPPING_IMPLICIT_EULER, 1},
    {"implicit-euler", SS_CUT_SUBSTEPS, SS_MAPPING_IMPLICIT_EULER, 0},
    {"matched", SS_CUT_SUBSTEPS, SS_MAPPING_MATCHED, 0},
    {"exact", SS_CUT_SUBSTEPS, SS_MAPPING_EXACT, 0},
    {"fixed", SS_CUT_FIXED, SS_MAPPING_IMPLICIT_EULER, 0},
    {"fixed-matched", SS_CUT_FIXED, SS_MAPPING_MATCHED, 0},
    {"fixed-exact", SS_CUT_FIXED, SS_MAPPING_EXACT, 0},
};
enum { POLICY_COUNT = sizeof policies / sizeof policies[0] };

int ssSteppingPolicyCount(void) { return POLICY_COUNT; }

const char* ssSteppingPolicyNameAt(int index) {
  return index >= 0 && index < POLICY_COUNT ? policies[index].name : NULL;
}

ssStatus ssSteppingForPolicy(const char* name, double reference_step_s, ssStepping* stepping) {
  if (stepping == NULL) return ssFail(SS_ERROR_OUT_OF_RANGE, "stepping = NULL: needs somewhere to write the policy");
  for (int i = 0; i < POLICY_COUNT; ++i) {
    if (name == NULL || strcmp(name, policies[i].name) != 0) continue;
    if (policies[i].frozen && reference_step_s != 0) {
      ssStatus status = ssCheckStepLength("reference_step_s", reference_step_s);
      if (status != SS_OK) return status;
    }
    stepping->cut = policies[i].cut;
    stepping->mapping = policies[i].mapping;
    stepping->frozen_step_s = !policies[i].frozen ? 0 : reference_step_s != 0 ? reference_step_s
                                                                               : SS_FROZEN_AT_TUNED_STEP;
    /* naive is the program's own loop, which leaves ODE's generator alone; the others make each step replayable */
    if (policies[i].cut == SS_CUT_WHOLE_FRAME) stepping->step_seed = -1;
    else if (stepping->step_seed < 0) stepping->step_seed = 0;
    return SS_OK;
  }
  char known[160] = "";
  for (int i = 0; i < POLICY_COUNT; ++i) {
    strncat(known, i ? ", " : "", sizeof known - strlen(known) - 1);
    strncat(known, policies[i].name, sizeof known - strlen(known) - 1);
  }
  return ssFail(SS_ERROR_PARSE, "policy \"%.64s\": unknown (%s)", name ? name : "(null)", known);
}

const char* ssSteppingPolicyName(const ssStepping* stepping) {
  if (stepping == NULL) return NULL;
  for (int i = 0; i < POLICY_COUNT; ++i)
    if (policies[i].cut == stepping->cut && policies[i].mapping == stepping->mapping &&
        policies[i].frozen == (stepping->frozen_step_s != 0))
      return policies[i].name;
  return NULL;
}

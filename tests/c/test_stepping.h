// Test support: the stepping a test's program states. The library has no default ODE step and no default step
// length without a tuned step, so every test says which: dWorldQuickStep, substeps and fixed steps of 1/60 s.
#ifndef STEADYSTEP_TESTS_TEST_STEPPING_H
#define STEADYSTEP_TESTS_TEST_STEPPING_H

#include "steadystep/stepper.h"

inline ssStepping TestStepping(double step_s = 1.0 / 60.0) {
  ssStepping stepping = ssDefaultStepping();
  stepping.solver = SS_SOLVER_QUICK;
  stepping.max_step_s = step_s;
  stepping.fixed_step_s = step_s;
  return stepping;
}

inline ssStepperDef TestStepperDef() {
  ssStepperDef def = ssDefaultStepperDef();
  def.stepping = TestStepping();
  return def;
}

#endif

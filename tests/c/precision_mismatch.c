/* A program built against one ODE and run with a libode of the other precision under the same name (the test in
 * CMakeLists.txt swaps it in with LD_LIBRARY_PATH): ssStepper_Create must refuse by name before anything steps.
 * It calls nothing of ODE that takes or returns a dReal, which the other precision would garble. Prints the
 * refusal and exits 0 when refused; exits 1 when the stepper was made. */
#include <stdio.h>

#include <ode/ode.h>

#include <steadystep/steadystep.h>

int main(void) {
  dInitODE2(0);
  dWorldID world = dWorldCreate();
  ssStepperDef def = ssDefaultStepperDef();
  def.world = world;
  def.stepping.solver = SS_SOLVER_QUICK;
  def.stepping.max_step_s = 1.0 / 60;
  ssStepper* stepper = NULL;
  ssStatus status = ssStepper_Create(&def, &stepper);
  printf("ssStepper_Create: %s: %s\n", ssStatusName(status), status == SS_OK ? "made" : ssLastError());
  ssStepper_Destroy(stepper);
  dWorldDestroy(world);
  dCloseODE();
  return status == SS_OK;
}

/* The ODE a program runs with against the one the library was built with (stepper.h, ssCheckOdePrecision). */
#include <ode/ode.h>

#include "error.h"
#include "steadystep/stepper.h"

ssStatus ssCheckOdePrecision(void) {
  /* the library reads and writes dReal through ODE's own pointers: a libode of the other precision, loaded in its
   * place (same soname), would step every world wrongly without a word */
  int loaded_double = dCheckConfiguration("ODE_double_precision") != 0;
  int built_double = SS_ODE_DOUBLE_PRECISION;
  if (loaded_double == built_double) return SS_OK;
  return ssFail(SS_ERROR_UNSUPPORTED,
                "the ODE loaded at run time is %s precision (dCheckConfiguration), but steadystep was built against "
                "%s-precision ODE: build the program and steadystep against one ODE, and run them with it",
                loaded_double ? "double" : "single", built_double ? "double" : "single");
}

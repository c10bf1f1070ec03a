/* Fuzz target: Apply against its reference. The input is a scenario for tests/c/apply_differential.c (bindings among
 * more laws than Apply's table holds, loads, unbinding, rebinding, attachment and mass changes, kinematic bodies,
 * every mapping, ODE steps between Applies); the promise is that the fast paths write into ODE exactly what the
 * reference Apply writes, with the same status and report. */
#include "fuzz_input.h"
#include "apply_differential.h"

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  char message[256] = "";
  FUZZ_REQUIRE(ssApplyDifferential(data, size, message, sizeof message, NULL) == 0, "%s", message);
  return 0;
}

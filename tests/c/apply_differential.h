/* The differential check of Apply: ssRegistry_Apply (with its caches) and the reference Apply
 * (src/apply_reference.h) driven side by side on twin worlds by a byte string, which picks bindings among more laws
 * than Apply's law table holds (springs, dampers, undamped and hard rows, rows above Nyquist), loads, unbinding,
 * rebinding, attachment and mass changes, kinematic bodies, every mapping, many steps, and Apply's caches turned off
 * and on. After every Apply, every bound or unbound parameter the worlds' joints have, the world's ERP/CFM, damping
 * and the forces added for loads must be equal bit for bit, as must the statuses and the reports; after every ODE
 * step, every body's state. Shared by the GoogleTest (test_apply.cpp) and the fuzz target (tests/fuzz/fuzz_apply.c). */
#ifndef STEADYSTEP_APPLY_DIFFERENTIAL_H
#define STEADYSTEP_APPLY_DIFFERENTIAL_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct ssDifferentialCounts {
  long applies, applies_failed, steps, compared_values;
} ssDifferentialCounts;

/* Runs the scenario the bytes describe. Returns 0 when the two Applies agreed throughout, else 1 with message filled
 * (what differed, at which operation). counts (may be NULL) accumulates what was done. */
int ssApplyDifferential(const uint8_t* data, size_t size, char* message, size_t message_size,
                        ssDifferentialCounts* counts);

#ifdef __cplusplus
}
#endif

#endif

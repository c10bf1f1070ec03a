/* The tests' reference Apply: Apply as its documentation states it, with no cache and no state of its own beyond the
 * last binding stamp it wrote for. Every row's mass is measured
 * from its bodies (or given), every softness computed and checked, every load correction bounded; then each value
 * that differs from what ODE holds is written. The differential test and fuzz target (tests/c/apply_differential.c)
 * drive it beside ssRegistry_Apply on twin worlds and require the same values in ODE. */
#ifndef STEADYSTEP_APPLY_REFERENCE_H
#define STEADYSTEP_APPLY_REFERENCE_H

#include "steadystep/registry.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ssRegistry_Apply's contract, computed plainly; row_writes counts the parameter sets written: those whose value ODE
 * did not hold already, and those bound since the last Apply (a stamp above *applied_stamp, which starts at 0 and
 * which each Apply that succeeds sets to the registry's last stamp). Errors: those of ssRegistry_Apply, with nothing
 * written. */
ssStatus ssRegistryApplyReference(ssRegistry* registry, unsigned* applied_stamp, ssMapping mapping, double step_s,
                                  double previous_step_s, ssApplyReport* report);

#ifdef __cplusplus
}
#endif

#endif

/* The checks at the boundary between the library and ODE. The ranges and how they were found: limits.h. */
#include "ode_bounds.h"

#include <math.h>

#include "error.h"

static ssStatus checkRange(const char* name, const char* unit, double value, double low, double high) {
  if (!isfinite(value)) return ssFail(SS_ERROR_NOT_FINITE, "%s = %g%s: must be finite", name, value, unit);
  if (!(value >= low && value <= high))
    return ssFail(SS_ERROR_OUT_OF_RANGE, "%s = %g%s: must be in [%g, %g]%s for ODE", name, value, unit, low, high,
                  unit);
  return SS_OK;
}

ssStatus ssCheckStepLength(const char* name, double step_s) {
  return checkRange(name, " s", step_s, SS_MIN_STEP_S, SS_MAX_STEP_S);
}

ssStatus ssCheckSoftnessForOde(const char* name, double erp, double cfm) {
  if (!isfinite(erp)) return ssFail(SS_ERROR_NOT_FINITE, "%s: erp = %g: must be finite", name, erp);
  if (!isfinite(cfm)) return ssFail(SS_ERROR_NOT_FINITE, "%s: cfm = %g: must be finite", name, cfm);
  if (!(fabs(erp) <= SS_MAX_ERP))
    return ssFail(SS_ERROR_OUT_OF_RANGE, "%s: erp = %g: must be in [-%g, %g] for ODE", name, erp, SS_MAX_ERP,
                  SS_MAX_ERP);
  if (!(cfm >= 0 && cfm <= SS_MAX_CFM))
    return ssFail(SS_ERROR_OUT_OF_RANGE, "%s: cfm = %g: must be in [0, %g] for ODE", name, cfm, SS_MAX_CFM);
  return SS_OK;
}

ssStatus ssCheckComputedSoftness(const char* name, ssSoftness softness) {
  ssStatus status = ssCheckSoftnessForOde(name, softness.erp, softness.cfm);
  if (status == SS_OK && !(softness.cfm >= SS_MIN_POSITIVE_CFM))
    status = ssFail(SS_ERROR_OUT_OF_RANGE,
                    "%s: cfm = %g: a spring's cfm must be positive, at least %g (the smallest normal dReal)", name,
                    softness.cfm, SS_MIN_POSITIVE_CFM);
  return status;
}

ssStatus ssCheckMass(const char* name, double mass_kg) {
  return checkRange(name, " kg", mass_kg, SS_MIN_MASS_KG, SS_MAX_MASS_KG);
}

ssStatus ssCheckSpaceListable(const char* what, dSpaceID space) {
  if (dSpaceGetClass(space) != dQuadTreeSpaceClass) return SS_OK;
  return ssFail(SS_ERROR_UNSUPPORTED, "%s %p: a quadtree space, whose geoms ODE 0.16 cannot list (dSpaceGetGeom is not "
                "implemented there and aborts): use a hash, simple or sweep-and-prune space, or make its bodies "
                "known with ssStepper_WatchBody", what, (void*)space);
}

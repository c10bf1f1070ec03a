/* Internal: the checks at the boundary between the library and ODE (the ranges are in steadystep/limits.h).
 *
 * Each check returns SS_OK for a value ODE handles, or records a message naming the value (via ssFail) and returns
 * SS_ERROR_NOT_FINITE (NaN or an infinity) or SS_ERROR_OUT_OF_RANGE (finite, outside the range). None of them
 * changes anything else, so a caller checks every value first and touches ODE only when all passed. */
#ifndef STEADYSTEP_ODE_BOUNDS_H
#define STEADYSTEP_ODE_BOUNDS_H

#include <ode/common.h>
#include <ode/collision.h>

#include "steadystep/limits.h"
#include "steadystep/spring.h"
#include "steadystep/status.h"

/* A step length (s) for dWorldStep / dWorldQuickStep: finite and in [SS_MIN_STEP_S, SS_MAX_STEP_S]. */
ssStatus ssCheckStepLength(const char* name, double step_s);

/* A row's softness for ODE: erp finite with |erp| <= SS_MAX_ERP (above 1 is fine), cfm finite in [0, SS_MAX_CFM]
 * (0 is a hard row, as programs tune it). name is the row's, e.g. "hinge 3 stop": the message reads
 * "hinge 3 stop: cfm = 1e+307: ...". */
ssStatus ssCheckSoftnessForOde(const char* name, double erp, double cfm);

/* The same for a softness the library computed from a spring: as ssCheckSoftnessForOde, and cfm at least
 * SS_MIN_POSITIVE_CFM (it reaches ODE's dReal as a positive normal number, not as 0). */
ssStatus ssCheckComputedSoftness(const char* name, ssSoftness softness);

/* Whether writing a where ODE was given b leaves ODE holding the same value: the two compared as ODE stores them,
 * so that every path decides alike whether a value needs writing, whether it remembers b in double or reads it back
 * from ODE. NAN (nothing written yet) is never the same. */
static inline int ssSameInOde(double a, double b) { return (dReal)a == (dReal)b; }

/* A space whose geoms the library may list with dSpaceGetGeom: ODE 0.16 implements it for simple, hash and
 * sweep-and-prune spaces, and asserts (aborts the process) in a quadtree space. what names the space's role in the
 * message ("def.space", "a space nested in the adopted one"). Errors: SS_ERROR_UNSUPPORTED. */
ssStatus ssCheckSpaceListable(const char* what, dSpaceID space);

/* A body mass (kg) for dBodySetMass: finite and in [SS_MIN_MASS_KG, SS_MAX_MASS_KG]. */
ssStatus ssCheckMass(const char* name, double mass_kg);

#endif

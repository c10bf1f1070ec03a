// Test support: the precision of the ODE the tests are built with. dReal is double in Debian's build and float in
// a single-precision one (scripts/ode-single.sh). The library computes in double and rounds what it writes into ODE
// once to dReal, so a value read back equals the double rounded once (AsDReal), within half a dReal ulp of it; and
// what ODE integrates over n steps carries about n dReal roundings. The tolerances here follow from dReal's epsilon
// so that a test states the same truth in either build.
#ifndef STEADYSTEP_TESTS_PRECISION_H
#define STEADYSTEP_TESTS_PRECISION_H

#include <ode/ode.h>

#include <algorithm>
#include <cmath>
#include <limits>

constexpr double kDRealEpsilon = std::numeric_limits<dReal>::epsilon();
constexpr bool kSinglePrecision = sizeof(dReal) == sizeof(float);

// x as ODE stores it: rounded once to dReal.
inline double AsDReal(double x) { return static_cast<double>(static_cast<dReal>(x)); }

// A tolerance stated for double, widened to what one rounding to dReal leaves of `value`: |value|·ε.
inline double ReadBackTolerance(double tolerance, double value) {
  return std::max(tolerance, std::fabs(value) * kDRealEpsilon);
}

// A tolerance for a quantity ODE integrated over many steps (positions, velocities): `tolerance` as stated for a
// double build; in a float build at least `single_precision_tolerance`, since every step rounds the state to float
// (ε = 1.2e-7 relative) and the roundings add up. Each test states its float tolerance beside what it measured.
inline double IntegratedTolerance(double tolerance, double single_precision_tolerance) {
  return kSinglePrecision ? std::max(tolerance, single_precision_tolerance) : tolerance;
}

#endif

// The library in the precision of the ODE it is built with (dReal: double in Debian's build, float in the
// single-precision one of scripts/ode-single.sh). The conversions run in double and what is written into ODE is
// rounded once; a spring's softness never reaches ODE as cfm = 0 (a hard row) because its cfm underflowed the dReal:
// an accurate mapping whose cfm would falls back to implicit Euler and is counted, and a spring whose implicit-Euler
// cfm would underflow at some step is refused when it is bound. The truths are computed here, in double, from the
// mappings' formulas (spring.h, docs/exact-mappings.md).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "ode_fixture.h"
#include "precision.h"
#include "steadystep/steadystep.h"

extern "C" {
#include "row_law.h"
}

namespace {

// A heavily over-damped row: the matched mapping's a = P/(1 - P), P = exp(-c·h/m), and cfm = a·h/m is about
// 1.3e-54: a normal double, and far below the smallest float.
constexpr double kMass = 1.0, kStep = 1.0 / 60;
const ssSpring kOverDamped = {1.0, 120.0 / kStep};

double MatchedCfm(ssSpring spring, double mass, double step_s) {
  const double product = std::exp(-spring.damping * step_s / mass);
  return product / (1 - product) * step_s / mass;
}

TEST(Precision, AnAccurateMappingWhoseCfmUnderflowsTheDRealFallsBackToImplicitEulerCounted) {
  const double matched_cfm = MatchedCfm(kOverDamped, kMass, kStep);
  ASSERT_GT(matched_cfm, 0);
  const bool representable = matched_cfm >= SS_MIN_POSITIVE_CFM;
  EXPECT_EQ(representable, !kSinglePrecision) << matched_cfm;

  const ssRowLaw law = ssRowLawOfSpring(kOverDamped);
  for (ssMapping mapping : {SS_MAPPING_MATCHED, SS_MAPPING_EXACT}) {
    ssRowFallback fallback;
    ssSoftness softness;
    // load declared: the static-stiffness rule (row_law.c) would hand this strongly damped row on in any precision;
    // here the only reason left is the dReal
    ASSERT_EQ(ssRowSoftness(&law, mapping, kMass, kStep, kStep, 1, &fallback, &softness), SS_OK) << ssLastError();
    EXPECT_EQ(fallback.to_implicit_euler, representable ? 0 : 1) << mapping;
    // Whoever served it, the row reaches ODE as a spring: a positive normal dReal.
    EXPECT_GE(softness.cfm, SS_MIN_POSITIVE_CFM);
    EXPECT_GT(AsDReal(softness.cfm), 0);
    const double hk_plus_c = kStep * kOverDamped.stiffness + kOverDamped.damping;
    if (representable) {
      EXPECT_NEAR(softness.cfm, matched_cfm, 1e-9 * matched_cfm) << mapping;
    } else {  // implicit Euler: cfm = 1/(h·k + c), erp = h·k/(h·k + c)
      EXPECT_DOUBLE_EQ(softness.cfm, 1 / hk_plus_c) << mapping;
      EXPECT_DOUBLE_EQ(softness.erp, kStep * kOverDamped.stiffness / hk_plus_c) << mapping;
    }
  }
  // The pure function says why, by name.
  ssSoftness untouched = {0.25, 0.5};
  EXPECT_EQ(ssMatchedSoftness(kOverDamped, kMass, kStep, &untouched),
            representable ? SS_OK : SS_ERROR_NO_FINITE_MAPPING);
  if (!representable) {
    EXPECT_NE(std::string(ssLastError()).find("not a usable softness"), std::string::npos) << ssLastError();
    EXPECT_EQ(untouched.erp, 0.25);
  }
}

class PrecisionOde : public OdeTest {};

TEST_F(PrecisionOde, WhatIsWrittenIsTheDoubleRoundedOnceAndNeverAHardRow) {
  dBodyID body = MakeBody(kMass);
  dJointID slider = dJointCreateSlider(world, 0);
  dJointAttach(slider, body, 0);
  dJointSetSliderAxis(slider, 0, 0, 1);
  ssRegistry* registry = ssRegistry_Create(world);
  ASSERT_EQ(ssRegistry_BindJoint(registry, slider, SS_PARAM_STOP, 1, kOverDamped, kMass), SS_OK) << ssLastError();
  const ssRowLaw law = ssRowLawOfSpring(kOverDamped);
  for (ssMapping mapping : {SS_MAPPING_IMPLICIT_EULER, SS_MAPPING_MATCHED, SS_MAPPING_EXACT}) {
    ASSERT_EQ(ssRegistry_Apply(registry, mapping, kStep, kStep, nullptr), SS_OK) << ssLastError();
    ssSoftness expected;
    ASSERT_EQ(ssRowSoftness(&law, mapping, kMass, kStep, kStep, 0, nullptr, &expected), SS_OK);
    EXPECT_EQ(dJointGetSliderParam(slider, dParamStopCFM), AsDReal(expected.cfm)) << mapping;
    EXPECT_EQ(dJointGetSliderParam(slider, dParamStopERP), AsDReal(expected.erp)) << mapping;
    EXPECT_GT(dJointGetSliderParam(slider, dParamStopCFM), 0) << mapping;
  }
  ssRegistry_Destroy(registry);
}

TEST_F(PrecisionOde, ASpringWhoseCfmWouldUnderflowAtTheLongestStepIsRefusedByName) {
  dBodyID body = MakeBody(kMass);
  dJointID slider = dJointCreateSlider(world, 0);
  dJointAttach(slider, body, 0);
  ssRegistry* registry = ssRegistry_Create(world);
  // cfm = 1/(h·k + c) is smallest at SS_MAX_STEP_S: k puts it at half and at twice SS_MIN_POSITIVE_CFM there.
  const double too_stiff = 2 / (SS_MAX_STEP_S * SS_MIN_POSITIVE_CFM);
  const double stiff = 0.5 / (SS_MAX_STEP_S * SS_MIN_POSITIVE_CFM);
  EXPECT_EQ(ssRegistry_BindJoint(registry, slider, SS_PARAM_STOP, 1, ssSpring{too_stiff, 1}, kMass),
            SS_ERROR_NO_FINITE_MAPPING);
  EXPECT_NE(std::string(ssLastError()).find("k = "), std::string::npos) << ssLastError();
  EXPECT_EQ(ssRegistry_JointBindingCount(registry), 0);
  ASSERT_EQ(ssRegistry_BindJoint(registry, slider, SS_PARAM_STOP, 1, ssSpring{stiff, 1}, kMass), SS_OK)
      << ssLastError();
  ASSERT_EQ(ssRegistry_Apply(registry, SS_MAPPING_IMPLICIT_EULER, SS_MAX_STEP_S, 0, nullptr), SS_OK);
  EXPECT_GT(dJointGetSliderParam(slider, dParamStopCFM), 0);
  EXPECT_NEAR(dJointGetSliderParam(slider, dParamStopCFM), 1 / (SS_MAX_STEP_S * stiff + 1),
              ReadBackTolerance(0, 1 / (SS_MAX_STEP_S * stiff + 1)));
  ssRegistry_Destroy(registry);
}

}  // namespace

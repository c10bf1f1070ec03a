// Apply against its reference (tests/c/apply_reference.h): random scenarios on twin worlds, through many laws, loads,
// unbinding, rebinding, attachment and mass changes and every mapping, must write the same values into ODE.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "apply_differential.h"
extern "C" {
#include "row_law.h"
}

namespace {

TEST(ApplyTest, FastPathsWriteWhatTheReferenceWrites) {
  std::mt19937 random(19);
  ssDifferentialCounts counts = {0, 0, 0, 0};
  const int scenarios = 1500;
  for (int s = 0; s < scenarios; ++s) {
    // lengths from a few operations to the most a scenario reads
    std::vector<uint8_t> bytes(5 + random() % 1500);
    for (auto& byte : bytes) byte = static_cast<uint8_t>(random());
    char message[256] = "";
    ASSERT_EQ(ssApplyDifferential(bytes.data(), bytes.size(), message, sizeof message, &counts), 0)
        << "scenario " << s << ": " << message;
  }
  // the scenarios reached what they are for: many Applies, ODE steps between them (no Apply fails: every law was
  // checked for every step at bind time)
  EXPECT_GT(counts.applies, 20 * scenarios);
  EXPECT_EQ(counts.applies_failed, 0);
  EXPECT_GT(counts.steps, 5 * scenarios);
  RecordProperty("applies", static_cast<int>(counts.applies));
  RecordProperty("compared_values", static_cast<int>(counts.compared_values));
}

// ssSurelyFailsStaticResponse lets Apply skip the accurate arithmetic of a row: wherever it says so, ssRowSoftness
// (the reference's rule) must hand the row to implicit Euler under both accurate mappings, with implicit Euler's
// softness. Swept over the rule's own coordinates (x = c*h/2m, w = q*h^2, densest near both tolerance edges) at
// masses and steps from small to large, and over random springs.
TEST(ApplyTest, RowsSurelyHandedOnAreHandedOnByTheRule) {
  long decided = 0, kept_by_rule = 0, undecided_failing = 0, tried = 0;
  auto check = [&](ssSpring spring, double mass, double step_s) {
    tried += 1;
    ssRowLaw law = ssRowLawOfSpring(spring);
    ssSoftness euler, softness;
    ssRowFallback fallback;
    ASSERT_EQ(ssRowSoftness(&law, SS_MAPPING_MATCHED, mass, step_s, 0, 0, &fallback, &softness), SS_OK);
    int fails = fallback.to_implicit_euler;
    kept_by_rule += !fails;
    if (!ssSurelyFailsStaticResponse(spring, mass, step_s)) {
      undecided_failing += fails;
      return;
    }
    decided += 1;
    ASSERT_EQ(ssImplicitEulerSoftness(spring, step_s, &euler), SS_OK);
    ASSERT_TRUE(fails) << "k " << spring.stiffness << " c " << spring.damping << " m " << mass << " h " << step_s;
    EXPECT_EQ(softness.erp, euler.erp);
    EXPECT_EQ(softness.cfm, euler.cfm);
    ASSERT_EQ(ssRowSoftness(&law, SS_MAPPING_EXACT, mass, step_s, 0.75 * step_s, 0, &fallback, &softness), SS_OK);
    EXPECT_TRUE(fallback.to_implicit_euler);
    EXPECT_EQ(softness.cfm, euler.cfm);
  };
  const double masses[] = {1e-4, 0.0035, 1.0, 350.0, 1e6};
  const double steps[] = {1e-4, 1.0 / 90, 1.0 / 60, 1.0 / 15, 0.5};
  for (double mass : masses)
    for (double step_s : steps)
      for (int i = 1; i <= 400; ++i)
        for (int j = 0; j <= 100; ++j) {
          // x up to 1.1 and w up to 4.4 (beyond the bounds' range), with steps of 1/400 near the edges
          double x = 1.1 * i / 400.0, w = 4.4 * j / 100.0 * (j % 2 ? 1.0 : x * x);
          ssSpring spring = {(x * x + w) * mass / (step_s * step_s), 2.0 * mass * x / step_s};
          check(spring, mass, step_s);
        }
  // dampers (k = 0), to far beyond the step's decay: the motor rows of programs tuned at ODE's CFM 1e-10
  for (double mass : masses)
    for (double step_s : steps)
      for (int i = 1; i <= 2000; ++i) {
        double x = i <= 1000 ? 1e-4 * i : std::pow(1.02, i - 1000);
        check({0.0, 2.0 * mass * x / step_s}, mass, step_s);
      }
  std::mt19937 random(7);
  std::uniform_real_distribution<double> exponent(-4.0, 4.0);
  for (int i = 0; i < 200000; ++i) {
    double mass = std::pow(10.0, exponent(random)), step_s = std::pow(10.0, exponent(random) / 2 - 2);
    check({i % 4 == 0 ? 0.0 : std::pow(10.0, 2 * exponent(random)), std::pow(10.0, exponent(random))}, mass, step_s);
  }
  // it decides most rows the rule hands on, and not all: near the tolerance the rule's own arithmetic decides
  long failing = tried - kept_by_rule;
  EXPECT_GT(decided, failing / 2);
  EXPECT_GT(undecided_failing, 0);
  EXPECT_GT(kept_by_rule, tried / 50);
}

}  // namespace

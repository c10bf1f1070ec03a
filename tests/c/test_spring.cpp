// The conversions between springs and softness, checked against truths written out here: the exact solution of
// m x'' + c x' + k x = 0 and ODE's step for one row, v' = (a v - (erp/h) x) / (1 + a), a = cfm m / h, x' = x + h v'
// (ode/src/step.cpp: J v' = -(erp/h) x - cfm f with the row force f = m (v' - v) / h).
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <limits>
#include <random>
#include <string>

#include "steadystep/spring.h"

namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();
const double kInf = std::numeric_limits<double>::infinity();

struct Exact {
  // x(t) of m x'' + c x' + k x = 0 from x(0) = x0, x'(0) = v0, through the two roots of m s^2 + c s + k.
  double m, k, c, x0, v0;
  double operator()(double t) const {
    double sigma = c / (2 * m);
    std::complex<double> root = std::sqrt(std::complex<double>(sigma * sigma - k / m, 0));
    if (std::abs(root) < 1e-9) return (x0 + (v0 + sigma * x0) * t) * std::exp(-sigma * t);
    std::complex<double> s1 = -sigma + root, s2 = -sigma - root;
    std::complex<double> b = (v0 - s1 * x0) / (s2 - s1), a = x0 - b;
    return std::real(a * std::exp(s1 * t) + b * std::exp(s2 * t));
  }
};

struct Row {  // ODE's step of one soft row of mass m, written out
  double m, x, v;
  void Step(ssSoftness s, double h) {
    double a = s.cfm * m / h;
    v = (a * v - s.erp / h * x) / (1 + a);
    x += h * v;
  }
};

ssSoftness Sentinel() { return ssSoftness{-7, -7}; }

void ExpectUnchanged(const ssSoftness& s) {
  EXPECT_EQ(s.erp, -7);
  EXPECT_EQ(s.cfm, -7);
}

bool MessageNames(const char* fragment) { return std::string(ssLastError()).find(fragment) != std::string::npos; }

TEST(SpringMapping, IsTheArticlesFormula) {
  ssSoftness s;
  ASSERT_EQ(ssSoftnessFromSpring(ssSpring{40, 1}, 1.0 / 30, &s), SS_OK);
  EXPECT_DOUBLE_EQ(s.erp, (40.0 / 30) / (40.0 / 30 + 1));
  EXPECT_DOUBLE_EQ(s.cfm, 1 / (40.0 / 30 + 1));
}

TEST(SpringMapping, IsImplicitEulerOfTheSpring) {
  const double m = 1.5, k = 250, c = 3, h = 1.0 / 45;
  ssSoftness s;
  ASSERT_EQ(ssSoftnessFromSpring(ssSpring{k, c}, h, &s), SS_OK);
  Row row{m, 0.2, -1.0};
  for (int i = 0; i < 100; ++i) {
    double x = row.x, v = row.v;
    row.Step(s, h);
    // m (v' - v) / h = -k (x + h v') - c v'
    EXPECT_NEAR(m * (row.v - v) / h, -k * (x + h * row.v) - c * row.v, 1e-10);
  }
}

TEST(SpringMapping, RoundTripsOverRandomSprings) {
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> log_uniform(-3, 4);
  for (int i = 0; i < 5000; ++i) {
    ssSpring spring{std::pow(10, log_uniform(rng)), std::pow(10, log_uniform(rng))};
    double h = std::pow(10, log_uniform(rng) - 4);
    ssSoftness s;
    ssSpring back;
    ASSERT_EQ(ssSoftnessFromSpring(spring, h, &s), SS_OK);
    EXPECT_GT(s.erp, 0);
    EXPECT_LE(s.erp, 1);
    EXPECT_GT(s.cfm, 0);
    ASSERT_EQ(ssSpringFromSoftness(s, h, &back), SS_OK);
    EXPECT_NEAR(back.stiffness / spring.stiffness, 1, 1e-9);
    EXPECT_NEAR(back.damping, spring.damping, 1e-9 * (spring.damping + h * spring.stiffness));
  }
}

TEST(SpringMapping, InverseRoundTripsOverRandomSoftness) {
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> unit(1e-6, 1), log_uniform(-8, 2);
  for (int i = 0; i < 5000; ++i) {
    ssSoftness s{unit(rng), std::pow(10, log_uniform(rng))}, back;
    double h = 1.0 / (10 + 1000 * unit(rng));
    ssSpring spring;
    ASSERT_EQ(ssSpringFromSoftness(s, h, &spring), SS_OK);
    ASSERT_EQ(ssSoftnessFromSpring(spring, h, &back), SS_OK);
    EXPECT_NEAR(back.erp, s.erp, 1e-12);
    EXPECT_NEAR(back.cfm / s.cfm, 1, 1e-12);
  }
}

TEST(SpringMapping, FixedSoftnessMeansAStiffnessThatChangesWithTheStep) {
  // The problem the article fixes: erp, cfm tuned at 1/30 s stand for another spring at 1/15 s.
  ssSoftness tuned{0.2, 1e-3};
  ssSpring at30, at15;
  ASSERT_EQ(ssSpringFromSoftness(tuned, 1.0 / 30, &at30), SS_OK);
  ASSERT_EQ(ssSpringFromSoftness(tuned, 1.0 / 15, &at15), SS_OK);
  EXPECT_NEAR(at15.stiffness / at30.stiffness, 0.5, 1e-12);
}

TEST(Frequency, RoundTripsAndMatchesTheDefinition) {
  ssSpring spring;
  ASSERT_EQ(ssSpringFromFrequency(2.0, 0.3, 4.0, &spring), SS_OK);
  const double w = 2 * M_PI * 2.0;
  EXPECT_DOUBLE_EQ(spring.stiffness, 4.0 * w * w);
  EXPECT_DOUBLE_EQ(spring.damping, 2 * 0.3 * 4.0 * w);
  double hz, ratio;
  ASSERT_EQ(ssFrequencyFromSpring(spring, 4.0, &hz, &ratio), SS_OK);
  EXPECT_NEAR(hz, 2.0, 1e-12);
  EXPECT_NEAR(ratio, 0.3, 1e-12);
  ASSERT_EQ(ssFrequencyFromSpring(ssSpring{0, 2}, 1.0, &hz, &ratio), SS_OK);
  EXPECT_EQ(hz, 0);
  EXPECT_TRUE(std::isinf(ratio));
}

TEST(BadInput, SpringsAreRefusedNamingTheValue) {
  struct Case {
    ssSpring spring;
    ssStatus status;
    const char* names;
  } cases[] = {
      {{kNaN, 1}, SS_ERROR_NOT_FINITE, "k = nan"},   {{40, kNaN}, SS_ERROR_NOT_FINITE, "c = nan"},
      {{kInf, 1}, SS_ERROR_NOT_FINITE, "k = inf"},   {{40, -kInf}, SS_ERROR_NOT_FINITE, "c = -inf"},
      {{-1, 1}, SS_ERROR_OUT_OF_RANGE, "k = -1"},    {{40, -0.5}, SS_ERROR_OUT_OF_RANGE, "c = -0.5"},
      {{0, 0}, SS_ERROR_NO_SPRING, "k = 0"},
  };
  for (const Case& bad : cases) {
    ssSoftness s = Sentinel();
    EXPECT_EQ(ssSoftnessFromSpring(bad.spring, 1.0 / 60, &s), bad.status) << bad.names;
    EXPECT_TRUE(MessageNames(bad.names)) << ssLastError();
    ExpectUnchanged(s);
    EXPECT_EQ(ssMatchedSoftness(bad.spring, 1, 1.0 / 60, &s), bad.status);
    EXPECT_EQ(ssExactSoftness(bad.spring, 1, 1.0 / 60, 1.0 / 60, &s), bad.status);
    ExpectUnchanged(s);
  }
}

TEST(BadInput, StepLengthsAreRefusedNamingTheValue) {
  for (double h : {0.0, -0.01, kNaN, kInf, -kInf}) {
    ssSoftness s = Sentinel();
    ssSpring spring{1, 1};
    EXPECT_NE(ssSoftnessFromSpring(ssSpring{40, 1}, h, &s), SS_OK);
    EXPECT_TRUE(MessageNames("step_s")) << ssLastError();
    EXPECT_NE(ssMatchedSoftness(ssSpring{40, 1}, 1, h, &s), SS_OK);
    EXPECT_NE(ssExactSoftness(ssSpring{40, 1}, 1, h, 0, &s), SS_OK);
    EXPECT_NE(ssSpringFromSoftness(ssSoftness{0.5, 0.1}, h, &spring), SS_OK);
    ExpectUnchanged(s);
    EXPECT_EQ(spring.stiffness, 1);
  }
  ssSoftness s = Sentinel();
  EXPECT_EQ(ssExactSoftness(ssSpring{40, 1}, 1, 0.01, -0.01, &s), SS_ERROR_OUT_OF_RANGE);
  EXPECT_TRUE(MessageNames("previous_step_s = -0.01"));
  ExpectUnchanged(s);
}

TEST(BadInput, SoftnessOutsideItsRangeIsRefused) {
  struct Case {
    ssSoftness softness;
    ssStatus status;
    const char* names;
  } cases[] = {
      {{0, 0.1}, SS_ERROR_OUT_OF_RANGE, "erp = 0"},     {{1.5, 0.1}, SS_ERROR_OUT_OF_RANGE, "erp = 1.5"},
      {{-0.2, 0.1}, SS_ERROR_OUT_OF_RANGE, "erp = -0.2"}, {{0.5, 0}, SS_ERROR_OUT_OF_RANGE, "cfm = 0"},
      {{0.5, -1}, SS_ERROR_OUT_OF_RANGE, "cfm = -1"},   {{kNaN, 0.1}, SS_ERROR_NOT_FINITE, "erp = nan"},
      {{0.5, kInf}, SS_ERROR_NOT_FINITE, "cfm = inf"},
  };
  for (const Case& bad : cases) {
    ssSpring spring{-7, -7};
    EXPECT_EQ(ssSpringFromSoftness(bad.softness, 1.0 / 30, &spring), bad.status) << bad.names;
    EXPECT_TRUE(MessageNames(bad.names)) << ssLastError();
    EXPECT_EQ(spring.stiffness, -7);
  }
}

TEST(BadInput, FrequencyFormIsChecked) {
  ssSpring spring{-7, -7};
  EXPECT_EQ(ssSpringFromFrequency(0, 0.5, 1, &spring), SS_ERROR_OUT_OF_RANGE);
  EXPECT_TRUE(MessageNames("frequency_hz = 0"));
  EXPECT_EQ(ssSpringFromFrequency(2, -0.1, 1, &spring), SS_ERROR_OUT_OF_RANGE);
  EXPECT_TRUE(MessageNames("damping_ratio = -0.1"));
  EXPECT_EQ(ssSpringFromFrequency(2, 0.5, 0, &spring), SS_ERROR_OUT_OF_RANGE);
  EXPECT_TRUE(MessageNames("mass = 0"));
  EXPECT_EQ(ssSpringFromFrequency(kNaN, 0.5, 1, &spring), SS_ERROR_NOT_FINITE);
  EXPECT_EQ(spring.stiffness, -7);
}

TEST(BadInput, MatchedNeedsDampingAndMass) {
  ssSoftness s = Sentinel();
  EXPECT_EQ(ssMatchedSoftness(ssSpring{40, 0}, 1, 1.0 / 30, &s), SS_ERROR_NO_FINITE_MAPPING);
  EXPECT_TRUE(MessageNames("c = 0"));
  EXPECT_EQ(ssExactSoftness(ssSpring{40, 0}, 1, 1.0 / 30, 0, &s), SS_ERROR_NO_FINITE_MAPPING);
  for (double mass : {0.0, -1.0, kNaN, kInf}) {
    EXPECT_NE(ssMatchedSoftness(ssSpring{40, 1}, mass, 1.0 / 30, &s), SS_OK);
    EXPECT_TRUE(MessageNames("mass")) << ssLastError();
  }
  EXPECT_EQ(ssSoftnessFor(static_cast<ssMapping>(7), ssSpring{40, 1}, 1, 0.01, 0, &s), SS_ERROR_UNSUPPORTED);
  EXPECT_TRUE(MessageNames("mapping = 7"));
  ExpectUnchanged(s);
  EXPECT_EQ(ssMappingName(static_cast<ssMapping>(7)), nullptr);
}

// Springs of every kind of damping: light, the article's, heavy, critical and over-damped.
struct SpringCase {
  double m, k, c;
};
const SpringCase kSprings[] = {{1, 40, 0.05}, {1, 40, 1}, {2, 500, 30}, {1, 100, 20}, {1, 40, 30}, {0.5, 5, 40}};

TEST(MatchedMapping, SamplesTheExactMotionAtAConstantStep) {
  for (const SpringCase& sc : kSprings) {
    for (double h : {1.0 / 15, 1.0 / 30, 1.0 / 60, 1.0 / 144}) {
      Exact exact{sc.m, sc.k, sc.c, 0.5, 0};
      ssSoftness s;
      ASSERT_EQ(ssMatchedSoftness(ssSpring{sc.k, sc.c}, sc.m, h, &s), SS_OK);
      // ODE's velocity is the slope over the last step: start from a history that came from the exact motion.
      Row row{sc.m, exact(0), (exact(0) - exact(-h)) / h};
      double worst = 0;
      for (int n = 1; n <= 300; ++n) {
        row.Step(s, h);
        worst = std::max(worst, std::abs(row.x - exact(n * h)));
      }
      EXPECT_LT(worst, 1e-11) << "m " << sc.m << " k " << sc.k << " c " << sc.c << " h " << h;
    }
  }
}

TEST(MatchedMapping, ErpExceedsOneForLightDamping) {
  ssSoftness s;
  ASSERT_EQ(ssMatchedSoftness(ssSpring{40, 1}, 1, 1.0 / 30, &s), SS_OK);
  EXPECT_GT(s.erp, 1);
}

TEST(ExactMapping, SamplesTheExactMotionUnderRandomSteps) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> fps(15, 45);
  for (const SpringCase& sc : kSprings) {
    Exact exact{sc.m, sc.k, sc.c, 0.5, -0.3};
    Row row{sc.m, exact.x0, exact.v0};
    double t = 0, previous = 0, worst = 0;
    int refused = 0;
    for (int n = 0; n < 200; ++n) {
      double h = 1 / fps(rng);
      ssSoftness s;
      ssStatus status = ssExactSoftness(ssSpring{sc.k, sc.c}, sc.m, h, previous, &s);
      if (status == SS_ERROR_NO_FINITE_MAPPING) {  // only a lightly damped spring can refuse a step
        ++refused;
        break;
      }
      ASSERT_EQ(status, SS_OK) << ssLastError();
      row.Step(s, h);
      t += h;
      previous = h;
      worst = std::max(worst, std::abs(row.x - exact(t)));
    }
    if (sc.c >= 1) {
      EXPECT_EQ(refused, 0) << "k " << sc.k << " c " << sc.c;
    }
    if (!refused) {
      EXPECT_LT(worst, 1e-10) << "m " << sc.m << " k " << sc.k << " c " << sc.c;
    }
  }
}

TEST(ExactMapping, EqualsMatchedAtEqualSteps) {
  for (const SpringCase& sc : kSprings) {
    ssSoftness exact, matched;
    ASSERT_EQ(ssExactSoftness(ssSpring{sc.k, sc.c}, sc.m, 0.02, 0.02, &exact), SS_OK);
    ASSERT_EQ(ssMatchedSoftness(ssSpring{sc.k, sc.c}, sc.m, 0.02, &matched), SS_OK);
    EXPECT_NEAR(exact.erp, matched.erp, 1e-9 * std::abs(matched.erp));
    EXPECT_NEAR(exact.cfm, matched.cfm, 1e-9 * matched.cfm);
  }
}

TEST(ExactMapping, RefusesAStepThatWouldNeedNegativeCfm) {
  // A long step then a much shorter one on a barely damped spring: the slope ODE carries overshoots the true
  // velocity more than damping can absorb.
  ssSoftness s = Sentinel();
  EXPECT_EQ(ssExactSoftness(ssSpring{400, 0.01}, 1, 0.001, 0.1, &s), SS_ERROR_NO_FINITE_MAPPING);
  EXPECT_TRUE(MessageNames("step_s = 0.001")) << ssLastError();
  ExpectUnchanged(s);
}

}  // namespace

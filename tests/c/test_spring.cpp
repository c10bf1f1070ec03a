// The conversions between springs and softness, checked against truths written out here: the exact solution of
// m x'' + c x' + k x = 0 and ODE's step for one row, v' = (a v - (erp/h) x) / (1 + a), a = cfm m / h, x' = x + h v'
// (ode/src/step.cpp: J v' = -(erp/h) x - cfm f with the row force f = m (v' - v) / h).
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <cstring>
#include <limits>
#include <random>
#include <string>

#include "steadystep/limits.h"
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

TEST(ImplicitEulerMapping, IsTheArticlesFormula) {
  ssSoftness s;
  ASSERT_EQ(ssImplicitEulerSoftness(ssSpring{40, 1}, 1.0 / 30, &s), SS_OK);
  EXPECT_DOUBLE_EQ(s.erp, (40.0 / 30) / (40.0 / 30 + 1));
  EXPECT_DOUBLE_EQ(s.cfm, 1 / (40.0 / 30 + 1));
}

TEST(ImplicitEulerMapping, IsImplicitEulerOfTheSpring) {
  const double m = 1.5, k = 250, c = 3, h = 1.0 / 45;
  ssSoftness s;
  ASSERT_EQ(ssImplicitEulerSoftness(ssSpring{k, c}, h, &s), SS_OK);
  Row row{m, 0.2, -1.0};
  for (int i = 0; i < 100; ++i) {
    double x = row.x, v = row.v;
    row.Step(s, h);
    // m (v' - v) / h = -k (x + h v') - c v'
    EXPECT_NEAR(m * (row.v - v) / h, -k * (x + h * row.v) - c * row.v, 1e-10);
  }
}

TEST(ImplicitEulerMapping, RoundTripsOverRandomSprings) {
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> log_uniform(-3, 4);
  for (int i = 0; i < 5000; ++i) {
    ssSpring spring{std::pow(10, log_uniform(rng)), std::pow(10, log_uniform(rng))};
    double h = std::pow(10, log_uniform(rng) - 4);
    ssSoftness s;
    ssSpring back;
    ASSERT_EQ(ssImplicitEulerSoftness(spring, h, &s), SS_OK);
    EXPECT_GT(s.erp, 0);
    EXPECT_LE(s.erp, 1);
    EXPECT_GT(s.cfm, 0);
    ASSERT_EQ(ssSpringFromSoftness(s, h, &back), SS_OK);
    EXPECT_NEAR(back.stiffness / spring.stiffness, 1, 1e-9);
    EXPECT_NEAR(back.damping, spring.damping, 1e-9 * (spring.damping + h * spring.stiffness));
  }
}

TEST(ImplicitEulerMapping, InverseRoundTripsOverRandomSoftness) {
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> unit(1e-6, 1), log_uniform(-8, 2);
  for (int i = 0; i < 5000; ++i) {
    ssSoftness s{unit(rng), std::pow(10, log_uniform(rng))}, back;
    double h = 1.0 / (10 + 1000 * unit(rng));
    ssSpring spring;
    ASSERT_EQ(ssSpringFromSoftness(s, h, &spring), SS_OK);
    ASSERT_EQ(ssImplicitEulerSoftness(spring, h, &back), SS_OK);
    EXPECT_NEAR(back.erp, s.erp, 1e-12);
    EXPECT_NEAR(back.cfm / s.cfm, 1, 1e-12);
  }
}

TEST(ImplicitEulerMapping, FixedSoftnessMeansAStiffnessThatChangesWithTheStep) {
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
  // A pure damper has no natural frequency: its damping ratio would be infinite, which no caller can use.
  EXPECT_EQ(ssFrequencyFromSpring(ssSpring{0, 2}, 1.0, &hz, &ratio), SS_ERROR_NO_FINITE_MAPPING);
  EXPECT_TRUE(MessageNames("k = 0")) << ssLastError();
  EXPECT_NEAR(hz, 2.0, 1e-12);
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
    EXPECT_EQ(ssImplicitEulerSoftness(bad.spring, 1.0 / 60, &s), bad.status) << bad.names;
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
    EXPECT_NE(ssImplicitEulerSoftness(ssSpring{40, 1}, h, &s), SS_OK);
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
      {{1.5, 0.1}, SS_ERROR_OUT_OF_RANGE, "erp = 1.5"},  {{0.5, 1e21}, SS_ERROR_OUT_OF_RANGE, "cfm = 1e+21"},
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

// ---- The conversions' contract over many inputs, extremes included: SS_OK only with a finite result that is valid
// input for the library (and converts back), otherwise an error naming a value and the output bytes untouched.

// Doubles from the edges of the format as often as from its middle: zeros of both signs, denormals, the normal
// limits, huge values, infinities and NaN, and log-uniform values of either sign across the whole exponent range.
class ExtremeDoubles {
 public:
  explicit ExtremeDoubles(uint64_t seed) : rng_(seed) {}
  double operator()() {
    static const double kSpecial[] = {0.0,   -0.0,   std::numeric_limits<double>::denorm_min(), 1e-320, 1e-310,
                                      std::numeric_limits<double>::min(), 1e-300, 1e-200, 1e-20, 1e-9, 1e-3, 0.2,
                                      0.5,   1.0,    10.0,   1e3,    1e9,    1e20,   1e21,   1e200,  1e300, 1e308,
                                      std::numeric_limits<double>::max(), kInf, kNaN};
    const size_t special_count = sizeof kSpecial / sizeof kSpecial[0];
    uint64_t pick = rng_() % 4;
    double sign = rng_() % 5 == 0 ? -1.0 : 1.0;
    if (pick == 0) return sign * kSpecial[rng_() % special_count];
    if (pick == 1) return sign * std::pow(10.0, std::uniform_real_distribution<double>(-330, 309)(rng_));
    return std::pow(10.0, std::uniform_real_distribution<double>(-4, 4)(rng_));  // the ordinary middle, often
  }
  double Unit() { return std::uniform_real_distribution<double>(0, 1)(rng_); }

 private:
  std::mt19937_64 rng_;
};

template <typename T>
T Filled() {  // an output filled with a byte pattern that no conversion writes
  T value;
  std::memset(&value, 0xA5, sizeof value);
  return value;
}

template <typename T>
bool Untouched(const T& value) {
  T pattern = Filled<T>();
  return std::memcmp(&value, &pattern, sizeof value) == 0;
}

bool ValidSoftness(ssSoftness s) {
  return std::isfinite(s.erp) && std::isfinite(s.cfm) && std::abs(s.erp) <= SS_MAX_ERP && s.cfm > 0 &&
         s.cfm <= SS_MAX_CFM;
}

bool NamesSomething() { return std::string(ssLastError()).find(" = ") != std::string::npos; }

const int kDraws = 200000;

TEST(ConversionContract, ImplicitEulerSoftness) {
  ExtremeDoubles draw(11);
  int ok = 0;
  for (int i = 0; i < kDraws; ++i) {
    ssSpring spring{draw(), draw()};
    double h = draw();
    ssSoftness s = Filled<ssSoftness>();
    if (ssImplicitEulerSoftness(spring, h, &s) == SS_OK) {
      ++ok;
      ASSERT_TRUE(ValidSoftness(s)) << spring.stiffness << " " << spring.damping << " " << h;
      ASSERT_GE(s.erp, 0);
      ASSERT_LE(s.erp, 1);
      ASSERT_EQ(ssValidateSpring(spring), SS_OK);
      ASSERT_GE(h, SS_MIN_STEP_S);
      ASSERT_LE(h, SS_MAX_STEP_S);
    } else {
      ASSERT_TRUE(Untouched(s)) << spring.stiffness << " " << spring.damping << " " << h;
      ASSERT_TRUE(NamesSomething()) << ssLastError();
    }
  }
  EXPECT_GT(ok, kDraws / 20);  // the draw reaches the accepted region often, so the OK branch is exercised
}

TEST(ConversionContract, SpringFromSoftnessRoundTrips) {
  ExtremeDoubles draw(12);
  int ok = 0;
  for (int i = 0; i < kDraws; ++i) {
    // erp from the extremes and from [0, 1] (with its ends), where most tuned values live
    double erp = i % 3 == 0 ? draw() : i % 3 == 1 ? draw.Unit() : (i % 2 ? 0.0 : 1.0);
    ssSoftness softness{erp, draw()};
    double h = draw();
    ssSpring spring = Filled<ssSpring>();
    if (ssSpringFromSoftness(softness, h, &spring) == SS_OK) {
      ++ok;
      ASSERT_TRUE(std::isfinite(spring.stiffness) && std::isfinite(spring.damping));
      ASSERT_EQ(ssValidateSpring(spring), SS_OK) << ssLastError();
      ssSoftness back;
      ASSERT_EQ(ssImplicitEulerSoftness(spring, h, &back), SS_OK) << ssLastError();
      ASSERT_NEAR(back.erp, softness.erp, 1e-12) << softness.erp << " " << softness.cfm << " " << h;
      ASSERT_NEAR(back.cfm / softness.cfm, 1, 1e-12) << softness.erp << " " << softness.cfm << " " << h;
    } else {
      ASSERT_TRUE(Untouched(spring)) << softness.erp << " " << softness.cfm << " " << h;
      ASSERT_TRUE(NamesSomething()) << ssLastError();
    }
  }
  EXPECT_GT(ok, kDraws / 20);
}

TEST(ConversionContract, SpringFromFrequencyRoundTrips) {
  ExtremeDoubles draw(13);
  int ok = 0;
  for (int i = 0; i < kDraws; ++i) {
    double hz = draw(), ratio = i % 4 == 0 ? 0.0 : draw(), mass = draw();
    ssSpring spring = Filled<ssSpring>();
    if (ssSpringFromFrequency(hz, ratio, mass, &spring) == SS_OK) {
      ++ok;
      ASSERT_TRUE(std::isfinite(spring.stiffness) && std::isfinite(spring.damping));
      ASSERT_EQ(ssValidateSpring(spring), SS_OK) << ssLastError();
      double hz_back, ratio_back;
      ASSERT_EQ(ssFrequencyFromSpring(spring, mass, &hz_back, &ratio_back), SS_OK) << ssLastError();
      ASSERT_NEAR(hz_back / hz, 1, 1e-12) << hz << " " << ratio << " " << mass;
      ASSERT_NEAR(ratio_back, ratio, 1e-12 * ratio) << hz << " " << ratio << " " << mass;
    } else {
      ASSERT_TRUE(Untouched(spring)) << hz << " " << ratio << " " << mass;
      ASSERT_TRUE(NamesSomething()) << ssLastError();
    }
  }
  EXPECT_GT(ok, kDraws / 20);
}

TEST(ConversionContract, FrequencyFromSpringRoundTrips) {
  ExtremeDoubles draw(14);
  int ok = 0;
  for (int i = 0; i < kDraws; ++i) {
    ssSpring spring{draw(), i % 4 == 0 ? 0.0 : draw()};
    double mass = draw();
    double hz = Filled<double>(), ratio = Filled<double>();
    if (ssFrequencyFromSpring(spring, mass, &hz, &ratio) == SS_OK) {
      ++ok;
      ASSERT_TRUE(std::isfinite(hz) && hz > 0 && std::isfinite(ratio) && ratio >= 0);
      ssSpring back;
      ASSERT_EQ(ssSpringFromFrequency(hz, ratio, mass, &back), SS_OK)
          << spring.stiffness << " " << spring.damping << " " << mass << ": " << ssLastError();
      ASSERT_NEAR(back.stiffness / spring.stiffness, 1, 1e-12);
      ASSERT_NEAR(back.damping, spring.damping, 1e-12 * spring.damping);
    } else {
      ASSERT_TRUE(Untouched(hz) && Untouched(ratio));
      ASSERT_TRUE(NamesSomething()) << ssLastError();
    }
  }
  EXPECT_GT(ok, kDraws / 20);
}

TEST(ConversionContract, MatchedAndExactGiveSoftnessOdeHandles) {
  ExtremeDoubles draw(15);
  int ok = 0;
  for (int i = 0; i < kDraws; ++i) {
    ssSpring spring{draw(), draw()};
    double mass = draw(), h = draw(), previous = i % 3 == 0 ? 0.0 : draw();
    for (ssMapping mapping : {SS_MAPPING_MATCHED, SS_MAPPING_EXACT}) {
      ssSoftness s = Filled<ssSoftness>();
      if (ssSoftnessFor(mapping, spring, mass, h, previous, &s) == SS_OK) {
        ++ok;
        ASSERT_TRUE(ValidSoftness(s)) << spring.stiffness << " " << spring.damping << " " << mass << " " << h;
      } else {
        ASSERT_TRUE(Untouched(s));
        ASSERT_TRUE(NamesSomething()) << ssLastError();
      }
    }
  }
  EXPECT_GT(ok, kDraws / 50);
}

TEST(ConversionContract, TheReportedCasesAreRefusedOrServed) {
  ssSoftness s = Filled<ssSoftness>();
  // h·k overflows: was OK with erp = NaN, and wrote {0, inf} before other refusals.
  EXPECT_EQ(ssImplicitEulerSoftness(ssSpring{1e308, 1}, 10, &s), SS_ERROR_NO_FINITE_MAPPING);
  EXPECT_TRUE(MessageNames("k = 1e+308")) << ssLastError();
  EXPECT_TRUE(Untouched(s));
  EXPECT_EQ(ssImplicitEulerSoftness(ssSpring{0, 1e-307}, 1.0 / 60, &s), SS_ERROR_NO_FINITE_MAPPING);  // cfm = 1e307
  EXPECT_TRUE(Untouched(s));
  EXPECT_EQ(ssImplicitEulerSoftness(ssSpring{1, 1}, 1e-200, &s), SS_ERROR_OUT_OF_RANGE);
  EXPECT_TRUE(MessageNames("step_s = 1e-200")) << ssLastError();
  ssSpring spring = Filled<ssSpring>();
  // denormals: were k = inf, or k = c = 0
  EXPECT_NE(ssSpringFromSoftness(ssSoftness{1, 1e-320}, 1.0 / 60, &spring), SS_OK);
  EXPECT_NE(ssSpringFromSoftness(ssSoftness{0.5, 4.9e-324}, 1.0 / 60, &spring), SS_OK);
  EXPECT_NE(ssSpringFromSoftness(ssSoftness{1e-320, 1e300}, 1.0 / 60, &spring), SS_OK);
  EXPECT_TRUE(Untouched(spring));
  EXPECT_EQ(ssSpringFromFrequency(1e200, 0.5, 1, &spring), SS_ERROR_NO_FINITE_MAPPING);
  EXPECT_TRUE(MessageNames("frequency_hz = 1e+200")) << ssLastError();
  EXPECT_EQ(ssSpringFromFrequency(1e-200, 0.5, 1, &spring), SS_ERROR_NO_FINITE_MAPPING);
  EXPECT_TRUE(Untouched(spring));
  double hz = Filled<double>(), ratio = Filled<double>();
  EXPECT_EQ(ssFrequencyFromSpring(ssSpring{1e-320, 1}, 1e300, &hz, &ratio), SS_ERROR_NO_FINITE_MAPPING);
  EXPECT_TRUE(Untouched(hz) && Untouched(ratio));
}

TEST(ConversionContract, ZeroErpIsAPureDamper) {
  ssSpring spring;
  ASSERT_EQ(ssSpringFromSoftness(ssSoftness{0, 0.25}, 1.0 / 60, &spring), SS_OK);
  EXPECT_EQ(spring.stiffness, 0);
  EXPECT_FALSE(std::signbit(spring.stiffness));
  EXPECT_DOUBLE_EQ(spring.damping, 4);
  ASSERT_EQ(ssSpringFromSoftness(ssSoftness{-0.0, 0.25}, 1.0 / 60, &spring), SS_OK);
  EXPECT_FALSE(std::signbit(spring.stiffness));
  // A damper is the same at every step: erp 0, cfm 1/c.
  ssSoftness s;
  ASSERT_EQ(ssImplicitEulerSoftness(spring, 1.0 / 15, &s), SS_OK);
  EXPECT_EQ(s.erp, 0);
  EXPECT_DOUBLE_EQ(s.cfm, 0.25);
}

TEST(ConversionContract, NullOutputsAreRefusedByName) {
  double hz;
  EXPECT_EQ(ssImplicitEulerSoftness(ssSpring{1, 1}, 0.01, nullptr), SS_ERROR_OUT_OF_RANGE);
  EXPECT_TRUE(MessageNames("out = NULL"));
  EXPECT_EQ(ssSpringFromSoftness(ssSoftness{0.5, 0.1}, 0.01, nullptr), SS_ERROR_OUT_OF_RANGE);
  EXPECT_TRUE(MessageNames("out = NULL"));
  EXPECT_EQ(ssSpringFromFrequency(1, 0.5, 1, nullptr), SS_ERROR_OUT_OF_RANGE);
  EXPECT_TRUE(MessageNames("out = NULL"));
  EXPECT_EQ(ssFrequencyFromSpring(ssSpring{1, 1}, 1, nullptr, &hz), SS_ERROR_OUT_OF_RANGE);
  EXPECT_TRUE(MessageNames("frequency_hz = NULL"));
  EXPECT_EQ(ssFrequencyFromSpring(ssSpring{1, 1}, 1, &hz, nullptr), SS_ERROR_OUT_OF_RANGE);
  EXPECT_TRUE(MessageNames("damping_ratio = NULL"));
  for (ssMapping mapping : {SS_MAPPING_IMPLICIT_EULER, SS_MAPPING_MATCHED, SS_MAPPING_EXACT}) {
    EXPECT_EQ(ssSoftnessFor(mapping, ssSpring{1, 1}, 1, 0.01, 0.01, nullptr), SS_ERROR_OUT_OF_RANGE);
    EXPECT_TRUE(MessageNames("out = NULL"));
  }
  EXPECT_EQ(ssMatchedSoftness(ssSpring{1, 1}, 1, 0.01, nullptr), SS_ERROR_OUT_OF_RANGE);
  EXPECT_EQ(ssExactSoftness(ssSpring{1, 1}, 1, 0.01, 0, nullptr), SS_ERROR_OUT_OF_RANGE);
  EXPECT_TRUE(MessageNames("out = NULL"));
}

}  // namespace

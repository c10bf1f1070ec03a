// The method held to independent truth in real ODE: the implicit-Euler recurrence (spring), the article's
// consistency claim (spring vs naive), the exact poles (matched) and the exact motion (exact).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include "test_stepping.h"
#include "oscillator_rig.h"
#include "precision.h"

namespace {

class Oscillator : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { dInitODE2(0); }
};

// The article's setting: one physics step per frame (max_step_s no shorter than the longest frame).
void OneStepPerFrame(OscillatorRig& rig, const char* policy, ssSolver solver) {
  ssSteppingForPolicy(policy, 1.0 / 30, &rig.def.stepping);
  rig.def.stepping.solver = solver;
  rig.def.stepping.max_step_s = 1.0 / 15.0;
}

TEST_F(Oscillator, ImplicitEulerFollowsTheRecurrenceAtFixedAndVariableSteps) {
  struct Case {
    const char* profile;
    ssSolver solver;
    double tolerance_m;
  } cases[] = {
      {"fixed:30", SS_SOLVER_STEP, 1e-9},      {"uniform:15:45", SS_SOLVER_STEP, 1e-9},
      {"fixed:30", SS_SOLVER_QUICK, 1e-8},     {"uniform:15:45", SS_SOLVER_QUICK, 1e-8},
      {"jitter:60:2", SS_SOLVER_STEP, 1e-9},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(std::string(c.profile) + (c.solver == SS_SOLVER_STEP ? " step" : " quick"));
    OscillatorRig rig;
    OneStepPerFrame(rig, "implicit-euler", c.solver);
    ASSERT_EQ(rig.Build(), SS_OK) << ssLastError();
    ASSERT_EQ(rig.Run(c.profile, 5.0, 7), SS_OK) << ssLastError();
    ASSERT_GT(rig.x.size(), 70u);
    // in float (x0 = 0.5 m) measured 2.5e-8 to 6.8e-8 m: the float state's roundings, 0.2 to 0.6 ε·x0 a step
    EXPECT_LT(MaxDifference(rig.x, ImplicitEuler(rig, rig.h)), IntegratedTolerance(c.tolerance_m, 1e-6));
  }
}

TEST_F(Oscillator, SubstepsFollowImplicitEulerAtEachSubstep) {
  OscillatorRig rig;
  rig.def.stepping.solver = SS_SOLVER_STEP;  // max_step_s stays 1/60: 15-45 fps frames become 1 to 4 substeps
  ASSERT_EQ(rig.Build(), SS_OK);
  ASSERT_EQ(rig.Run("uniform:15:45", 3.0, 3), SS_OK);
  for (double h : rig.h) EXPECT_LE(h, (1 + rig.def.stepping.max_step_slack) / 60.0 + 1e-15);  // the slack
  EXPECT_LT(MaxDifference(rig.x, ImplicitEuler(rig, rig.h)), IntegratedTolerance(1e-9, 1e-6));  // float: 1.1e-7 m
}

// Steps world through 150 frames drawn uniformly from 1/45 to 1/15 s, one step each, and returns the largest
// difference between measure() and the implicit-Euler recurrence of a row of mass (kg or kg·m²) and spring from x0
// at rest. -1 when the stepper refuses.
template <typename Measure>
double WorstAgainstImplicitEuler(dWorldID world, ssRegistry* registry, ssSolver solver, uint64_t seed, double mass,
                                 ssSpring spring, double x0, Measure measure) {
  ssStepperDef def = TestStepperDef();
  def.world = world;
  def.registry = registry;
  def.stepping.solver = solver;
  def.stepping.max_step_s = 1.0 / 15.0;
  ssStepper* stepper;
  if (ssStepper_Create(&def, &stepper) != SS_OK) return -1;
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> frame(1.0 / 45.0, 1.0 / 15.0);
  double x = x0, v = 0, worst = 0;
  for (int i = 0; i < 150 && worst >= 0; ++i) {
    double h = frame(random);
    if (ssStepper_Step(stepper, h, nullptr) != SS_OK) worst = -1;
    ImplicitEulerStep(mass, spring, 0, h, &x, &v);
    if (worst >= 0) worst = std::fmax(worst, std::fabs(measure() - x));
  }
  ssStepper_Destroy(stepper);
  return worst;
}

// An angular stop on a hinge: the same recurrence in angle, with the body's inertia about the axis.
TEST_F(Oscillator, HingeAngularStopFollowsImplicitEuler) {
  const double inertia = 0.02, k = 3.0, c = 0.05, theta0 = 0.3;
  for (ssSolver solver : {SS_SOLVER_STEP, SS_SOLVER_QUICK}) {
    dWorldID world = dWorldCreate();
    dBodyID body = dBodyCreate(world);
    dMass m;
    dMassSetZero(&m);
    dMassSetParameters(&m, 1.0, 0, 0, 0, inertia, inertia, inertia, 0, 0, 0);
    dBodySetMass(body, &m);
    dBodySetFiniteRotationMode(body, 1);  // ODE's default rotation update is first order in the angle
    dBodySetFiniteRotationAxis(body, 0, 0, 1);
    dJointID hinge = dJointCreateHinge(world, 0);
    dJointAttach(hinge, body, 0);
    dJointSetHingeAxis(hinge, 0, 0, 1);
    dJointSetHingeParam(hinge, dParamLoStop, 0);
    dJointSetHingeParam(hinge, dParamHiStop, 0);
    dQuaternion q;
    dQFromAxisAndAngle(q, 0, 0, 1, theta0);
    dBodySetQuaternion(body, q);
    ASSERT_NEAR(dJointGetHingeAngle(hinge), theta0, IntegratedTolerance(1e-12, 1e-6));  // float quaternion: 1.9e-7

    ssRegistry* registry = ssRegistry_Create(world);
    ASSERT_EQ(ssRegistry_BindJoint(registry, hinge, SS_PARAM_STOP, 1, ssSpring{k, c}, 0), SS_OK);
    double worst = WorstAgainstImplicitEuler(world, registry, solver, 11, inertia, ssSpring{k, c}, theta0,
                                             [&] { return dJointGetHingeAngle(hinge); });
    EXPECT_GE(worst, 0) << ssLastError();
    EXPECT_LT(worst, IntegratedTolerance(solver == SS_SOLVER_STEP ? 1e-9 : 1e-8, 1e-6)) << "solver " << solver;
    ssRegistry_Destroy(registry);
    dWorldDestroy(world);
  }
}

// Hinge-2 suspension: a wheel on a chassis that does not move (kinematic), sprung along axis 1.
TEST_F(Oscillator, Hinge2SuspensionFollowsImplicitEuler) {
  const double wheel_kg = 2.0, k = 800.0, c = 20.0, z0 = 0.05;
  for (ssSolver solver : {SS_SOLVER_STEP, SS_SOLVER_QUICK}) {
    dWorldID world = dWorldCreate();
    dWorldSetGravity(world, 0, 0, 0);
    dBodyID chassis = dBodyCreate(world);
    dBodySetKinematic(chassis);
    dBodyID wheel = dBodyCreate(world);
    dMass m;
    dMassSetSphereTotal(&m, wheel_kg, 0.3);
    dBodySetMass(wheel, &m);
    dBodySetPosition(wheel, 1, 0, 0);
    dJointID hinge2 = dJointCreateHinge2(world, 0);
    dJointAttach(hinge2, chassis, wheel);
    dJointSetHinge2Anchor(hinge2, 1, 0, 0);
    const dReal axis1[] = {0, 0, 1}, axis2[] = {0, 1, 0};
    dJointSetHinge2Axes(hinge2, axis1, axis2);
    dBodySetPosition(wheel, 1, 0, z0);

    ssRegistry* registry = ssRegistry_Create(world);
    ASSERT_EQ(ssRegistry_BindJoint(registry, hinge2, SS_PARAM_SUSPENSION, 1, ssSpring{k, c}, 0), SS_OK);
    double effective = 0;
    ASSERT_EQ(ssJointEffectiveMass(hinge2, SS_PARAM_SUSPENSION, 1, &effective), SS_OK);
    EXPECT_NEAR(effective, wheel_kg, 1e-12);
    double worst = WorstAgainstImplicitEuler(world, registry, solver, 5, wheel_kg, ssSpring{k, c}, z0,
                                             [&] { return dBodyGetPosition(wheel)[2]; });
    EXPECT_GE(worst, 0) << ssLastError();
    EXPECT_LT(worst, IntegratedTolerance(solver == SS_SOLVER_STEP ? 1e-9 : 1e-8, 1e-6)) << "solver " << solver;
    ssRegistry_Destroy(registry);
    dWorldDestroy(world);
  }
}

// RMS over the variable run's samples of (variable - fixed run linearly interpolated), over x0.
double RmsAgainst(const OscillatorRig& variable, const OscillatorRig& fixed) {
  double sum = 0;
  size_t j = 0;
  for (size_t i = 0; i < variable.t.size(); ++i) {
    double t = variable.t[i];
    while (j + 1 < fixed.t.size() && fixed.t[j + 1] < t) ++j;
    double t0 = j == 0 && t < fixed.t[0] ? 0 : fixed.t[j], x0 = j == 0 && t < fixed.t[0] ? fixed.x0 : fixed.x[j];
    size_t k = j == 0 && t < fixed.t[0] ? 0 : std::min(j + 1, fixed.t.size() - 1);
    double along = fixed.t[k] > t0 ? (t - t0) / (fixed.t[k] - t0) : 0;
    double interpolated = x0 + along * (fixed.x[k] - x0);
    sum += (variable.x[i] - interpolated) * (variable.x[i] - interpolated);
  }
  return std::sqrt(sum / variable.t.size()) / variable.x0;
}

// The article's claim: with the implicit-Euler mapping a run at 15-45 fps stays with the run at 30 fps; with ERP/CFM
// frozen at their 30 fps values it does not.
TEST_F(Oscillator, ImplicitEulerIsConsistentAcrossFrameRatesAndNaiveIsNot) {
  double implicit_euler_sum = 0, naive_sum = 0;
  const int seeds = 8;
  for (int seed = 0; seed < seeds; ++seed) {
    double rms[2];
    for (int which = 0; which < 2; ++which) {
      const char* policy = which == 0 ? "implicit-euler" : "naive";
      OscillatorRig fixed, variable;
      OneStepPerFrame(fixed, policy, SS_SOLVER_QUICK);
      OneStepPerFrame(variable, policy, SS_SOLVER_QUICK);
      ASSERT_EQ(fixed.Build(), SS_OK);
      ASSERT_EQ(variable.Build(), SS_OK);
      ASSERT_EQ(fixed.Run("fixed:30", 5.0), SS_OK);
      ASSERT_EQ(variable.Run("uniform:15:45", 5.0, seed), SS_OK);
      rms[which] = RmsAgainst(variable, fixed);
    }
    EXPECT_LE(rms[0], 0.05) << "seed " << seed;
    implicit_euler_sum += rms[0];
    naive_sum += rms[1];
  }
  double implicit_euler = implicit_euler_sum / seeds, naive = naive_sum / seeds;
  std::printf("RMS(15-45 fps vs 30 fps)/x0 over %d seeds: implicit-euler %.4f, naive %.4f (ratio %.1f)\n", seeds,
              implicit_euler, naive, naive / implicit_euler);
  EXPECT_LE(implicit_euler, 0.05);
  EXPECT_GE(naive, 2 * implicit_euler);
}

// Fits x_(n+1) = a1 x_n + a2 x_(n-1), which a damped sinusoid sampled at a constant step obeys exactly:
// a1 = 2 e^(-σh) cos(ωh), a2 = -e^(-2σh). Returns σ (1/s) and ω (rad/s).
void FitDecayAndFrequency(const std::vector<double>& x, double h, double* sigma, double* omega) {
  double s11 = 0, s12 = 0, s22 = 0, b1 = 0, b2 = 0;
  for (size_t n = 1; n + 1 < x.size(); ++n) {
    s11 += x[n] * x[n];
    s12 += x[n] * x[n - 1];
    s22 += x[n - 1] * x[n - 1];
    b1 += x[n + 1] * x[n];
    b2 += x[n + 1] * x[n - 1];
  }
  double det = s11 * s22 - s12 * s12;
  double a1 = (b1 * s22 - b2 * s12) / det, a2 = (s11 * b2 - s12 * b1) / det;
  *sigma = -std::log(-a2) / (2 * h);
  *omega = std::acos(a1 / (2 * std::sqrt(-a2))) / h;
}

TEST_F(Oscillator, MatchedHasTheExactDecayAndFrequencyAtEveryFixedStep) {
  for (int fps : {15, 30, 60, 144}) {
    for (ssSolver solver : {SS_SOLVER_STEP, SS_SOLVER_QUICK}) {
      OscillatorRig rig;
      ssSteppingForPolicy("matched", 1.0 / 30, &rig.def.stepping);
      rig.def.stepping.solver = solver;
      rig.def.stepping.max_step_s = 1.0 / fps;
      ASSERT_EQ(rig.Build(), SS_OK);
      ASSERT_EQ(rig.Run(("fixed:" + std::to_string(fps)).c_str(), 5.0), SS_OK);
      std::vector<double> xs = {rig.x0};
      xs.insert(xs.end(), rig.x.begin(), rig.x.end());
      double sigma, omega;
      FitDecayAndFrequency(xs, 1.0 / fps, &sigma, &omega);
      const double true_sigma = 0.5, true_omega = std::sqrt(40.0 - 0.25);
      EXPECT_NEAR(sigma / true_sigma, 1.0, 1e-3) << fps << " fps, solver " << solver;
      EXPECT_NEAR(omega / true_omega, 1.0, 1e-3) << fps << " fps, solver " << solver;
    }
  }
}

double RmsAgainstExact(const OscillatorRig& rig) {
  double sum = 0;
  for (size_t i = 0; i < rig.t.size(); ++i) sum += std::pow(rig.x[i] - ExactPosition(rig, rig.t[i]), 2);
  return std::sqrt(sum / rig.t.size()) / rig.x0;
}

TEST_F(Oscillator, ExactReproducesTheExactMotionUnderVariableFrames) {
  for (ssSolver solver : {SS_SOLVER_STEP, SS_SOLVER_QUICK}) {
    for (double max_step_s : {1.0 / 15.0, 1.0 / 60.0}) {
      OscillatorRig rig;
      ssSteppingForPolicy("exact", 1.0 / 30, &rig.def.stepping);
      rig.def.stepping.solver = solver;
      rig.def.stepping.max_step_s = max_step_s;
      ASSERT_EQ(rig.Build(), SS_OK);
      ASSERT_EQ(rig.Run("uniform:15:45", 5.0, 1), SS_OK) << ssLastError();
      double rms = RmsAgainstExact(rig);
      std::printf("exact, %s, max_step 1/%.0f s: RMS vs exact / x0 = %.3g\n",
                  solver == SS_SOLVER_STEP ? "dWorldStep" : "dWorldQuickStep(20)", 1 / max_step_s, rms);
      // QuickStep's iterations leave a residual (measured 5e-11): bounded loosely, the claim is dWorldStep's
      EXPECT_LE(rms, IntegratedTolerance(solver == SS_SOLVER_STEP ? 1e-6 : 1e-9, 1e-6));  // float: 5e-8 to 8e-8
    }
  }
}

// Gravity along the slider: the implicit-Euler mapping keeps the static deflection m g / k (its erp/(h cfm) is k); matched
// and exact have erp/(h cfm) != k, so their rest position is off unless the load is declared, which makes exact
// exact again. The figures are printed; see docs/exact-mappings.md.
TEST_F(Oscillator, GravityAlongTheSliderByMapping) {
  for (bool declared : {false, true}) {
    for (const char* policy : {"implicit-euler", "matched", "exact"}) {
      OscillatorRig rig;
      rig.gravity = 9.81;
      rig.declare_load = declared;
      ssSteppingForPolicy(policy, 1.0 / 30, &rig.def.stepping);
      rig.def.stepping.solver = SS_SOLVER_STEP;
      ASSERT_EQ(rig.Build(), SS_OK) << ssLastError();
      ASSERT_EQ(rig.Run("uniform:15:45", 60.0, 2), SS_OK);  // long enough for the motion to die out (e^-30)
      double rest = -rig.mass * rig.gravity / rig.spring.stiffness;
      double rest_error = std::fabs(rig.x.back() - rest) / std::fabs(rest), rms = RmsAgainstExact(rig);
      std::printf("gravity, %-7s load %-8s: rest position off by %.3g of m g / k, RMS vs exact / x0 %.3g\n",
                  policy, declared ? "declared" : "unknown", rest_error, rms);
      if (std::string(policy) == "implicit-euler" || declared) {
        EXPECT_LT(rest_error, 1e-6);
      } else {
        EXPECT_GT(rest_error, 1e-3);  // the effect the declared load removes
      }
      if (std::string(policy) == "exact" && declared) {
        EXPECT_LT(rms, 1e-6);
      }
    }
  }
}

TEST_F(Oscillator, LoadsAreRefusedWhereTheyHaveNoMeaning) {
  OscillatorRig rig;
  ASSERT_EQ(rig.Build(), SS_OK);
  EXPECT_EQ(ssRegistry_SetJointLoad(rig.registry, rig.slider, SS_PARAM_STOP, 1, NAN), SS_ERROR_NOT_FINITE);
  EXPECT_NE(std::string(ssLastError()).find("load"), std::string::npos) << ssLastError();
  EXPECT_EQ(ssRegistry_SetJointLoad(rig.registry, rig.slider, SS_PARAM_MOTOR, 1, -9.81), SS_ERROR_NOT_FOUND);
  dJointID ball = dJointCreateBall(rig.world, 0);
  dJointAttach(ball, rig.body, 0);
  ASSERT_EQ(ssRegistry_BindJoint(rig.registry, ball, SS_PARAM_JOINT, 1, rig.spring, 0), SS_OK);
  EXPECT_EQ(ssRegistry_SetJointLoad(rig.registry, ball, SS_PARAM_JOINT, 1, -9.81), SS_ERROR_UNSUPPORTED);
}

TEST_F(Oscillator, UndampedSpringUnderMatchedIsHandedToImplicitEulerAndCounted) {
  OscillatorRig rig;
  rig.spring = {40.0, 0.0};  // poles on the unit circle: no finite matched softness
  ssSteppingForPolicy("matched", 1.0 / 30, &rig.def.stepping);
  ASSERT_EQ(rig.Build(), SS_OK);
  ssFrameReport report;
  ASSERT_EQ(ssStepper_Step(rig.stepper, 1.0 / 30.0, &report), SS_OK) << ssLastError();
  EXPECT_EQ(report.steps, 2);
  EXPECT_EQ(report.rows.handed_to_implicit_euler, 2);  // one row, two steps
  EXPECT_EQ(report.rows.by_mapping, 0);
  ssSoftness spring;
  ASSERT_EQ(ssImplicitEulerSoftness(rig.spring, 1.0 / 60.0, &spring), SS_OK);
  EXPECT_EQ(dJointGetSliderParam(rig.slider, dParamStopERP), spring.erp);
  EXPECT_EQ(dJointGetSliderParam(rig.slider, dParamStopCFM), spring.cfm);
}

}  // namespace

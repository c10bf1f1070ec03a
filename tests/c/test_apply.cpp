// Apply against its reference (tests/c/apply_reference.h): random scenarios on twin worlds, through many laws, loads,
// unbinding, rebinding, attachment and mass changes and every mapping, must write the same values into ODE.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include <ode/ode.h>

#include "apply_differential.h"
extern "C" {
#include "joint_rows.h"
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

// ssSurelyFailsUpToMass lets Apply hand every row of a law to implicit Euler without measuring one: wherever it says
// so for a bound, ssRowSoftness must hand the row on under both accurate mappings at every mass up to the bound.
// Masses are tried where the rule's arithmetic turns: at and just under the bound, around Nyquist (k*h^2/pi^2),
// critical damping (c^2/4k) and a damper's x = 0.06, and spread over twelve decades below.
TEST(ApplyTest, LawsSurelyHandedOnAreHandedOnAtEveryMassUpToTheBound) {
  long decided = 0, undecided = 0, masses_tried = 0;
  auto check = [&](ssSpring spring, double bound, double step_s) {
    if (!ssSurelyFailsUpToMass(spring, bound, step_s)) {
      undecided += 1;
      return;
    }
    decided += 1;
    ssRowLaw law = ssRowLawOfSpring(spring);
    ssSoftness euler;
    ASSERT_EQ(ssImplicitEulerSoftness(spring, step_s, &euler), SS_OK);
    const double k = spring.stiffness, c = spring.damping, pi2 = 9.869604401089358;
    std::vector<double> masses = {bound, bound * (1 - 1e-12), 0.999 * bound, 0.9 * bound, 0.5 * bound};
    for (double edge : {k * step_s * step_s / pi2, k > 0 ? c * c / (4 * k) : 0.0, c * step_s / 0.12})
      for (double factor : {1 - 1e-9, 1.0, 1 + 1e-9, 0.97, 1.03, 0.5, 2.0})
        masses.push_back(edge * factor);
    for (int decade = 1; decade <= 12; ++decade) masses.push_back(bound * std::pow(10.0, -decade) * 3.7);
    for (double mass : masses) {
      if (!(mass > 0 && mass <= bound)) continue;
      masses_tried += 1;
      for (ssMapping mapping : {SS_MAPPING_MATCHED, SS_MAPPING_EXACT}) {
        ssSoftness softness;
        ssRowFallback fallback;
        ASSERT_EQ(ssRowSoftness(&law, mapping, mass, step_s, 0.8 * step_s, 0, &fallback, &softness), SS_OK);
        ASSERT_TRUE(fallback.to_implicit_euler) << "k " << k << " c " << c << " m " << mass << " (bound " << bound
                                                << ") h " << step_s << " mapping " << ssMappingName(mapping);
        EXPECT_EQ(softness.erp, euler.erp);
        EXPECT_EQ(softness.cfm, euler.cfm);
      }
    }
  };
  std::mt19937 random(29);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  auto decades = [&](double low, double high) { return std::pow(10.0, low + (high - low) * unit(random)); };
  for (int i = 0; i < 60000; ++i) {
    double step_s = decades(-4, -0.3), bound = decades(-6, 4);
    double k = i % 5 == 0 ? 0.0 : decades(-4, 12), c = decades(-4, 10);
    check({k, c}, bound, step_s);
  }
  // the laws programs tune: ODE's ERP and CFM at 1/60 s (near-rigid rows and motors), on links of 1 g to 1 t
  for (double erp : {0.0, 0.1, 0.2, 0.5, 0.8, 0.99})
    for (double cfm : {1e-10, 1e-7, 1e-5, 1e-3, 0.1})
      for (double bound : {1e-3, 0.0035, 1.0, 80.0, 1000.0})
        for (double step_s : {1.0 / 240, 1.0 / 90, 1.0 / 60, 1.0 / 30, 1.0 / 15}) {
          ssRowLaw law;
          ASSERT_EQ(ssRowLawFromTuned("law", erp, cfm, 1.0 / 60, &law), SS_OK);
          check(law.spring, bound, step_s);
        }
  EXPECT_GT(decided, 10000);
  EXPECT_GT(undecided, 10000);
  EXPECT_GT(masses_tried, 10 * decided);
}

// The bound Apply gives a law's rows from their bodies (ssBodyInverseBoundOf) is at least each row's effective mass
// as Apply measures it, for every kind of row, at random rotations, with inertias diagonal or turned (off-diagonal
// terms), light and heavy, and with a kinematic body or the static world on one side.
TEST(ApplyTest, BodyBoundsBoundTheMassOfEveryRow) {
  dInitODE2(0);
  dWorldID world = dWorldCreate();
  std::mt19937 random(31);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  auto decades = [&](double low, double high) { return std::pow(10.0, low + (high - low) * unit(random)); };
  auto makeBody = [&]() {
    dBodyID body = dBodyCreate(world);
    dMass mass;
    dMassSetBoxTotal(&mass, decades(-3, 3), decades(-2, 0.5), decades(-2, 0.5), decades(-2, 0.5));
    if (unit(random) < 0.5) {
      dMatrix3 turn;
      dRFromEulerAngles(turn, 6 * unit(random), 6 * unit(random), 6 * unit(random));
      dMassRotate(&mass, turn);
    }
    dBodySetMass(body, &mass);
    dMatrix3 rotation;
    dRFromEulerAngles(rotation, 6 * unit(random), 6 * unit(random), 6 * unit(random));
    dBodySetRotation(body, rotation);
    dBodySetPosition(body, unit(random), unit(random), unit(random));
    return body;
  };
  const int types[] = {dJointTypeHinge, dJointTypeSlider, dJointTypeUniversal, dJointTypeHinge2, dJointTypePR,
                       dJointTypePU,    dJointTypePiston, dJointTypeBall,      dJointTypeFixed,  dJointTypeLMotor};
  long rows = 0, tight = 0, unbounded = 0;
  for (int i = 0; i < 3000; ++i) {
    dBodyID first = makeBody(), second = unit(random) < 0.25 ? 0 : makeBody();
    if (second != 0 && unit(random) < 0.2) dBodySetKinematic(second);
    dJointID joint = 0;
    switch (types[i % 10]) {
      case dJointTypeHinge: joint = dJointCreateHinge(world, 0); break;
      case dJointTypeSlider: joint = dJointCreateSlider(world, 0); break;
      case dJointTypeUniversal: joint = dJointCreateUniversal(world, 0); break;
      case dJointTypeHinge2: joint = dJointCreateHinge2(world, 0); break;
      case dJointTypePR: joint = dJointCreatePR(world, 0); break;
      case dJointTypePU: joint = dJointCreatePU(world, 0); break;
      case dJointTypePiston: joint = dJointCreatePiston(world, 0); break;
      case dJointTypeBall: joint = dJointCreateBall(world, 0); break;
      case dJointTypeFixed: joint = dJointCreateFixed(world, 0); break;
      case dJointTypeLMotor: joint = dJointCreateLMotor(world, 0); break;
    }
    if (types[i % 10] == dJointTypeHinge2 && second == 0) second = makeBody(); // hinge-2 needs both
    dJointAttach(joint, first, second);
    double axis[3] = {unit(random) - 0.5, unit(random) - 0.5, unit(random) - 0.5};
    switch (types[i % 10]) {
      case dJointTypeHinge: dJointSetHingeAxis(joint, axis[0], axis[1], axis[2]); break;
      case dJointTypeSlider: dJointSetSliderAxis(joint, axis[0], axis[1], axis[2]); break;
      case dJointTypePiston: dJointSetPistonAxis(joint, axis[0], axis[1], axis[2]); break;
      case dJointTypeHinge2: {
        const dReal suspension[3] = {0, 0, 1}, wheel[3] = {1, 0, 0};
        dJointSetHinge2Axes(joint, suspension, wheel);
        break;
      }
      case dJointTypeLMotor:
        dJointSetLMotorNumAxes(joint, 1);
        dJointSetLMotorAxis(joint, 0, 0, axis[0], axis[1], axis[2]);
        break;
      default: break;
    }
    const int type = dJointGetType(joint);
    for (int param = SS_PARAM_JOINT; param <= SS_PARAM_SUSPENSION; ++param)
      for (int a = 1; a <= 3; ++a) {
        double mass = 0;
        if (!ssJointSupports(joint, (ssJointParam)param, a) ||
            ssJointEffectiveMass(joint, (ssJointParam)param, a, &mass) != SS_OK)
          continue;
        const int angular = ssJointRowIsAngular(type, (ssJointParam)param, a);
        double inverse = 0;
        for (dBodyID body : {first, second}) {
          ssBodyInverseBound bound = ssBodyInverseBoundOf(body);
          inverse += angular ? bound.angular : bound.linear;
        }
        rows += 1;
        if (std::isnan(inverse)) { // no bound claimed: an inertia turned and too far from a sphere's
          unbounded += 1;
          continue;
        }
        ASSERT_LE(mass, (1 + SS_MASS_BOUND_MARGIN) / inverse)
            << "joint type " << type << " param " << param << " axis " << a;
        tight += mass > 0.1 / inverse;
      }
  }
  EXPECT_GT(rows, 5000);
  EXPECT_LT(unbounded, rows / 4);
  EXPECT_GT(tight, rows / 2); // a bound that says something: most rows within a factor 10 of it
  dWorldDestroy(world);
}

// Apply tells angular rows from linear ones without ODE's getters (ssJointRowIsAngular) where it bounds their masses;
// it must say what the row's measured geometry says, for every row of every joint type.
TEST(ApplyTest, EveryRowIsAngularAsItsGeometrySays) {
  dInitODE2(0);
  dWorldID world = dWorldCreate();
  dBodyID first = dBodyCreate(world), second = dBodyCreate(world);
  dBodySetPosition(second, 0.3, 0.2, 0.1);
  dJointID joints[] = {dJointCreateHinge(world, 0),    dJointCreateSlider(world, 0),  dJointCreateUniversal(world, 0),
                       dJointCreateHinge2(world, 0),   dJointCreatePR(world, 0),      dJointCreatePU(world, 0),
                       dJointCreatePiston(world, 0),   dJointCreateAMotor(world, 0),  dJointCreateLMotor(world, 0),
                       dJointCreatePlane2D(world, 0),  dJointCreateBall(world, 0),    dJointCreateFixed(world, 0),
                       dJointCreateDBall(world, 0),    dJointCreateDHinge(world, 0)};
  dJointSetAMotorNumAxes(joints[7], 3);
  dJointSetLMotorNumAxes(joints[8], 3);
  int rows = 0;
  for (dJointID joint : joints) {
    dJointAttach(joint, first, dJointGetType(joint) == dJointTypePlane2D ? 0 : second);
    const int type = dJointGetType(joint);
    for (int param = SS_PARAM_JOINT; param <= SS_PARAM_SUSPENSION; ++param)
      for (int axis = 1; axis <= 3; ++axis) {
        ssRowGeometry geometry;
        if (!ssJointSupports(joint, (ssJointParam)param, axis) ||
            !ssJointRowGeometry(joint, type, (ssJointParam)param, axis, &geometry))
          continue;
        rows += 1;
        EXPECT_EQ(ssJointRowIsAngular(type, (ssJointParam)param, axis), geometry.angular)
            << "joint type " << type << " param " << param << " axis " << axis;
      }
  }
  EXPECT_GT(rows, 30);
  dWorldDestroy(world);
}

}  // namespace

// The registry against real ODE joints: every joint type and parameter set is written for the step length and read
// back, bad bindings are refused at bind time, and an error in Apply writes nothing.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "joint_params.h"
#include "ode_fixture.h"
#include "precision.h"
#include "served_softness.h"
#include "steadystep/steadystep.h"

namespace {

const ssSpring kSpring = {400.0, 12.0};

struct Row {
  ssJointParam param;
  int axis;
};

struct JointCase {
  const char* name;
  dJointID joint;
  std::vector<Row> rows;
};

class RegistryTest : public OdeTest {
 protected:
  void SetUp() override {
    OdeTest::SetUp();
    a = MakeBody(2.0, 0, 0, 1);
    b = MakeBody(3.0, 0.5, 0.2, 1.3);
  }

  // Every joint type with every parameter set it has, attached to two bodies.
  std::vector<JointCase> AllJoints() {
    std::vector<JointCase> cases;
    auto add = [&](const char* name, dJointID joint, std::vector<Row> rows) {
      dJointAttach(joint, a, b);
      cases.push_back({name, joint, rows});
    };
    const Row j1{SS_PARAM_JOINT, 1};
    add("ball", dJointCreateBall(world, 0), {j1});
    add("fixed", dJointCreateFixed(world, 0), {j1});
    add("dball", dJointCreateDBall(world, 0), {j1});
    add("dhinge", dJointCreateDHinge(world, 0), {j1});
    dJointID transmission = dJointCreateTransmission(world, 0);
    add("transmission", transmission, {j1});
    dJointSetTransmissionMode(transmission, dTransmissionParallelAxes);
    auto limits = [](int axes) {
      std::vector<Row> rows;
      for (int axis = 1; axis <= axes; ++axis) {
        rows.push_back({SS_PARAM_STOP, axis});
        rows.push_back({SS_PARAM_MOTOR, axis});
      }
      return rows;
    };
    add("hinge", dJointCreateHinge(world, 0), limits(1));
    add("slider", dJointCreateSlider(world, 0), limits(1));
    add("universal", dJointCreateUniversal(world, 0), limits(2));
    std::vector<Row> hinge2 = limits(2);
    hinge2.push_back({SS_PARAM_SUSPENSION, 1});
    dJointID h2 = dJointCreateHinge2(world, 0);
    add("hinge2", h2, hinge2);
    dJointSetHinge2Axes(h2, (const dReal[]){0, 0, 1}, (const dReal[]){0, 1, 0});
    add("pr", dJointCreatePR(world, 0), limits(2));
    add("pu", dJointCreatePU(world, 0), limits(3));
    add("piston", dJointCreatePiston(world, 0), limits(2));
    dJointID amotor = dJointCreateAMotor(world, 0);
    add("amotor", amotor, limits(3));
    dJointSetAMotorNumAxes(amotor, 3);
    dJointSetAMotorAxis(amotor, 0, 1, 1, 0, 0);
    dJointSetAMotorAxis(amotor, 1, 1, 0, 1, 0);
    dJointSetAMotorAxis(amotor, 2, 1, 0, 0, 1);
    dJointID lmotor = dJointCreateLMotor(world, 0);
    add("lmotor", lmotor, limits(3));
    dJointSetLMotorNumAxes(lmotor, 3);
    dJointSetLMotorAxis(lmotor, 0, 1, 1, 0, 0);
    dJointSetLMotorAxis(lmotor, 1, 1, 0, 1, 0);
    dJointSetLMotorAxis(lmotor, 2, 1, 0, 0, 1);
    return cases;
  }

  dBodyID a = nullptr, b = nullptr;
};

int ErpParam(ssJointParam param) {
  return param == SS_PARAM_JOINT ? dParamERP : param == SS_PARAM_STOP ? dParamStopERP : dParamSuspensionERP;
}
int CfmParam(ssJointParam param) {
  return param == SS_PARAM_JOINT || param == SS_PARAM_MOTOR ? dParamCFM
         : param == SS_PARAM_STOP                          ? dParamStopCFM
                                                           : dParamSuspensionCFM;
}

TEST_F(RegistryTest, EveryJointTypeAndParameterIsWrittenForEachStepLength) {
  ssRegistry* registry = ssRegistry_Create(world);
  std::vector<JointCase> cases = AllJoints();
  int bound = 0;
  for (const JointCase& c : cases)
    for (const Row& row : c.rows) {
      ASSERT_EQ(ssRegistry_BindJoint(registry, c.joint, row.param, row.axis, kSpring, 0), SS_OK)
          << c.name << " " << ssLastError();
      ++bound;
    }
  EXPECT_EQ(ssRegistry_JointBindingCount(registry), bound);
  for (double step_s : {1.0 / 30.0, 1.0 / 144.0}) {
    ssApplyReport report;
    ASSERT_EQ(ssRegistry_Apply(registry, SS_MAPPING_IMPLICIT_EULER, step_s, 0, &report), SS_OK) << ssLastError();
    EXPECT_EQ(report.rows.by_mapping, bound);
    EXPECT_EQ(report.row_writes, bound);  // every row's softness changed with the step
    ssSoftness expected;
    ASSERT_EQ(ssImplicitEulerSoftness(kSpring, step_s, &expected), SS_OK);
    for (const JointCase& c : cases)
      for (const Row& row : c.rows) {
        SCOPED_TRACE(std::string(c.name) + " param " + std::to_string(row.param) + " axis " +
                     std::to_string(row.axis) + " h " + std::to_string(step_s));
        EXPECT_DOUBLE_EQ(GetParam(c.joint, CfmParam(row.param), row.axis), AsDReal(expected.cfm));
        if (row.param != SS_PARAM_MOTOR) {
          EXPECT_DOUBLE_EQ(GetParam(c.joint, ErpParam(row.param), row.axis), AsDReal(expected.erp));
        }
      }
  }
  ssRegistry_Destroy(registry);
}

TEST_F(RegistryTest, MatchedMappingUsesEachRowsEffectiveMass) {
  ssRegistry* registry = ssRegistry_Create(world);
  dJointID slider = dJointCreateSlider(world, 0);
  dJointAttach(slider, a, 0);
  ASSERT_EQ(ssRegistry_BindJoint(registry, slider, SS_PARAM_STOP, 1, kSpring, 0), SS_OK);
  const double step_s = 1.0 / 60.0;
  ASSERT_EQ(ssRegistry_Apply(registry, SS_MAPPING_MATCHED, step_s, 0, nullptr), SS_OK);
  ssSoftness expected;
  ASSERT_EQ(ssMatchedSoftness(kSpring, 2.0, step_s, &expected), SS_OK);  // body a is 2 kg
  EXPECT_NEAR(dJointGetSliderParam(slider, dParamStopERP), expected.erp, ReadBackTolerance(1e-12, expected.erp));
  EXPECT_NEAR(dJointGetSliderParam(slider, dParamStopCFM), expected.cfm, ReadBackTolerance(1e-12, expected.cfm));
  ssRegistry_Destroy(registry);
}

// Apply keeps each body's inverse mass once per Apply and shares a softness between rows with the same law and mass:
// neither may outlive what it was computed from. Sliders bound to one spring move 2, 3, 5 and 1.2 kg (a and b
// together); then a body's mass changes and a joint is attached to another body, and the same step is applied again.
TEST_F(RegistryTest, AccurateMappingsFollowMassesAndAttachmentsBetweenApplies) {
  dBodyID c = MakeBody(5.0, 1, 1, 1);
  ssRegistry* registry = ssRegistry_Create(world);
  struct Slider {
    dJointID joint;
    double mass_kg;
  };
  std::vector<Slider> sliders;
  auto add = [&](dBodyID first, dBodyID second, double mass_kg) {
    dJointID slider = dJointCreateSlider(world, 0);
    dJointAttach(slider, first, second);
    ASSERT_EQ(ssRegistry_BindJoint(registry, slider, SS_PARAM_STOP, 1, kSpring, 0), SS_OK);
    sliders.push_back({slider, mass_kg});
  };
  add(a, 0, 2.0);
  add(b, 0, 3.0);
  add(c, 0, 5.0);
  add(a, b, 1.0 / (1.0 / 2.0 + 1.0 / 3.0));
  add(c, 0, 5.0);
  auto expectMasses = [&](ssMapping mapping, double step_s, double previous_s) {
    for (const Slider& slider : sliders) {
      ssSoftness expected;
      ASSERT_EQ(ServedSoftness(mapping, kSpring, slider.mass_kg, step_s, previous_s, &expected), SS_OK);
      EXPECT_NEAR(dJointGetSliderParam(slider.joint, dParamStopERP), expected.erp,
                  ReadBackTolerance(1e-12 * std::fabs(expected.erp), expected.erp));
      EXPECT_NEAR(dJointGetSliderParam(slider.joint, dParamStopCFM), expected.cfm,
                  ReadBackTolerance(1e-12 * expected.cfm, expected.cfm))
          << "slider of " << slider.mass_kg << " kg";
    }
  };
  const double step_s = 1.0 / 60.0, other_s = 1.0 / 90.0;
  for (ssMapping mapping : {SS_MAPPING_MATCHED, SS_MAPPING_EXACT}) {
    SCOPED_TRACE(ssMappingName(mapping));
    ASSERT_EQ(ssRegistry_Apply(registry, mapping, step_s, other_s, nullptr), SS_OK);
    expectMasses(mapping, step_s, other_s);
    dMass mass;
    dMassSetBoxTotal(&mass, 7.0, 0.1, 0.1, 0.1);
    dBodySetMass(c, &mass);
    sliders[2].mass_kg = sliders[4].mass_kg = 7.0;
    dJointAttach(sliders[0].joint, b, 0);
    sliders[0].mass_kg = 3.0;
    for (int again = 0; again < 2; ++again) {  // the second Apply after the attachment uses the rebuilt cache
      ASSERT_EQ(ssRegistry_Apply(registry, mapping, step_s, other_s, nullptr), SS_OK);
      expectMasses(mapping, step_s, other_s);
    }
    dMassSetBoxTotal(&mass, 5.0, 0.1, 0.1, 0.1);  // as they were, for the next mapping
    dBodySetMass(c, &mass);
    sliders[2].mass_kg = sliders[4].mass_kg = 5.0;
    dJointAttach(sliders[0].joint, a, 0);
    sliders[0].mass_kg = 2.0;
  }
  ssRegistry_Destroy(registry);
}

// Apply keeps a table of the distinct laws (programs bind many rows to a few springs); rows beyond it take another
// path. With more distinct springs than fit, every row still gets exactly the implicit-Euler softness of its own.
TEST_F(RegistryTest, ManyDistinctSpringsEachGetTheirOwnSoftness) {
  ssRegistry* registry = ssRegistry_Create(world);
  std::vector<dJointID> sliders;
  for (int i = 0; i < 40; ++i) {
    dJointID slider = dJointCreateSlider(world, 0);
    dJointAttach(slider, i % 2 ? a : b, 0);
    const ssSpring spring = {100.0 + 10.0 * (i % 25), 1.0 + 0.5 * (i % 25)};  // 25 distinct springs, some twice
    ASSERT_EQ(ssRegistry_BindJoint(registry, slider, SS_PARAM_STOP, 1, spring, 0), SS_OK);
    sliders.push_back(slider);
  }
  for (ssMapping mapping : {SS_MAPPING_IMPLICIT_EULER, SS_MAPPING_MATCHED}) {
    for (double step_s : {1.0 / 60.0, 1.0 / 90.0, 1.0 / 60.0}) {
      ASSERT_EQ(ssRegistry_Apply(registry, mapping, step_s, 0, nullptr), SS_OK) << ssLastError();
      for (int i = 0; i < 40; ++i) {
        const ssSpring spring = {100.0 + 10.0 * (i % 25), 1.0 + 0.5 * (i % 25)};
        ssSoftness expected;
        ASSERT_EQ(ServedSoftness(mapping, spring, i % 2 ? 2.0 : 3.0, step_s, 0, &expected), SS_OK);
        // implicit Euler is the same function of the same numbers: equal to the bit; matched reads a computed mass
        const double tolerance = mapping == SS_MAPPING_IMPLICIT_EULER ? 0.0 : 1e-12;
        EXPECT_NEAR(dJointGetSliderParam(sliders[i], dParamStopERP), expected.erp,
                    ReadBackTolerance(tolerance * expected.erp, expected.erp)) << i;
        EXPECT_NEAR(dJointGetSliderParam(sliders[i], dParamStopCFM), expected.cfm,
                    ReadBackTolerance(tolerance * expected.cfm, expected.cfm)) << i;
      }
    }
  }
  ssRegistry_Destroy(registry);
}

// Implicit Euler writes rows by law and skips a law whose softness did not change (a pure damper's is the same at
// every step); the other mappings compare each row with what it was last given. Over a long random mix of mappings,
// step lengths, rebindings and new rows, every row holds in ODE what its own spring, mass and step give.
TEST_F(RegistryTest, RowsFollowAnyMixOfMappingsStepsAndRebindings) {
  ssRegistry* registry = ssRegistry_Create(world);
  const ssSpring springs[] = {kSpring, {0.0, 5.0}, {150.0, 4.0}};  // the second a pure damper
  struct Slider {
    dJointID joint;
    int spring;
    double mass_kg;
  };
  std::vector<Slider> sliders;
  auto add = [&](int spring) {
    dJointID slider = dJointCreateSlider(world, 0);
    const bool on_a = sliders.size() % 2 == 0;
    dJointAttach(slider, on_a ? a : b, 0);
    ASSERT_EQ(ssRegistry_BindJoint(registry, slider, SS_PARAM_STOP, 1, springs[spring], 0), SS_OK);
    sliders.push_back({slider, spring, on_a ? 2.0 : 3.0});
  };
  for (int i = 0; i < 12; ++i) add(i % 2);
  const ssMapping mappings[] = {SS_MAPPING_IMPLICIT_EULER, SS_MAPPING_MATCHED, SS_MAPPING_EXACT};
  const double steps_s[] = {1.0 / 60.0, 1.0 / 90.0, 1.0 / 144.0, 1.0 / 30.0};
  unsigned seed = 12345;
  auto next = [&](unsigned n) {
    seed = seed * 1103515245u + 12345u;
    return (seed >> 16) % n;
  };
  for (int apply = 0; apply < 400; ++apply) {
    // mostly implicit Euler, often at the same step as before, as a program with a few frame rates does
    const ssMapping mapping = next(3) == 0 ? mappings[1 + next(2)] : SS_MAPPING_IMPLICIT_EULER;
    const double step_s = steps_s[next(4)], previous_s = steps_s[next(4)];
    const unsigned change = next(20);
    if (change == 0) {
      Slider& slider = sliders[next((unsigned)sliders.size())];
      slider.spring = (slider.spring + 1) % 3;
      ASSERT_EQ(ssRegistry_BindJoint(registry, slider.joint, SS_PARAM_STOP, 1, springs[slider.spring], 0), SS_OK);
    } else if (change == 1 && sliders.size() < 40) {
      add((int)next(3));
    }
    ASSERT_EQ(ssRegistry_Apply(registry, mapping, step_s, previous_s, nullptr), SS_OK) << ssLastError();
    for (size_t i = 0; i < sliders.size(); ++i) {
      ssSoftness expected;
      const ssSpring spring = springs[sliders[i].spring];
      // a pure damper has no position to correct: the exact mapping serves it as the matched one does
      ASSERT_EQ(ServedSoftness(mapping, spring, sliders[i].mass_kg, step_s, previous_s, &expected), SS_OK);
      const double tolerance = mapping == SS_MAPPING_IMPLICIT_EULER ? 0.0 : 1e-12;
      SCOPED_TRACE("apply " + std::to_string(apply) + " " + ssMappingName(mapping) + " slider " + std::to_string(i));
      EXPECT_NEAR(dJointGetSliderParam(sliders[i].joint, dParamStopERP), expected.erp,
                  ReadBackTolerance(tolerance * expected.erp, expected.erp));
      EXPECT_NEAR(dJointGetSliderParam(sliders[i].joint, dParamStopCFM), expected.cfm,
                  ReadBackTolerance(tolerance * expected.cfm, expected.cfm));
    }
  }
  ssRegistry_Destroy(registry);
}

TEST_F(RegistryTest, EffectiveMassOfLinearAndAngularRows) {
  dJointID slider = dJointCreateSlider(world, 0);
  dJointAttach(slider, a, b);
  double mass = 0;
  ASSERT_EQ(ssJointEffectiveMass(slider, SS_PARAM_STOP, 1, &mass), SS_OK);
  EXPECT_NEAR(mass, 1.0 / (1.0 / 2.0 + 1.0 / 3.0), 1e-12);

  // A box of 2 kg and side 0.1 m has inertia m·s²/6 about any axis through its centre; rotate it to be sure the
  // world-frame inertia is used.
  dMatrix3 rotation;
  dRFromAxisAndAngle(rotation, 1, 2, 3, 0.7);
  dBodySetRotation(a, rotation);
  dJointID hinge = dJointCreateHinge(world, 0);
  dJointAttach(hinge, a, 0);
  dJointSetHingeAxis(hinge, 0.3, -0.2, 0.9);
  ASSERT_EQ(ssJointEffectiveMass(hinge, SS_PARAM_STOP, 1, &mass), SS_OK);
  EXPECT_NEAR(mass, 2.0 * 0.01 / 6.0, ReadBackTolerance(1e-12, 0.01));

  dJointID unattached = dJointCreateHinge(world, 0);
  EXPECT_EQ(ssJointEffectiveMass(unattached, SS_PARAM_STOP, 1, &mass), SS_ERROR_OUT_OF_RANGE);
  EXPECT_NE(std::string(ssLastError()).find("no dynamic body"), std::string::npos) << ssLastError();
}

// Two boxes of three different principal moments, rotated about skew axes, on a hinge about a skew axis: the mass
// of the hinge's rows is 1/(a·I1⁻¹a + a·I2⁻¹a) with each world-frame inertia formed by ODE itself (dMassRotate:
// R·I·Rᵀ) and solved here by Cramer's rule, independently of how the library computes it.
TEST_F(RegistryTest, EffectiveMassOfRotatedAnisotropicBodies) {
  dBodyID bodies[2] = {a, b};
  const double sides[2][3] = {{0.4, 0.1, 0.2}, {0.05, 0.3, 0.15}};
  const double axes[2][4] = {{1, 2, 3, 0.7}, {-2, 0.5, 1, 2.1}};
  dMass masses[2];
  for (int i = 0; i < 2; ++i) {
    dMassSetBoxTotal(&masses[i], 2.0 + i, sides[i][0], sides[i][1], sides[i][2]);
    dBodySetMass(bodies[i], &masses[i]);
    dMatrix3 rotation;
    dRFromAxisAndAngle(rotation, axes[i][0], axes[i][1], axes[i][2], axes[i][3]);
    dBodySetRotation(bodies[i], rotation);
    dMassRotate(&masses[i], dBodyGetRotation(bodies[i]));  // the world-frame inertia, about the centre
  }
  dJointID hinge = dJointCreateHinge(world, 0);
  dJointAttach(hinge, a, b);
  dJointSetHingeAxis(hinge, 0.3, -0.2, 0.9);
  dVector3 axis;
  dJointGetHingeAxis(hinge, axis);
  double inverse = 0;
  for (const dMass& mass : masses) {
    auto I = [&](int row, int column) { return static_cast<double>(mass.I[4 * row + column]); };
    auto det = [&](const double c0[3], const double c1[3], const double c2[3]) {
      return c0[0] * (c1[1] * c2[2] - c1[2] * c2[1]) - c1[0] * (c0[1] * c2[2] - c0[2] * c2[1]) +
             c2[0] * (c0[1] * c1[2] - c0[2] * c1[1]);
    };
    const double col[3][3] = {{I(0, 0), I(1, 0), I(2, 0)}, {I(0, 1), I(1, 1), I(2, 1)}, {I(0, 2), I(1, 2), I(2, 2)}};
    const double d[3] = {axis[0], axis[1], axis[2]};
    const double whole = det(col[0], col[1], col[2]);
    const double x[3] = {det(d, col[1], col[2]) / whole, det(col[0], d, col[2]) / whole,
                         det(col[0], col[1], d) / whole};
    inverse += d[0] * x[0] + d[1] * x[1] + d[2] * x[2];  // a·I⁻¹a
  }
  double mass = 0;
  ASSERT_EQ(ssJointEffectiveMass(hinge, SS_PARAM_STOP, 1, &mass), SS_OK);
  EXPECT_NEAR(mass, 1.0 / inverse, ReadBackTolerance(1e-12, 1.0 / inverse));
  // the registry's own pass measures the same: a spring that matched serves at this mass (c·h/2m = 0.01,
  // k·h²/m = 0.1) is written with matched's softness for it
  const double step_s = 1.0 / 60;
  const ssSpring spring = {0.1 * mass / (step_s * step_s), 0.02 * mass / step_s};
  ssRegistry* registry = ssRegistry_Create(world);
  ASSERT_EQ(ssRegistry_BindJoint(registry, hinge, SS_PARAM_STOP, 1, spring, 0), SS_OK);
  ssApplyReport report;
  ASSERT_EQ(ssRegistry_Apply(registry, SS_MAPPING_MATCHED, step_s, 0, &report), SS_OK);
  EXPECT_EQ(report.rows.by_mapping, 1);
  ssSoftness expected;
  ASSERT_EQ(ssMatchedSoftness(spring, mass, step_s, &expected), SS_OK);
  EXPECT_NEAR(dJointGetHingeParam(hinge, dParamStopERP), expected.erp, ReadBackTolerance(1e-12, expected.erp));
  EXPECT_NEAR(dJointGetHingeParam(hinge, dParamStopCFM), expected.cfm, ReadBackTolerance(1e-12, expected.cfm));
  ssRegistry_Destroy(registry);
}

TEST_F(RegistryTest, UnsupportedBindingsAreRefusedAtBindTime) {
  ssRegistry* registry = ssRegistry_Create(world);
  dJointID hinge = dJointCreateHinge(world, 0);
  dJointID ball = dJointCreateBall(world, 0);
  dJointID amotor = dJointCreateAMotor(world, 0);
  dJointSetAMotorNumAxes(amotor, 1);
  struct Bad {
    dJointID joint;
    int param, axis;
    const char* named;
  } bad[] = {
      {hinge, SS_PARAM_JOINT, 1, "hinge"},      {hinge, SS_PARAM_STOP, 2, "axis = 2"},
      {hinge, SS_PARAM_SUSPENSION, 1, "hinge"}, {ball, SS_PARAM_STOP, 1, "ball"},
      {amotor, SS_PARAM_STOP, 2, "axis = 2"},   {hinge, 7, 1, "param = 7"},
      {hinge, SS_PARAM_STOP, 0, "axis = 0"},
  };
  for (const Bad& b : bad) {
    EXPECT_EQ(ssRegistry_BindJoint(registry, b.joint, (ssJointParam)b.param, b.axis, kSpring, 0),
              SS_ERROR_UNSUPPORTED);
    EXPECT_NE(std::string(ssLastError()).find(b.named), std::string::npos) << ssLastError();
  }
  EXPECT_EQ(ssRegistry_BindJoint(registry, nullptr, SS_PARAM_STOP, 1, kSpring, 0), SS_ERROR_OUT_OF_RANGE);
  EXPECT_EQ(ssRegistry_BindJoint(registry, hinge, SS_PARAM_STOP, 1, ssSpring{-1, 1}, 0), SS_ERROR_OUT_OF_RANGE);
  EXPECT_EQ(ssRegistry_BindJoint(registry, hinge, SS_PARAM_STOP, 1, ssSpring{0, 0}, 0), SS_ERROR_NO_SPRING);
  EXPECT_EQ(ssRegistry_BindJoint(registry, hinge, SS_PARAM_STOP, 1, ssSpring{NAN, 1}, 0), SS_ERROR_NOT_FINITE);
  EXPECT_EQ(ssRegistry_BindJoint(registry, hinge, SS_PARAM_STOP, 1, kSpring, -2), SS_ERROR_OUT_OF_RANGE);
  EXPECT_NE(std::string(ssLastError()).find("effective_mass = -2"), std::string::npos) << ssLastError();
  EXPECT_EQ(ssRegistry_JointBindingCount(registry), 0);
  ssRegistry_Destroy(registry);
}

TEST_F(RegistryTest, BindingAgainReplacesAndUnbindRemoves) {
  ssRegistry* registry = ssRegistry_Create(world);
  dJointID hinge = dJointCreateHinge(world, 0);
  dJointAttach(hinge, a, 0);
  ASSERT_EQ(ssRegistry_BindJoint(registry, hinge, SS_PARAM_STOP, 1, kSpring, 0), SS_OK);
  ASSERT_EQ(ssRegistry_BindJoint(registry, hinge, SS_PARAM_STOP, 1, ssSpring{100, 1}, 0), SS_OK);
  ASSERT_EQ(ssRegistry_BindJoint(registry, hinge, SS_PARAM_MOTOR, 1, ssSpring{0, 5}, 0), SS_OK);
  EXPECT_EQ(ssRegistry_JointBindingCount(registry), 2);
  ASSERT_EQ(ssRegistry_Apply(registry, SS_MAPPING_IMPLICIT_EULER, 0.01, 0, nullptr), SS_OK);
  EXPECT_DOUBLE_EQ(dJointGetHingeParam(hinge, dParamStopCFM), 1.0 / (0.01 * 100 + 1));
  EXPECT_DOUBLE_EQ(dJointGetHingeParam(hinge, dParamCFM), AsDReal(1.0 / 5.0));  // a pure damper: same at every h

  ASSERT_EQ(ssRegistry_UnbindJoint(registry, hinge), SS_OK);
  EXPECT_EQ(ssRegistry_JointBindingCount(registry), 0);
  EXPECT_EQ(ssRegistry_UnbindJoint(registry, hinge), SS_ERROR_NOT_FOUND);
  dJointDestroy(hinge);
  EXPECT_EQ(ssRegistry_Apply(registry, SS_MAPPING_IMPLICIT_EULER, 0.01, 0, nullptr), SS_OK);
  ssRegistry_Destroy(registry);
}

// Many bindings, rebound, unbound in a scattered order and bound again: each row is found (or not) as a plain list of
// what is bound says, and Apply writes each bound row's own spring.
TEST_F(RegistryTest, ManyBindingsAreFoundAfterRebindingAndUnbindingInAnyOrder) {
  ssRegistry* registry = ssRegistry_Create(world);
  const int count = 3000;
  std::vector<dJointID> hinges;
  std::vector<dBodyID> bodies;
  for (int i = 0; i < count; ++i) {
    bodies.push_back(MakeBody(1.0, 0.01 * i, 0, 1));
    hinges.push_back(dJointCreateHinge(world, 0));
    dJointAttach(hinges.back(), bodies.back(), 0);
    ASSERT_EQ(ssRegistry_BindJoint(registry, hinges[i], SS_PARAM_STOP, 1, kSpring, 0), SS_OK);
    ASSERT_EQ(ssRegistry_BindJoint(registry, hinges[i], SS_PARAM_MOTOR, 1, ssSpring{0, 5}, 0), SS_OK);
    ASSERT_EQ(ssRegistry_BindDamping(registry, bodies[i], 0.1, 0.2), SS_OK);
  }
  // rebinding replaces: the stop of every third hinge gets a spring of its own
  std::vector<double> stiffness(count, kSpring.stiffness);
  for (int i = 0; i < count; i += 3) {
    stiffness[i] = 100.0 + i;
    ASSERT_EQ(ssRegistry_BindJoint(registry, hinges[i], SS_PARAM_STOP, 1, ssSpring{stiffness[i], 12.0}, 0), SS_OK);
  }
  EXPECT_EQ(ssRegistry_JointBindingCount(registry), 2 * count);
  // unbind a scattered half (a multiplicative walk visits every index once)
  std::vector<bool> bound(count, true);
  for (int k = 0; k < count / 2; ++k) {
    int i = (int)((k * 2654435761u) % count);
    if (!bound[i]) continue;
    bound[i] = false;
    ASSERT_EQ(ssRegistry_UnbindJoint(registry, hinges[i]), SS_OK);
    ASSERT_EQ(ssRegistry_UnbindBody(registry, bodies[i]), SS_OK);
  }
  int still = 0;
  for (int i = 0; i < count; ++i) {
    still += bound[i];
    // a load can be declared exactly on the rows still bound
    EXPECT_EQ(ssRegistry_SetJointLoad(registry, hinges[i], SS_PARAM_STOP, 1, 0.5), bound[i] ? SS_OK : SS_ERROR_NOT_FOUND)
        << i;
    EXPECT_EQ(ssRegistry_UnbindBody(registry, bodies[i]), bound[i] ? SS_OK : SS_ERROR_NOT_FOUND) << i;
    ASSERT_EQ(ssRegistry_BindDamping(registry, bodies[i], 0.1, 0.2), SS_OK);
  }
  EXPECT_EQ(ssRegistry_JointBindingCount(registry), 2 * still);
  // the unbound half bound again, with a spring that says which
  for (int i = 0; i < count; ++i)
    if (!bound[i]) {
      stiffness[i] = 50.0;
      ASSERT_EQ(ssRegistry_BindJoint(registry, hinges[i], SS_PARAM_STOP, 1, ssSpring{50.0, 12.0}, 0), SS_OK);
    }
  EXPECT_EQ(ssRegistry_JointBindingCount(registry), count + still);
  const double h = 0.01;
  ASSERT_EQ(ssRegistry_Apply(registry, SS_MAPPING_IMPLICIT_EULER, h, 0, nullptr), SS_OK);
  for (int i = 0; i < count; ++i) {
    // as ODE holds them: the double rounded once to dReal
    EXPECT_DOUBLE_EQ(dJointGetHingeParam(hinges[i], dParamStopCFM), AsDReal(1.0 / (h * stiffness[i] + 12.0))) << i;
    EXPECT_DOUBLE_EQ(dBodyGetLinearDamping(bodies[i]), AsDReal(-std::expm1(-0.1 * h))) << i;
  }
  ssRegistry_Destroy(registry);
}

TEST_F(RegistryTest, SpringsWithoutSoftnessAtSomeStepAreRefusedAtBindTimeAndApplyErrorsWriteNothing) {
  ssRegistry* registry = ssRegistry_Create(world);
  dJointID first = dJointCreateSlider(world, 0);
  dJointAttach(first, a, 0);
  dJointID other = dJointCreateSlider(world, 0);
  dJointAttach(other, b, 0);
  ASSERT_EQ(ssRegistry_BindWorld(registry, kSpring, 0), SS_OK);
  ASSERT_EQ(ssRegistry_BindJoint(registry, first, SS_PARAM_STOP, 1, kSpring, 0), SS_OK);
  // Every mapping falls back to implicit Euler, so a spring is bound only if implicit Euler gives it a softness
  // ODE handles at every step the library takes: then Apply cannot fail in the middle of a frame.
  const ssSpring unbindable[] = {{0, 1e-320},                    // cfm = 1/c overflows at every step
                                 {1.7976931348623157e308, 1e308},  // h*k + c overflows at long steps
                                 {1e-300, 1e-25}};                 // cfm above SS_MAX_CFM at short steps
  for (const ssSpring& spring : unbindable) {
    EXPECT_EQ(ssRegistry_BindJoint(registry, other, SS_PARAM_STOP, 1, spring, 0), SS_ERROR_NO_FINITE_MAPPING);
    EXPECT_NE(std::string(ssLastError()).find("no softness ODE handles"), std::string::npos) << ssLastError();
    EXPECT_EQ(ssRegistry_BindWorld(registry, spring, 0), SS_ERROR_NO_FINITE_MAPPING);
  }
  EXPECT_EQ(ssRegistry_JointBindingCount(registry), 1);
  ASSERT_EQ(ssRegistry_BindDamping(registry, a, 1.0, 1.0), SS_OK);
  const double erp = dWorldGetERP(world), cfm = dWorldGetCFM(world);
  const double stop_erp = dJointGetSliderParam(first, dParamStopERP);
  const double damping = dBodyGetLinearDamping(a);
  for (double step_s : {0.0, -0.01, double(NAN), double(INFINITY), 1e-12, 1e5}) {
    EXPECT_NE(ssRegistry_Apply(registry, SS_MAPPING_IMPLICIT_EULER, step_s, 0, nullptr), SS_OK);
    EXPECT_NE(std::string(ssLastError()).find("step_s"), std::string::npos) << ssLastError();
  }
  EXPECT_EQ(ssRegistry_Apply(registry, SS_MAPPING_IMPLICIT_EULER, 0.01, -1, nullptr), SS_ERROR_OUT_OF_RANGE);
  EXPECT_EQ(ssRegistry_Apply(registry, (ssMapping)9, 0.01, 0, nullptr), SS_ERROR_UNSUPPORTED);
  EXPECT_EQ(dWorldGetERP(world), erp);
  EXPECT_EQ(dWorldGetCFM(world), cfm);
  EXPECT_EQ(dJointGetSliderParam(first, dParamStopERP), stop_erp);
  EXPECT_EQ(dBodyGetLinearDamping(a), damping);
  EXPECT_EQ(ssRegistry_Apply(registry, SS_MAPPING_IMPLICIT_EULER, 0.01, 0, nullptr), SS_OK);
  ssRegistry_Destroy(registry);
}

TEST_F(RegistryTest, DampingRatesRemoveTheSameFractionPerSecond) {
  ssRegistry* registry = ssRegistry_Create(world);
  ASSERT_EQ(ssRegistry_BindDamping(registry, a, 0.5, 2.0), SS_OK);
  ASSERT_EQ(ssRegistry_BindDamping(registry, nullptr, 0.25, 0.0), SS_OK);
  dWorldSetGravity(world, 0, 0, 0);
  for (double step_s : {1.0 / 15.0, 1.0 / 144.0}) {
    ASSERT_EQ(ssRegistry_Apply(registry, SS_MAPPING_IMPLICIT_EULER, step_s, 0, nullptr), SS_OK);
    EXPECT_NEAR(dBodyGetLinearDamping(a), 1 - std::exp(-0.5 * step_s), ReadBackTolerance(1e-15, 0.5 * step_s));
    EXPECT_NEAR(dBodyGetAngularDamping(a), 1 - std::exp(-2.0 * step_s), ReadBackTolerance(1e-15, 2.0 * step_s));
    EXPECT_NEAR(dWorldGetLinearDamping(world), 1 - std::exp(-0.25 * step_s), ReadBackTolerance(1e-15, 0.25 * step_s));
    // One simulated second at this step length leaves exp(-0.5) of the speed, whatever the step.
    dBodySetLinearVel(a, 10, 0, 0);
    dBodySetLinearDampingThreshold(a, 0);
    int steps = (int)std::lround(1.0 / step_s);
    for (int i = 0; i < steps; ++i) dWorldStep(world, step_s);
    EXPECT_NEAR(dBodyGetLinearVel(a)[0], 10 * std::exp(-0.5), IntegratedTolerance(1e-9, 1e-4));  // float: 1e-5
  }
  EXPECT_EQ(ssRegistry_BindDamping(registry, a, -1, 0), SS_ERROR_OUT_OF_RANGE);
  EXPECT_EQ(ssRegistry_BindDamping(registry, a, 0, NAN), SS_ERROR_NOT_FINITE);
  ssRegistry_Destroy(registry);
}

TEST_F(RegistryTest, AutoDisableIsGivenInSeconds) {
  ssRegistry* registry = ssRegistry_Create(world);
  ASSERT_EQ(ssRegistry_BindAutoDisable(registry, a, 0.5, 0.1), SS_OK);
  ASSERT_EQ(ssRegistry_Apply(registry, SS_MAPPING_IMPLICIT_EULER, 1.0 / 60.0, 0, nullptr), SS_OK);
  EXPECT_EQ(dBodyGetAutoDisableSteps(a), 30);
  EXPECT_DOUBLE_EQ(dBodyGetAutoDisableTime(a), 0.5);
  EXPECT_EQ(dBodyGetAutoDisableAverageSamplesCount(a), 6u);
  ASSERT_EQ(ssRegistry_Apply(registry, SS_MAPPING_IMPLICIT_EULER, 1.0 / 15.0, 0, nullptr), SS_OK);
  EXPECT_EQ(dBodyGetAutoDisableSteps(a), 8);
  EXPECT_EQ(dBodyGetAutoDisableAverageSamplesCount(a), 2u);
  EXPECT_EQ(ssRegistry_BindAutoDisable(registry, a, 0, 0.1), SS_ERROR_OUT_OF_RANGE);
  EXPECT_NE(std::string(ssLastError()).find("idle_time_s = 0"), std::string::npos) << ssLastError();
  ASSERT_EQ(ssRegistry_UnbindBody(registry, a), SS_OK);
  EXPECT_EQ(ssRegistry_UnbindBody(registry, a), SS_ERROR_NOT_FOUND);
  ssRegistry_Destroy(registry);
}

// Apply at the step of its last write passes only the bindings changed or added since: a binding added, bound again in
// place, or moved by an unbinding is written at that same step, and a sleeping body is passed over
// (ODE steps none of it) and written at the first Apply for another step once it is awake.
TEST_F(RegistryTest, EveryBodyBindingChangedSinceTheLastWriteIsWrittenAtTheSameStep) {
  ssRegistry* registry = ssRegistry_Create(world);
  const double step_s = 1.0 / 90.0, other_step_s = 1.0 / 45.0;
  auto scale = [](double rate, double h) { return 1 - std::exp(-rate * h); };
  auto tolerance = [](double rate, double h) { return ReadBackTolerance(1e-15, rate * h); };
  std::vector<dBodyID> bodies;
  for (int i = 0; i < 6; ++i) {
    bodies.push_back(MakeBody(1.0));
    ASSERT_EQ(ssRegistry_BindDamping(registry, bodies.back(), 1.0, 1.0), SS_OK);
  }
  dBodyID sleeper = bodies[3];
  dBodyDisable(sleeper);
  dBodySetLinearDamping(sleeper, 0.5);
  ASSERT_EQ(ssRegistry_Apply(registry, SS_MAPPING_IMPLICIT_EULER, step_s, 0, nullptr), SS_OK);
  for (dBodyID body : bodies) {
    if (body == sleeper) continue;
    EXPECT_NEAR(dBodyGetLinearDamping(body), scale(1.0, step_s), tolerance(1.0, step_s));
  }
  EXPECT_EQ(dBodyGetLinearDamping(sleeper), 0.5);  // passed over asleep

  // woken, with a body bound since: the write at the same step passes the new binding alone
  dBodyEnable(sleeper);
  dBodyID added = MakeBody(1.0);
  ASSERT_EQ(ssRegistry_BindDamping(registry, added, 2.0, 2.0), SS_OK);
  ASSERT_EQ(ssRegistry_Apply(registry, SS_MAPPING_IMPLICIT_EULER, step_s, 0, nullptr), SS_OK);
  EXPECT_NEAR(dBodyGetLinearDamping(added), scale(2.0, step_s), tolerance(2.0, step_s));
  EXPECT_EQ(dBodyGetLinearDamping(sleeper), 0.5);  // a stepper writes it before the step it wakes for

  // bound again in place
  ASSERT_EQ(ssRegistry_BindDamping(registry, bodies[1], 3.0, 3.0), SS_OK);
  ASSERT_EQ(ssRegistry_Apply(registry, SS_MAPPING_IMPLICIT_EULER, step_s, 0, nullptr), SS_OK);
  EXPECT_NEAR(dBodyGetLinearDamping(bodies[1]), scale(3.0, step_s), tolerance(3.0, step_s));

  // bound after the last write, then moved to the first place by an unbinding
  dBodyID moved = MakeBody(1.0);
  ASSERT_EQ(ssRegistry_BindDamping(registry, moved, 5.0, 5.0), SS_OK);
  ASSERT_EQ(ssRegistry_UnbindBody(registry, bodies[0]), SS_OK);
  dBodySetLinearDamping(bodies[0], 0.25);  // not bound: left as the program sets it
  ASSERT_EQ(ssRegistry_Apply(registry, SS_MAPPING_IMPLICIT_EULER, step_s, 0, nullptr), SS_OK);
  EXPECT_NEAR(dBodyGetLinearDamping(moved), scale(5.0, step_s), tolerance(5.0, step_s));
  EXPECT_EQ(dBodyGetLinearDamping(bodies[0]), 0.25);

  ASSERT_EQ(ssRegistry_Apply(registry, SS_MAPPING_IMPLICIT_EULER, other_step_s, 0, nullptr), SS_OK);
  EXPECT_NEAR(dBodyGetLinearDamping(sleeper), scale(1.0, other_step_s), tolerance(1.0, other_step_s));
  EXPECT_NEAR(dBodyGetLinearDamping(bodies[1]), scale(3.0, other_step_s), tolerance(3.0, other_step_s));
  EXPECT_NEAR(dBodyGetLinearDamping(added), scale(2.0, other_step_s), tolerance(2.0, other_step_s));
  EXPECT_NEAR(dBodyGetLinearDamping(moved), scale(5.0, other_step_s), tolerance(5.0, other_step_s));
  ssRegistry_Destroy(registry);
}

// Between two writes at one step, any number of bindings changed anywhere, and places emptied by unbinding, in random
// rounds: each write leaves every bound body with its own rate's damping for the step, whatever the registry keeps
// of what changed (a few places, or everything from the first of many).
TEST_F(RegistryTest, AnyNumberOfBodyBindingsChangedBetweenWritesAreAllWritten) {
  ssRegistry* registry = ssRegistry_Create(world);
  const double step_s = 1.0 / 60.0;
  std::vector<dBodyID> bound;
  std::vector<double> rate;
  for (int i = 0; i < 60; ++i) {
    bound.push_back(MakeBody(1.0));
    rate.push_back(1.0);
    ASSERT_EQ(ssRegistry_BindDamping(registry, bound.back(), 1.0, 1.0), SS_OK);
  }
  ASSERT_EQ(ssRegistry_Apply(registry, SS_MAPPING_IMPLICIT_EULER, step_s, 0, nullptr), SS_OK);
  unsigned seed = 7;
  auto next = [&seed](int n) { return static_cast<int>((seed = seed * 1103515245u + 12345u) / 65536u % n); };
  for (int round = 0; round < 40; ++round) {
    SCOPED_TRACE(round);
    const int changes = round % 4 == 3 ? 30 : 1 + round % 5;  // a few, or more than the registry lists
    for (int c = 0; c < changes; ++c) {
      const int k = next(static_cast<int>(bound.size()));
      if (next(3) == 0 && bound.size() > 20) {  // unbound: the last binding moves to its place
        ASSERT_EQ(ssRegistry_UnbindBody(registry, bound[k]), SS_OK);
        bound.erase(bound.begin() + k), rate.erase(rate.begin() + k);
      } else {
        rate[k] = 0.5 + next(100) / 10.0;
        ASSERT_EQ(ssRegistry_BindDamping(registry, bound[k], rate[k], rate[k]), SS_OK);
      }
    }
    if (round % 2) {  // one made and bound besides
      bound.push_back(MakeBody(1.0));
      rate.push_back(2.5);
      ASSERT_EQ(ssRegistry_BindDamping(registry, bound.back(), 2.5, 2.5), SS_OK);
    }
    ASSERT_EQ(ssRegistry_Apply(registry, SS_MAPPING_IMPLICIT_EULER, step_s, 0, nullptr), SS_OK);
    for (size_t i = 0; i < bound.size(); ++i)
      ASSERT_NEAR(dBodyGetLinearDamping(bound[i]), 1 - std::exp(-rate[i] * step_s),
                  ReadBackTolerance(1e-15, rate[i] * step_s))
          << "body " << i;
  }
  ssRegistry_Destroy(registry);
}

TEST_F(RegistryTest, VisitsEachBoundBodyOnce) {
  ssRegistry* registry = ssRegistry_Create(world);
  for (int i = 0; i < 3; ++i) {
    dJointID hinge = dJointCreateHinge(world, 0);
    dJointAttach(hinge, a, i == 2 ? nullptr : b);
    ASSERT_EQ(ssRegistry_BindJoint(registry, hinge, SS_PARAM_STOP, 1, kSpring, 0), SS_OK);
  }
  dBodyID c = MakeBody(1.0);
  ASSERT_EQ(ssRegistry_BindDamping(registry, c, 1, 1), SS_OK);
  ASSERT_EQ(ssRegistry_BindDamping(registry, a, 1, 1), SS_OK);
  std::vector<dBodyID> seen;
  ssRegistry_VisitBodies(
      registry, [](void* context, dBodyID body) { static_cast<std::vector<dBodyID>*>(context)->push_back(body); },
      &seen);
  std::sort(seen.begin(), seen.end());
  std::vector<dBodyID> expected = {a, b, c};
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(seen, expected);
  ssRegistry_Destroy(registry);
}

TEST_F(RegistryTest, ContactSoftenFillsTheSurface) {
  dContact contact;
  std::memset(&contact, 0, sizeof contact);
  contact.geom.normal[2] = 1;
  dBodySetPosition(a, 0, 0, 0.05);
  contact.geom.pos[2] = 0;
  ASSERT_EQ(ssContactSoften(&contact, a, nullptr, kSpring, SS_MAPPING_IMPLICIT_EULER, 0.02, 0), SS_OK);
  ssSoftness expected;
  ssImplicitEulerSoftness(kSpring, 0.02, &expected);
  EXPECT_TRUE(contact.surface.mode & dContactSoftERP);
  EXPECT_TRUE(contact.surface.mode & dContactSoftCFM);
  EXPECT_DOUBLE_EQ(contact.surface.soft_erp, AsDReal(expected.erp));
  EXPECT_DOUBLE_EQ(contact.surface.soft_cfm, AsDReal(expected.cfm));

  // Under the accurate mappings implicit Euler serves every contact (its load is never known, issue 15): the same
  // softness, with a dynamic body or none.
  for (ssMapping mapping : {SS_MAPPING_MATCHED, SS_MAPPING_EXACT}) {
    for (dBodyID body : {a, static_cast<dBodyID>(nullptr)}) {
      contact.surface.soft_cfm = 0;
      ASSERT_EQ(ssContactSoften(&contact, body, nullptr, kSpring, mapping, 0.02, 0.02), SS_OK);
      EXPECT_EQ(contact.surface.soft_erp, AsDReal(expected.erp));
      EXPECT_EQ(contact.surface.soft_cfm, AsDReal(expected.cfm));
    }
  }

  dContact before = contact;
  EXPECT_EQ(ssContactSoften(&contact, a, nullptr, kSpring, (ssMapping)7, 0.02, 0), SS_ERROR_UNSUPPORTED);
  EXPECT_EQ(ssContactSoften(&contact, a, nullptr, ssSpring{1, -1}, SS_MAPPING_IMPLICIT_EULER, 0.02, 0),
            SS_ERROR_OUT_OF_RANGE);
  EXPECT_EQ(ssContactSoften(&contact, a, nullptr, kSpring, SS_MAPPING_IMPLICIT_EULER, 0, 0), SS_ERROR_OUT_OF_RANGE);
  EXPECT_EQ(std::memcmp(&before, &contact, sizeof contact), 0);
}

}  // namespace

// Adoption on real ODE: what a program tuned at its step, read back after steadystep took it over, at that step
// and at others; hard rows, dampers, damping and auto-disable in seconds; objects made later; contacts in the near
// callback; refusals that leave the registry as it was.
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "joint_params.h"
#include "ode_fixture.h"
#include "precision.h"
#include "steadystep/steadystep.h"

namespace {

const double kTunedStep = 1.0 / 60.0;

// One tuned ODE parameter of one joint.
struct Tuned {
  dJointID joint;
  int param;
  int axis;
  double value;
};

class AdoptTest : public OdeTest {
 protected:
  void SetUp() override {
    OdeTest::SetUp();
    space = dSimpleSpaceCreate(0);
    registry = ssRegistry_Create(world);
  }
  void TearDown() override {
    ssRegistry_Destroy(registry);
    dSpaceDestroy(space);
    OdeTest::TearDown();
  }

  // A body with a box geom in the space, so that adoption reaches it.
  dBodyID Body(double x, double y, double z) {
    dBodyID body = MakeBody(1.5, x, y, z);
    dGeomSetBody(dCreateBox(space, 0.1, 0.1, 0.1), body);
    return body;
  }

  // Sets a distinct non-default value on a parameter and remembers it.
  void Tune(dJointID joint, int param, int axis) {
    double value = 0.05 + 0.01 * (double)tuned.size();
    if (param == dParamCFM || param == dParamStopCFM || param == dParamSuspensionCFM) value *= 1e-3;
    SetParam(joint, param, axis, value);
    tuned.push_back({joint, param, axis, value});
  }

  // Every joint type of ODE 0.16 with a soft parameter, between a body of the space and a free one reached only
  // through the joint, every soft parameter of every axis tuned.
  void BuildEveryJoint() {
    auto pair = [&](dJointID joint) {
      dBodyID a = Body(0, 0, 1 + 0.1 * joints.size());
      dBodyID b = MakeBody(2.0, 0.3, 0.1, 1.2 + 0.1 * joints.size());  // no geom: reached through the joint
      dJointAttach(joint, a, b);
      joints.push_back(joint);
      return joint;
    };
    for (dJointID j : {pair(dJointCreateBall(world, 0)), pair(dJointCreateFixed(world, 0)),
                       pair(dJointCreateDBall(world, 0)), pair(dJointCreateDHinge(world, 0))}) {
      Tune(j, dParamERP, 1);
      Tune(j, dParamCFM, 1);
    }
    dJointID transmission = pair(dJointCreateTransmission(world, 0));
    Tune(transmission, dParamERP, 1);
    Tune(transmission, dParamCFM, 1);
    struct Limited {
      dJointID joint;
      int axes;
    } limited[] = {{pair(dJointCreateHinge(world, 0)), 1},     {pair(dJointCreateSlider(world, 0)), 1},
                   {pair(dJointCreateUniversal(world, 0)), 2}, {pair(dJointCreateHinge2(world, 0)), 2},
                   {pair(dJointCreatePR(world, 0)), 2},        {pair(dJointCreatePU(world, 0)), 3},
                   {pair(dJointCreatePiston(world, 0)), 2},    {pair(dJointCreateAMotor(world, 0)), 3},
                   {pair(dJointCreateLMotor(world, 0)), 3}};
    dJointSetAMotorNumAxes(limited[7].joint, 3);
    dJointSetLMotorNumAxes(limited[8].joint, 3);
    for (const Limited& l : limited)
      for (int axis = 1; axis <= l.axes; ++axis) {
        Tune(l.joint, dParamStopERP, axis);
        Tune(l.joint, dParamStopCFM, axis);
        Tune(l.joint, dParamCFM, axis);
      }
    Tune(limited[3].joint, dParamSuspensionERP, 1);
    Tune(limited[3].joint, dParamSuspensionCFM, 1);
  }

  void ExpectTunedValues(const char* when) {
    for (const Tuned& t : tuned) {
      double now = GetParam(t.joint, t.param, t.axis);
      EXPECT_NEAR(now, t.value, ReadBackTolerance(1e-12 * t.value, t.value))
          << when << ": joint type " << dJointGetType(t.joint) << " param " << t.param << " axis " << t.axis;
    }
  }

  dSpaceID space = nullptr;
  ssRegistry* registry = nullptr;
  std::vector<dJointID> joints;
  std::vector<Tuned> tuned;
};

TEST_F(AdoptTest, EveryJointTypeKeepsItsTunedValuesAtTheTunedStep) {
  dWorldSetERP(world, 0.35);
  dWorldSetCFM(world, 2e-5);
  BuildEveryJoint();
  ssAdoptReport report = {};
  ASSERT_EQ(ssRegistry_Adopt(registry, kTunedStep, space, &report), SS_OK) << ssLastError();
  EXPECT_EQ(report.world, 1);
  EXPECT_EQ(report.joints, (int)joints.size());
  EXPECT_EQ(report.joint_rows, 5);
  EXPECT_EQ(report.stop_rows, 1 + 1 + 2 + 2 + 2 + 3 + 2 + 3 + 3);
  EXPECT_EQ(report.motor_rows, report.stop_rows);
  EXPECT_EQ(report.suspension_rows, 1);
  EXPECT_EQ(report.hard_rows, 0);
  EXPECT_EQ(report.bodies, 2 * (int)joints.size());
  EXPECT_EQ(report.skipped_joints, 0);

  // Other step lengths change the softness of every row (all but motors, which are dampers)...
  ASSERT_EQ(ssRegistry_Apply(registry, SS_MAPPING_IMPLICIT_EULER, 1.0 / 25.0, 0, nullptr), SS_OK);
  int changed = 0;
  for (const Tuned& t : tuned) changed += GetParam(t.joint, t.param, t.axis) != t.value;
  EXPECT_GE(changed, (int)tuned.size() - report.motor_rows);
  EXPECT_NE(dWorldGetERP(world), 0.35);
  // ...and the tuned step gives back exactly what the program tuned.
  ASSERT_EQ(ssRegistry_Apply(registry, SS_MAPPING_IMPLICIT_EULER, kTunedStep, 0, nullptr), SS_OK);
  ExpectTunedValues("at the tuned step");
  EXPECT_NEAR(dWorldGetERP(world), 0.35, ReadBackTolerance(1e-12, 0.35));
  EXPECT_NEAR(dWorldGetCFM(world), 2e-5, ReadBackTolerance(1e-12 * 2e-5, 2e-5));
}

TEST_F(AdoptTest, OdeDefaultsAreAdoptedLikeTunedValues) {
  // A program that set nothing: ODE's double-precision world CFM 1e-10 and ERP 0.2, copied into joints.
  dJointID ball = dJointCreateBall(world, 0);
  dJointAttach(ball, Body(0, 0, 1), 0);
  const double erp = dWorldGetERP(world), cfm = dWorldGetCFM(world);
  ASSERT_EQ(ssRegistry_Adopt(registry, kTunedStep, space, nullptr), SS_OK) << ssLastError();
  for (ssMapping mapping : {SS_MAPPING_IMPLICIT_EULER, SS_MAPPING_MATCHED, SS_MAPPING_EXACT}) {
    ssApplyReport applied;
    ASSERT_EQ(ssRegistry_Apply(registry, mapping, kTunedStep, kTunedStep, &applied), SS_OK) << ssLastError();
    EXPECT_NEAR(dJointGetBallParam(ball, dParamCFM), cfm, 1e-12 * cfm);
    EXPECT_NEAR(dJointGetBallParam(ball, dParamERP), erp, 1e-12);
    // near-rigid: far above the step's Nyquist frequency, so the accurate mappings hand the rows to spring
    if (mapping != SS_MAPPING_IMPLICIT_EULER) {
      EXPECT_GE(applied.rows.handed_to_implicit_euler, 2) << ssMappingName(mapping);
    }
  }
}

TEST_F(AdoptTest, HardRowsAndDampersAreCarriedAsTheyAre) {
  dJointID hard = dJointCreateHinge(world, 0);
  dJointAttach(hard, Body(0, 0, 1), 0);
  dJointSetHingeParam(hard, dParamStopERP, 0.4);
  dJointSetHingeParam(hard, dParamStopCFM, 0);
  dJointID damper = dJointCreateSlider(world, 0);
  dJointAttach(damper, Body(1, 0, 1), 0);
  dJointSetSliderParam(damper, dParamStopERP, 0);
  dJointSetSliderParam(damper, dParamStopCFM, 0.02);
  ssAdoptReport report = {};
  ASSERT_EQ(ssRegistry_Adopt(registry, kTunedStep, space, &report), SS_OK) << ssLastError();
  EXPECT_EQ(report.hard_rows, 1);
  for (double h : {kTunedStep, 1.0 / 20.0, 1.0 / 240.0}) {
    ASSERT_EQ(ssRegistry_Apply(registry, SS_MAPPING_IMPLICIT_EULER, h, 0, nullptr), SS_OK);
    // hard: cfm stays 0, and the error is corrected at the same rate per second r = erp/(h0 (1 - erp))
    const double rate = 0.4 / (kTunedStep * 0.6);
    EXPECT_EQ(dJointGetHingeParam(hard, dParamStopCFM), 0.0);
    EXPECT_NEAR(dJointGetHingeParam(hard, dParamStopERP), rate * h / (rate * h + 1), ReadBackTolerance(1e-12, 1)) << h;
    // a pure damper (erp 0): k = 0, c = 1/cfm, the same at every step
    EXPECT_EQ(dJointGetSliderParam(damper, dParamStopERP), 0.0);
    EXPECT_NEAR(dJointGetSliderParam(damper, dParamStopCFM), 0.02, ReadBackTolerance(1e-15, 0.02)) << h;
  }
}

TEST_F(AdoptTest, DampingAndAutoDisableBecomeSecondsAndReachBodiesMadeLater) {
  dWorldSetLinearDamping(world, 0.01);
  dWorldSetAngularDamping(world, 0.02);
  dWorldSetAutoDisableSteps(world, 12);
  dWorldSetAutoDisableAverageSamplesCount(world, 3);
  dBodyID early = Body(0, 0, 1);  // copies the world's defaults
  dBodyID own = Body(1, 0, 1);
  dBodySetLinearDamping(own, 0.05);
  dBodySetAutoDisableSteps(own, 30);
  dBodySetAutoDisableTime(own, 0.2);
  ASSERT_EQ(ssRegistry_Adopt(registry, kTunedStep, space, nullptr), SS_OK) << ssLastError();

  const double h = kTunedStep / 2;
  ASSERT_EQ(ssRegistry_Apply(registry, SS_MAPPING_IMPLICIT_EULER, h, 0, nullptr), SS_OK);
  // half the step: the velocity kept per step is the square root, so the same fraction is kept per second
  EXPECT_NEAR(1 - dBodyGetLinearDamping(early), std::sqrt(1 - 0.01), ReadBackTolerance(1e-12, 1));
  EXPECT_NEAR(1 - dBodyGetAngularDamping(early), std::sqrt(1 - 0.02), ReadBackTolerance(1e-12, 1));
  EXPECT_NEAR(1 - dBodyGetLinearDamping(own), std::sqrt(1 - 0.05), ReadBackTolerance(1e-12, 1));
  EXPECT_EQ(dBodyGetAutoDisableSteps(early), 24);
  EXPECT_EQ(dBodyGetAutoDisableAverageSamplesCount(early), 6u);
  EXPECT_EQ(dBodyGetAutoDisableSteps(own), 60);  // 30 steps = 0.5 s > 0.2 s
  EXPECT_NEAR(dBodyGetAutoDisableTime(own), 0.5, 1e-12);

  // A body made now copies the world's current (rewritten) defaults: it adopts the world's rates.
  dBodyID late = Body(2, 0, 1);
  ssAdoptReport report = {};
  ASSERT_EQ(ssRegistry_AdoptBody(registry, late, &report), SS_OK) << ssLastError();
  EXPECT_EQ(report.bodies, 1);
  ASSERT_EQ(ssRegistry_Apply(registry, SS_MAPPING_IMPLICIT_EULER, kTunedStep, 0, nullptr), SS_OK);
  for (dBodyID body : {early, late}) {
    EXPECT_NEAR(dBodyGetLinearDamping(body), 0.01, ReadBackTolerance(1e-12, 0.01));
    EXPECT_EQ(dBodyGetAutoDisableSteps(body), 12);
    EXPECT_EQ(dBodyGetAutoDisableAverageSamplesCount(body), 3u);
  }
  EXPECT_EQ(dBodyGetAutoDisableSteps(own), 30);
  EXPECT_NEAR(dBodyGetLinearDamping(own), 0.05, ReadBackTolerance(1e-12, 0.05));
}

TEST_F(AdoptTest, JointsMadeLaterAdoptTheWorldsSpringAndAdoptingAgainChangesNothing) {
  dWorldSetERP(world, 0.3);
  dWorldSetCFM(world, 1e-4);
  dBodyID body = Body(0, 0, 1);
  ASSERT_EQ(ssRegistry_Adopt(registry, kTunedStep, space, nullptr), SS_OK) << ssLastError();
  ASSERT_EQ(ssRegistry_Apply(registry, SS_MAPPING_IMPLICIT_EULER, 1.0 / 20.0, 0, nullptr), SS_OK);
  dJointID ball = dJointCreateBall(world, 0);  // copies the world's ERP/CFM written for 1/20 s
  dJointAttach(ball, body, 0);
  ssAdoptReport report = {};
  ASSERT_EQ(ssRegistry_AdoptJoint(registry, ball, &report), SS_OK) << ssLastError();
  EXPECT_EQ(report.joint_rows, 1);
  ASSERT_EQ(ssRegistry_Apply(registry, SS_MAPPING_IMPLICIT_EULER, kTunedStep, 0, nullptr), SS_OK);
  EXPECT_NEAR(dJointGetBallParam(ball, dParamERP), 0.3, ReadBackTolerance(1e-12, 0.3));
  EXPECT_NEAR(dJointGetBallParam(ball, dParamCFM), 1e-4, ReadBackTolerance(1e-16, 1e-4));

  const int rows = ssRegistry_JointBindingCount(registry);
  ssAdoptReport again = {};
  ASSERT_EQ(ssRegistry_Adopt(registry, kTunedStep, space, &again), SS_OK) << ssLastError();
  EXPECT_EQ(ssRegistry_JointBindingCount(registry), rows);
  EXPECT_EQ(again.joint_rows + again.stop_rows + again.bodies + again.world, 0);
}

TEST_F(AdoptTest, BadInputIsRefusedByNameAndNothingIsBound) {
  dBodyID body = Body(0, 0, 1);
  EXPECT_EQ(ssRegistry_Adopt(nullptr, kTunedStep, space, nullptr), SS_ERROR_OUT_OF_RANGE);
  EXPECT_NE(std::string(ssLastError()).find("registry = NULL"), std::string::npos) << ssLastError();
  EXPECT_EQ(ssRegistry_Adopt(registry, kTunedStep, nullptr, nullptr), SS_ERROR_OUT_OF_RANGE);
  EXPECT_NE(std::string(ssLastError()).find("space = NULL"), std::string::npos) << ssLastError();
  for (double step_s : {0.0, -kTunedStep, double(NAN), double(INFINITY)}) {
    EXPECT_NE(ssRegistry_Adopt(registry, step_s, space, nullptr), SS_OK) << step_s;
    EXPECT_NE(std::string(ssLastError()).find("tuned_step_s"), std::string::npos) << ssLastError();
  }
  EXPECT_EQ(ssRegistry_AdoptBody(registry, body, nullptr), SS_ERROR_OUT_OF_RANGE);  // the world first
  EXPECT_NE(std::string(ssLastError()).find("adopt the world first"), std::string::npos) << ssLastError();

  // A tuned value that stands for no spring (erp > 1): named, and nothing is bound, the world included.
  dJointID hinge = dJointCreateHinge(world, 0);
  dJointAttach(hinge, body, 0);
  dJointSetHingeParam(hinge, dParamStopERP, 1.5);
  EXPECT_EQ(ssRegistry_Adopt(registry, kTunedStep, space, nullptr), SS_ERROR_OUT_OF_RANGE);
  EXPECT_NE(std::string(ssLastError()).find("hinge joint"), std::string::npos) << ssLastError();
  EXPECT_NE(std::string(ssLastError()).find("erp = 1.5"), std::string::npos) << ssLastError();
  EXPECT_EQ(ssRegistry_JointBindingCount(registry), 0);
  EXPECT_EQ(ssRegistry_TunedStep(registry), 0.0);
  const double world_erp = dWorldGetERP(world);
  ASSERT_EQ(ssRegistry_Apply(registry, SS_MAPPING_IMPLICIT_EULER, 0.1, 0, nullptr), SS_OK);
  EXPECT_EQ(dWorldGetERP(world), world_erp);

  // Plane-2D cannot be read back in ODE 0.16: skipped and counted, not guessed.
  dJointSetHingeParam(hinge, dParamStopERP, 0.5);
  dJointID plane = dJointCreatePlane2D(world, 0);
  dJointAttach(plane, body, 0);
  ssAdoptReport report = {};
  ASSERT_EQ(ssRegistry_Adopt(registry, kTunedStep, space, &report), SS_OK) << ssLastError();
  EXPECT_EQ(report.skipped_joints, 1);
  EXPECT_EQ(ssRegistry_Adopt(registry, 1.0 / 30.0, space, nullptr), SS_ERROR_OUT_OF_RANGE);  // another tuned step
  EXPECT_NE(std::string(ssLastError()).find("tuned at"), std::string::npos) << ssLastError();
  EXPECT_EQ(ssRegistry_AdoptJoint(registry, nullptr, nullptr), SS_ERROR_OUT_OF_RANGE);
  EXPECT_EQ(ssRegistry_AdoptBody(registry, nullptr, nullptr), SS_ERROR_OUT_OF_RANGE);
}

}  // namespace

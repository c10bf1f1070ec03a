// Adoption on real ODE: what a program tuned at its step, read back after steadystep took it over, at that step
// and at others; hard rows, dampers, damping and auto-disable in seconds; objects made later; contacts in the near
// callback; refusals that leave the registry as it was.
#include <cmath>
#include <cstring>
#include <cstdio>
#include <string>
#include <vector>

#include "joint_params.h"
#include "ode_fixture.h"
#include "precision.h"
#include "steadystep/steadystep.h"

// A value the library computed and ODE holds, rounded once to dReal: within tolerance (stated for double) of expected.
#define EXPECT_READ_BACK(held, expected, tolerance) \
  EXPECT_NEAR(held, expected, ReadBackTolerance(tolerance, expected))

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

  // Bit for bit: what the program set is what ODE holds again.
  void ExpectTunedValues(const char* when) {
    for (const Tuned& t : tuned) {
      double now = GetParam(t.joint, t.param, t.axis);
      EXPECT_EQ(now, AsDReal(t.value)) << when << ": joint type " << dJointGetType(t.joint) << " param " << t.param
                              << " axis " << t.axis;
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
  EXPECT_EQ(dWorldGetERP(world), AsDReal(0.35));
  EXPECT_EQ(dWorldGetCFM(world), AsDReal(2e-5));
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
    EXPECT_EQ(dJointGetBallParam(ball, dParamCFM), cfm);
    EXPECT_EQ(dJointGetBallParam(ball, dParamERP), erp);
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
    EXPECT_EQ(dJointGetHingeParam(hard, dParamStopCFM), AsDReal(0.0));
    EXPECT_NEAR(dJointGetHingeParam(hard, dParamStopERP), rate * h / (rate * h + 1), ReadBackTolerance(1e-12, 1)) << h;
    // a pure damper (erp 0): k = 0, c = 1/cfm, the same at every step
    EXPECT_EQ(dJointGetSliderParam(damper, dParamStopERP), AsDReal(0.0));
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
    EXPECT_EQ(dBodyGetLinearDamping(body), AsDReal(0.01));
    EXPECT_EQ(dBodyGetAutoDisableSteps(body), 12);
    EXPECT_EQ(dBodyGetAutoDisableAverageSamplesCount(body), 3u);
  }
  EXPECT_EQ(dBodyGetAutoDisableSteps(own), 30);
  EXPECT_EQ(dBodyGetLinearDamping(own), AsDReal(0.05));
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
  EXPECT_EQ(dJointGetBallParam(ball, dParamERP), AsDReal(0.3));
  EXPECT_EQ(dJointGetBallParam(ball, dParamCFM), AsDReal(1e-4));

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
  // A body's value that stands for no rate (a damping scale of 1 or more) is named with its body.
  dJointSetHingeParam(hinge, dParamStopERP, 0.2);
  dBodySetLinearDamping(body, 1.5);
  char named[64];
  std::snprintf(named, sizeof named, "body %p", static_cast<void*>(body));
  EXPECT_EQ(ssRegistry_Adopt(registry, kTunedStep, space, nullptr), SS_ERROR_OUT_OF_RANGE);
  EXPECT_NE(std::string(ssLastError()).find(named), std::string::npos) << ssLastError();
  EXPECT_NE(std::string(ssLastError()).find("1.5"), std::string::npos) << ssLastError();
  EXPECT_EQ(ssRegistry_TunedStep(registry), 0.0);
  dBodySetLinearDamping(body, 0);
  dJointSetHingeParam(hinge, dParamStopERP, 1.5);
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

TEST_F(AdoptTest, AtTheTunedStepEveryNumberIsTheProgramsOwnAtOthersItsRateInSeconds) {
  // Numbers whose round trip through k and c (or rates) is not exact in floating point.
  dWorldSetERP(world, 0.37);
  dWorldSetCFM(world, 3.3e-5);
  dWorldSetLinearDamping(world, 0.0013);
  dWorldSetAngularDamping(world, 0.0071);
  dWorldSetAutoDisableSteps(world, 10);  // "10 idle steps, no idle time"
  dWorldSetAutoDisableTime(world, 0);
  dWorldSetAutoDisableAverageSamplesCount(world, 7);
  dBodyID body = Body(0, 0, 1);  // copies the world's defaults
  dJointID hinge = dJointCreateHinge(world, 0);
  dJointAttach(hinge, body, 0);
  dJointSetHingeParam(hinge, dParamStopERP, 0.47);  // hard: cfm 0
  dJointSetHingeParam(hinge, dParamStopCFM, 0);
  dJointSetHingeParam(hinge, dParamCFM, 7.7e-3);  // the motor, a damper
  const double tuned_step = 1.0 / 47;            // no power of two
  ASSERT_EQ(ssRegistry_Adopt(registry, tuned_step, space, nullptr), SS_OK) << ssLastError();

  auto expect_as_tuned = [&](const char* when) {
    SCOPED_TRACE(when);
    EXPECT_EQ(dWorldGetERP(world), AsDReal(0.37));
    EXPECT_EQ(dWorldGetCFM(world), AsDReal(3.3e-5));
    EXPECT_EQ(dJointGetHingeParam(hinge, dParamStopERP), AsDReal(0.47));
    EXPECT_EQ(dJointGetHingeParam(hinge, dParamStopCFM), AsDReal(0.0));
    EXPECT_EQ(dJointGetHingeParam(hinge, dParamCFM), AsDReal(7.7e-3));
    EXPECT_EQ(dWorldGetLinearDamping(world), AsDReal(0.0013));
    EXPECT_EQ(dWorldGetAngularDamping(world), AsDReal(0.0071));
    EXPECT_EQ(dBodyGetLinearDamping(body), AsDReal(0.0013));
    EXPECT_EQ(dBodyGetAngularDamping(body), AsDReal(0.0071));
    EXPECT_EQ(dBodyGetAutoDisableSteps(body), 10);
    EXPECT_EQ(dBodyGetAutoDisableTime(body), 0.0);
    EXPECT_EQ(dBodyGetAutoDisableAverageSamplesCount(body), 7u);
    EXPECT_EQ(dWorldGetAutoDisableSteps(world), 10);
    EXPECT_EQ(dWorldGetAutoDisableTime(world), 0.0);
    EXPECT_EQ(dWorldGetAutoDisableAverageSamplesCount(world), 7u);
  };
  for (ssMapping mapping : {SS_MAPPING_IMPLICIT_EULER, SS_MAPPING_MATCHED, SS_MAPPING_EXACT}) {
    ASSERT_EQ(ssRegistry_Apply(registry, mapping, tuned_step, 0, nullptr), SS_OK) << ssLastError();
    // the accurate mappings have their own softness for soft rows; hard rows and bodies are theirs alike
    if (mapping == SS_MAPPING_IMPLICIT_EULER) expect_as_tuned("implicit Euler at the tuned step, first");
    EXPECT_EQ(dJointGetHingeParam(hinge, dParamStopERP), AsDReal(0.47)) << ssMappingName(mapping);
    EXPECT_EQ(dBodyGetAutoDisableTime(body), 0.0) << ssMappingName(mapping);
  }

  // Half the step: the rate-independent form (10 steps of h0 are 10 h0 seconds, whatever the step).
  const double h = tuned_step / 2;
  ASSERT_EQ(ssRegistry_Apply(registry, SS_MAPPING_IMPLICIT_EULER, h, 0, nullptr), SS_OK);
  EXPECT_READ_BACK(1 - dBodyGetLinearDamping(body), std::sqrt(1 - 0.0013), 1e-15);
  EXPECT_EQ(dBodyGetAutoDisableSteps(body), 20);
  EXPECT_READ_BACK(dBodyGetAutoDisableTime(body), 10 * tuned_step, 1e-15);
  EXPECT_EQ(dBodyGetAutoDisableAverageSamplesCount(body), 14u);
  const double rate = 0.47 / (tuned_step * (1 - 0.47));
  EXPECT_READ_BACK(dJointGetHingeParam(hinge, dParamStopERP), rate * h / (rate * h + 1), 1e-15);
  // k = erp/(h0 cfm), c = (1 - erp)/cfm written at h: erp = hk/(hk + c), cfm = 1/(hk + c)
  const double k = 0.37 / (tuned_step * 3.3e-5), c = (1 - 0.37) / 3.3e-5;
  EXPECT_READ_BACK(dWorldGetERP(world), h * k / (h * k + c), 1e-15);
  EXPECT_READ_BACK(dWorldGetCFM(world), 1 / (h * k + c), 1e-20);

  // Back at the tuned step, after another: the program's numbers again.
  ASSERT_EQ(ssRegistry_Apply(registry, SS_MAPPING_IMPLICIT_EULER, tuned_step, 0, nullptr), SS_OK);
  expect_as_tuned("implicit Euler at the tuned step, after half of it");
}

// The near callback of a program softening its contacts through the stepper, recording what it got.
struct ContactProbe {
  dWorldID world;
  dSpaceID space;
  dJointGroupID group;
  int mode;
  double soft_erp, soft_cfm;
  std::vector<dSurfaceParameters> softened;
};

struct ProbeContext {
  ContactProbe* probe;
  ssStepper* stepper;
};

void ProbeNearWithContext(void* data, dGeomID g1, dGeomID g2) {
  auto* context = static_cast<ProbeContext*>(data);
  ContactProbe* probe = context->probe;
  dContact contact[4];
  int count = dCollide(g1, g2, 4, &contact[0].geom, sizeof(dContact));
  for (int i = 0; i < count; ++i) {
    contact[i].surface = dSurfaceParameters{};
    contact[i].surface.mode = probe->mode;
    contact[i].surface.mu = 0.5;
    contact[i].surface.soft_erp = probe->soft_erp;
    contact[i].surface.soft_cfm = probe->soft_cfm;
    dBodyID b1 = dGeomGetBody(g1), b2 = dGeomGetBody(g2);
    EXPECT_EQ(ssStepper_SoftenContact(context->stepper, &contact[i], b1, b2), SS_OK) << ssLastError();
    probe->softened.push_back(contact[i].surface);
    dJointAttach(dJointCreateContact(probe->world, probe->group, &contact[i]), b1, b2);
  }
}

void ProbeCollide(void* context, ssStepper* stepper) {
  auto* probe = static_cast<ContactProbe*>(context);
  ProbeContext near = {probe, stepper};
  dSpaceCollide(probe->space, &near, ProbeNearWithContext);
}

TEST_F(AdoptTest, ContactsSoftenedAtTheFrozenTunedStepGetTheProgramsOwnNumbers) {
  dWorldSetGravity(world, 0, 0, -9.81);
  dWorldSetERP(world, 0.27);
  dCreatePlane(space, 0, 0, 1, 0);
  Body(0, 0, 0.049);  // resting on the plane, touching it
  const double tuned_step = 1.0 / 47;
  ASSERT_EQ(ssRegistry_Adopt(registry, tuned_step, space, nullptr), SS_OK) << ssLastError();
  ContactProbe probe = {world, space, dJointGroupCreate(0), 0, 0, 0, {}};
  ssStepperDef def = ssDefaultStepperDef();
  def.world = world;
  def.registry = registry;
  def.collide = ProbeCollide;
  def.collide_context = &probe;
  def.contact_group = probe.group;
  def.stepping.solver = SS_SOLVER_QUICK;
  ASSERT_EQ(ssSteppingForPolicy("naive", tuned_step, &def.stepping), SS_OK);
  ssStepper* stepper = nullptr;
  ASSERT_EQ(ssStepper_Create(&def, &stepper), SS_OK) << ssLastError();

  // soft CFM alone (ERP is the world's), and both soft; frames of the tuned step and of others: naive freezes the
  // softness at the tuned step, so every contact gets what the program set.
  struct Case {
    int mode;
    double erp, cfm;
  } cases[] = {{dContactSoftCFM, 0, 1.3e-4}, {dContactSoftERP | dContactSoftCFM, 0.41, 2.9e-3}};
  for (const Case& c : cases) {
    probe.mode = c.mode;
    probe.soft_erp = c.erp;
    probe.soft_cfm = c.cfm;
    for (double frame_s : {tuned_step, 1.0 / 30, 1.0 / 120}) {
      probe.softened.clear();
      ASSERT_EQ(ssStepper_Step(stepper, frame_s, nullptr), SS_OK) << ssLastError();
      ASSERT_FALSE(probe.softened.empty());
      for (const dSurfaceParameters& surface : probe.softened) {
        EXPECT_EQ(surface.soft_erp, AsDReal((c.mode & dContactSoftERP) ? c.erp : 0.27)) << frame_s;
        EXPECT_EQ(surface.soft_cfm, AsDReal(c.cfm)) << frame_s;
      }
    }
  }

  // Frozen at another step than the tuned one is refused by name: the tuned numbers mean their softness at the tuned
  // step alone, so a second step could only disagree with it (naive would no longer be the program's stepping).
  ssStepping other = ssStepper_Stepping(stepper);
  other.frozen_step_s = tuned_step / 2;
  EXPECT_EQ(ssStepper_SetStepping(stepper, &other), SS_ERROR_OUT_OF_RANGE);
  EXPECT_NE(std::string(ssLastError()).find("not the tuned step"), std::string::npos) << ssLastError();
  EXPECT_EQ(ssStepper_Stepping(stepper).frozen_step_s, tuned_step);
  // At another step, unfrozen, the rate-independent form: what the tuned numbers stand for at that step.
  ASSERT_EQ(ssSteppingForPolicy("implicit-euler", 0, &other), SS_OK);
  ASSERT_EQ(ssStepper_SetStepping(stepper, &other), SS_OK) << ssLastError();
  probe.softened.clear();
  ASSERT_EQ(ssStepper_Step(stepper, tuned_step / 2, nullptr), SS_OK) << ssLastError();
  ASSERT_FALSE(probe.softened.empty());
  const double h = tuned_step / 2, k = 0.41 / (tuned_step * 2.9e-3), c = (1 - 0.41) / 2.9e-3;
  EXPECT_READ_BACK(probe.softened[0].soft_erp, h * k / (h * k + c), 1e-15);
  EXPECT_READ_BACK(probe.softened[0].soft_cfm, 1 / (h * k + c), 1e-18);
  ssStepper_Destroy(stepper);
  dJointGroupDestroy(probe.group);
}

TEST_F(AdoptTest, AutoDisableSamplesWrittenAreBoundedAndAProgramThatNeverSamplesKeepsNot) {
  dWorldSetAutoDisableFlag(world, 1);
  dWorldSetAutoDisableSteps(world, 20);
  dWorldSetAutoDisableAverageSamplesCount(world, 5);  // a window of 5 samples of 1/60 s
  dBodyID sampled = Body(0, 0, 1);
  dBodyID never = Body(1, 0, 1);
  dBodySetAutoDisableAverageSamplesCount(never, 0);  // ODE never samples it: it never sleeps
  dBodyID by_hand = MakeBody(1.0, 2, 0, 1);           // no geom: bound by hand
  ASSERT_EQ(ssRegistry_Adopt(registry, kTunedStep, space, nullptr), SS_OK) << ssLastError();
  ASSERT_EQ(ssRegistry_BindAutoDisable(registry, by_hand, 0.5, 5 * kTunedStep), SS_OK) << ssLastError();

  // 1 ns: the window would take ceil(5/60 s / 1e-9 s) = 83,333,334 samples (5 GB a body).
  ASSERT_EQ(ssRegistry_Apply(registry, SS_MAPPING_IMPLICIT_EULER, 1e-9, 0, nullptr), SS_OK) << ssLastError();
  EXPECT_EQ(dBodyGetAutoDisableAverageSamplesCount(sampled), (unsigned)SS_MAX_AVERAGE_SAMPLES);
  EXPECT_EQ(dBodyGetAutoDisableAverageSamplesCount(by_hand), (unsigned)SS_MAX_AVERAGE_SAMPLES);
  EXPECT_EQ(dWorldGetAutoDisableAverageSamplesCount(world), (unsigned)SS_MAX_AVERAGE_SAMPLES);
  EXPECT_EQ(dBodyGetAutoDisableAverageSamplesCount(never), 0u);
  // ODE steps the bodies with their buffers
  EXPECT_EQ(dWorldQuickStep(world, 1e-9), 1);
  // within the bound, the window in seconds: 5 samples of 1/60 s are 10 of 1/120 s
  ASSERT_EQ(ssRegistry_Apply(registry, SS_MAPPING_IMPLICIT_EULER, kTunedStep / 2, 0, nullptr), SS_OK);
  EXPECT_EQ(dBodyGetAutoDisableAverageSamplesCount(sampled), 10u);
  EXPECT_EQ(dBodyGetAutoDisableAverageSamplesCount(by_hand), 10u);
  EXPECT_EQ(dBodyGetAutoDisableAverageSamplesCount(never), 0u);
}

// What a program bound by hand before adopting, observable through what Apply writes at a step.
struct HandBindings {
  ssSpring world_spring{2000.0, 30.0};
  ssSpring joint_spring{500.0, 4.0};
  double world_damping_rate = 0.7, body_idle_s = 0.4;
};

TEST_F(AdoptTest, ARefusedAdoptionLeavesEveryEarlierBinding) {
  const HandBindings hand;
  dBodyID body = Body(0, 0, 1);
  dJointID ball = dJointCreateBall(world, 0);
  dJointAttach(ball, body, 0);
  ASSERT_EQ(ssRegistry_BindWorld(registry, hand.world_spring, 0), SS_OK) << ssLastError();
  ASSERT_EQ(ssRegistry_BindJoint(registry, ball, SS_PARAM_JOINT, 1, hand.joint_spring, 0), SS_OK);
  ASSERT_EQ(ssRegistry_BindDamping(registry, 0, hand.world_damping_rate, 0), SS_OK);
  ASSERT_EQ(ssRegistry_BindAutoDisable(registry, body, hand.body_idle_s, 0), SS_OK);

  const double h = 1.0 / 100;
  auto expect_hand_bindings = [&](const char* after) {
    SCOPED_TRACE(after);
    EXPECT_EQ(ssRegistry_TunedStep(registry), 0.0);
    EXPECT_EQ(ssRegistry_JointBindingCount(registry), 1);
    ASSERT_EQ(ssRegistry_Apply(registry, SS_MAPPING_IMPLICIT_EULER, h, 0, nullptr), SS_OK) << ssLastError();
    const double kw = hand.world_spring.stiffness, cw = hand.world_spring.damping;
    EXPECT_READ_BACK(dWorldGetERP(world), h * kw / (h * kw + cw), 1e-15);
    EXPECT_READ_BACK(dWorldGetCFM(world), 1 / (h * kw + cw), 1e-18);
    const double kj = hand.joint_spring.stiffness, cj = hand.joint_spring.damping;
    EXPECT_READ_BACK(dJointGetBallParam(ball, dParamERP), h * kj / (h * kj + cj), 1e-15);
    EXPECT_READ_BACK(dWorldGetLinearDamping(world), 1 - std::exp(-hand.world_damping_rate * h), 1e-15);
    EXPECT_EQ(dBodyGetAutoDisableSteps(body), 40);
    EXPECT_READ_BACK(dBodyGetAutoDisableTime(body), hand.body_idle_s, 1e-15);
    // an Apply at another step tells the next check apart from a leftover
    ASSERT_EQ(ssRegistry_Apply(registry, SS_MAPPING_IMPLICIT_EULER, 2 * h, 0, nullptr), SS_OK);
  };
  expect_hand_bindings("binding by hand");

  // One bad value anywhere refuses the adoption: a joint row's, a body's, the world's.
  dJointID hinge = dJointCreateHinge(world, 0);
  dJointAttach(hinge, body, 0);
  dJointSetHingeParam(hinge, dParamStopERP, 1.5);
  EXPECT_EQ(ssRegistry_Adopt(registry, kTunedStep, space, nullptr), SS_ERROR_OUT_OF_RANGE);
  EXPECT_NE(std::string(ssLastError()).find("erp = 1.5"), std::string::npos) << ssLastError();
  expect_hand_bindings("a refused joint row");
  dJointSetHingeParam(hinge, dParamStopERP, 0.5);

  dBodyID damped = Body(1, 0, 1);
  dBodySetLinearDamping(damped, 1.0);  // removes all velocity: no rate
  EXPECT_EQ(ssRegistry_Adopt(registry, kTunedStep, space, nullptr), SS_ERROR_OUT_OF_RANGE);
  EXPECT_NE(std::string(ssLastError()).find("damping scale = 1"), std::string::npos) << ssLastError();
  expect_hand_bindings("a refused body");
  dBodySetLinearDamping(damped, 0);

  dWorldSetAutoDisableTime(world, -1);
  EXPECT_EQ(ssRegistry_AdoptWorld(registry, kTunedStep, nullptr), SS_ERROR_OUT_OF_RANGE);
  EXPECT_NE(std::string(ssLastError()).find("world auto-disable time = -1"), std::string::npos) << ssLastError();
  expect_hand_bindings("a refused world");
  dWorldSetAutoDisableTime(world, 0);

  // Now valid: adopted, the rows and bodies already bound keeping their bindings.
  ssAdoptReport report = {};
  ASSERT_EQ(ssRegistry_Adopt(registry, kTunedStep, space, &report), SS_OK) << ssLastError();
  EXPECT_EQ(report.world, 1);
  EXPECT_EQ(report.bodies, 1);  // `damped`: `body` was bound by hand
  const double kj = hand.joint_spring.stiffness, cj = hand.joint_spring.damping;
  ASSERT_EQ(ssRegistry_Apply(registry, SS_MAPPING_IMPLICIT_EULER, h, 0, nullptr), SS_OK) << ssLastError();
  EXPECT_READ_BACK(dJointGetBallParam(ball, dParamERP), h * kj / (h * kj + cj), 1e-15);
  EXPECT_EQ(dBodyGetAutoDisableSteps(body), 40);
}

TEST_F(AdoptTest, ObjectsOfAnotherWorldAreRefusedByName) {
  dWorldID other = dWorldCreate();
  Body(0, 0, 1);
  dBodyID foreign = dBodyCreate(other);
  dBodyID foreign_too = dBodyCreate(other);
  dJointID foreign_ball = dJointCreateBall(other, 0);
  dJointAttach(foreign_ball, foreign, foreign_too);
  auto expect_named = [&](ssStatus status, const char* call) {
    EXPECT_EQ(status, SS_ERROR_OUT_OF_RANGE) << call;
    const std::string message = ssLastError();
    EXPECT_NE(message.find("is of world"), std::string::npos) << call << ": " << message;
    EXPECT_NE(message.find("not of the registry's world"), std::string::npos) << call << ": " << message;
  };
  expect_named(ssRegistry_BindJoint(registry, foreign_ball, SS_PARAM_JOINT, 1, {100, 1}, 0), "BindJoint");
  expect_named(ssRegistry_BindDamping(registry, foreign, 0.1, 0.1), "BindDamping");
  expect_named(ssRegistry_BindAutoDisable(registry, foreign, 1, 0), "BindAutoDisable");
  EXPECT_EQ(ssRegistry_JointBindingCount(registry), 0);

  // a geom of the space carrying a body of the other world: the whole adoption is refused, nothing is bound
  dGeomID stray = dCreateSphere(space, 0.1);
  dGeomSetBody(stray, foreign);
  expect_named(ssRegistry_Adopt(registry, kTunedStep, space, nullptr), "Adopt");
  EXPECT_EQ(ssRegistry_TunedStep(registry), 0.0);
  dGeomSetBody(stray, 0);
  // (a joint between bodies of two worlds cannot be made: dJointAttach aborts the process)
  ASSERT_EQ(ssRegistry_Adopt(registry, kTunedStep, space, nullptr), SS_OK) << ssLastError();
  expect_named(ssRegistry_AdoptBody(registry, foreign, nullptr), "AdoptBody");
  expect_named(ssRegistry_AdoptJoint(registry, foreign_ball, nullptr), "AdoptJoint");
  EXPECT_EQ(ssRegistry_JointBindingCount(registry), 0);

  // a registry of this world given to a stepper of the other
  ssStepperDef def = ssDefaultStepperDef();
  def.world = other;
  def.registry = registry;
  def.stepping.solver = SS_SOLVER_QUICK;
  ssStepper* stepper = nullptr;
  EXPECT_EQ(ssStepper_Create(&def, &stepper), SS_ERROR_OUT_OF_RANGE);
  EXPECT_EQ(stepper, nullptr);
  EXPECT_NE(std::string(ssLastError()).find("registry of world"), std::string::npos) << ssLastError();
  dWorldDestroy(other);
}

}  // namespace

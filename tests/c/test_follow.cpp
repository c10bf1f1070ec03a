// The program stays in charge of what it tuned: values it writes into ODE after adoption (world ERP/CFM, a joint's
// stop ERP/CFM, a body's damping) are taken as newly tuned, the same way at every frame length. The truth, stated
// on its own: the article's conversion of the program's last numbers, tuned at h0, to each step's h.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "ode_fixture.h"
#include "precision.h"
#include "test_stepping.h"
#include "steadystep/steadystep.h"

namespace {

const double kTunedStep = 1.0 / 60;

// What erp and cfm tuned at h0 mean at a step of h: the same spring, k = erp/(h0·cfm), c = (1 - erp)/cfm.
void SoftnessAt(double erp, double cfm, double h, double* erp_h, double* cfm_h) {
  if (h == kTunedStep) {  // at the tuned step, the program's own numbers
    *erp_h = erp, *cfm_h = cfm;
    return;
  }
  const double k = erp / (kTunedStep * cfm), c = (1 - erp) / cfm;
  *erp_h = h * k / (h * k + c);
  *cfm_h = 1 / (h * k + c);
}

// A damping scale tuned per step of h0, at a step of h: the same fraction removed per second.
double DampingAt(double scale, double h) {
  return h == kTunedStep ? scale : -std::expm1(std::log1p(-scale) / kTunedStep * h);
}

struct Settings {  // what the program writes from its settings
  double world_erp, world_cfm, stop_erp, stop_cfm, damping;
};

class FollowTest : public OdeTest {
 public:  // the callbacks below reach the program's world through it
  void SetUp() override {
    OdeTest::SetUp();
    space = dSimpleSpaceCreate(0);
    arm = MakeBody(1.0, 0, 0, 1);
    dGeomSetBody(dCreateBox(space, 0.1, 0.1, 0.1), arm);
    hinge = dJointCreateHinge(world, 0);
    dJointAttach(hinge, arm, 0);
    dJointSetHingeAnchor(hinge, 0, 0, 1.2);
    dJointSetHingeAxis(hinge, 0, 1, 0);
    dJointSetHingeParam(hinge, dParamLoStop, -0.1);
    dJointSetHingeParam(hinge, dParamHiStop, 0.1);
    Write({0.2, 1e-5, 0.3, 1e-4, 0.01});
  }
  void TearDown() override {
    ssStepper_Destroy(stepper);
    dSpaceDestroy(space);
    OdeTest::TearDown();
  }

  void Write(const Settings& s) {
    dWorldSetERP(world, s.world_erp);
    dWorldSetCFM(world, s.world_cfm);
    dJointSetHingeParam(hinge, dParamStopERP, s.stop_erp);
    dJointSetHingeParam(hinge, dParamStopCFM, s.stop_cfm);
    dBodySetLinearDamping(arm, s.damping);
  }

  // What ODE must hold at a step of h after the program last wrote s.
  void ExpectHeld(const Settings& s, double h, const std::string& where) {
    double erp, cfm;
    SoftnessAt(s.world_erp, s.world_cfm, h, &erp, &cfm);
    EXPECT_NEAR(dWorldGetERP(world), erp, ReadBackTolerance(1e-13, erp)) << where;
    EXPECT_NEAR(dWorldGetCFM(world), cfm, ReadBackTolerance(1e-13 * cfm, cfm)) << where;
    SoftnessAt(s.stop_erp, s.stop_cfm, h, &erp, &cfm);
    EXPECT_NEAR(dJointGetHingeParam(hinge, dParamStopERP), erp, ReadBackTolerance(1e-13, erp)) << where;
    EXPECT_NEAR(dJointGetHingeParam(hinge, dParamStopCFM), cfm, ReadBackTolerance(1e-13 * cfm, cfm)) << where;
    EXPECT_NEAR(dBodyGetLinearDamping(arm), DampingAt(s.damping, h), ReadBackTolerance(1e-13, s.damping)) << where;
  }

  ssStatus Make(ssStepCallback* before_step, void* context) {
    ssStepperDef def = TestStepperDef();
    def.world = world;
    def.space = space;
    def.tuned_step_s = kTunedStep;
    def.before_step = before_step;
    def.before_step_context = context;
    return ssStepper_Create(&def, &stepper);
  }

  dSpaceID space = nullptr;
  dBodyID arm = nullptr;
  dJointID hinge = nullptr;
  ssStepper* stepper = nullptr;
};

// The program writes its settings every frame (some frames new ones, some the same again), at frames alternating
// 1/50 and 1/60 s: at every step ODE holds what its last settings mean for that step's length.
TEST_F(FollowTest, ValuesWrittenEveryFrameAreFollowedAtEveryFrameLength) {
  struct Probe {
    FollowTest* test;
    Settings last;
    int checked = 0;
  } probe{this, {0.2, 1e-5, 0.3, 1e-4, 0.01}};
  ASSERT_EQ(Make(
                [](void* context, ssStepper* s) {  // Apply ran for this step: ODE holds what the step uses
                  auto* p = static_cast<Probe*>(context);
                  ssStepInfo step = ssStepper_CurrentStep(s);
                  p->test->ExpectHeld(p->last, step.step_s, "step at " + std::to_string(step.time_s) + " s");
                  p->checked += 1;
                },
                &probe),
            SS_OK)
      << ssLastError();
  for (int frame = 0; frame < 40; ++frame) {
    if (frame % 4 != 3) {  // three frames of four the program writes; one it writes nothing
      Settings s = {0.2 + 0.5 * (frame % 7) / 7, 1e-5 * (1 + frame % 5), 0.3 + 0.05 * (frame % 3),
                    1e-4 * (1 + 0.5 * (frame % 4)), 0.01 + 0.002 * (frame % 6)};
      if (frame % 8 == 5) s = probe.last;  // the same settings again
      Write(s);
      probe.last = s;
    }
    ssFrameReport report;
    ASSERT_EQ(ssStepper_Step(stepper, frame % 2 ? 1.0 / 60 : 1.0 / 50, &report), SS_OK) << ssLastError();
    EXPECT_EQ(report.steps, 1);
    if (frame % 4 == 3) {
      EXPECT_EQ(report.program_writes, 0) << frame;
    } else if (frame > 0) {
      EXPECT_GT(report.program_writes, 0) << frame;
    }
  }
  EXPECT_EQ(probe.checked, 40);
}

// At steps that keep one length, other than the tuned step, a body's damping the program writes is followed and
// written for that length before the next step (Apply passes only the bindings changed since its last write).
TEST_F(FollowTest, ABodysWriteAtAnUnchangedStepIsWrittenForThatStep) {
  ASSERT_EQ(Make(nullptr, nullptr), SS_OK) << ssLastError();
  for (int frame = 0; frame < 6; ++frame) {
    if (frame == 3) dBodySetLinearDamping(arm, 0.05);
    ssFrameReport report;
    ASSERT_EQ(ssStepper_Step(stepper, 1.0 / 120, &report), SS_OK) << ssLastError();
    ASSERT_EQ(report.steps, 1);
    EXPECT_EQ(report.program_writes, frame == 3 ? 1 : 0) << frame;
    double damping = frame >= 3 ? 0.05 : 0.01;
    EXPECT_NEAR(dBodyGetLinearDamping(arm), DampingAt(damping, 1.0 / 120), ReadBackTolerance(1e-13, damping)) << frame;
  }
}

// Under naive (the softness frozen at the tuned step) a body's damping the program writes stays in ODE as written,
// unread: Apply writes nothing over it. When the stepping changes, it is followed before Apply writes for the new
// step: the damping then holds what the program's last value means at that step.
TEST_F(FollowTest, UnderNaiveABodysWriteStaysAsWrittenAndIsFollowedWhenTheSteppingChanges) {
  ASSERT_EQ(Make(nullptr, nullptr), SS_OK) << ssLastError();
  ssStepping stepping = ssStepper_Stepping(stepper);
  ASSERT_EQ(ssSteppingForPolicy("naive", kTunedStep, &stepping), SS_OK);
  ASSERT_EQ(ssStepper_SetStepping(stepper, &stepping), SS_OK) << ssLastError();
  ASSERT_EQ(ssStepper_Step(stepper, 1.0 / 50, nullptr), SS_OK) << ssLastError();
  dBodySetLinearDamping(arm, 0.03);
  for (int frame = 0; frame < 5; ++frame) {
    ASSERT_EQ(ssStepper_Step(stepper, frame % 2 ? 1.0 / 60 : 1.0 / 50, nullptr), SS_OK) << ssLastError();
    EXPECT_EQ(dBodyGetLinearDamping(arm), AsDReal(0.03)) << frame;
  }
  ASSERT_EQ(ssSteppingForPolicy("implicit-euler", kTunedStep, &stepping), SS_OK);
  ASSERT_EQ(ssStepper_SetStepping(stepper, &stepping), SS_OK) << ssLastError();
  ssFrameReport report;
  ASSERT_EQ(ssStepper_Step(stepper, 1.0 / 120, &report), SS_OK) << ssLastError();
  EXPECT_GE(report.program_writes, 1);
  EXPECT_NEAR(dBodyGetLinearDamping(arm), DampingAt(0.03, 1.0 / 120), ReadBackTolerance(1e-13, 0.03));
}

// A value the program writes in a callback is taken before the next step; one no spring stands for refuses the
// frame by name, with nothing stepped, until the program writes another.
TEST_F(FollowTest, AValueWrittenInACallbackIsTakenBeforeTheNextStepAndABadOneRefusedByName) {
  struct Probe {
    FollowTest* test;
    int calls = 0;
  } probe{this};
  ASSERT_EQ(Make(
                [](void* context, ssStepper* s) {
                  auto* p = static_cast<Probe*>(context);
                  ssStepInfo step = ssStepper_CurrentStep(s);
                  if (++p->calls == 1) p->test->Write({0.6, 2e-5, 0.4, 3e-4, 0.02});  // in step 1 of 3
                  if (p->calls == 2) p->test->ExpectHeld({0.6, 2e-5, 0.4, 3e-4, 0.02}, step.step_s, "step 2");
                },
                &probe),
            SS_OK)
      << ssLastError();
  ssFrameReport report;
  ASSERT_EQ(ssStepper_Step(stepper, 0.05, &report), SS_OK) << ssLastError();  // three steps of 1/60 s
  EXPECT_EQ(report.steps, 3);
  EXPECT_EQ(report.program_writes, 3);  // the world's rows, the stop, the body's damping

  const dReal* p = dBodyGetPosition(arm);
  const dReal before[3] = {p[0], p[1], p[2]};
  dJointSetHingeParam(hinge, dParamStopERP, 1.5);  // no spring has erp above 1
  EXPECT_EQ(ssStepper_Step(stepper, 0.05, &report), SS_ERROR_OUT_OF_RANGE);
  EXPECT_NE(std::string(ssLastError()).find("stop axis 1, as the program wrote it"), std::string::npos)
      << ssLastError();
  EXPECT_EQ(report.steps, 0);
  EXPECT_EQ(p[0], before[0]);
  EXPECT_EQ(ssStepper_Step(stepper, 0.05, &report), SS_ERROR_OUT_OF_RANGE);  // until the program writes another
  dJointSetHingeParam(hinge, dParamStopERP, 0.5);
  EXPECT_EQ(ssStepper_Step(stepper, 0.05, &report), SS_OK) << ssLastError();
  EXPECT_EQ(report.program_writes, 1);
}

}  // namespace

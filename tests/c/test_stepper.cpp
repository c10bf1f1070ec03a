// The stepper: how frames become steps under each policy, what the callbacks are handed, refusals that leave the
// world as it was, blow-up and speed checks, and the Nyquist report.
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "test_stepping.h"
#include "ode_fixture.h"
#include "oscillator_rig.h"
#include "precision.h"

namespace {

class StepperTest : public OdeTest {};

TEST_F(StepperTest, FramesAreSplitIntoEqualSubstepsNoLongerThanTheMaximum) {
  OscillatorRig rig;
  ASSERT_EQ(rig.Build(), SS_OK);  // max_step_s = 1/60
  struct Case {
    double frame_s;
    int steps;
  } cases[] = {{1.0 / 60.0, 1}, {2.0 / 60.0, 2}, {0.05, 3}, {1.0 / 144.0, 1}, {0.1 + 0.2, 18}};
  double previous_step_s = 0;
  for (const Case& c : cases) {
    ssFrameReport report;
    ASSERT_EQ(ssStepper_Step(rig.stepper, c.frame_s, &report), SS_OK);
    EXPECT_EQ(report.steps, c.steps) << c.frame_s;
    EXPECT_NEAR(report.step_s, c.frame_s / c.steps, 1e-15);
    EXPECT_NEAR(report.simulated_s, c.frame_s, 1e-15);
    EXPECT_EQ(report.rows.by_mapping, c.steps);  // the one bound row, counted once per step it served
    EXPECT_EQ(report.rows.handed_to_matched + report.rows.handed_to_implicit_euler, 0);
    // the implicit-Euler mapping is written once a frame, and only where the step length changed
    EXPECT_EQ(report.row_writes, report.step_s != previous_step_s ? 1 : 0) << c.frame_s;
    previous_step_s = report.step_s;
  }
}

TEST_F(StepperTest, NaiveTakesOneStepWithSoftnessFrozenAtTheReference) {
  OscillatorRig rig;
  ssSteppingForPolicy("naive", 1.0 / 30, &rig.def.stepping);
  ASSERT_EQ(rig.Build(), SS_OK);
  ssSoftness reference;
  ASSERT_EQ(ssImplicitEulerSoftness(rig.spring, 1.0 / 30.0, &reference), SS_OK);
  for (double frame_s : {1.0 / 15.0, 1.0 / 45.0}) {
    ssFrameReport report;
    ASSERT_EQ(ssStepper_Step(rig.stepper, frame_s, &report), SS_OK);
    EXPECT_EQ(report.steps, 1);
    EXPECT_DOUBLE_EQ(report.step_s, frame_s);
    EXPECT_DOUBLE_EQ(dJointGetSliderParam(rig.slider, dParamStopERP), AsDReal(reference.erp));
    EXPECT_DOUBLE_EQ(dJointGetSliderParam(rig.slider, dParamStopCFM), AsDReal(reference.cfm));
  }
}

TEST_F(StepperTest, FixedStepsFromAnAccumulatorWithInterpolationAndACap) {
  OscillatorRig rig;
  ssSteppingForPolicy("fixed", 1.0 / 30, &rig.def.stepping);
  rig.def.stepping.fixed_step_s = 0.01;
  rig.def.stepping.max_steps_per_frame = 4;
  ASSERT_EQ(rig.Build(), SS_OK);
  ssFrameReport report;
  ASSERT_EQ(ssStepper_Step(rig.stepper, 0.025, &report), SS_OK);
  EXPECT_EQ(report.steps, 2);
  EXPECT_NEAR(report.interpolation, 0.5, 1e-9);
  ASSERT_EQ(ssStepper_Step(rig.stepper, 0.006, &report), SS_OK);  // 0.005 + 0.006 in the accumulator
  EXPECT_EQ(report.steps, 1);
  EXPECT_NEAR(report.interpolation, 0.1, 1e-9);
  EXPECT_EQ(report.dropped_s, 0);
  ASSERT_EQ(ssStepper_Step(rig.stepper, 0.004, &report), SS_OK);
  EXPECT_EQ(report.steps, 0);
  EXPECT_NEAR(report.interpolation, 0.5, 1e-9);
  // A one-second hitch: four steps, the rest dropped rather than spiralling.
  ASSERT_EQ(ssStepper_Step(rig.stepper, 1.0, &report), SS_OK);
  EXPECT_EQ(report.steps, 4);
  EXPECT_NEAR(report.dropped_s, 0.96, 1e-9);
  EXPECT_GE(report.interpolation, 0.0);
  EXPECT_LT(report.interpolation, 1.0);
  for (double h : rig.h) EXPECT_DOUBLE_EQ(h, 0.01);
}

TEST_F(StepperTest, BadFramesAreRefusedAndTheWorldIsLeftAsItWas) {
  OscillatorRig rig;
  ASSERT_EQ(rig.Build(), SS_OK);
  const double x = dJointGetSliderPosition(rig.slider);
  for (double frame_s : {double(NAN), double(INFINITY), -0.01, -double(INFINITY)}) {
    ssFrameReport report;
    ssStatus status = ssStepper_Step(rig.stepper, frame_s, &report);
    EXPECT_NE(status, SS_OK) << frame_s;
    EXPECT_NE(std::string(ssLastError()).find("frame_s"), std::string::npos) << ssLastError();
    EXPECT_EQ(report.steps, 0);
  }
  ssFrameReport report;
  EXPECT_EQ(ssStepper_Step(rig.stepper, 0.0, &report), SS_OK);
  EXPECT_EQ(report.steps, 0);
  EXPECT_EQ(dJointGetSliderPosition(rig.slider), x);
  EXPECT_TRUE(rig.x.empty());
}

TEST_F(StepperTest, CreateRefusesBadDefinitionsNamingTheField) {
  dWorldID other = dWorldCreate();
  struct Case {
    void (*change)(ssStepperDef*);
    ssStatus status;
    const char* named;
  } cases[] = {
      {[](ssStepperDef* d) { d->world = nullptr; }, SS_ERROR_OUT_OF_RANGE, "world"},
      {[](ssStepperDef* d) { d->stepping.max_step_s = 0; }, SS_ERROR_OUT_OF_RANGE, "max_step_s = 0"},
      {[](ssStepperDef* d) { d->stepping.max_step_s = NAN; }, SS_ERROR_NOT_FINITE, "max_step_s"},
      {[](ssStepperDef* d) { d->stepping.frozen_step_s = -2; }, SS_ERROR_OUT_OF_RANGE, "frozen_step_s = -2"},
      {[](ssStepperDef* d) { d->stepping.frozen_step_s = SS_FROZEN_AT_TUNED_STEP; }, SS_ERROR_OUT_OF_RANGE,
       "frozen_step_s = the tuned step, but there is no tuned step"},
      {[](ssStepperDef* d) { d->tuned_step_s = 1.0 / 60; d->stepping.frozen_step_s = 1.0 / 30; },
       SS_ERROR_OUT_OF_RANGE, "frozen_step_s = 0.033333333333333333 s: not the tuned step 0.016666666666666666 s"},
      {[](ssStepperDef* d) { d->stepping.fixed_step_s = INFINITY; }, SS_ERROR_NOT_FINITE, "fixed_step_s"},
      {[](ssStepperDef* d) { d->stepping.quick_iterations = -1; }, SS_ERROR_OUT_OF_RANGE, "quick_iterations = -1"},
      {[](ssStepperDef* d) { d->stepping.max_step_s = 1e-12; }, SS_ERROR_OUT_OF_RANGE, "max_step_s = 1e-12"},
      {[](ssStepperDef* d) { d->stepping.max_angular_speed = -1; }, SS_ERROR_OUT_OF_RANGE, "max_angular_speed = -1"},
      {[](ssStepperDef* d) { d->stepping.max_steps_per_frame = -3; }, SS_ERROR_OUT_OF_RANGE, "max_steps_per_frame = -3"},
      {[](ssStepperDef* d) { d->stepping.max_speed = -1; }, SS_ERROR_OUT_OF_RANGE, "max_speed = -1"},
      {[](ssStepperDef* d) { d->stepping.cut = (ssFrameCut)42; }, SS_ERROR_UNSUPPORTED, "cut = 42"},
      {[](ssStepperDef* d) { d->stepping.solver = (ssSolver)7; }, SS_ERROR_UNSUPPORTED, "solver = 7"},
      {[](ssStepperDef* d) { d->stepping.solver = SS_SOLVER_UNSET; }, SS_ERROR_UNSUPPORTED, "solver = unset"},
      {[](ssStepperDef* d) { d->stepping.fixed_step_s = 0; d->stepping.cut = SS_CUT_FIXED; }, SS_ERROR_OUT_OF_RANGE,
       "fixed_step_s = 0 s (the tuned step)"},
      {[](ssStepperDef* d) { d->space = (dSpaceID)1; }, SS_ERROR_OUT_OF_RANGE, "tuned_step_s = 0 s: with a space"},
      {[](ssStepperDef* d) { d->tuned_step_s = -1; }, SS_ERROR_OUT_OF_RANGE, "tuned_step_s = -1"},
  };
  for (const Case& c : cases) {
    ssStepperDef def = TestStepperDef();
    def.world = other;
    c.change(&def);
    ssStepper* stepper = nullptr;
    EXPECT_EQ(ssStepper_Create(&def, &stepper), c.status) << c.named;
    EXPECT_EQ(stepper, nullptr);
    EXPECT_NE(std::string(ssLastError()).find(c.named), std::string::npos) << ssLastError();
  }
  dWorldDestroy(other);
}

TEST_F(StepperTest, PoliciesArePresetsOfCutAndMappingNamedByTheLibrary) {
  ASSERT_EQ(ssSteppingPolicyCount(), 8);
  for (int i = 0; i < ssSteppingPolicyCount(); ++i) {
    ssStepping stepping = TestStepping();
    ASSERT_EQ(ssSteppingForPolicy(ssSteppingPolicyNameAt(i), 1.0 / 60, &stepping), SS_OK);
    EXPECT_STREQ(ssSteppingPolicyName(&stepping), ssSteppingPolicyNameAt(i));
    EXPECT_EQ(ssValidateStepping(&stepping), SS_OK);
  }
  EXPECT_EQ(ssSteppingPolicyNameAt(ssSteppingPolicyCount()), nullptr);
  ssStepping stepping = TestStepping();
  const ssStepping before = stepping;
  EXPECT_EQ(ssSteppingForPolicy("smooth", 1.0 / 60, &stepping), SS_ERROR_PARSE);
  EXPECT_NE(std::string(ssLastError()).find("smooth"), std::string::npos);
  EXPECT_NE(std::string(ssLastError()).find("fixed-exact"), std::string::npos);  // the known names, listed
  EXPECT_EQ(ssSteppingForPolicy("naive", -1, &stepping), SS_ERROR_OUT_OF_RANGE);
  EXPECT_EQ(ssSteppingForPolicy("substeps-frozen", 1e-12, &stepping), SS_ERROR_OUT_OF_RANGE);
  EXPECT_EQ(std::memcmp(&before, &stepping, sizeof stepping), 0);
  // 0: frozen at the stepper's tuned step, whatever it is; one stepper with a tuned step takes no other
  ASSERT_EQ(ssSteppingForPolicy("naive", 0, &stepping), SS_OK);
  EXPECT_EQ(stepping.frozen_step_s, SS_FROZEN_AT_TUNED_STEP);
  EXPECT_STREQ(ssSteppingPolicyName(&stepping), "naive");
  ssStepperDef def = TestStepperDef();
  def.world = world;
  def.stepping = stepping;
  def.tuned_step_s = 1.0 / 47;
  ssStepper* stepper = nullptr;
  ASSERT_EQ(ssStepper_Create(&def, &stepper), SS_OK) << ssLastError();
  EXPECT_EQ(ssStepper_Stepping(stepper).frozen_step_s, 1.0 / 47);
  ssStepper_Destroy(stepper);
  // The control: implicit-euler's cut with naive's frozen softness.
  ssStepping control = TestStepping();
  ASSERT_EQ(ssSteppingForPolicy("substeps-frozen", 1.0 / 30, &control), SS_OK);
  EXPECT_EQ(control.cut, SS_CUT_SUBSTEPS);
  EXPECT_EQ(control.mapping, SS_MAPPING_IMPLICIT_EULER);
  EXPECT_DOUBLE_EQ(control.frozen_step_s, 1.0 / 30);
  // Every combination of cut and mapping is a valid stepping; whole-frame matched is no preset.
  stepping.cut = SS_CUT_WHOLE_FRAME;
  stepping.mapping = SS_MAPPING_MATCHED;
  EXPECT_EQ(ssValidateStepping(&stepping), SS_OK);
  EXPECT_EQ(ssSteppingPolicyName(&stepping), nullptr);
}

TEST_F(StepperTest, FixedStepsWithTheExactMappingCarryTheirHistory) {
  OscillatorRig rig;
  ASSERT_EQ(ssSteppingForPolicy("fixed-exact", 1.0 / 30, &rig.def.stepping), SS_OK);
  rig.def.stepping.fixed_step_s = 0.01;
  ASSERT_EQ(rig.Build(), SS_OK);
  ssFrameReport report;
  for (double frame_s : {0.025, 0.013, 0.031}) ASSERT_EQ(ssStepper_Step(rig.stepper, frame_s, &report), SS_OK);
  for (double h : rig.h) EXPECT_DOUBLE_EQ(h, 0.01);
  ssStepInfo last = ssStepper_CurrentStep(rig.stepper);
  EXPECT_EQ(last.mapping, SS_MAPPING_EXACT);
  EXPECT_DOUBLE_EQ(last.previous_step_s, 0.01);  // fixed steps keep the exact mapping's history
}

struct CallbackLog {
  std::vector<ssStepInfo> before, collide;
};

TEST_F(StepperTest, CallbacksAreHandedTheStepAndTheMapping) {
  OscillatorRig rig;
  CallbackLog log;
  ssSteppingForPolicy("exact", 1.0 / 30, &rig.def.stepping);
  rig.def.before_step = [](void* context, ssStepper* stepper) {
    static_cast<CallbackLog*>(context)->before.push_back(ssStepper_CurrentStep(stepper));
  };
  rig.def.before_step_context = &log;
  rig.def.collide = [](void* context, ssStepper* stepper) {
    static_cast<CallbackLog*>(context)->collide.push_back(ssStepper_CurrentStep(stepper));
  };
  rig.def.collide_context = &log;
  ASSERT_EQ(rig.Build(), SS_OK);
  ASSERT_EQ(ssStepper_Step(rig.stepper, 0.05, nullptr), SS_OK);  // three substeps of 1/60
  ASSERT_EQ(log.collide.size(), 3u);
  ASSERT_EQ(log.before.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(log.collide[i].index, i);
    EXPECT_EQ(log.collide[i].count, 3);
    EXPECT_DOUBLE_EQ(log.collide[i].step_s, 0.05 / 3);
    EXPECT_EQ(log.collide[i].step_s, log.collide[i].softness_step_s);
    EXPECT_EQ(log.before[i].index, i);
  }
  EXPECT_EQ(log.collide[0].previous_step_s, 0.0);
  EXPECT_DOUBLE_EQ(log.collide[1].previous_step_s, 0.05 / 3);
  EXPECT_EQ(log.collide[0].mapping, SS_MAPPING_EXACT);
  EXPECT_EQ(rig.h.size(), 3u);
  ssStepper_ResetHistory(rig.stepper);
  ASSERT_EQ(ssStepper_Step(rig.stepper, 0.01, nullptr), SS_OK);
  EXPECT_EQ(log.collide.back().previous_step_s, 0.0);
  ssStepping naive = ssStepper_Stepping(rig.stepper);
  ASSERT_EQ(ssSteppingForPolicy("naive", 1.0 / 30, &naive), SS_OK);
  ASSERT_EQ(ssStepper_SetStepping(rig.stepper, &naive), SS_OK);
  ASSERT_EQ(ssStepper_Step(rig.stepper, 0.01, nullptr), SS_OK);
  EXPECT_EQ(log.collide.back().mapping, SS_MAPPING_IMPLICIT_EULER);
  EXPECT_DOUBLE_EQ(log.collide.back().step_s, 0.01);
  EXPECT_DOUBLE_EQ(log.collide.back().softness_step_s, 1.0 / 30.0);  // frozen at the reference step
  naive.mapping = (ssMapping)-1;
  EXPECT_EQ(ssStepper_SetStepping(rig.stepper, &naive), SS_ERROR_UNSUPPORTED);
}

TEST_F(StepperTest, ContactGroupIsEmptiedAfterEveryStep) {
  OscillatorRig rig;
  dJointGroupID contacts = dJointGroupCreate(0);
  rig.def.contact_group = contacts;
  rig.def.collide = [](void* context, ssStepper*) {
    auto* r = static_cast<OscillatorRig*>(context);
    dContact contact = {};
    contact.geom.normal[2] = 1;
    contact.geom.pos[2] = -0.05;
    dJointID joint = dJointCreateContact(r->world, r->def.contact_group, &contact);
    dJointAttach(joint, r->body, 0);
    EXPECT_EQ(dBodyGetNumJoints(r->body), 2);  // the slider and this step's contact, never an old one
  };
  rig.def.collide_context = &rig;
  ASSERT_EQ(rig.Build(), SS_OK);
  ASSERT_EQ(ssStepper_Step(rig.stepper, 0.05, nullptr), SS_OK);
  EXPECT_EQ(dBodyGetNumJoints(rig.body), 1);
  dJointGroupDestroy(contacts);
}

TEST_F(StepperTest, BlowUpsAndRunawaysAreReportedAndStepsAreRefusedUntilReset) {
  OscillatorRig rig;
  rig.def.stepping.max_speed = 100;
  ASSERT_EQ(rig.Build(), SS_OK);
  EXPECT_EQ(ssStepper_WatchBody(rig.stepper, MakeBody(1.0)), SS_ERROR_OUT_OF_RANGE);  // of the fixture's world
  EXPECT_NE(std::string(ssLastError()).find("of another world"), std::string::npos) << ssLastError();
  dBodyID loose = dBodyCreate(rig.world);  // 1 kg
  ASSERT_EQ(ssStepper_WatchBody(rig.stepper, loose), SS_OK);
  ssFrameReport report;
  // Set between frames: refused before anything is stepped.
  dBodySetLinearVel(loose, 150, 0, 0);
  EXPECT_EQ(ssStepper_Step(rig.stepper, 0.05, &report), SS_ERROR_SPEED_LIMIT);
  EXPECT_EQ(report.failed_body, loose);
  EXPECT_EQ(report.steps, 0);
  EXPECT_NE(std::string(ssLastError()).find("speed 150 m/s before the frame"), std::string::npos) << ssLastError();
  EXPECT_EQ(ssStepper_Step(rig.stepper, 0.05, &report), SS_ERROR_FAILED);
  ssStepper_Reset(rig.stepper);
  // Reached in a step: 99 m/s plus 3000 N on 1 kg for 1/60 s is 149 m/s after the first of three substeps.
  dBodySetLinearVel(loose, 99, 0, 0);
  dBodyAddForce(loose, 3000, 0, 0);
  EXPECT_EQ(ssStepper_Step(rig.stepper, 0.05, &report), SS_ERROR_SPEED_LIMIT);
  EXPECT_EQ(report.failed_body, loose);
  EXPECT_EQ(report.steps, 1);  // the frame stops at the step that failed
  EXPECT_NE(std::string(ssLastError()).find("max_speed = 100"), std::string::npos) << ssLastError();
  EXPECT_NE(std::string(ssLastError()).find("after step 1 of 3"), std::string::npos) << ssLastError();

  // Latched: every later frame is refused, names the first failure and touches nothing.
  dBodySetLinearVel(loose, 0, 0, 0);
  const double x = dJointGetSliderPosition(rig.slider);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(ssStepper_Step(rig.stepper, 0.05, &report), SS_ERROR_FAILED);
    EXPECT_EQ(report.steps, 0);
    EXPECT_NE(std::string(ssLastError()).find("max_speed = 100"), std::string::npos) << ssLastError();
    EXPECT_NE(std::string(ssLastError()).find("ssStepper_Reset"), std::string::npos) << ssLastError();
  }
  EXPECT_EQ(dJointGetSliderPosition(rig.slider), x);
  ssStepper_Reset(rig.stepper);
  EXPECT_EQ(ssStepper_Step(rig.stepper, 0.05, &report), SS_OK) << ssLastError();

  // A body of a bound joint is watched without being asked.
  dBodySetLinearVel(rig.body, 500, 0, 0);
  EXPECT_EQ(ssStepper_Step(rig.stepper, 0.05, &report), SS_ERROR_SPEED_LIMIT);
  EXPECT_EQ(report.failed_body, rig.body);
  ssStepper_Reset(rig.stepper);

  dBodySetLinearVel(rig.body, 0, 0, 0);
  dBodySetLinearVel(loose, NAN, 0, 0);
  EXPECT_EQ(ssStepper_Step(rig.stepper, 0.05, &report), SS_ERROR_BLOWUP);
  EXPECT_EQ(report.failed_body, loose);
  EXPECT_NE(std::string(ssLastError()).find("not finite"), std::string::npos) << ssLastError();
  EXPECT_EQ(ssStepper_UnwatchBody(rig.stepper, loose), SS_OK);
  EXPECT_EQ(ssStepper_UnwatchBody(rig.stepper, loose), SS_ERROR_NOT_FOUND);
}

TEST_F(StepperTest, TheSpeedGuardIsOnByDefaultForLinearAndAngularSpeed) {
  ssStepperDef def = TestStepperDef();
  EXPECT_GT(def.stepping.max_speed, 0);
  EXPECT_GT(def.stepping.max_angular_speed, 0);
  OscillatorRig rig;
  ASSERT_EQ(rig.Build(), SS_OK);
  dBodyID spinning = dBodyCreate(rig.world);
  ASSERT_EQ(ssStepper_WatchBody(rig.stepper, spinning), SS_OK);
  dBodySetAngularVel(spinning, 0, 0, 2 * def.stepping.max_angular_speed);
  ssFrameReport report;
  EXPECT_EQ(ssStepper_Step(rig.stepper, 1.0 / 60, &report), SS_ERROR_SPEED_LIMIT);
  EXPECT_NE(std::string(ssLastError()).find("max_angular_speed"), std::string::npos) << ssLastError();
}

TEST_F(StepperTest, RowsAboveHalfTheStepRateAreHandedToImplicitEulerAndCounted) {
  OscillatorRig rig;
  rig.spring = {40000.0, 1.0};  // 1 kg: w = 200 rad/s, so w h > π above h = 15.7 ms
  ssSteppingForPolicy("matched", 1.0 / 30, &rig.def.stepping);
  rig.def.stepping.max_step_s = 1.0 / 30.0;
  ASSERT_EQ(rig.Build(), SS_OK);
  ssFrameReport report;
  ASSERT_EQ(ssStepper_Step(rig.stepper, 1.0 / 30.0, &report), SS_OK);
  EXPECT_EQ(report.rows.handed_to_implicit_euler, 1);
  EXPECT_EQ(report.rows.by_mapping, 0);
  // w h = 0.4: below Nyquist, and the matched static stiffness within 5 % of k (issue 15's rule, row_law.c)
  ASSERT_EQ(ssStepper_Step(rig.stepper, 1.0 / 500.0, &report), SS_OK);
  EXPECT_EQ(report.rows.handed_to_implicit_euler, 0);
  EXPECT_EQ(report.rows.by_mapping, 1);
  // w h = 2 (1/100 s): below Nyquist, but matched's static stiffness is k·sinc²(w h / 2) = 0.71 k there, where
  // an undeclared load would rest 41 % further out than F/k: implicit Euler serves the row
  ASSERT_EQ(ssStepper_Step(rig.stepper, 1.0 / 100.0, &report), SS_OK);
  EXPECT_EQ(report.rows.handed_to_implicit_euler, 1);
  EXPECT_EQ(report.rows.by_mapping, 0);
}

// Issue 15's rule on damping: a spring whose decay takes a few steps (c/2m · h = 1) has a matched static stiffness
// far from k; implicit Euler serves it, and its load-free motion is then the implicit-Euler recurrence itself.
TEST_F(StepperTest, RowsWhoseStaticStiffnessTheAccurateMappingsMissAreHandedToImplicitEuler) {
  for (const char* policy : {"matched", "exact"}) {
    OscillatorRig rig;
    rig.spring = {400.0, 120.0};  // 1 kg: σ h = 1 at 1/60 s
    ssSteppingForPolicy(policy, 1.0 / 60, &rig.def.stepping);
    ASSERT_EQ(rig.Build(), SS_OK);
    ssFrameReport report;
    ASSERT_EQ(ssStepper_Step(rig.stepper, 1.0 / 60.0, &report), SS_OK);
    EXPECT_EQ(report.rows.handed_to_implicit_euler, 1) << policy;
    EXPECT_EQ(report.rows.by_mapping + report.rows.handed_to_matched, 0) << policy;
    // a declared load is corrected (the registry adds F·(k'/k - 1) along the row): the mapping serves the row
    OscillatorRig loaded;
    loaded.spring = rig.spring;
    loaded.gravity = 9.81;
    loaded.declare_load = true;
    loaded.def.stepping = rig.def.stepping;
    ASSERT_EQ(loaded.Build(), SS_OK);
    ASSERT_EQ(ssStepper_Step(loaded.stepper, 1.0 / 60.0, &report), SS_OK);
    EXPECT_EQ(report.rows.by_mapping, 1) << policy;
    EXPECT_EQ(report.rows.handed_to_implicit_euler, 0) << policy;
  }
}

TEST_F(StepperTest, ExactFallsBackToMatchedWhereAStepPairHasNoFiniteMapping) {
  OscillatorRig rig;
  rig.spring = {40.0, 0.05};  // lightly damped
  ssSteppingForPolicy("exact", 1.0 / 30, &rig.def.stepping);
  rig.def.stepping.max_step_s = 1.0;
  ASSERT_EQ(rig.Build(), SS_OK);
  int fallbacks = 0;
  for (double frame_s : {0.4, 0.004, 0.4, 0.004}) {
    ssFrameReport report;
    ASSERT_EQ(ssStepper_Step(rig.stepper, frame_s, &report), SS_OK) << ssLastError();
    fallbacks += report.rows.handed_to_matched;
    EXPECT_EQ(report.rows.by_mapping + report.rows.handed_to_matched + report.rows.handed_to_implicit_euler,
              report.steps);  // each row-step counted once
  }
  EXPECT_GT(fallbacks, 0);
}

TEST_F(StepperTest, ALongSubstepFrameIsCappedAndTheDroppedTimeReported) {
  OscillatorRig rig;
  rig.def.stepping.max_steps_per_frame = 5;
  ASSERT_EQ(rig.Build(), SS_OK);  // max_step_s = 1/60
  ssFrameReport report;
  ASSERT_EQ(ssStepper_Step(rig.stepper, 5.0 / 60, &report), SS_OK);  // exactly the cap: nothing dropped
  EXPECT_EQ(report.steps, 5);
  EXPECT_EQ(report.dropped_s, 0);
  ASSERT_EQ(ssStepper_Step(rig.stepper, 10.0, &report), SS_OK);  // a breakpoint: 5 steps, not 600
  EXPECT_EQ(report.steps, 5);
  EXPECT_DOUBLE_EQ(report.step_s, 1.0 / 60);
  EXPECT_NEAR(report.simulated_s, 5.0 / 60, 1e-15);
  EXPECT_NEAR(report.dropped_s, 10.0 - 5.0 / 60, 1e-12);
  EXPECT_EQ(ssDefaultStepping().max_steps_per_frame, 32);
}

// The stepper's clock: each step starts at the sum of the steps before it; between frames ssStepper_CurrentStep
// tells the next step, at the clock's time, and a frame refused before its first step reports the time as it was.
TEST_F(StepperTest, TheClockIsTheSumOfTheStepsTakenAndTheNextStepStartsThere) {
  OscillatorRig rig;
  ASSERT_EQ(rig.Build(), SS_OK);  // max_step_s = 1/60
  double sum = 0;
  for (double frame_s : {1.0 / 60, 0.05, 1.0 / 144, 0.0, 0.03}) {
    ssFrameReport report;
    ASSERT_EQ(ssStepper_Step(rig.stepper, frame_s, &report), SS_OK) << ssLastError();
    for (int i = 0; i < report.steps; ++i) sum += report.step_s;  // equal substeps
    EXPECT_EQ(report.time_s, sum) << frame_s;
    EXPECT_EQ(ssStepper_CurrentStep(rig.stepper).time_s, sum) << frame_s;
    EXPECT_EQ(ssStepper_CurrentStep(rig.stepper).index, 0);
  }
  dBodySetLinearVel(rig.body, NAN, 0, 0);  // refused before the frame's first step
  ssFrameReport report;
  EXPECT_EQ(ssStepper_Step(rig.stepper, 0.05, &report), SS_ERROR_BLOWUP);
  EXPECT_EQ(report.time_s, sum);
  EXPECT_EQ(report.steps, 0);
}

// The slack: a frame a little longer than the largest step (jitter, a 59 Hz display, a frame time kept in a float)
// is one step, not two; beyond the slack the frame is cut as before, and no step is ever longer than the slack
// allows: the guard against instability stays.
TEST_F(StepperTest, AFrameWithinTheSlackIsOneStepAndNoStepIsLongerThanTheSlackAllows) {
  const double max_step_s = 1.0 / 60;
  for (double slack : {0.25, 0.0, 1.0}) {
    OscillatorRig rig;
    rig.def.stepping.max_step_slack = slack;
    ASSERT_EQ(rig.Build(), SS_OK);
    std::vector<double> frames = {max_step_s * (1 + 1e-9), 1.0 / 59, static_cast<float>(1.0 / 60),
                                  max_step_s * (1 + slack), max_step_s * (1 + slack) * (1 + 1e-6), 0.05, 0.1};
    for (int i = 0; i < 400; ++i) frames.push_back(1e-3 + 0.16 * std::fabs(std::sin(1.3 * i + 0.2)));
    for (double frame_s : frames) {
      ssFrameReport report;
      ASSERT_EQ(ssStepper_Step(rig.stepper, frame_s, &report), SS_OK) << ssLastError();
      // the rule, stated on its own: one step within the slack, else ceil(frame / max) equal steps
      int expected = frame_s <= max_step_s * (1 + slack) ? 1 : static_cast<int>(std::ceil(frame_s / max_step_s - 1e-9));
      EXPECT_EQ(report.steps, expected) << "slack " << slack << ", frame " << frame_s;
      // frame times are sums of floating-point parts: 1e-9 of a step is the rounding the cut forgives (stepper.c)
      EXPECT_LE(report.step_s, max_step_s * (1 + slack) * (1 + 2e-9)) << "slack " << slack << ", frame " << frame_s;
      EXPECT_NEAR(report.simulated_s, frame_s, 1e-15);
    }
  }
  ssStepping stepping = TestStepping();
  for (double bad : {-0.1, 1.5, std::nan(""), std::numeric_limits<double>::infinity()}) {
    stepping.max_step_slack = bad;
    EXPECT_NE(ssValidateStepping(&stepping), SS_OK) << bad;
    EXPECT_NE(std::string(ssLastError()).find("stepping.max_step_slack"), std::string::npos) << ssLastError();
  }
  stepping = TestStepping();
  stepping.step_seed = -2;
  EXPECT_EQ(ssValidateStepping(&stepping), SS_ERROR_OUT_OF_RANGE);
  EXPECT_NE(std::string(ssLastError()).find("stepping.step_seed = -2"), std::string::npos) << ssLastError();
  EXPECT_EQ(ssDefaultStepping().max_step_slack, 0.25);
}

// A chain of capsules on ball joints from the static world, its end pushed: QuickStep's row order matters to it.
struct BallChain {
  std::vector<dBodyID> links;
  BallChain(dWorldID world, int count) {
    dMass mass;
    dMassSetCapsuleTotal(&mass, 1, 3, 0.05, 0.3);
    for (int i = 0; i < count; ++i) {
      dBodyID link = dBodyCreate(world);
      dBodySetMass(link, &mass);
      dBodySetPosition(link, 0.4 * (i + 0.5), 0, 2);
      dJointID ball = dJointCreateBall(world, 0);
      dJointAttach(ball, link, i == 0 ? nullptr : links.back());
      dJointSetBallAnchor(ball, 0.4 * i, 0, 2);
      links.push_back(link);
    }
  }
  std::vector<double> State() const {
    std::vector<double> state;
    for (dBodyID link : links)
      for (const dReal* v : {dBodyGetPosition(link), dBodyGetLinearVel(link), dBodyGetAngularVel(link)})
        state.insert(state.end(), v, v + 3);
    return state;
  }
};

// Runs a chain under implicit Euler for 120 frames of varying length; between frames, `elsewhere` QuickSteps of
// another world (other code in the process using ODE's generator). Returns every frame's state, and whether ODE's
// generator was left as the program had it across each frame.
std::vector<double> ChainRun(int step_seed, int elsewhere, bool* generator_untouched) {
  dWorldID world = dWorldCreate(), other = dWorldCreate();
  dWorldSetGravity(world, 0, 0, -9.81);
  BallChain chain(world, 6), other_chain(other, 4);
  dRandSetSeed(1234);
  ssStepperDef def = TestStepperDef();
  def.world = world;
  def.stepping.step_seed = step_seed;
  ssStepper* stepper = nullptr;
  EXPECT_EQ(ssStepper_Create(&def, &stepper), SS_OK);
  EXPECT_EQ(ssStepper_WatchBody(stepper, chain.links[0]), SS_OK);
  std::vector<double> states;
  *generator_untouched = true;
  for (int frame = 0; frame < 120; ++frame) {
    for (int i = 0; i < elsewhere * (frame % 3); ++i) dWorldQuickStep(other, 0.01);
    dBodyAddForce(chain.links.back(), 5 * std::sin(0.1 * frame), 2, 0);
    unsigned long before = dRandGetSeed();
    EXPECT_EQ(ssStepper_Step(stepper, 0.01 + 0.03 * std::fabs(std::sin(0.7 * frame)), nullptr), SS_OK);
    *generator_untouched = *generator_untouched && dRandGetSeed() == before;
    std::vector<double> state = chain.State();
    states.insert(states.end(), state.begin(), state.end());
  }
  ssStepper_Destroy(stepper);
  dWorldDestroy(other);
  dWorldDestroy(world);
  return states;
}

TEST_F(StepperTest, AStepDependsOnTheWorldNotOnQuickStepsTakenElsewhere) {
  bool untouched_alone, untouched_interleaved;
  std::vector<double> alone = ChainRun(0, 0, &untouched_alone);
  std::vector<double> interleaved = ChainRun(0, 2, &untouched_interleaved);
  ASSERT_EQ(alone.size(), interleaved.size());
  EXPECT_EQ(std::memcmp(alone.data(), interleaved.data(), alone.size() * sizeof(double)), 0)
      << "another world's QuickSteps changed this world's steps";
  EXPECT_TRUE(untouched_alone && untouched_interleaved) << "the program's dRand sequence was read or advanced";
  EXPECT_GT(std::fabs(alone[alone.size() - 9] - alone[0]), 1e-3) << "the chain moved";
  // The control: with ODE's generator left alone (-1, naive's way), the same two runs part, and the steps advance
  // the program's generator, as its own loop's do.
  bool untouched;
  std::vector<double> own_alone = ChainRun(-1, 0, &untouched);
  EXPECT_FALSE(untouched);
  std::vector<double> own_interleaved = ChainRun(-1, 2, &untouched);
  EXPECT_NE(std::memcmp(own_alone.data(), own_interleaved.data(), own_alone.size() * sizeof(double)), 0);
  // A different seed is a different (equally reproducible) row order.
  std::vector<double> other_seed = ChainRun(7, 0, &untouched);
  EXPECT_NE(std::memcmp(alone.data(), other_seed.data(), alone.size() * sizeof(double)), 0);
}

TEST_F(StepperTest, WithASpaceTheStepperAdoptsIntoARegistryOfItsOwnAtTheTunedStep) {
  dSpaceID space = dSimpleSpaceCreate(0);
  dBodyID body = MakeBody(1.0);
  dGeomSetBody(dCreateSphere(space, 0.1), body);
  dJointID slider = dJointCreateSlider(world, 0);
  dJointAttach(slider, body, 0);
  dJointSetSliderAxis(slider, 1, 0, 0);
  dJointSetSliderParam(slider, dParamLoStop, 0);
  dJointSetSliderParam(slider, dParamHiStop, 0);
  dJointSetSliderParam(slider, dParamStopERP, 0.4);  // tuned at 1/50 s
  dJointSetSliderParam(slider, dParamStopCFM, 1e-3);
  ssStepperDef def = ssDefaultStepperDef();
  def.world = world;
  def.space = space;
  def.stepping.solver = SS_SOLVER_STEP;
  ssStepper* stepper = nullptr;
  EXPECT_EQ(ssStepper_Create(&def, &stepper), SS_ERROR_OUT_OF_RANGE);  // which step was it tuned for?
  EXPECT_NE(std::string(ssLastError()).find("tuned_step_s = 0 s"), std::string::npos) << ssLastError();
  def.tuned_step_s = 1.0 / 50;
  ASSERT_EQ(ssStepper_Create(&def, &stepper), SS_OK) << ssLastError();
  const ssStepping stepping = ssStepper_Stepping(stepper);
  EXPECT_EQ(stepping.max_step_s, 1.0 / 50);  // 0: the tuned step
  EXPECT_EQ(stepping.fixed_step_s, 1.0 / 50);
  EXPECT_EQ(stepping.solver, SS_SOLVER_STEP);
  ssFrameReport report;
  ASSERT_EQ(ssStepper_Step(stepper, 1.0 / 100, &report), SS_OK) << ssLastError();
  EXPECT_EQ(report.rows.by_mapping, 3);  // adopted: the world's ERP/CFM, the slider's stop and its motor row
  // The stop's spring, k = erp / (h0 cfm), c = (1 - erp) / cfm, written for the step of 1/100 s.
  const double h0 = 1.0 / 50, h = 1.0 / 100, k = 0.4 / (h0 * 1e-3), c = 0.6 / 1e-3;
  EXPECT_NEAR(dJointGetSliderParam(slider, dParamStopERP), h * k / (h * k + c), ReadBackTolerance(1e-12, 1));
  EXPECT_NEAR(dJointGetSliderParam(slider, dParamStopCFM), 1 / (h * k + c), ReadBackTolerance(1e-12, 1 / (h * k + c)));
  ssStepper_Destroy(stepper);  // and its registry

  // A registry of another world is refused by name.
  dWorldID other = dWorldCreate();
  ssRegistry* foreign = ssRegistry_Create(other);
  def.registry = foreign;
  stepper = nullptr;
  EXPECT_EQ(ssStepper_Create(&def, &stepper), SS_ERROR_OUT_OF_RANGE);
  EXPECT_EQ(stepper, nullptr);
  EXPECT_NE(std::string(ssLastError()).find("not def.world"), std::string::npos) << ssLastError();
  ssRegistry_Destroy(foreign);
  dWorldDestroy(other);
  dSpaceDestroy(space);
}

}  // namespace

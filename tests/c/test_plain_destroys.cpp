// A program destroys and re-creates with ODE's own calls, as real ones do (an entity's joint rebuilt each frame, a
// prop despawned with its geom, a level's space torn down): the stepper forgets what was destroyed without reading
// it, adopts what replaced it, and leaves the program's own numbers in ODE when it goes. Run under AddressSanitizer
// and valgrind too, where reading freed memory is a failure.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "ode_fixture.h"
#include "precision.h"
#include "test_stepping.h"
#include "steadystep/steadystep.h"

namespace {

const double kTunedStep = 1.0 / 60;
const double kStopErp = 0.3, kStopCfm = 1e-4;  // the program's stop, tuned at 60 fps

// The stop's softness at a step of h: the spring the tuned numbers stand for, converted by the article's formulas.
void StopAt(double h, double* erp, double* cfm) {
  if (h == kTunedStep) {
    *erp = kStopErp, *cfm = kStopCfm;
    return;
  }
  const double k = kStopErp / (kTunedStep * kStopCfm), c = (1 - kStopErp) / kStopCfm;
  *erp = h * k / (h * k + c), *cfm = 1 / (h * k + c);
}

class PlainDestroyTest : public OdeTest, public ::testing::WithParamInterface<bool> {
 public:  // the callbacks reach the program through it
  void SetUp() override {
    OdeTest::SetUp();
    dWorldSetGravity(world, 0, 0, -9.81);
    root = dHashSpaceCreate(0);
    nested = dSimpleSpaceCreate(root);
    level = dSimpleSpaceCreate(root);
    a = Box(root, 0, 1);
    b = Box(nested, 0.5, 1);
    c = Box(root, 2, 0.05);
    d = Box(level, 3, 0.05);
    MakeJoint();
  }
  void TearDown() override {
    ssStepper_Destroy(stepper);
    dSpaceDestroy(root);
    OdeTest::TearDown();
  }

  dBodyID Box(dSpaceID space, double x, double z) {
    dBodyID body = MakeBody(1.0, x, 0, z);
    dGeomSetBody(dCreateBox(space, 0.1, 0.1, 0.1), body);
    return body;
  }
  static void DestroyWithGeoms(dBodyID body) {
    while (dBodyGetFirstGeom(body) != nullptr) dGeomDestroy(dBodyGetFirstGeom(body));
    dBodyDestroy(body);
  }
  void MakeJoint() {
    joint = dJointCreateHinge(world, 0);
    dJointAttach(joint, a, b);
    dJointSetHingeAnchor(joint, 0.25, 0, 1);
    dJointSetHingeAxis(joint, 0, 1, 0);
    dJointSetHingeParam(joint, dParamLoStop, -0.2);
    dJointSetHingeParam(joint, dParamHiStop, 0.2);
    dJointSetHingeParam(joint, dParamStopERP, kStopErp);
    dJointSetHingeParam(joint, dParamStopCFM, kStopCfm);
  }

  // What the program does to its world in frame f: its entity's joint rebuilt every frame, a prop despawned and
  // another spawned every third, the level's space torn down and another built every fifth.
  void Act(int f) {
    dJointDestroy(joint);
    MakeJoint();
    if (f % 3 == 0) {
      DestroyWithGeoms(c);
      c = Box(root, 2, 0.05 + 0.01 * (f % 2));
    }
    if (f % 5 == 0) {
      DestroyWithGeoms(d);  // its geom first, then the space (which would destroy its geoms)
      dSpaceDestroy(level);
      level = dSimpleSpaceCreate(root);
      d = Box(level, 3, 0.05);
    }
  }

  dSpaceID root = nullptr, nested = nullptr, level = nullptr;
  dBodyID a = nullptr, b = nullptr, c = nullptr, d = nullptr;
  dJointID joint = nullptr;
  ssStepper* stepper = nullptr;
  int frame = 0;
  bool acted = false;
};

TEST_P(PlainDestroyTest, JointsBodiesAndSpacesDestroyedWithODEsOwnCallsAreForgottenAndTheirSuccessorsAdopted) {
  const bool in_before_step = GetParam();
  ssStepperDef def = TestStepperDef();
  def.world = world;
  def.space = root;
  def.tuned_step_s = kTunedStep;
  if (in_before_step) {
    def.before_step = [](void* context, ssStepper* s) {
      auto* test = static_cast<PlainDestroyTest*>(context);
      if (test->acted) return;
      // what the last frame's step made was found at this frame's start
      EXPECT_EQ(ssStepper_KnownBodyCount(s), 4) << "frame " << test->frame;
      test->Act(test->frame);
      test->acted = true;
    };
    def.before_step_context = this;
  }
  ASSERT_EQ(ssStepper_Create(&def, &stepper), SS_OK) << ssLastError();
  const int known = ssStepper_KnownBodyCount(stepper);
  EXPECT_EQ(known, 4);
  for (frame = 0; frame < 30; ++frame) {
    SCOPED_TRACE("frame " + std::to_string(frame));
    acted = false;
    if (!in_before_step) Act(frame);
    const double frame_s = frame % 2 ? 1.0 / 60 : 1.0 / 50;
    ssFrameReport report;
    ASSERT_EQ(ssStepper_Step(stepper, frame_s, &report), SS_OK) << ssLastError();
    ASSERT_EQ(report.steps, 1);
    if (in_before_step) continue;  // what the step's callback made steps as made, and is found at the next frame
    EXPECT_EQ(ssStepper_KnownBodyCount(stepper), known);
    // the joint made between frames was adopted as tuned, and stepped with the frame's softness
    double erp, cfm;
    StopAt(frame_s, &erp, &cfm);
    EXPECT_NEAR(dJointGetHingeParam(joint, dParamStopERP), erp, ReadBackTolerance(1e-13, erp));
    EXPECT_NEAR(dJointGetHingeParam(joint, dParamStopCFM), cfm, ReadBackTolerance(1e-13 * cfm, cfm));
  }
  // (A joint made where the destroyed one was, at its address, is the program's new joint to the stepper either way:
  // adopted as new, or its numbers followed as the program's writes; the softness checked above is the same.)
}

INSTANTIATE_TEST_SUITE_P(BetweenFramesAndInBeforeStep, PlainDestroyTest, ::testing::Values(false, true),
                         [](const ::testing::TestParamInfo<bool>& info) {
                           return std::string(info.param ? "InBeforeStep" : "BetweenFrames");
                         });

// A joint made before the one it replaces is destroyed has another address, and is at the head of both bodies' lists:
// they hold as many joints as before, none of them a contact, and the stepper tells the new one by the head (two reads
// a body, not a walk of its list), adopts it and writes it for the frame's step.
TEST_F(PlainDestroyTest, AJointMadeBeforeTheOneItReplacesIsDestroyedIsAdoptedAtTheNextFrame) {
  ssStepperDef def = TestStepperDef();
  def.world = world;
  def.space = root;
  def.tuned_step_s = kTunedStep;
  ASSERT_EQ(ssStepper_Create(&def, &stepper), SS_OK) << ssLastError();
  for (frame = 0; frame < 6; ++frame) {
    SCOPED_TRACE("frame " + std::to_string(frame));
    dJointID replaced = joint;
    MakeJoint();
    ASSERT_NE(joint, replaced);
    dJointDestroy(replaced);
    ASSERT_EQ(dBodyGetNumJoints(a), 1);
    const double frame_s = frame % 2 ? 1.0 / 60 : 1.0 / 50;
    ASSERT_EQ(ssStepper_Step(stepper, frame_s, nullptr), SS_OK) << ssLastError();
    double erp, cfm;
    StopAt(frame_s, &erp, &cfm);
    EXPECT_NEAR(dJointGetHingeParam(joint, dParamStopERP), erp, ReadBackTolerance(1e-13, erp));
    EXPECT_NEAR(dJointGetHingeParam(joint, dParamStopCFM), cfm, ReadBackTolerance(1e-13 * cfm, cfm));
  }
}

// A body destroyed with ODE's own calls and another made at once, as a pool or a game's debris does: the allocator
// most often gives the new body the old one's address, which no ODE call tells from the old body (docs/adopting.md).
// The new body is drawn where it was made, then blends its own two states, and ODE steps it with the damping the
// program gave it, as a body made at another address (the truths: the pose it was made at, the blend of the poses
// recorded around its step, and that other body's numbers).
TEST_F(OdeTest, ABodyMadeAtTheAddressOfOneDestroyedWithODEsOwnCallsIsDrawnAndWrittenAsItself) {
  dWorldSetGravity(world, 0, 0, -9.81);
  dSpaceID space = dHashSpaceCreate(nullptr);
  auto make = [&](double x, double damping) {
    dBodyID body = MakeBody(1.0, x, 0, 5);
    dBodySetLinearDamping(body, damping);
    dBodySetLinearVel(body, 1.0, 0, 2.0);
    dGeomSetBody(dCreateSphere(space, 0.1), body);
    return body;
  };
  struct Program {
    dBodyID made = nullptr, other = nullptr;
    double poses[2][3] = {};  // the made body's position before and after the last step
    int steps = 0;
    double made_damping = NAN, other_damping = NAN;
  } program;
  dBodyID old = make(3, 0.0);
  ssStepperDef def = TestStepperDef();
  def.world = world;
  def.space = space;
  def.tuned_step_s = kTunedStep;
  ASSERT_EQ(ssSteppingForPolicy("fixed", kTunedStep, &def.stepping), SS_OK);
  def.stepping.fixed_step_s = 0.01;
  def.before_step = [](void* context, ssStepper*) {
    auto* p = static_cast<Program*>(context);
    if (p->made == nullptr) return;
    std::copy_n(dBodyGetPosition(p->made), 3, p->poses[0]);
    p->made_damping = dBodyGetLinearDamping(p->made);
    p->other_damping = dBodyGetLinearDamping(p->other);
  };
  def.before_step_context = &program;
  def.step_done = [](void* context, double) {
    auto* p = static_cast<Program*>(context);
    if (p->made != nullptr) std::copy_n(dBodyGetPosition(p->made), 3, p->poses[1]), p->steps += 1;
  };
  def.step_done_context = &program;
  ssStepper* stepper = nullptr;
  ASSERT_EQ(ssStepper_Create(&def, &stepper), SS_OK) << ssLastError();
  ssFrameReport report;
  ASSERT_EQ(ssStepper_Step(stepper, 0.025, &report), SS_OK) << ssLastError();  // 2 steps: the old body has a history
  ASSERT_EQ(report.steps, 2);
  // made in the same gap between frames: the other body first (it cannot take the freed address), then the plain
  // destroy, then the body that most often takes it
  program.other = make(-8, 0.3);
  dGeomDestroy(dBodyGetFirstGeom(old));
  dBodyDestroy(old);
  program.made = make(-4, 0.3);
  RecordProperty("made_at_the_freed_address", program.made == old ? "yes" : "no");
  const double made_at[3] = {-4, 0, 5};
  ASSERT_EQ(ssStepper_Step(stepper, 0.001, &report), SS_OK) << ssLastError();  // no step
  ASSERT_EQ(report.steps, 0);
  double position[3], quaternion[4];
  ASSERT_EQ(ssStepper_InterpolatedPose(stepper, program.made, position, quaternion), SS_OK) << ssLastError();
  for (int i = 0; i < 3; ++i) EXPECT_EQ(position[i], made_at[i]) << i;
  ASSERT_EQ(ssStepper_Step(stepper, 0.012, &report), SS_OK) << ssLastError();  // 0.006 + 0.012: one step, a = 0.8
  ASSERT_EQ(report.steps, 1);
  ASSERT_EQ(program.steps, 1);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(program.poses[0][i], made_at[i]) << i;  // it stepped from where it was made
  ASSERT_EQ(ssStepper_InterpolatedPose(stepper, program.made, position, quaternion), SS_OK) << ssLastError();
  const double a = report.interpolation;
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(position[i], (1 - a) * program.poses[0][i] + a * program.poses[1][i], 1e-12) << i;
  // its damping in the step is the other body's: its own 0.3 tuned at 60 fps, for a step of 0.01 s
  EXPECT_NE(program.other_damping, AsDReal(0.3));
  EXPECT_EQ(program.made_damping, program.other_damping);
  ssStepper_Destroy(stepper);
  dSpaceDestroy(space);
}

class RebuildTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { dInitODE2(0); }
};

// A level restarted ten times: a new world, space, bodies and stepper each time, the stepper destroyed first and the
// world after it, as the README's order says.
TEST_F(RebuildTest, AWorldRebuiltWithANewStepperTenTimes) {
  for (int level = 0; level < 10; ++level) {
    dWorldID world = dWorldCreate();
    dWorldSetGravity(world, 0, 0, -9.81);
    dSpaceID space = dHashSpaceCreate(0);
    dJointGroupID contacts = dJointGroupCreate(0);
    dCreatePlane(space, 0, 0, 1, 0);
    for (int i = 0; i < 5; ++i) {
      dBodyID body = dBodyCreate(world);
      dMass mass;
      dMassSetSphereTotal(&mass, 1, 0.1);
      dBodySetMass(body, &mass);
      dBodySetPosition(body, 0.3 * i, 0, 0.5 + 0.1 * level);
      dGeomSetBody(dCreateSphere(space, 0.1), body);
    }
    ssStepperDef def = TestStepperDef();
    def.world = world;
    def.space = space;
    def.tuned_step_s = kTunedStep;
    def.contact_group = contacts;
    ssStepper* stepper = nullptr;
    ASSERT_EQ(ssStepper_Create(&def, &stepper), SS_OK) << ssLastError();
    for (int frame = 0; frame < 20; ++frame) ASSERT_EQ(ssStepper_Step(stepper, 1.0 / 45, nullptr), SS_OK);
    EXPECT_EQ(ssStepper_KnownBodyCount(stepper), 5);
    ssStepper_Destroy(stepper);
    dJointGroupDestroy(contacts);
    dSpaceDestroy(space);
    dWorldDestroy(world);
  }
}

// Destroyed, a stepper leaves the program's own numbers in ODE; a stepper made again adopts them, not the ones the
// first one last wrote for another step.
TEST_F(RebuildTest, AStepperDestroyedThenMadeAgainAdoptsTheProgramsOwnValues) {
  dWorldID world = dWorldCreate();
  dWorldSetERP(world, 0.4);
  dWorldSetCFM(world, 1e-5);
  dWorldSetAutoDisableFlag(world, 1);
  dWorldSetAutoDisableSteps(world, 10);
  dSpaceID space = dSimpleSpaceCreate(0);
  dBodyID body = dBodyCreate(world);
  dGeomSetBody(dCreateSphere(space, 0.1), body);
  for (int round = 0; round < 2; ++round) {
    SCOPED_TRACE("stepper " + std::to_string(round + 1));
    ssStepperDef def = TestStepperDef();
    def.world = world;
    def.space = space;
    def.tuned_step_s = kTunedStep;
    ssStepper* stepper = nullptr;
    ASSERT_EQ(ssStepper_Create(&def, &stepper), SS_OK) << ssLastError();
    ASSERT_EQ(ssStepper_Step(stepper, kTunedStep, nullptr), SS_OK);  // at the tuned step: the program's numbers
    EXPECT_EQ(dWorldGetERP(world), AsDReal(0.4));
    EXPECT_EQ(dBodyGetAutoDisableSteps(body), 10);
    ASSERT_EQ(ssStepper_Step(stepper, 1.0 / 50, nullptr), SS_OK);  // another step: other numbers in ODE
    EXPECT_NE(dWorldGetERP(world), AsDReal(0.4));
    EXPECT_NE(dBodyGetAutoDisableSteps(body), 10);
    ssStepper_Destroy(stepper);
    EXPECT_EQ(dWorldGetERP(world), AsDReal(0.4));  // the program's own again
    EXPECT_EQ(dWorldGetCFM(world), AsDReal(1e-5));
    EXPECT_EQ(dBodyGetAutoDisableSteps(body), 10);
    EXPECT_EQ(dWorldGetAutoDisableSteps(world), 10);
  }
  dSpaceDestroy(space);
  dWorldDestroy(world);
}

}  // namespace

// A level asleep and a level that spawns: what the stepper reads of a sleeping body is what ODE would act on, and a
// body made or destroyed between frames is followed at the cost of the change. The truths: ODE's own auto-disable
// (a sleeping body stays where it was), F·dt for a force held over a frame of substeps, and a value ODE would abort
// on refused by name before it reaches ODE, whichever way it arrives at a sleeping body.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "ode_fixture.h"
#include "precision.h"
#include "test_stepping.h"
#include "steadystep/steadystep.h"

namespace {

class Sleeping : public OdeTest {
 protected:
  void SetUp() override {
    OdeTest::SetUp();
    dWorldSetGravity(world, 0, 0, -9.81);
    dWorldSetAutoDisableFlag(world, 1);
    space = dHashSpaceCreate(nullptr);
    contacts = dJointGroupCreate(0);
    dCreatePlane(space, 0, 0, 1, 0);
    for (int i = 0; i < kBoxes; ++i) {
      dBodyID box = MakeBody(1.0, 2.0 * (i % 5), 2.0 * (i / 5), 0.05);
      dGeomSetBody(dCreateBox(space, 0.1, 0.1, 0.1), box);
      boxes.push_back(box);
    }
    // the program settles its level with its own steps: every box falls asleep
    for (int i = 0; i < 300 && Awake() > 0; ++i) {
      Collide(nullptr);
      dWorldQuickStep(world, 1.0 / 60);
      dJointGroupEmpty(contacts);
    }
    ASSERT_EQ(Awake(), 0);
  }
  void TearDown() override {
    ssStepper_Destroy(stepper);
    ssRegistry_Destroy(registry);
    dJointGroupDestroy(contacts);
    dSpaceDestroy(space);
    OdeTest::TearDown();
  }

  int Awake() const {
    int awake = 0;
    for (dBodyID box : boxes) awake += dBodyIsEnabled(box) != 0;
    return awake;
  }

  static void Near(void* data, dGeomID o1, dGeomID o2) {
    auto* test = static_cast<Sleeping*>(data);
    dBodyID b1 = dGeomGetBody(o1), b2 = dGeomGetBody(o2);
    dContact contact[4];
    int count = dCollide(o1, o2, 4, &contact[0].geom, sizeof(dContact));
    for (int i = 0; i < count; ++i) {
      contact[i].surface.mode = dContactSoftCFM | dContactApprox1;
      contact[i].surface.mu = 0.5;
      contact[i].surface.soft_cfm = 1e-4;
      if (test->stepper != nullptr && ssStepper_SoftenContact(test->stepper, &contact[i], b1, b2) != SS_OK) continue;
      dJointAttach(dJointCreateContact(test->world, test->contacts, &contact[i]), b1, b2);
    }
  }
  void Collide(ssStepper*) { dSpaceCollide(space, this, &Near); }
  static void CollideCallback(void* context, ssStepper* stepper) { static_cast<Sleeping*>(context)->Collide(stepper); }

  void Adopt(const char* policy, double max_step_s = 1.0 / 60, ssStepDoneCallback* step_done = nullptr,
             void* step_done_context = nullptr) {
    ssStepperDef def = TestStepperDef();
    def.world = world;
    def.space = space;
    def.tuned_step_s = 1.0 / 60;
    def.registry = registry;
    ASSERT_EQ(ssSteppingForPolicy(policy, def.tuned_step_s, &def.stepping), SS_OK) << ssLastError();
    def.stepping.max_step_s = max_step_s;
    def.stepping.max_step_slack = 0;
    if (!program_collides) {
      def.collide = &CollideCallback;
      def.collide_context = this;
      def.contact_group = contacts;
    }
    def.step_done = step_done;
    def.step_done_context = step_done_context;
    ASSERT_EQ(ssStepper_Create(&def, &stepper), SS_OK) << ssLastError();
  }

  // A ball of 0.2 kg made by the program, in the air above the level's corner, with its geom in the space.
  dBodyID Ball(double x, double y, double z) {
    dBodyID ball = dBodyCreate(world);
    dMass mass;
    dMassSetSphereTotal(&mass, 0.2, 0.05);
    dBodySetMass(ball, &mass);
    dBodySetPosition(ball, x, y, z);
    dGeomSetBody(dCreateSphere(space, 0.05), ball);
    return ball;
  }

  static constexpr int kBoxes = 20;
  bool program_collides = false;  // the program collides before each frame, the stepper empties no contacts
  ssRegistry* registry = nullptr;  // the stepper's own when none is given
  dSpaceID space = nullptr;
  dJointGroupID contacts = nullptr;
  std::vector<dBodyID> boxes;
  ssStepper* stepper = nullptr;
};

TEST_F(Sleeping, ASleepingLevelStaysAsleepAndWhereItWas) {
  Adopt("implicit-euler");
  std::vector<dVector3> before(boxes.size());
  for (size_t i = 0; i < boxes.size(); ++i)
    for (int j = 0; j < 3; ++j) before[i][j] = dBodyGetPosition(boxes[i])[j];
  for (int frame = 0; frame < 60; ++frame)
    ASSERT_EQ(ssStepper_Step(stepper, frame % 2 ? 1.0 / 50 : 1.0 / 70, nullptr), SS_OK) << ssLastError();
  EXPECT_EQ(Awake(), 0);
  for (size_t i = 0; i < boxes.size(); ++i)
    for (int j = 0; j < 3; ++j) EXPECT_EQ(dBodyGetPosition(boxes[i])[j], before[i][j]) << "box " << i;
}

TEST_F(Sleeping, ASleepingBodyMovedOutOfRangeIsRefusedBeforeCollision) {
  Adopt("implicit-euler");
  ASSERT_EQ(ssStepper_Step(stepper, 1.0 / 60, nullptr), SS_OK) << ssLastError();
  for (double far : {1e12, static_cast<double>(NAN)}) {
    SCOPED_TRACE(far);
    const dReal* p = dBodyGetPosition(boxes[7]);
    const double x = p[0], y = p[1], z = p[2];
    dBodySetPosition(boxes[7], far, 0, 0);  // ODE leaves it asleep; a hash space's collide would abort on it
    ASSERT_FALSE(dBodyIsEnabled(boxes[7]));
    ssFrameReport report;
    ssStatus status = ssStepper_Step(stepper, 1.0 / 60, &report);
    EXPECT_TRUE(status == SS_ERROR_POSITION_LIMIT || status == SS_ERROR_BLOWUP) << ssLastError();
    EXPECT_NE(std::string(ssLastError()).find("position"), std::string::npos) << ssLastError();
    EXPECT_EQ(report.failed_body, boxes[7]);
    dBodySetPosition(boxes[7], x, y, z);
    ssStepper_Reset(stepper);
    EXPECT_EQ(ssStepper_Step(stepper, 1.0 / 60, nullptr), SS_OK) << ssLastError();
  }
}

// The look walks each space up to the geom that was first after the last step. A sleeping box at every place of the
// list behind it, moved out of range, is refused before collision; with the first geom's body destroyed through the
// stepper, a body made after is still found and stepped.
TEST_F(Sleeping, WhatTheProgramMovesOrMakesIsFoundWhereverItWasInTheList) {
  Adopt("implicit-euler");
  ASSERT_EQ(ssStepper_Step(stepper, 1.0 / 60, nullptr), SS_OK) << ssLastError();
  for (int place = 0; place < dSpaceGetNumGeoms(space); ++place) {
    dBodyID box = dGeomGetBody(dSpaceGetGeom(space, place));
    if (box == nullptr) continue;  // the plane
    SCOPED_TRACE(place);
    const dReal* p = dBodyGetPosition(box);
    const double x = p[0], y = p[1], z = p[2];
    dBodySetPosition(box, 1e12, 0, 0);
    ssFrameReport report;
    EXPECT_EQ(ssStepper_Step(stepper, 1.0 / 60, &report), SS_ERROR_POSITION_LIMIT) << ssLastError();
    EXPECT_EQ(report.failed_body, box);
    dBodySetPosition(box, x, y, z);
    ssStepper_Reset(stepper);
    ASSERT_EQ(ssStepper_Step(stepper, 1.0 / 60, nullptr), SS_OK) << ssLastError();
  }
  dGeomID first = dSpaceGetGeom(space, 0);
  dBodyID gone = dGeomGetBody(first);
  ASSERT_NE(gone, nullptr);
  const int known = ssStepper_KnownBodyCount(stepper);
  dGeomDestroy(first);
  ASSERT_EQ(ssStepper_DestroyBody(stepper, gone), SS_OK) << ssLastError();
  dBodyID ball = Ball(20, 20, 1);
  ssFrameReport report;
  ASSERT_EQ(ssStepper_Step(stepper, 1.0 / 60, &report), SS_OK) << ssLastError();
  EXPECT_EQ(ssStepper_KnownBodyCount(stepper), known);  // one gone, one made
  EXPECT_LT(dBodyGetPosition(ball)[2], 1.0);             // stepped: it falls
}

// A stepper that adopts no space cannot see a sleeping body moved (ODE tells a move by a geom at the head of its space
// only): it reads such a body asleep too, whether the program moves it between frames or in before_step.
TEST_F(Sleeping, ASleepingBodyMovedWhereTheStepperDoesNotLookIsRefused) {
  ssStepperDef def = TestStepperDef();
  def.world = world;
  def.tuned_step_s = 1.0 / 60;
  ASSERT_EQ(ssSteppingForPolicy("implicit-euler", def.tuned_step_s, &def.stepping), SS_OK) << ssLastError();
  struct Move {
    dBodyID body = nullptr;
    double to = 0;
  } move;
  def.before_step = [](void* context, ssStepper*) {
    auto* m = static_cast<Move*>(context);
    if (m->body != nullptr) dBodySetPosition(m->body, m->to, 0, 0);
  };
  def.before_step_context = &move;
  ASSERT_EQ(ssStepper_Create(&def, &stepper), SS_OK) << ssLastError();
  for (dBodyID box : boxes) ASSERT_EQ(ssStepper_WatchBody(stepper, box), SS_OK) << ssLastError();
  ASSERT_EQ(ssStepper_Step(stepper, 1.0 / 60, nullptr), SS_OK) << ssLastError();  // the first frame checks all
  for (int in_before_step = 0; in_before_step < 2; ++in_before_step) {
    for (double far : {1e12, -static_cast<double>(INFINITY), static_cast<double>(NAN)}) {
      SCOPED_TRACE(testing::Message() << far << (in_before_step ? " in before_step" : " between frames"));
      const dReal* p = dBodyGetPosition(boxes[7]);
      const double x = p[0], y = p[1], z = p[2];
      if (in_before_step) move = {boxes[7], far};
      else dBodySetPosition(boxes[7], far, 0, 0);
      ssFrameReport report;
      ssStatus status = ssStepper_Step(stepper, 1.0 / 60, &report);
      move = {};
      EXPECT_TRUE(status == SS_ERROR_POSITION_LIMIT || status == SS_ERROR_BLOWUP) << ssStatusName(status);
      EXPECT_EQ(report.failed_body, boxes[7]) << ssLastError();
      EXPECT_FALSE(dBodyIsEnabled(boxes[7]));
      dBodySetPosition(boxes[7], x, y, z);
      ssStepper_Reset(stepper);
      ASSERT_EQ(ssStepper_Step(stepper, 1.0 / 60, nullptr), SS_OK) << ssLastError();
    }
  }
  EXPECT_EQ(Awake(), 0);
}

TEST_F(Sleeping, ASleepingBodyWithANanSpinIsRefusedWhenABallWakesIt) {
  Adopt("implicit-euler");
  ASSERT_EQ(ssStepper_Step(stepper, 1.0 / 60, nullptr), SS_OK) << ssLastError();  // the first frame checks all
  // a box behind the head of the space's list: the geom the stepper marks there is read at every look
  dBodyID box = dGeomGetBody(dSpaceGetGeom(space, 1));
  ASSERT_NE(box, nullptr);
  dBodySetAngularVel(box, NAN, 0, 0);  // asleep and alone: ODE neither steps it nor reads it
  ASSERT_EQ(ssStepper_Step(stepper, 1.0 / 60, nullptr), SS_OK) << ssLastError();
  // a ball dropped onto it: the step whose contact joins them would wake it inside ODE, spin and all
  const dReal* p = dBodyGetPosition(box);
  dBodyID ball = Ball(p[0], p[1], p[2] + 0.2);
  dBodySetLinearVel(ball, 0, 0, -2);
  ssFrameReport report;
  ssStatus status = SS_OK;
  int frames_before = -1;  // the frames the ball fell before it touched the box
  for (; frames_before < 30 && status == SS_OK; ++frames_before)
    status = ssStepper_Step(stepper, 1.0 / 60, &report);
  EXPECT_GE(frames_before, 2);
  EXPECT_EQ(status, SS_ERROR_BLOWUP) << ssLastError();
  EXPECT_NE(std::string(ssLastError()).find("angular velocity (nan"), std::string::npos) << ssLastError();
  EXPECT_EQ(report.failed_body, box);
  EXPECT_FALSE(dBodyIsEnabled(box));  // never stepped
}

TEST_F(Sleeping, ASleepingBodyTheProgramWakesIsCheckedBeforeItSteps) {
  Adopt("naive");
  ASSERT_EQ(ssStepper_Step(stepper, 1.0 / 60, nullptr), SS_OK) << ssLastError();  // the first frame checks all
  dBodySetLinearVel(boxes[3], INFINITY, 0, 0);
  dBodyAddForce(boxes[4], NAN, 0, 0);
  ASSERT_EQ(ssStepper_Step(stepper, 1.0 / 60, nullptr), SS_OK) << ssLastError();  // asleep: nothing acts on them
  for (dBodyID woken : {boxes[3], boxes[4]}) {
    dBodyEnable(woken);
    ssFrameReport report;
    EXPECT_NE(ssStepper_Step(stepper, 1.0 / 60, &report), SS_OK);
    EXPECT_EQ(report.failed_body, woken) << ssLastError();
    dBodySetLinearVel(woken, 0, 0, 0);
    dBodySetForce(woken, 0, 0, 0);
    ssStepper_Reset(stepper);
  }
  EXPECT_EQ(ssStepper_Step(stepper, 1.0 / 60, nullptr), SS_OK) << ssLastError();
}

// Wherever a body is among the sleepers, one the program wakes is found and checked before it steps: the check after
// the callbacks passes over a run of sleepers four at a time, and one at a time where fewer than four are left.
TEST_F(Sleeping, AWokenBodyIsCheckedWhereverItIsAmongTheSleepers) {
  Adopt("naive");
  for (dBodyID woken : boxes) {
    ASSERT_EQ(ssStepper_Step(stepper, 1.0 / 60, nullptr), SS_OK) << ssLastError();  // every box read, asleep
    ASSERT_EQ(ssStepper_Step(stepper, 1.0 / 60, nullptr), SS_OK) << ssLastError();  // the sleepers passed over
    dBodySetLinearVel(woken, 1e6, 0, 0);  // above max_speed; stepped unchecked, it flies off, and ODE goes on
    dBodyEnable(woken);
    ssFrameReport report;
    EXPECT_EQ(ssStepper_Step(stepper, 1.0 / 60, &report), SS_ERROR_SPEED_LIMIT);
    EXPECT_EQ(report.failed_body, woken) << ssLastError();
    dBodySetLinearVel(woken, 0, 0, 0);
    dBodyDisable(woken);
    ssStepper_Reset(stepper);
  }
  EXPECT_EQ(Awake(), 0);
}

// A body adopted asleep is written when it wakes, whatever the frames: at steps of constant length as well, where
// Apply has nothing else to write. Its idle time stays the program's (10 steps of 1/60 s are 20 of 1/120 s).
TEST_F(Sleeping, ABodyAdoptedAsleepIsWrittenForTheStepWhenItWakes) {
  for (dBodyID box : boxes) dBodySetAutoDisableSteps(box, 10);
  Adopt("implicit-euler", 1.0 / 120);
  for (int frame = 0; frame < 5; ++frame) {
    Ball(50.0 + frame, 50, 5);  // a body made every frame: Apply writes the new ones, not the sleeping level
    ASSERT_EQ(ssStepper_Step(stepper, 1.0 / 120, nullptr), SS_OK) << ssLastError();
  }
  EXPECT_EQ(dBodyGetAutoDisableSteps(boxes[7]), 10);  // asleep: left as the program set it
  dBodyEnable(boxes[7]);
  ASSERT_EQ(ssStepper_Step(stepper, 1.0 / 120, nullptr), SS_OK) << ssLastError();
  EXPECT_EQ(dBodyGetAutoDisableSteps(boxes[7]), 20);
  // woken by ODE, through a ball's contact in its step: written before the step after
  Ball(0, 0, 0.2);
  int frames = 0;
  while (!dBodyIsEnabled(boxes[0]) && frames++ < 120)
    ASSERT_EQ(ssStepper_Step(stepper, 1.0 / 120, nullptr), SS_OK) << ssLastError();
  ASSERT_TRUE(dBodyIsEnabled(boxes[0]));
  ASSERT_EQ(ssStepper_Step(stepper, 1.0 / 120, nullptr), SS_OK) << ssLastError();
  EXPECT_EQ(dBodyGetAutoDisableSteps(boxes[0]), 20);
}

// A joint the program attaches to a sleeping body with no joint is stepped by ODE only once the body wakes: it is
// adopted, and written for the step, before that step, whether the program wakes the body or a ball's contact does
// in ODE's step, and whether the stepper collides or the program does before the frame. (The stepper reads no joints
// of such a body while it sleeps.)
TEST_F(Sleeping, AJointAttachedToASleepingBodyIsWrittenBeforeTheStepThatWakesIt) {
  const double tuned_erp = 0.2, tuned_cfm = 1e-5, tuned_s = 1.0 / 60, step_s = 1.0 / 120;
  // the stop's spring at the tuned step, as the program set it, at a step of step_s (implicit Euler)
  const double k = tuned_erp / (tuned_s * tuned_cfm), c = (1 - tuned_erp) / tuned_cfm;
  const double erp = step_s * k / (step_s * k + c), cfm = 1 / (step_s * k + c);
  struct Watch {
    dBodyID body = nullptr;
    dJointID hinge = nullptr;
    int steps_awake = 0;
    double erp = 0, cfm = 0;  // the stop's, after the first step the body was awake for
  };
  for (int variant = 0; variant < 4; ++variant) {
    const bool by_ball = variant % 2 == 1;
    program_collides = variant >= 2;
    SCOPED_TRACE(std::string(by_ball ? "woken by a ball's contact" : "woken by the program") +
                 (program_collides ? ", the program colliding" : ", the stepper colliding"));
    Watch watch;
    watch.body = boxes[6 + 2 * variant];
    Adopt("implicit-euler", step_s,
          [](void* context, double) {
            auto* w = static_cast<Watch*>(context);
            if (!dBodyIsEnabled(w->body) || w->steps_awake++ > 0) return;
            w->erp = dJointGetHingeParam(w->hinge, dParamStopERP);
            w->cfm = dJointGetHingeParam(w->hinge, dParamStopCFM);
          },
          &watch);
    auto frame = [&] {
      if (program_collides) Collide(nullptr);
      ssStatus status = ssStepper_Step(stepper, step_s, nullptr);
      if (program_collides) dJointGroupEmpty(contacts);
      return status;
    };
    ASSERT_EQ(frame(), SS_OK) << ssLastError();
    const dReal* p = dBodyGetPosition(watch.body);
    watch.hinge = dJointCreateHinge(world, 0);
    dJointAttach(watch.hinge, watch.body, 0);
    dJointSetHingeAnchor(watch.hinge, p[0], p[1], p[2]);
    dJointSetHingeAxis(watch.hinge, 0, 0, 1);
    dJointSetHingeParam(watch.hinge, dParamLoStop, -0.1);
    dJointSetHingeParam(watch.hinge, dParamHiStop, 0.1);
    dJointSetHingeParam(watch.hinge, dParamStopERP, tuned_erp);
    dJointSetHingeParam(watch.hinge, dParamStopCFM, tuned_cfm);
    for (int i = 0; i < 3; ++i) ASSERT_EQ(frame(), SS_OK) << ssLastError();
    ASSERT_EQ(watch.steps_awake, 0);
    if (by_ball) Ball(p[0], p[1], p[2] + 0.12);
    else dBodyEnable(watch.body);
    for (int i = 0; i < 120 && watch.steps_awake == 0; ++i) ASSERT_EQ(frame(), SS_OK) << ssLastError();
    ASSERT_GT(watch.steps_awake, 0);
    EXPECT_NEAR(watch.erp, erp, ReadBackTolerance(1e-12, erp));
    EXPECT_NEAR(watch.cfm, cfm, ReadBackTolerance(1e-12 * cfm, cfm));
    ssStepper_Destroy(stepper);
    stepper = nullptr;
  }
}

// A joint the program destroys with ODE's own call while its body sleeps is forgotten before Apply writes the rows
// again for another step length (the frame's start reads the joints of a sleeping body that has any).
TEST_F(Sleeping, AJointDestroyedWhileItsBodySleepsIsForgottenBeforeApplyWritesIt) {
  registry = ssRegistry_Create(world);
  Adopt("implicit-euler", 1.0 / 120);
  ASSERT_EQ(ssStepper_Step(stepper, 1.0 / 120, nullptr), SS_OK) << ssLastError();
  const int bound_before = ssRegistry_JointBindingCount(registry);
  dBodyID box = boxes[2];
  const dReal* p = dBodyGetPosition(box);
  dJointID hinge = dJointCreateHinge(world, 0);
  dJointAttach(hinge, box, 0);
  dJointSetHingeAnchor(hinge, p[0], p[1], p[2]);
  dJointSetHingeAxis(hinge, 0, 0, 1);
  dJointSetHingeParam(hinge, dParamLoStop, -0.1);
  dJointSetHingeParam(hinge, dParamHiStop, 0.1);
  dBodyEnable(box);
  ASSERT_EQ(ssStepper_Step(stepper, 1.0 / 120, nullptr), SS_OK) << ssLastError();
  ASSERT_GT(ssRegistry_JointBindingCount(registry), bound_before);
  dBodyDisable(box);  // asleep again, joint and all
  for (int frame = 0; frame < 3; ++frame)
    ASSERT_EQ(ssStepper_Step(stepper, 1.0 / 120, nullptr), SS_OK) << ssLastError();
  dJointDestroy(hinge);
  ASSERT_EQ(ssStepper_Step(stepper, 1.0 / 90, nullptr), SS_OK) << ssLastError();  // Apply writes every row anew
  EXPECT_EQ(ssRegistry_JointBindingCount(registry), bound_before);
  EXPECT_FALSE(dBodyIsEnabled(box));
}

// What the program sets on a sleeping body stays the program's when the body wakes: followed as newly tuned, not
// written over with what adoption read. Under naive it stays as written, bit for bit; at steps of 1/120 s the idle
// time it stands for is kept (30 steps tuned at 1/60 s are 60).
TEST_F(Sleeping, WhatTheProgramSetsOnASleepingBodyIsFollowedWhenItWakes) {
  for (const char* policy : {"naive", "implicit-euler"}) {
    SCOPED_TRACE(policy);
    const bool naive = std::string(policy) == "naive";
    dBodyID box = boxes[naive ? 9 : 11];  // one of the sleeping level's, asleep still
    for (dBodyID each : boxes) dBodySetAutoDisableSteps(each, 10);
    Adopt(policy, 1.0 / 120);
    const double frame_s = naive ? 1.0 / 60 : 1.0 / 120;
    ASSERT_EQ(ssStepper_Step(stepper, frame_s, nullptr), SS_OK) << ssLastError();
    ASSERT_FALSE(dBodyIsEnabled(box));
    dBodySetAutoDisableSteps(box, 30);  // asleep: the program's settings change
    ASSERT_EQ(ssStepper_Step(stepper, frame_s, nullptr), SS_OK) << ssLastError();
    dBodyEnable(box);
    ssFrameReport report;
    ASSERT_EQ(ssStepper_Step(stepper, frame_s, &report), SS_OK) << ssLastError();
    EXPECT_EQ(dBodyGetAutoDisableSteps(box), naive ? 30 : 60);
    EXPECT_EQ(report.program_writes, 1);
    ssStepper_Destroy(stepper);
    stepper = nullptr;
  }
}

// A body the program wakes between frames and pushes with a force gets the force over every substep of the frame
// (F·dt), though the frame's start passes over a sleeping body when a check after the callbacks reads it.
TEST_F(Sleeping, ABodyWokenBetweenFramesWithAForceGetsItOverTheWholeFrame) {
  Adopt("implicit-euler", 1.0 / 180);
  ASSERT_EQ(ssStepper_Step(stepper, 1.0 / 60, nullptr), SS_OK) << ssLastError();
  dWorldSetGravity(world, 0, 0, 0);
  dBodyID box = boxes[5];
  const dReal* p = dBodyGetPosition(box);
  dBodySetPosition(box, p[0], p[1], 2.0);  // in the air, asleep: nothing touches it
  ASSERT_EQ(ssStepper_Step(stepper, 1.0 / 60, nullptr), SS_OK) << ssLastError();
  ASSERT_FALSE(dBodyIsEnabled(box));
  dBodyEnable(box);
  dBodyAddForce(box, 3.0, 0, 0);
  ssFrameReport report;
  ASSERT_EQ(ssStepper_Step(stepper, 1.0 / 60, &report), SS_OK) << ssLastError();
  EXPECT_EQ(report.steps, 3);
  // F·dt over the frame, 1 kg; in float three steps' roundings (4.5e-9 measured)
  EXPECT_NEAR(dBodyGetLinearVel(box)[0], 3.0 * (1.0 / 60) / 1.0, IntegratedTolerance(1e-12, 1e-7));
}

TEST_F(Sleeping, BodiesMadeAndDestroyedEveryFrameAreFollowed) {
  Adopt("implicit-euler", 1.0 / 240);  // four substeps a frame of 1/60 s
  const int first_known = ssStepper_KnownBodyCount(stepper);
  std::vector<dBodyID> balls;
  for (int frame = 0; frame < 90; ++frame) {
    SCOPED_TRACE(frame);
    if (balls.size() == 10) {  // the oldest goes, through the stepper or with ODE's own calls, in turn
      dBodyID oldest = balls.front();
      balls.erase(balls.begin());
      dGeomDestroy(dBodyGetFirstGeom(oldest));
      if (frame % 2) ASSERT_EQ(ssStepper_DestroyBody(stepper, oldest), SS_OK) << ssLastError();
      else dBodyDestroy(oldest);
    }
    dBodyID ball = Ball(-5.0 - frame, -5.0, 10.0);  // far from the level, falling freely
    balls.push_back(ball);
    const double force = 0.3, frame_s = 1.0 / 60;
    dBodyAddForce(ball, force, 0, 0);
    ssFrameReport report;
    ASSERT_EQ(ssStepper_Step(stepper, frame_s, &report), SS_OK) << ssLastError();
    ASSERT_EQ(report.steps, 4);
    EXPECT_NEAR(0.2 * dBodyGetLinearVel(ball)[0], force * frame_s, IntegratedTolerance(1e-9 * force * frame_s, 1e-6));
    EXPECT_EQ(ssStepper_KnownBodyCount(stepper), first_known + static_cast<int>(balls.size()));
    if (frame % 17 == 5) {  // and a NaN on the newest is refused by name, not passed to ODE
      dBodySetAngularVel(ball, NAN, 0, 0);
      EXPECT_EQ(ssStepper_Step(stepper, frame_s, &report), SS_ERROR_BLOWUP);
      EXPECT_EQ(report.failed_body, ball);
      dBodySetAngularVel(ball, 0, 0, 0);
      ssStepper_Reset(stepper);
    }
  }
  EXPECT_EQ(Awake(), 0);  // the level slept through it all
}

}  // namespace

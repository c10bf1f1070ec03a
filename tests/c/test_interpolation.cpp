// Smooth rendering of fixed steps (steadystep/interpolation.h), on real ODE: falling, spinning bodies under the
// fixed cut. The test records each physics step's pose itself, just before it (before_step) and after it
// (step_done); the pose to draw after a frame must be (1 - a) p_prev + a p_curr and the slerp of the two rotations
// (computed here another way: prev · (prev⁻¹ curr)^a by axis and angle) to 1e-12, at the frame's interpolation
// factor a, where prev and curr are the poses before and after the last step taken, at frames of no step, one
// and several. A body the program moves between frames is drawn where it put it.
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "ode_fixture.h"
#include "precision.h"
#include "steadystep/steadystep.h"

namespace {

struct Pose {
  double p[3], q[4];
};

Pose PoseOf(dBodyID body) {
  Pose pose;
  const dReal* p = dBodyGetPosition(body);
  const dReal* q = dBodyGetQuaternion(body);
  for (int i = 0; i < 3; ++i) pose.p[i] = p[i];
  for (int i = 0; i < 4; ++i) pose.q[i] = q[i];
  return pose;
}

// Hamilton product of (w, x, y, z) quaternions.
void Multiply(const double a[4], const double b[4], double out[4]) {
  out[0] = a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3];
  out[1] = a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2];
  out[2] = a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1];
  out[3] = a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0];
}

// prev · (prev⁻¹ · curr)^a on the shortest arc, by the relative rotation's axis and angle.
void Slerp(const double prev[4], const double curr[4], double a, double out[4]) {
  double inverse[4] = {prev[0], -prev[1], -prev[2], -prev[3]}, relative[4];
  Multiply(inverse, curr, relative);
  if (relative[0] < 0)
    for (double& c : relative) c = -c;
  double s = std::sqrt(relative[1] * relative[1] + relative[2] * relative[2] + relative[3] * relative[3]);
  double angle = 2 * std::atan2(s, relative[0]);
  double part[4] = {std::cos(a * angle / 2), 0, 0, 0};
  for (int i = 1; i < 4; ++i) part[i] = s > 0 ? relative[i] / s * std::sin(a * angle / 2) : 0;
  Multiply(prev, part, out);
}

class InterpolationTest : public OdeTest {
 protected:
  static constexpr int kBodies = 3;

  void SetUp() override {
    OdeTest::SetUp();
    dWorldSetGravity(world, 0, 0, -9.81);
    for (int i = 0; i < kBodies; ++i) {
      bodies[i] = MakeBody(1.0 + i, i, 0, 10);
      dBodySetLinearVel(bodies[i], 1.0, -0.5 * i, 2.0);
      dBodySetAngularVel(bodies[i], 3.0 + i, -2.0, 1.5 * i);  // a few hundredths of a rad per step
    }
    ssStepperDef def = ssDefaultStepperDef();
    def.world = world;
    ASSERT_EQ(ssSteppingForPolicy("fixed", 1.0 / 60, &def.stepping), SS_OK);
    def.stepping.solver = SS_SOLVER_QUICK;
    def.stepping.fixed_step_s = 0.01;
    def.stepping.max_steps_per_frame = 8;
    def.before_step = [](void* context, ssStepper*) { static_cast<InterpolationTest*>(context)->Record(&before); };
    def.before_step_context = this;
    def.step_done = [](void* context, double) { static_cast<InterpolationTest*>(context)->Record(&after); };
    def.step_done_context = this;
    ASSERT_EQ(ssStepper_Create(&def, &stepper), SS_OK);
    for (dBodyID body : bodies) ASSERT_EQ(ssStepper_WatchBody(stepper, body), SS_OK);
  }
  void TearDown() override {
    ssStepper_Destroy(stepper);
    OdeTest::TearDown();
  }

  void Record(std::vector<std::vector<Pose>>* into) {
    into->emplace_back();
    for (dBodyID body : bodies) into->back().push_back(PoseOf(body));
  }

  // The pose drawn for every body after a frame, against (prev, curr) and the frame's factor a.
  void ExpectBlend(const std::vector<Pose>& prev, const std::vector<Pose>& curr, double a) {
    for (int b = 0; b < kBodies; ++b) {
      double position[3], quaternion[4], expected[4];
      ASSERT_EQ(ssStepper_InterpolatedPose(stepper, bodies[b], position, quaternion), SS_OK);
      for (int i = 0; i < 3; ++i) EXPECT_NEAR(position[i], (1 - a) * prev[b].p[i] + a * curr[b].p[i], 1e-12);
      Slerp(prev[b].q, curr[b].q, a, expected);
      // a float ODE's quaternion is unit only to its epsilon: the two slerps part by up to 9e-8 there
      for (int i = 0; i < 4; ++i)
        EXPECT_NEAR(quaternion[i], expected[i], ReadBackTolerance(1e-12, 2)) << "body " << b << " a " << a;
    }
  }

  dBodyID bodies[kBodies];
  ssStepper* stepper = nullptr;
  static std::vector<std::vector<Pose>> before, after;
};

std::vector<std::vector<Pose>> InterpolationTest::before, InterpolationTest::after;

TEST_F(InterpolationTest, PosesBlendTheLastTwoStatesAtFramesOfNoneOneAndSeveralSteps) {
  before.clear();
  after.clear();
  std::vector<Pose> start;
  for (dBodyID body : bodies) start.push_back(PoseOf(body));
  // Steps of 0.01 s: 0.004 waits, 0.011 gives 1 (0.001 left), 0.036 gives 3 (0.006), 0.008 none, 0.013 one (0.003),
  // 0.053 five (0.003), 0.0079 none.
  const double frames[] = {0.004, 0.007, 0.035, 0.002, 0.005, 0.05, 0.0049};
  const int expected_steps[] = {0, 1, 3, 0, 1, 5, 0};
  int seen_zero = 0, seen_one = 0, seen_several = 0;
  for (int f = 0; f < 7; ++f) {
    ssFrameReport report;
    ASSERT_EQ(ssStepper_Step(stepper, frames[f], &report), SS_OK);
    ASSERT_EQ(report.steps, expected_steps[f]);
    seen_zero += report.steps == 0, seen_one += report.steps == 1, seen_several += report.steps > 1;
    ASSERT_EQ(before.size(), after.size());
    if (after.empty()) {
      ExpectBlend(start, start, report.interpolation);  // no step yet: where the bodies are
      continue;
    }
    // The last two physics states: before the last step is after the one before it (nothing moved them).
    if (after.size() >= 2) {
      for (int b = 0; b < kBodies; ++b)
        EXPECT_EQ(std::memcmp(&before.back()[b], &after[after.size() - 2][b], sizeof(Pose)), 0);
    }
    EXPECT_GT(report.interpolation, 0.0);
    ExpectBlend(before.back(), after.back(), report.interpolation);
  }
  EXPECT_GT(seen_zero, 0);
  EXPECT_GT(seen_one, 0);
  EXPECT_GT(seen_several, 0);
}

TEST_F(InterpolationTest, ATeleportIsDrawnWhereTheProgramPutIt) {
  ssFrameReport report;
  ASSERT_EQ(ssStepper_Step(stepper, 0.025, &report), SS_OK);  // 2 steps, a = 0.5
  ASSERT_EQ(report.steps, 2);
  dBodySetPosition(bodies[1], 5, 6, 7);
  dQuaternion turned = {0.5, 0.5, -0.5, 0.5};
  dBodySetQuaternion(bodies[1], turned);
  Pose put = PoseOf(bodies[1]);
  // A frame of no step: the teleported body drawn where it was put, the others still blended.
  before.clear();
  after.clear();
  ASSERT_EQ(ssStepper_Step(stepper, 0.001, &report), SS_OK);
  ASSERT_EQ(report.steps, 0);
  double position[3], quaternion[4];
  ASSERT_EQ(ssStepper_InterpolatedPose(stepper, bodies[1], position, quaternion), SS_OK);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(position[i], put.p[i]);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(quaternion[i], put.q[i], 1e-15);
  // The next step blends from where it was put, not from where it had been.
  dBodySetPosition(bodies[1], -5, 0, 3);
  ASSERT_EQ(ssStepper_Step(stepper, 0.0052, &report), SS_OK);  // 0.006 + 0.0052: one step
  ASSERT_EQ(report.steps, 1);
  ASSERT_EQ(before.size(), 1u);
  EXPECT_EQ(before[0][1].p[0], -5.0);
  ExpectBlend(before.back(), after.back(), report.interpolation);
}

TEST_F(InterpolationTest, OtherCutsResetsAndRefusals) {
  double position[3], quaternion[4];
  dBodyID stranger = MakeBody(1.0, 3, 3, 3);
  ssFrameReport report;
  ASSERT_EQ(ssStepper_Step(stepper, 0.015, &report), SS_OK);
  EXPECT_EQ(ssStepper_InterpolatedPose(stepper, stranger, position, quaternion), SS_ERROR_NOT_FOUND);
  EXPECT_NE(std::string(ssLastError()).find("not known"), std::string::npos);
  EXPECT_EQ(ssStepper_InterpolatedPose(nullptr, bodies[0], position, quaternion), SS_ERROR_OUT_OF_RANGE);
  EXPECT_EQ(ssStepper_InterpolatedPose(stepper, bodies[0], nullptr, quaternion), SS_ERROR_OUT_OF_RANGE);
  EXPECT_EQ(ssStepper_InterpolatedPose(stepper, bodies[0], position, nullptr), SS_ERROR_OUT_OF_RANGE);
  // Turned off (a program that draws nothing): ODE's pose; refused values named.
  ASSERT_EQ(ssStepper_SetInterpolation(stepper, 0), SS_OK);
  ASSERT_EQ(ssStepper_Step(stepper, 0.013, &report), SS_OK);  // 0.005 + 0.013: one step, a = 0.8
  ASSERT_GT(report.interpolation, 0.0);
  ASSERT_EQ(ssStepper_InterpolatedPose(stepper, bodies[2], position, quaternion), SS_OK);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(position[i], dBodyGetPosition(bodies[2])[i]);
  EXPECT_EQ(ssStepper_SetInterpolation(stepper, 2), SS_ERROR_OUT_OF_RANGE);
  EXPECT_EQ(ssStepper_SetInterpolation(nullptr, 1), SS_ERROR_OUT_OF_RANGE);
  ASSERT_EQ(ssStepper_SetInterpolation(stepper, 1), SS_OK);
  before.clear();
  after.clear();
  ASSERT_EQ(ssStepper_Step(stepper, 0.004, &report), SS_OK);  // on again: blends from the next frame's steps
  ASSERT_EQ(report.steps, 1);
  ExpectBlend(before.back(), after.back(), report.interpolation);
  // After a reset, before the next frame: ODE's pose.
  ssStepper_Reset(stepper);
  ASSERT_EQ(ssStepper_InterpolatedPose(stepper, bodies[0], position, quaternion), SS_OK);
  Pose now = PoseOf(bodies[0]);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(position[i], now.p[i]);
  // Substeps end every frame on a physics state: ODE's pose, for any body.
  ssStepping substeps = ssStepper_Stepping(stepper);
  ASSERT_EQ(ssSteppingForPolicy("implicit-euler", 1.0 / 60, &substeps), SS_OK);
  substeps.max_step_s = 0.01;
  ASSERT_EQ(ssStepper_SetStepping(stepper, &substeps), SS_OK);
  ASSERT_EQ(ssStepper_Step(stepper, 0.021, &report), SS_OK);
  for (dBodyID body : {bodies[0], stranger}) {
    ASSERT_EQ(ssStepper_InterpolatedPose(stepper, body, position, quaternion), SS_OK);
    now = PoseOf(body);
    for (int i = 0; i < 3; ++i) EXPECT_EQ(position[i], now.p[i]);
    for (int i = 0; i < 4; ++i) EXPECT_EQ(quaternion[i], now.q[i]);
  }
}

// A body destroyed from a callback in the middle of a fixed frame leaves the history at once: the frame's end reads
// only live bodies (a sanitizer build would report the read of a freed body), and the others still blend.
TEST_F(OdeTest, ABodyDestroyedInACallbackLeavesThePoseHistory) {
  dBodyID doomed = MakeBody(1.0, 0, 0, 5), kept = MakeBody(1.0, 1, 0, 5);
  dBodySetLinearVel(kept, 1.0, 0, 0);
  struct Context {
    dBodyID doomed;
    int steps = 0;
  } context{doomed};
  ssStepperDef def = ssDefaultStepperDef();
  def.world = world;
  ASSERT_EQ(ssSteppingForPolicy("fixed", 1.0 / 60, &def.stepping), SS_OK);
  def.stepping.solver = SS_SOLVER_QUICK;
  def.stepping.fixed_step_s = 0.01;
  def.before_step = [](void* c, ssStepper* s) {
    auto* context = static_cast<Context*>(c);
    if (++context->steps == 2) {
      ASSERT_EQ(ssStepper_DestroyBody(s, context->doomed), SS_OK);
    }
  };
  def.before_step_context = &context;
  ssStepper* stepper = nullptr;
  ASSERT_EQ(ssStepper_Create(&def, &stepper), SS_OK);
  ASSERT_EQ(ssStepper_WatchBody(stepper, doomed), SS_OK);
  ASSERT_EQ(ssStepper_WatchBody(stepper, kept), SS_OK);
  ssFrameReport report;
  ASSERT_EQ(ssStepper_Step(stepper, 0.005, &report), SS_OK);  // no step: the history starts here
  ASSERT_EQ(ssStepper_Step(stepper, 0.03, &report), SS_OK);   // 3 steps; the doomed body goes before the 2nd
  ASSERT_EQ(report.steps, 3);
  double position[3], quaternion[4];
  EXPECT_EQ(ssStepper_InterpolatedPose(stepper, doomed, position, quaternion), SS_ERROR_NOT_FOUND);
  ASSERT_EQ(ssStepper_InterpolatedPose(stepper, kept, position, quaternion), SS_OK);
  // x moves at 1 m/s: the blend lies a fraction a of a step behind the body's position now; the step moved it by
  // 0.01 m up to the one rounding of its position to dReal (float: 4.8e-9 m measured)
  const double x = dBodyGetPosition(kept)[0];
  EXPECT_NEAR(position[0], x - (1 - report.interpolation) * 0.01, ReadBackTolerance(1e-12, x));
  ssStepper_Destroy(stepper);
}

}  // namespace

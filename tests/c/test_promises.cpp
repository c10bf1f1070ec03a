// The stepper's promises in ordinary programs (issue 14): nothing a program does the ordinary way aborts ODE, loses
// a force or changes its physics silently. Each case is a real ODE world doing what real programs do.
#include <gtest/gtest.h>

#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

#include "ode_fixture.h"
#include "precision.h"
#include "test_stepping.h"
#include "steadystep/steadystep.h"

namespace {

bool Names(const char* text) { return std::string(ssLastError()).find(text) != std::string::npos; }

// Whether this ODE keeps its asserts: Debian's build and `scripts/ode-single.sh --asserts` (CMake Debug) do; ODE's
// CMake build defines dNODEBUG in every other configuration (the tests' single-precision build is Release). Asked in
// a child: a transmission's per-gear axis set in the wrong mode.
bool OdeAsserts() {
  pid_t child = fork();
  if (child == 0) {
    std::freopen("/dev/null", "w", stderr);
    dWorldID world = dWorldCreate();
    dJointSetTransmissionAxis1(dJointCreateTransmission(world, 0), 0, 0, 1);
    _exit(0);
  }
  int status = 0;
  return child > 0 && waitpid(child, &status, 0) == child && WIFSIGNALED(status);
}

// A program's world: boxes of 1 kg with geoms in a hash space (ODE's usual broad phase), no gravity unless asked,
// stepped through a stepper made from the space (adopted as tuned at 1/60 s) in substeps of at most 1/60 s.
class PromiseTest : public OdeTest {
 public:  // the callbacks below reach the program's world through it
  void SetUp() override {
    OdeTest::SetUp();
    dWorldSetGravity(world, 0, 0, 0);
    space = dHashSpaceCreate(0);
    contacts = dJointGroupCreate(0);
  }
  void TearDown() override {
    ssStepper_Destroy(stepper);
    dJointGroupDestroy(contacts);
    dSpaceDestroy(space);
    OdeTest::TearDown();
  }

  dBodyID Box(double x, double y, double z) {
    dBodyID body = MakeBody(1.0, x, y, z);
    dGeomSetBody(dCreateBox(space, 0.1, 0.1, 0.1), body);
    return body;
  }

  // The program's collision: every contact softened for the step, as a program adopted with the stepper does.
  static void Near(void* data, dGeomID a, dGeomID b) {
    auto* test = static_cast<PromiseTest*>(data);
    dContact contact[4];
    std::memset(contact, 0, sizeof contact);
    int n = dCollide(a, b, 4, &contact[0].geom, sizeof contact[0]);
    for (int i = 0; i < n; ++i) {
      contact[i].surface.mu = 1;
      dBodyID b1 = dGeomGetBody(a), b2 = dGeomGetBody(b);
      if (ssStepper_SoftenContact(test->stepper, &contact[i], b1, b2) != SS_OK) continue;
      dJointAttach(dJointCreateContact(test->world, test->contacts, &contact[i]), b1, b2);
    }
  }
  static void Collide(void* context, ssStepper*) {
    auto* test = static_cast<PromiseTest*>(context);
    dSpaceCollide(test->space, test, Near);
  }

  ssStepperDef Def() {
    ssStepperDef def = ssDefaultStepperDef();
    def.world = world;
    def.space = space;
    def.tuned_step_s = 1.0 / 60;
    def.stepping.solver = SS_SOLVER_QUICK;
    def.collide = Collide;
    def.collide_context = this;
    def.contact_group = contacts;
    return def;
  }
  ssStatus Make(ssStepperDef def) { return ssStepper_Create(&def, &stepper); }

  // The program's contact joint for a contact between a and b, in the contact group.
  void Attach(const dContact* contact, dGeomID a, dGeomID b) {
    dJointAttach(dJointCreateContact(world, contacts, contact), dGeomGetBody(a), dGeomGetBody(b));
  }

  // Two gears (boxes) on hinges about y to the static world (hinged) or free, 0.6 m apart at z = 1, geared 2:1 by a
  // transmission.
  dJointID Gears(dBodyID gears[2], bool hinged = true) {
    gears[0] = Box(0, 0, 1);
    gears[1] = Box(0.6, 0, 1);
    for (int i = 0; i < 2 && hinged; ++i) {
      dJointID hinge = dJointCreateHinge(world, 0);
      dJointAttach(hinge, gears[i], 0);
      const dReal* p = dBodyGetPosition(gears[i]);
      dJointSetHingeAnchor(hinge, p[0], p[1], p[2]);
      dJointSetHingeAxis(hinge, 0, 1, 0);
    }
    dJointID transmission = dJointCreateTransmission(world, 0);
    dJointAttach(transmission, gears[0], gears[1]);
    dJointSetTransmissionMode(transmission, dTransmissionParallelAxes);
    dJointSetTransmissionAxis(transmission, 0, 1, 0);
    dJointSetTransmissionAnchor1(transmission, 0, 0, 1);
    dJointSetTransmissionAnchor2(transmission, 0.6, 0, 1);
    dJointSetTransmissionRatio(transmission, 2.0);
    return transmission;
  }

  dSpaceID space = nullptr;
  dJointGroupID contacts = nullptr;
  ssStepper* stepper = nullptr;
  int batched = 0;  // the near callback softens a pair's contacts in one call
};

// ---- a. one check at the boundary, before every physics step ----

TEST_F(PromiseTest, ANanTorqueAddedByAControllerInBeforeStepIsRefusedByNameNotAnAbort) {
  dBodyID arm = Box(0, 0, 1);
  ssStepperDef def = Def();
  struct Pd {
    dBodyID arm;
    int calls = 0;
  } pd{arm};
  def.before_step = [](void* context, ssStepper*) {
    auto* pd = static_cast<Pd*>(context);
    double error = 0, rate = 0;  // a controller whose gain divides by a span that is zero this step
    if (++pd->calls == 2) dBodyAddTorque(pd->arm, (0.0 - error) / rate, 0, 0);
  };
  def.before_step_context = &pd;
  ASSERT_EQ(Make(def), SS_OK) << ssLastError();
  const dReal* p = dBodyGetPosition(arm);
  const dReal before[3] = {p[0], p[1], p[2]};  // as ODE holds it, bit for bit
  ssFrameReport report;
  EXPECT_EQ(ssStepper_Step(stepper, 0.05, &report), SS_ERROR_NOT_FINITE);
  EXPECT_TRUE(Names("torque (") && Names("nan, 0, 0) N*m")) << ssLastError();
  EXPECT_TRUE(Names("not finite")) << ssLastError();
  EXPECT_TRUE(Names("before step 2 of 3")) << ssLastError();
  EXPECT_EQ(report.failed_body, arm);
  EXPECT_EQ(report.steps, 1);
  EXPECT_EQ(dBodyGetTorque(arm)[0], 0);  // as the first step left it: nothing of the refused step remains
  EXPECT_EQ(std::memcmp(p, before, sizeof before), 0);
  EXPECT_EQ(ssStepper_Step(stepper, 0.05, &report), SS_ERROR_FAILED);  // latched until the program repairs
  ssStepper_Reset(stepper);
  EXPECT_EQ(ssStepper_Step(stepper, 0.05, &report), SS_OK) << ssLastError();
}

// Beyond the build's bounds and held by dReal: in double a speed whose square (the guard squares in double) is near
// DBL_MAX; a float holds no such speed, so there ten times SS_MAX_SAFE_SPEED. A force ten times SS_MAX_FORCE_N.
constexpr double kTooFastRadPerS = kSinglePrecision ? 10 * SS_MAX_SAFE_SPEED : 1e154;
constexpr double kTooStrongN = 10 * SS_MAX_FORCE_N;

// What a message prints for x as ODE holds it.
std::string Printed(const char* format, double x) {
  char text[64];
  std::snprintf(text, sizeof text, format, AsDReal(x));
  return text;
}

TEST_F(PromiseTest, AStateSetBetweenFramesIsRefusedByNameBeforeODEOrTheSpaceSeesIt) {
  dBodyID body = Box(0, 0, 1);
  ssStepperDef def = Def();
  def.stepping.max_speed = 0;  // the guard at its widest: SS_MAX_SAFE_SPEED
  def.stepping.max_angular_speed = 0;
  ASSERT_EQ(Make(def), SS_OK) << ssLastError();
  const std::string too_fast = Printed("angular speed %g rad/s", kTooFastRadPerS);
  const std::string too_strong = Printed("force (0, 0, %g) N", kTooStrongN);
  struct Case {
    void (*set)(dBodyID);
    ssStatus status;
    const char* named;
  } cases[] = {
      {[](dBodyID b) { dBodySetAngularVel(b, kTooFastRadPerS, 0, 0); }, SS_ERROR_SPEED_LIMIT, too_fast.c_str()},
      {[](dBodyID b) { dBodySetAngularVel(b, 0, INFINITY, 0); }, SS_ERROR_BLOWUP, "angular velocity (0, inf, 0)"},
      {[](dBodyID b) { dBodySetLinearVel(b, NAN, 0, 0); }, SS_ERROR_BLOWUP, "linear velocity (nan, 0, 0)"},
      {[](dBodyID b) { dBodySetPosition(b, 1e9, 0, 1); }, SS_ERROR_POSITION_LIMIT, "position (1e+09, 0, 1) m"},
      {[](dBodyID b) { dBodyAddForce(b, 0, 0, kTooStrongN); }, SS_ERROR_OUT_OF_RANGE, too_strong.c_str()},
  };
  for (const Case& c : cases) {
    dBodySetPosition(body, 0, 0, 1);
    dBodySetLinearVel(body, 0, 0, 0);
    dBodySetAngularVel(body, 0, 0, 0);
    dBodySetForce(body, 0, 0, 0);
    c.set(body);
    ssFrameReport report;
    EXPECT_EQ(ssStepper_Step(stepper, 1.0 / 60, &report), c.status) << c.named;
    EXPECT_TRUE(Names(c.named)) << ssLastError();
    EXPECT_TRUE(Names("before the frame")) << ssLastError();
    EXPECT_EQ(report.failed_body, body);
    EXPECT_EQ(report.steps, 0);
    ssStepper_Reset(stepper);
  }
}

// step_done runs between a frame's steps: what it sets is checked before the next step even when the program has no
// before_step or collide callback (without them, nothing else runs between two steps and no other check is made).
TEST_F(PromiseTest, AStateSetInStepDoneIsRefusedBeforeTheNextStepWithNoOtherCallback) {
  dBodyID body = Box(0, 0, 1);
  struct Case {
    void (*set)(dBodyID);
    ssStatus status;
    const char* named;
  } cases[] = {
      {[](dBodyID b) { dBodySetLinearVel(b, NAN, 0, 0); }, SS_ERROR_BLOWUP, "linear velocity (nan, 0, 0)"},
      {[](dBodyID b) { dBodyAddForce(b, 0, 0, kTooStrongN); }, SS_ERROR_OUT_OF_RANGE, "beyond SS_MAX_FORCE_N"},
  };
  for (const Case& c : cases) {
    ssStepper_Destroy(stepper);
    stepper = nullptr;
    dBodySetPosition(body, 0, 0, 1);
    dBodySetLinearVel(body, 0, 0, 0);
    ssStepperDef def = Def();
    def.collide = nullptr;
    struct Setter {
      const Case* c;
      dBodyID body;
      int calls = 0;
    } setter{&c, body};
    def.step_done = [](void* context, double) {
      auto* s = static_cast<Setter*>(context);
      if (++s->calls == 1) s->c->set(s->body);
    };
    def.step_done_context = &setter;
    ASSERT_EQ(Make(def), SS_OK) << ssLastError();
    ssFrameReport report;
    EXPECT_EQ(ssStepper_Step(stepper, 0.05, &report), c.status) << c.named;
    EXPECT_TRUE(Names(c.named)) << ssLastError();
    EXPECT_TRUE(Names("before step 2 of 3")) << ssLastError();
    EXPECT_EQ(report.steps, 1);
    EXPECT_EQ(report.failed_body, body);
  }
}

// A teleport far out of range in step_done or before_step is refused before the next collision: in a hash space
// ODE's dSpaceCollide aborts on such a position (the body's geom would reach it before the check before the step).
TEST_F(PromiseTest, ATeleportInACallbackIsRefusedBeforeTheCollisionNotAnAbort) {
  dBodyID body = Box(0, 0, 1);
  Box(0.5, 0, 1);  // another body in the space, so that the collision has pairs to look at
  for (int in_step_done = 0; in_step_done < 2; ++in_step_done) {
    ssStepper_Destroy(stepper);
    stepper = nullptr;
    dBodySetPosition(body, 0, 0, 1);
    ssStepperDef def = Def();
    struct Teleport {
      dBodyID body;
      int calls = 0;
    } teleport{body};
    if (in_step_done) {
      def.step_done = [](void* context, double) {
        auto* t = static_cast<Teleport*>(context);
        if (++t->calls == 1) dBodySetPosition(t->body, 1e30, 0, 0);  // beyond the bound, finite in float too
      };
      def.step_done_context = &teleport;
    } else {
      def.before_step = [](void* context, ssStepper*) {
        auto* t = static_cast<Teleport*>(context);
        if (++t->calls == 2) dBodySetPosition(t->body, 1e30, 0, 0);  // beyond the bound, finite in float too
      };
      def.before_step_context = &teleport;
    }
    ASSERT_EQ(Make(def), SS_OK) << ssLastError();
    ssFrameReport report;
    EXPECT_EQ(ssStepper_Step(stepper, 0.05, &report), SS_ERROR_POSITION_LIMIT);
    EXPECT_TRUE(Names("position (1e+30, 0, 0) m before the collision of step 2 of 3")) << ssLastError();
    EXPECT_EQ(report.steps, 1);
    EXPECT_EQ(report.failed_body, body);
  }
}

// ODE's own sphere-cylinder collider makes a contact with a NaN normal for a sphere at the cylinder's centre: the
// stepper refuses to soften it, by name, and leaves it as it was (the program drops it, as Near above does).
TEST_F(PromiseTest, AContactWithANonFiniteNormalIsRefusedByNameNotSoftened) {
  dGeomID cylinder = dCreateCylinder(space, 0.5, 1.0);
  dGeomID sphere = dCreateSphere(space, 0.2);
  ASSERT_EQ(Make(Def()), SS_OK) << ssLastError();
  dContact contact;
  std::memset(&contact, 0, sizeof contact);
  ASSERT_EQ(dCollide(sphere, cylinder, 1, &contact.geom, sizeof contact), 1);
  ASSERT_TRUE(std::isnan(contact.geom.normal[0]));  // ODE's own collider made it
  contact.surface.mode = dContactSoftCFM;
  contact.surface.soft_cfm = 1e-4;
  dContact before = contact;
  EXPECT_EQ(ssStepper_SoftenContact(stepper, &contact, 0, 0), SS_ERROR_NOT_FINITE);
  EXPECT_TRUE(Names("normal not finite")) << ssLastError();
  EXPECT_EQ(std::memcmp(&before, &contact, sizeof contact), 0);
  EXPECT_EQ(ssContactSoften(&contact, 0, 0, ssSpring{100, 1}, SS_MAPPING_IMPLICIT_EULER, 1.0 / 60, 0),
            SS_ERROR_NOT_FINITE);
  EXPECT_EQ(std::memcmp(&before, &contact, sizeof contact), 0);
  contact.geom.normal[0] = 1, contact.geom.normal[1] = 0, contact.geom.normal[2] = 0;
  contact.geom.depth = INFINITY;
  EXPECT_EQ(ssStepper_SoftenContact(stepper, &contact, 0, 0), SS_ERROR_NOT_FINITE);
  EXPECT_TRUE(Names("depth not finite")) << ssLastError();
  // stepped with them, the world is safe: Near drops what is refused
  ssFrameReport report;
  EXPECT_EQ(ssStepper_Step(stepper, 1.0 / 60, &report), SS_OK) << ssLastError();
}

// ssStepper_SoftenContacts softens a batch as ssStepper_SoftenContact softens each contact alone, bit for bit, over
// many random batches: surfaces alike and unlike, modes with and without ERP and CFM, values the mode does not use
// left as garbage, steps of several lengths under every mapping.
TEST_F(PromiseTest, ABatchIsSoftenedAsEachContactAlone) {
  ASSERT_EQ(Make(Def()), SS_OK) << ssLastError();
  unsigned seed = 12345;
  auto uniform = [&seed]() { return (seed = seed * 1103515245u + 12345u) / 4294967296.0; };
  const int modes[] = {dContactSoftCFM, dContactSoftERP, dContactSoftERP | dContactSoftCFM, dContactApprox1};
  const char* policies[] = {"naive", "implicit-euler", "matched", "exact"};
  for (int round = 0; round < 400; ++round) {
    if (round % 50 == 0) {
      ssStepping stepping = ssStepper_Stepping(stepper);
      ASSERT_EQ(ssSteppingForPolicy(policies[round / 100], 1.0 / 60, &stepping), SS_OK);
      ASSERT_EQ(ssStepper_SetStepping(stepper, &stepping), SS_OK) << ssLastError();
    }
    dContact batch[6], alone[6];
    const int count = 1 + round % 6;
    for (int i = 0; i < count; ++i) {
      std::memset(&batch[i], 0, sizeof batch[i]);
      for (int j = 0; j < 3; ++j) batch[i].geom.pos[j] = uniform() - 0.5, batch[i].geom.normal[j] = uniform();
      batch[i].geom.depth = 0.01 * uniform();
      const bool like_first = i > 0 && uniform() < 0.7;  // most contacts of a pair share one surface
      batch[i].surface = like_first ? batch[0].surface : dSurfaceParameters{};
      if (!like_first) {
        batch[i].surface.mode = modes[static_cast<int>(uniform() * 4)];
        batch[i].surface.soft_erp = uniform() < 0.5 ? 0.2 : uniform();
        batch[i].surface.soft_cfm = uniform() < 0.5 ? 1e-4 : 1e-6 + uniform() * 1e-3;
      }
      if (!(batch[i].surface.mode & dContactSoftERP)) batch[i].surface.soft_erp = uniform() * 1e300;  // unused
      alone[i] = batch[i];
    }
    ASSERT_EQ(ssStepper_SoftenContacts(stepper, batch, count), SS_OK) << ssLastError();
    for (int i = 0; i < count; ++i) ASSERT_EQ(ssStepper_SoftenContact(stepper, &alone[i], 0, 0), SS_OK);
    ASSERT_EQ(std::memcmp(batch, alone, count * sizeof batch[0]), 0) << "round " << round;
  }
}

// A batch in the program's near callback serves and counts what one call a contact does: the same motion, bit for
// bit, and the same counts in the frame's report.
TEST_F(PromiseTest, ABatchInTheNearCallbackCountsAndMovesAsOneCallAContact) {
  dWorldSetGravity(world, 0, 0, -9.81);
  dCreatePlane(space, 0, 0, 1, 0);
  dBodyID box = Box(0, 0, 0.06);
  dBodySetLinearVel(box, 0.3, 0, 0);
  std::vector<double> path[2];
  ssServedCounts counted[2] = {};
  for (batched = 0; batched < 2; ++batched) {
    dBodySetPosition(box, 0, 0, 0.06);
    dBodySetLinearVel(box, 0.3, 0, 0);
    dBodySetAngularVel(box, 0, 0, 0);
    const dReal upright[4] = {1, 0, 0, 0};
    dBodySetQuaternion(box, upright);
    dRandSetSeed(1);  // QuickStep's row order: the same for both runs
    ssStepperDef def = Def();
    def.collide_context = this;
    def.collide = [](void* context, ssStepper*) {
      dSpaceCollide(static_cast<PromiseTest*>(context)->space, context, [](void* data, dGeomID a, dGeomID b) {
        auto* t = static_cast<PromiseTest*>(data);
        dContact contact[4];
        std::memset(contact, 0, sizeof contact);
        for (dContact& c : contact) c.surface.mode = dContactSoftCFM, c.surface.mu = 1, c.surface.soft_cfm = 1e-4;
        int n = dCollide(a, b, 4, &contact[0].geom, sizeof(dContact));
        if (t->batched) {
          EXPECT_EQ(ssStepper_SoftenContacts(t->stepper, contact, n), SS_OK);
        }
        for (int i = 0; i < n; ++i) {
          if (!t->batched) {
            EXPECT_EQ(ssStepper_SoftenContact(t->stepper, &contact[i], 0, 0), SS_OK);
          }
          t->Attach(&contact[i], a, b);
        }
      });
    };
    ASSERT_EQ(Make(def), SS_OK) << ssLastError();
    for (int frame = 0; frame < 30; ++frame) {
      ssFrameReport report;
      ASSERT_EQ(ssStepper_Step(stepper, frame % 2 ? 1.0 / 30 : 1.0 / 90, &report), SS_OK) << ssLastError();
      counted[batched].by_mapping += report.contacts.by_mapping;
      counted[batched].handed_to_implicit_euler += report.contacts.handed_to_implicit_euler;
      EXPECT_EQ(report.unsoftened_contact_steps, 0);
      const dReal* p = dBodyGetPosition(box);
      path[batched].insert(path[batched].end(), {p[0], p[1], p[2]});
    }
    ssStepper_Destroy(stepper);
    stepper = nullptr;
  }
  EXPECT_GT(counted[0].by_mapping, 30);
  EXPECT_EQ(counted[1].by_mapping, counted[0].by_mapping);
  EXPECT_EQ(counted[1].handed_to_implicit_euler, counted[0].handed_to_implicit_euler);
  EXPECT_EQ(path[1], path[0]);
}

// One bad contact in a batch refuses the batch by name, and every contact of it is left as given: the program's
// near callback drops the batch (or softens its contacts one by one) instead of stepping with what it was not told.
TEST_F(PromiseTest, ABatchWithOneBadContactIsRefusedByNameAndLeftAsGiven) {
  dGeomID cylinder = dCreateCylinder(space, 0.5, 1.0);
  dGeomID sphere = dCreateSphere(space, 0.2);
  ASSERT_EQ(Make(Def()), SS_OK) << ssLastError();
  dContact batch[4];
  std::memset(batch, 0, sizeof batch);
  for (dContact& c : batch) {
    c.geom.normal[2] = 1, c.geom.depth = 0.001;
    c.surface.mode = dContactSoftCFM, c.surface.soft_cfm = 1e-4;
  }
  ASSERT_EQ(ssStepper_SoftenContacts(stepper, batch, 4), SS_OK);  // the memo: the fast path's surface
  for (dContact& c : batch) c.surface.mode = dContactSoftCFM, c.surface.soft_cfm = 1e-4;
  ASSERT_EQ(dCollide(sphere, cylinder, 1, &batch[2].geom, sizeof(dContact)), 1);  // ODE's own NaN normal
  dContact before[4];
  std::memcpy(before, batch, sizeof batch);
  EXPECT_EQ(ssStepper_SoftenContacts(stepper, batch, 4), SS_ERROR_NOT_FINITE);
  EXPECT_TRUE(Names("normal not finite")) << ssLastError();
  EXPECT_EQ(std::memcmp(before, batch, sizeof batch), 0);
  batch[2] = batch[1];
  batch[3].surface.soft_cfm = -1e-4;  // a tuned value ODE would take as negative compliance
  std::memcpy(before, batch, sizeof batch);
  EXPECT_EQ(ssStepper_SoftenContacts(stepper, batch, 4), SS_ERROR_OUT_OF_RANGE);
  EXPECT_TRUE(Names("-0.0001")) << ssLastError();
  EXPECT_EQ(std::memcmp(before, batch, sizeof batch), 0);
  batch[3].surface.soft_cfm = 1e-4;
  EXPECT_EQ(ssStepper_SoftenContacts(stepper, batch, 4), SS_OK) << ssLastError();
}

// Every value of a contact's geometry (its position's and normal's x, y and z, its depth), at every place in a batch
// whose surface is the last one softened, refused by name when it is NaN or either infinity: the check that serves
// such a batch sums them, and a sum of finite values is what it takes as finite.
TEST_F(PromiseTest, ABatchWithAnyGeometryValueNotFiniteIsRefusedAndLeftAsGiven) {
  ASSERT_EQ(Make(Def()), SS_OK) << ssLastError();
  dContact batch[4];
  std::memset(batch, 0, sizeof batch);
  for (dContact& c : batch) {
    c.geom.pos[0] = 0.25, c.geom.pos[1] = -0.5, c.geom.normal[2] = 1, c.geom.depth = 0.001;
    c.surface.mode = dContactSoftCFM, c.surface.soft_cfm = 1e-4;
  }
  const double bad[] = {NAN, INFINITY, -INFINITY};
  const char* names[] = {"position", "position", "position", "normal", "normal", "normal", "depth"};
  for (int place = 0; place < 4; ++place)
    for (int value = 0; value < 7; ++value)
      for (double b : bad) {
        ASSERT_EQ(ssStepper_SoftenContacts(stepper, batch, 4), SS_OK) << ssLastError();  // the memo is this surface
        dContact given[4];
        std::memcpy(given, batch, sizeof batch);
        dContactGeom& geom = given[place].geom;
        (value < 3 ? geom.pos[value] : value < 6 ? geom.normal[value - 3] : geom.depth) = b;
        dContact before[4];
        std::memcpy(before, given, sizeof given);
        EXPECT_EQ(ssStepper_SoftenContacts(stepper, given, 4), SS_ERROR_NOT_FINITE)
            << "contact " << place << ", value " << value << " = " << b;
        EXPECT_TRUE(Names(names[value])) << ssLastError();
        EXPECT_EQ(std::memcmp(before, given, sizeof given), 0);
      }
}

TEST_F(PromiseTest, ABatchRefusesANullStepperANullArrayAndANegativeCount) {
  ASSERT_EQ(Make(Def()), SS_OK) << ssLastError();
  dContact contact;
  std::memset(&contact, 0, sizeof contact);
  EXPECT_EQ(ssStepper_SoftenContacts(nullptr, &contact, 1), SS_ERROR_OUT_OF_RANGE);
  EXPECT_TRUE(Names("stepper = NULL")) << ssLastError();
  EXPECT_EQ(ssStepper_SoftenContacts(stepper, nullptr, 2), SS_ERROR_OUT_OF_RANGE);
  EXPECT_TRUE(Names("contacts = NULL with count = 2")) << ssLastError();
  EXPECT_EQ(ssStepper_SoftenContacts(stepper, &contact, -1), SS_ERROR_OUT_OF_RANGE);
  EXPECT_TRUE(Names("count = -1")) << ssLastError();
  EXPECT_EQ(ssStepper_SoftenContacts(stepper, nullptr, 0), SS_OK);  // dCollide found nothing
}

// A geom set far from its body (dGeomSetOffsetPosition) lies beyond the bound before its body does: the body's bound
// is what is left of SS_MAX_POSITION_M.
TEST_F(PromiseTest, AGeomsOffsetFromItsBodyCountsTowardThePositionBound) {
  dBodyID body = MakeBody(1.0, 0, 0, 1);
  dGeomID geom = dCreateBox(space, 0.1, 0.1, 0.1);
  dGeomSetBody(geom, body);
  dGeomSetOffsetPosition(geom, 0.75 * SS_MAX_POSITION_M, 0, 0);
  ASSERT_EQ(Make(Def()), SS_OK) << ssLastError();
  ASSERT_EQ(ssStepper_Step(stepper, 1.0 / 60, nullptr), SS_OK) << ssLastError();
  dBodySetPosition(body, 0.5 * SS_MAX_POSITION_M, 0, 1);  // within the bound, but its geom at 1.25 times it
  EXPECT_EQ(ssStepper_Step(stepper, 1.0 / 60, nullptr), SS_ERROR_POSITION_LIMIT);
  EXPECT_TRUE(Names("with a geom offset 750000 m from it")) << ssLastError();
}

TEST_F(PromiseTest, TheRunawayLeftByAResetWithoutRepairIsRefusedAgainNotStepped) {
  dBodyID body = Box(0, 0, 1);
  ssStepperDef def = Def();
  def.stepping.max_speed = 100;
  ASSERT_EQ(Make(def), SS_OK) << ssLastError();
  dBodySetLinearVel(body, 90, 0, 0);
  dBodyAddForce(body, 6000, 0, 0);  // 100 m/s more over the frame
  ssFrameReport report;
  EXPECT_EQ(ssStepper_Step(stepper, 1.0 / 60, &report), SS_ERROR_SPEED_LIMIT);
  EXPECT_TRUE(Names("after step 1 of 1")) << ssLastError();
  ssStepper_Reset(stepper);  // without the repair
  const double x = dBodyGetPosition(body)[0];
  EXPECT_EQ(ssStepper_Step(stepper, 1.0 / 60, &report), SS_ERROR_SPEED_LIMIT);
  EXPECT_TRUE(Names("before the frame")) << ssLastError();
  EXPECT_EQ(report.steps, 0);
  EXPECT_EQ(dBodyGetPosition(body)[0], x);
}

TEST_F(PromiseTest, ABodyFallingFarInAHashSpaceIsStoppedAtThePositionBoundBeforeTheSpaceAborts) {
  dBodyID body = Box(0, 0, -0.99 * SS_MAX_POSITION_M);
  ssStepperDef def = Def();
  def.stepping.max_speed = 0;  // the widest guard: the speed alone would let it go on to ODE's abort
  ASSERT_EQ(Make(def), SS_OK) << ssLastError();
  dBodySetLinearVel(body, 0, 0, -1e5);
  ssStatus status = SS_OK;
  int frames = 0;
  for (; frames < 100 && status == SS_OK; ++frames) status = ssStepper_Step(stepper, 1.0 / 60, nullptr);
  EXPECT_EQ(status, SS_ERROR_POSITION_LIMIT);
  EXPECT_TRUE(Names("SS_MAX_POSITION_M")) << ssLastError();
  EXPECT_LT(std::fabs(dBodyGetPosition(body)[2]), SS_MAX_POSITION_M + 1e5 / 60 + 1);
}

// ---- b. callbacks that destroy and re-enter ----

struct Destroyer {
  ssStepper** stepper;
  dBodyID body;
  int at_step;  // destroy before (or after) this step index
  PromiseTest* test;
  int done = 0;
};

void DestroyBodyOnce(void* context, ssStepper* stepper) {
  auto* d = static_cast<Destroyer*>(context);
  if (d->done || ssStepper_CurrentStep(stepper).index != d->at_step) return;
  d->done = 1;
  dGeomDestroy(dBodyGetFirstGeom(d->body));
  EXPECT_EQ(ssStepper_DestroyBody(stepper, d->body), SS_OK);
}

// Two gears on hinges to the static world, geared 2:1 by a transmission joint. ODE 0.16 aborts the process when a
// gear turns by pi or more between two steps (transmission.cpp): a torque added in step_done that would spin a gear
// up within the speed guard (at 1/60 s, 188 rad/s turn pi) is stopped by name before the step it would act in (its
// spin plus what the torque adds over the step, on the smallest principal moment); the frame before it, at a modest
// spin, is stepped as usual.
TEST_F(PromiseTest, AGearSpunPastHalfATurnAStepIsStoppedBeforeODEsTransmissionAborts) {
  dBodyID gears[2];
  Gears(gears);
  dBodySetAngularVel(gears[0], 0, 1, 0);
  ssStepperDef def = Def();
  def.stepping.solver = SS_SOLVER_STEP;
  struct Spin {
    dBodyID gear;
    bool on = false;
  } spin{gears[0]};
  def.step_done = [](void* context, double) {
    auto* spin = static_cast<Spin*>(context);
    if (spin->on) dBodyAddTorque(spin->gear, 0, 10, 0);  // about 100 rad/s more a step on a 0.1 m box
  };
  def.step_done_context = &spin;
  ASSERT_EQ(Make(def), SS_OK) << ssLastError();
  ssFrameReport report;
  ASSERT_EQ(ssStepper_Step(stepper, 1.0 / 30, &report), SS_OK) << ssLastError();
  spin.on = true;
  ssStatus status = SS_OK;
  for (int frame = 0; frame < 20 && status == SS_OK; ++frame) status = ssStepper_Step(stepper, 1.0 / 30, &report);
  EXPECT_EQ(status, SS_ERROR_SPEED_LIMIT);
  EXPECT_TRUE(Names("turns its transmission gear") && Names("SS_MAX_GEAR_TURN_RAD")) << ssLastError();
  EXPECT_TRUE(report.failed_body == gears[0] || report.failed_body == gears[1]);
  // refused before the step whose torque would spin it past: the gear never got there
  EXPECT_TRUE(Names("with its force and torque")) << ssLastError();
  const double spun = std::sqrt(std::pow(dBodyGetAngularVel(report.failed_body)[1], 2));
  EXPECT_LE(spun * (1.0 / 60), SS_MAX_GEAR_TURN_RAD);
  EXPECT_EQ(ssStepper_Step(stepper, 1.0 / 30, &report), SS_ERROR_FAILED);
}

// ODE measures each gear's phase towards the mesh, which lies between the gears' anchors, so gears on free bodies
// that move relative to each other turn it with no spin at all: fuzz_callbacks found a world where that aborted
// Debian's ODE (`fabs(phase_hat - phase[i]) < M_PI`; the input is kept in its seed corpus,
// gears-slide-past-each-other). The line between the anchors may swing by asin(moved / distance) in a step, and by
// pi once they may pass: here the stepper refuses by name the step in which they could, and steps the ones before.
TEST_F(PromiseTest, GearsThatSlidePastEachOtherAreStoppedBeforeODEsTransmissionAborts) {
  dBodyID gears[2];
  Gears(gears, false);
  dWorldSetGravity(world, 0, 0, 0);
  dBodySetLinearVel(gears[1], -6, 0, 0);  // 0.1 m a step at 1/60 s: past the other gear in 6 steps
  ssStepperDef def = Def();
  def.stepping.solver = SS_SOLVER_STEP;
  ASSERT_EQ(Make(def), SS_OK) << ssLastError();
  ssFrameReport report;
  ssStatus status = SS_OK;
  int frames = 0;
  for (; frames < 20 && status == SS_OK; ++frames) status = ssStepper_Step(stepper, 1.0 / 60, &report);
  EXPECT_EQ(status, SS_ERROR_SPEED_LIMIT);
  EXPECT_TRUE(Names("swing of the line between the gears' anchors")) << ssLastError();
  EXPECT_TRUE(report.failed_body == gears[0] || report.failed_body == gears[1]);
  EXPECT_GE(frames, 3);  // the frames while they were well apart were stepped
  const dReal* a = dBodyGetPosition(gears[0]);
  const dReal* b = dBodyGetPosition(gears[1]);
  EXPECT_GT(b[0] - a[0], 0.0);  // refused before they passed
}

// ODE 0.16 measures a gear's phase from the step before and aborts when the gear's turn since then is not what its
// spin predicts to within pi. After a failure the runaway step has turned the gears by any angle (often by pi
// exactly: the rotation integrated from a runaway spin), and the program's repair sets their spins to zero. Here the
// program restores a gear at rest flipped by exactly half a turn about its axis, then calls ssStepper_Reset, as
// after a failure, and spins the other gear: the next frames step, and the gears stay meshed (ODE's phase error
// r1·phase1 + r2·phase2 near 0). ODE with its asserts aborts at that step: the same program without Reset, in a
// child process of its own, shows that the case is the real one.
TEST_F(PromiseTest, AGearTurnedHalfATurnAndResetIsMeasuredAfreshNotAborted) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  auto program = [this](bool reset) {
    dBodyID gears[2];
    dJointID transmission = Gears(gears);
    ssStepperDef def = Def();
    def.stepping.solver = SS_SOLVER_STEP;
    int refused = Make(def) != SS_OK || ssStepper_Step(stepper, 1.0 / 60, nullptr) != SS_OK;
    const dMatrix3 flipped = {-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -1, 0};  // half a turn about y, exact in any precision
    dBodySetRotation(gears[0], flipped);
    if (reset) ssStepper_Reset(stepper);
    dBodySetAngularVel(gears[1], 0, 1, 0);
    for (int frame = 0; frame < 30 && !refused; ++frame) refused = ssStepper_Step(stepper, 1.0 / 60, nullptr) != SS_OK;
    return refused ? nullptr : transmission;
  };
  if (OdeAsserts()) {
    EXPECT_EXIT(program(false), ::testing::KilledBySignal(SIGABRT), "transmission");
  }
  dJointID transmission = program(true);
  ASSERT_NE(transmission, nullptr) << ssLastError();
  const double phase1 = dJointGetTransmissionAngle1(transmission), phase2 = dJointGetTransmissionAngle2(transmission);
  const double r1 = dJointGetTransmissionRadius1(transmission), r2 = dJointGetTransmissionRadius2(transmission);
  EXPECT_GT(std::fabs(phase2), 0.05);  // measured from 0 at the flipped pose: turned by the spin, not by pi
  EXPECT_LT(std::fabs(phase2), 1.0);
  EXPECT_LT(std::fabs(r1 * phase1 + r2 * phase2), 1e-3 * r2 * std::fabs(phase2)) << phase1 << " " << phase2;
}

TEST_F(PromiseTest, DestroyingAKnownBodyFromEachCallbackIsSafe) {
  for (int where = 0; where < 3; ++where) {  // before_step, collide, step_done
    SCOPED_TRACE(where);
    ssStepper_Destroy(stepper);
    stepper = nullptr;
    dBodyID doomed = Box(0, 0, 0.05), other = Box(0.05, 0, 0.05);  // touching: contacts with the doomed one
    dJointID hinge = dJointCreateHinge(world, 0);
    dJointAttach(hinge, doomed, other);
    ssStepperDef def = Def();
    Destroyer d{&stepper, doomed, 1, this};
    if (where == 0) {
      def.before_step = DestroyBodyOnce;
      def.before_step_context = &d;
    } else if (where == 1) {
      def.collide = [](void* context, ssStepper* s) {  // after the contacts with it were made
        PromiseTest::Collide(static_cast<Destroyer*>(context)->test, s);
        DestroyBodyOnce(context, s);
      };
      def.collide_context = &d;
    } else {
      def.step_done = [](void* context, double) {
        auto* d = static_cast<Destroyer*>(context);
        if (!d->done) DestroyBodyOnce(context, *d->stepper);
      };
      def.step_done_context = &d;
      d.at_step = 0;
    }
    ASSERT_EQ(Make(def), SS_OK) << ssLastError();
    const int known = ssStepper_KnownBodyCount(stepper);
    ssFrameReport report;
    ASSERT_EQ(ssStepper_Step(stepper, 0.05, &report), SS_OK) << ssLastError();
    EXPECT_EQ(d.done, 1);
    EXPECT_EQ(report.steps, 3);
    EXPECT_EQ(ssStepper_KnownBodyCount(stepper), known - 1);
    for (int frame = 0; frame < 5; ++frame) ASSERT_EQ(ssStepper_Step(stepper, 0.05, nullptr), SS_OK) << ssLastError();
    EXPECT_TRUE(std::isfinite(dBodyGetPosition(other)[0]));
    ASSERT_EQ(ssStepper_DestroyBody(stepper, other), SS_OK);
  }
}

// Under fixed steps the stepper keeps every known body's last two poses: a watched body the program unwatches and
// destroys in a callback is never read again (under AddressSanitizer a read would be a heap-use-after-free report).
TEST_F(PromiseTest, ABodyUnwatchedAndDestroyedInACallbackIsForgottenByThePoseHistory) {
  dBodyID bob = MakeBody(1.0, 0, 0, 1);  // no geom: known only because it is watched
  ssStepperDef def = Def();
  ssSteppingForPolicy("fixed", 0, &def.stepping);
  struct Program {
    ssStepper** stepper;
    dBodyID bob;
    int calls = 0;
  } program{&stepper, bob};
  def.before_step = [](void* context, ssStepper* s) {
    auto* p = static_cast<Program*>(context);
    if (++p->calls != 3 || p->bob == nullptr) return;
    EXPECT_EQ(ssStepper_UnwatchBody(s, p->bob), SS_OK);
    dBodyDestroy(p->bob);  // with ODE's own call, after unwatching it
    p->bob = nullptr;
  };
  def.before_step_context = &program;
  ASSERT_EQ(Make(def), SS_OK) << ssLastError();
  ASSERT_EQ(ssStepper_WatchBody(stepper, bob), SS_OK);
  for (int frame = 0; frame < 4; ++frame) ASSERT_EQ(ssStepper_Step(stepper, 0.04, nullptr), SS_OK) << ssLastError();
  EXPECT_EQ(program.bob, nullptr);
  double position[3], quaternion[4];
  EXPECT_EQ(ssStepper_InterpolatedPose(stepper, bob, position, quaternion), SS_ERROR_NOT_FOUND);
}

// A near callback that makes contacts but forgets ssStepper_SoftenContact is told, step by step, in the frame's
// report: its contacts keep the softness tuned for one step length.
TEST_F(PromiseTest, ContactsMadeButNotSoftenedAreCountedInTheReport) {
  dWorldSetGravity(world, 0, 0, -9.81);
  dCreatePlane(space, 0, 0, 1, 0);
  Box(0, 0, 0.04);  // resting on the ground: contacts at every step
  ssStepperDef def = Def();
  def.collide = [](void* context, ssStepper*) {
    auto* test = static_cast<PromiseTest*>(context);
    dSpaceCollide(test->space, test, [](void* data, dGeomID a, dGeomID b) {  // the program's, without the line
      auto* t = static_cast<PromiseTest*>(data);
      dContact contact[4];
      std::memset(contact, 0, sizeof contact);
      int n = dCollide(a, b, 4, &contact[0].geom, sizeof contact[0]);
      dBodyID b1 = dGeomGetBody(a), b2 = dGeomGetBody(b);
      for (int i = 0; i < n; ++i)
        dJointAttach(dJointCreateContact(dBodyGetWorld(b1 ? b1 : b2), t->contacts, &contact[i]), b1, b2);
    });
  };
  ASSERT_EQ(Make(def), SS_OK) << ssLastError();
  ssFrameReport report;
  ASSERT_EQ(ssStepper_Step(stepper, 0.05, &report), SS_OK) << ssLastError();
  EXPECT_EQ(report.steps, 3);
  EXPECT_EQ(report.unsoftened_contact_steps, 3);
  ssStepper_Destroy(stepper);
  stepper = nullptr;
  ASSERT_EQ(Make(Def()), SS_OK) << ssLastError();  // the same world, its contacts softened
  ASSERT_EQ(ssStepper_Step(stepper, 0.05, &report), SS_OK) << ssLastError();
  EXPECT_GT(report.contacts.by_mapping, 0);
  EXPECT_EQ(report.unsoftened_contact_steps, 0);
}

TEST_F(PromiseTest, SteppingAgainFromItsOwnCallbackIsRefusedByName) {
  Box(0, 0, 1);
  struct Reentry {
    ssStatus step = SS_OK, set = SS_OK;
    std::string step_message, set_message, reset_message;
    ssFrameReport inner;
  } r;
  ssStepperDef def = Def();
  def.before_step = [](void* context, ssStepper* stepper) {
    auto* r = static_cast<Reentry*>(context);
    r->inner.steps = 99;
    r->step = ssStepper_Step(stepper, 0.05, &r->inner);
    r->step_message = ssLastError();
    ssStepping stepping = ssStepper_Stepping(stepper);
    r->set = ssStepper_SetStepping(stepper, &stepping);
    r->set_message = ssLastError();
    ssStepper_Reset(stepper);
    r->reset_message = ssLastError();
  };
  def.before_step_context = &r;
  ASSERT_EQ(Make(def), SS_OK) << ssLastError();
  ssFrameReport report;
  ASSERT_EQ(ssStepper_Step(stepper, 0.05, &report), SS_OK) << ssLastError();
  EXPECT_EQ(report.steps, 3);  // only the frame's own steps
  EXPECT_EQ(r.step, SS_ERROR_REENTERED);
  EXPECT_NE(r.step_message.find("ssStepper_Step: called from a callback"), std::string::npos) << r.step_message;
  EXPECT_EQ(r.inner.steps, 99);  // the refused call's report is left alone
  EXPECT_EQ(r.set, SS_ERROR_REENTERED);
  EXPECT_NE(r.set_message.find("ssStepper_SetStepping"), std::string::npos) << r.set_message;
  EXPECT_NE(r.reset_message.find("ssStepper_Reset: called from a callback"), std::string::npos) << r.reset_message;
  EXPECT_STREQ(ssStatusName(SS_ERROR_REENTERED), "reentered");
}

TEST_F(PromiseTest, DestroyingTheStepperFromItsOwnCallbackEndsTheFrameThenFreesIt) {
  Box(0, 0, 1);
  for (int from_step_done = 0; from_step_done < 2; ++from_step_done) {
    ssStepperDef def = Def();
    ssStepper* own = nullptr;
    if (from_step_done) {
      def.step_done = [](void* context, double) { ssStepper_Destroy(*static_cast<ssStepper**>(context)); };
      def.step_done_context = &own;
    } else {
      def.before_step = [](void*, ssStepper* s) {
        if (ssStepper_CurrentStep(s).index == 1) ssStepper_Destroy(s);
      };
    }
    ASSERT_EQ(ssStepper_Create(&def, &own), SS_OK) << ssLastError();
    ssFrameReport report;
    EXPECT_EQ(ssStepper_Step(own, 0.05, &report), SS_OK) << ssLastError();
    EXPECT_EQ(report.steps, 1);  // from step_done after the first step; from before_step the second is not taken
    // `own` is freed now (a sanitizer build would report a leak or a use after free otherwise)
  }
}

// ---- c. a frame of exactly 0 s ----

TEST_F(PromiseTest, AFrameOfZeroSecondsReadsAndClearsTheFramesForces) {
  dBodyID body = Box(0, 0, 1);
  ASSERT_EQ(Make(Def()), SS_OK) << ssLastError();
  for (double frame_s : {1.0 / 60, 0.0, 1.0 / 60}) {
    dBodyAddForce(body, 1, 0, 0);  // 1 N on 1 kg, added every frame
    ASSERT_EQ(ssStepper_Step(stepper, frame_s, nullptr), SS_OK) << ssLastError();
  }
  // F·(1/60 + 0 + 1/60) / m, over 2 steps (float: each rounds v, 1.7e-9 m/s measured)
  EXPECT_NEAR(dBodyGetLinearVel(body)[0], 2.0 / 60, IntegratedTolerance(1e-9, 2 * kDRealEpsilon * 2.0 / 60));
}

// ---- d. the bodies the stepper knows ----

TEST_F(PromiseTest, ABodySpawnedAfterAdoptionGetsItsWholeFrameForce) {
  Box(5, 0, 0);
  ASSERT_EQ(Make(Def()), SS_OK) << ssLastError();
  const int adopted = ssStepper_Adopted(stepper).bodies;
  ASSERT_EQ(ssStepper_Step(stepper, 0.05, nullptr), SS_OK);
  dBodyID spawned = Box(0, 0, 0);  // a box spawned on a key press
  for (int frame = 0; frame < 20; ++frame) {  // 1 s of 1/20 s frames, each 3 substeps of 1/60 s
    dBodyAddForce(spawned, 1, 0, 0);
    ssFrameReport report;
    ASSERT_EQ(ssStepper_Step(stepper, 1.0 / 20, &report), SS_OK) << ssLastError();
    ASSERT_EQ(report.steps, 3);
  }
  // F·t / m, over 60 steps (float: each rounds v, 3e-7 m/s measured)
  EXPECT_NEAR(dBodyGetLinearVel(spawned)[0], 1.0, IntegratedTolerance(1e-9, 60 * kDRealEpsilon * 1.0));
  EXPECT_EQ(ssStepper_Adopted(stepper).bodies, adopted + 1);
}

TEST_F(PromiseTest, ABodySpawnedInACallbackIsFoundBeforeTheNextStep) {
  Box(5, 0, 0);
  struct Spawner {
    PromiseTest* test;
    dBodyID body = nullptr;
    int known_after = 0;
  } spawner{this};
  ssStepperDef def = Def();
  def.before_step = [](void* context, ssStepper*) {
    auto* s = static_cast<Spawner*>(context);
    if (s->body == nullptr) s->body = s->test->Box(0, 0, 0);
  };
  def.before_step_context = &spawner;
  def.step_done = [](void* context, double) {
    auto* s = static_cast<Spawner*>(context);
    if (s->known_after == 0) s->known_after = -1;
  };
  def.step_done_context = &spawner;
  ASSERT_EQ(Make(def), SS_OK) << ssLastError();
  EXPECT_EQ(ssStepper_KnownBodyCount(stepper), 1);
  ASSERT_EQ(ssStepper_Step(stepper, 0.05, nullptr), SS_OK) << ssLastError();
  EXPECT_EQ(ssStepper_KnownBodyCount(stepper), 2);
  EXPECT_EQ(ssStepper_Adopted(stepper).bodies, 2);
  // known: its state is checked before every step
  dBodySetLinearVel(spawner.body, NAN, 0, 0);
  ssFrameReport report;
  EXPECT_EQ(ssStepper_Step(stepper, 0.05, &report), SS_ERROR_BLOWUP);
  EXPECT_EQ(report.failed_body, spawner.body);
}

// The stepper looks at an adopted space's geom count and its first geom to find what was added since: a program
// that destroys a box and spawns another between frames leaves the count as it was. In every kind of space that
// lists its geoms (a hash and a simple space add at the head of their list, sweep-and-prune appends), the spawned
// body is known at the next frame: its state is checked before ODE steps it.
TEST_F(PromiseTest, ABoxSpawnedInPlaceOfADestroyedOneIsFoundAtTheSameGeomCount) {
  struct Kind {
    const char* name;
    dSpaceID (*make)();
  } kinds[] = {
      {"hash", [] { return dHashSpaceCreate(0); }},
      {"simple", [] { return dSimpleSpaceCreate(0); }},
      {"sweep-and-prune", [] { return dSweepAndPruneSpaceCreate(0, dSAP_AXES_XYZ); }},
  };
  for (const Kind& kind : kinds) {
    for (int doomed_index = 0; doomed_index < 3; ++doomed_index) {
      SCOPED_TRACE(std::string(kind.name) + ", destroying box " + std::to_string(doomed_index));
      dSpaceID boxes = kind.make();
      dBodyID bodies[3];
      for (int i = 0; i < 3; ++i) {
        bodies[i] = MakeBody(1.0, 2.0 * i, 0, 0);
        dGeomSetBody(dCreateBox(boxes, 0.1, 0.1, 0.1), bodies[i]);
      }
      ssStepperDef def = Def();
      def.space = boxes;
      def.collide = nullptr;
      ssStepper* own = nullptr;
      ASSERT_EQ(ssStepper_Create(&def, &own), SS_OK) << ssLastError();
      ASSERT_EQ(ssStepper_Step(own, 1.0 / 60, nullptr), SS_OK) << ssLastError();
      const int geoms = dSpaceGetNumGeoms(boxes);
      dBodyID doomed = bodies[doomed_index];
      dGeomDestroy(dBodyGetFirstGeom(doomed));
      ASSERT_EQ(ssStepper_DestroyBody(own, doomed), SS_OK);
      dBodyID spawned = MakeBody(1.0, 0, 3, 0);
      dGeomSetBody(dCreateBox(boxes, 0.1, 0.1, 0.1), spawned);
      ASSERT_EQ(dSpaceGetNumGeoms(boxes), geoms);
      dBodySetLinearVel(spawned, NAN, 0, 0);
      ssFrameReport report;
      EXPECT_EQ(ssStepper_Step(own, 1.0 / 60, &report), SS_ERROR_BLOWUP);
      EXPECT_EQ(report.failed_body, spawned);
      EXPECT_TRUE(Names("before the frame")) << ssLastError();
      ssStepper_Destroy(own);
      dSpaceDestroy(boxes);
    }
  }
}

TEST_F(PromiseTest, ABobHungFromAKnownBodyIsKnownThroughItsJointAndOneHungFromTheWorldIsWatched) {
  dBodyID box = Box(0, 0, 0);
  ssStepperDef def = Def();
  def.stepping.max_step_s = 1.0 / 60;
  ASSERT_EQ(Make(def), SS_OK) << ssLastError();
  ASSERT_EQ(ssStepper_Step(stepper, 0.05, nullptr), SS_OK);
  // Made after the stepper, without a geom: a slider from the known box (found through the box's joints), and a
  // slider from the static world (nothing the stepper sees reaches it: the program watches it).
  dBodyID bob = MakeBody(1.0, 0, 0, -1), hung = MakeBody(1.0, 3, 0, -1);
  dJointID slider = dJointCreateSlider(world, 0);
  dJointAttach(slider, bob, box);
  dJointSetSliderAxis(slider, 1, 0, 0);
  dJointID rail = dJointCreateSlider(world, 0);
  dJointAttach(rail, hung, 0);
  dJointSetSliderAxis(rail, 1, 0, 0);
  EXPECT_EQ(ssStepper_KnownBodyCount(stepper), 1);  // the bob is found at the next frame, the hung body never
  ASSERT_EQ(ssStepper_WatchBody(stepper, hung), SS_OK);
  const double v_box = dBodyGetLinearVel(box)[0];
  for (int frame = 0; frame < 20; ++frame) {
    dBodyAddForce(bob, 1, 0, 0);
    dBodyAddForce(hung, 1, 0, 0);
    ASSERT_EQ(ssStepper_Step(stepper, 1.0 / 20, nullptr), SS_OK) << ssLastError();
  }
  EXPECT_EQ(ssStepper_KnownBodyCount(stepper), 3);
  // F·t / m on its rail, over 60 steps (float: each rounds v, 3e-7 m/s measured)
  EXPECT_NEAR(dBodyGetLinearVel(hung)[0], 1.0, IntegratedTolerance(1e-9, 60 * kDRealEpsilon * 1.0));
  // the bob and the box share the momentum along the slider: (m_bob + m_box) v = F t
  EXPECT_NEAR(dBodyGetLinearVel(bob)[0] + dBodyGetLinearVel(box)[0] - v_box, 1.0, 1e-6);
}

// ---- e. a frame of one step leaves the program's forces as it added them ----

TEST_F(PromiseTest, AOneStepFrameStepsTheProgramsForcesBitForBit) {
  // A force where F·h/h is not F: the rewrite would show in the last bit.
  const double h = 1.0 / 60;
  double force = 0;
  for (int milli = 1; milli <= 3000 && force == 0; ++milli)
    if (milli / 1000.0 * h / h != milli / 1000.0) force = milli / 1000.0;
  ASSERT_GT(force, 0);
  dWorldID own = dWorldCreate();  // the program's own stepping, beside the one through the stepper
  dWorldSetGravity(own, 0, 0, 0);
  dBodyID mine = dBodyCreate(own);
  dBodyID body = Box(0, 0, 0);
  dMass mass;
  dBodyGetMass(body, &mass);
  dBodySetMass(mine, &mass);
  ssStepperDef def = Def();
  def.collide = nullptr;
  struct Seen {
    dBodyID body;
    std::vector<double> forces;  // the x force in ODE's accumulator just before each step
  } seen{body, {}};
  def.before_step = [](void* context, ssStepper*) {
    auto* seen = static_cast<Seen*>(context);
    seen->forces.push_back(dBodyGetForce(seen->body)[0]);
  };
  def.before_step_context = &seen;
  ssSteppingForPolicy("naive", h, &def.stepping);
  ASSERT_EQ(Make(def), SS_OK) << ssLastError();
  for (int frame = 0; frame < 30; ++frame) {
    dBodyAddForce(mine, force, 0.3 * force, 0);
    dBodyAddTorque(mine, 0, 0, force);
    dWorldQuickStep(own, h);
    dBodyAddForce(body, force, 0.3 * force, 0);
    dBodyAddTorque(body, 0, 0, force);
    ASSERT_EQ(ssStepper_Step(stepper, h, nullptr), SS_OK) << ssLastError();
  }
  ASSERT_EQ(seen.forces.size(), 30u);
  // as added (ODE holds F rounded once to dReal), not F·h/h; in float a rewrite in double would round back to the
  // same bits, and the states compared below are what says the steps were the program's own
  for (double seen_force : seen.forces) EXPECT_EQ(seen_force, AsDReal(force));
  EXPECT_EQ(std::memcmp(dBodyGetLinearVel(mine), dBodyGetLinearVel(body), 3 * sizeof(dReal)), 0);
  EXPECT_EQ(std::memcmp(dBodyGetAngularVel(mine), dBodyGetAngularVel(body), 3 * sizeof(dReal)), 0);
  EXPECT_EQ(std::memcmp(dBodyGetPosition(mine), dBodyGetPosition(body), 3 * sizeof(dReal)), 0);
  dWorldDestroy(own);
}

TEST_F(PromiseTest, TheStepperWritesNoSolverSettingTheProgramDidNotAskFor) {
  Box(0, 0, 0);
  dWorldSetQuickStepNumIterations(world, 37);
  dWorldSetQuickStepW(world, 1.1);
  ASSERT_EQ(Make(Def()), SS_OK) << ssLastError();
  for (int frame = 0; frame < 5; ++frame) ASSERT_EQ(ssStepper_Step(stepper, 0.05, nullptr), SS_OK);
  EXPECT_EQ(dWorldGetQuickStepNumIterations(world), 37);
  EXPECT_EQ(dWorldGetQuickStepW(world), AsDReal(1.1));
}

}  // namespace

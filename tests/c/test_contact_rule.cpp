// ssStepper_CollideByRule against the near callback it stands for, written out as ODE's demos write it (nested
// spaces collided with dSpaceCollide2, a contact softened with ssStepper_SoftenContact, then joined): two copies of
// one scene, a pile of boxes and balls on the ground, a hinged pair and balls in a nested space, stepped under
// every cut with frame times that vary, end in the same bits. And every refusal leaves the group without a joint.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "ode_fixture.h"
#include "test_stepping.h"
#include "steadystep/steadystep.h"

namespace {

const double kTunedStepS = 1.0 / 60.0;

// The near callback the rule stands for (the test's truth, written independently of contact_rule.c).
struct Hand {
  ssStepper* stepper;
  dWorldID world;
  dJointGroupID contacts;
  dContact surface;
  int max_contacts;
  bool skip_connected;
};

void HandNear(void* data, dGeomID a, dGeomID b) {
  auto* hand = static_cast<Hand*>(data);
  if (dGeomIsSpace(a) || dGeomIsSpace(b)) {
    dSpaceCollide2(a, b, data, HandNear);
    return;
  }
  dBodyID body_a = dGeomGetBody(a), body_b = dGeomGetBody(b);
  if (body_a == 0 && body_b == 0) return;
  if (hand->skip_connected && body_a && body_b && dAreConnectedExcluding(body_a, body_b, dJointTypeContact)) return;
  std::vector<dContact> contact(hand->max_contacts);
  int count = dCollide(a, b, hand->max_contacts, &contact[0].geom, sizeof(dContact));
  for (int i = 0; i < count; ++i) {
    contact[i].surface = hand->surface.surface;
    std::memcpy(contact[i].fdir1, hand->surface.fdir1, sizeof contact[i].fdir1);
    ASSERT_EQ(ssStepper_SoftenContact(hand->stepper, &contact[i], body_a, body_b), SS_OK) << ssLastError();
    dJointAttach(dJointCreateContact(hand->world, hand->contacts, &contact[i]), body_a, body_b);
  }
}

// One copy of the scene, stepped through a stepper that adopted it, by hand or by the rule.
struct Scene {
  dWorldID world = nullptr;
  dSpaceID space = nullptr;
  dJointGroupID contacts = nullptr;
  std::vector<dBodyID> bodies;
  ssStepper* stepper = nullptr;
  Hand hand = {};
  ssContactRule rule = ssDefaultContactRule();
  bool by_rule = false;
  ssContactRuleReport last = {};
  int rule_contacts = 0;

  dBodyID Body(double x, double y, double z, dGeomID geom) {
    dBodyID body = dBodyCreate(world);
    dMass mass;
    dMassSetBoxTotal(&mass, 1.0, 0.2, 0.2, 0.2);
    dBodySetMass(body, &mass);
    dBodySetPosition(body, x, y, z);
    dGeomSetBody(geom, body);
    bodies.push_back(body);
    return body;
  }

  void Build(const dContact& surface, int max_contacts, bool skip_connected, const char* policy, bool rule_mode) {
    world = dWorldCreate();
    dWorldSetGravity(world, 0, 0, -9.81);
    dWorldSetERP(world, 0.3);
    dWorldSetCFM(world, 1e-5);
    space = dHashSpaceCreate(0);
    contacts = dJointGroupCreate(0);
    dCreatePlane(space, 0, 0, 1, 0);
    for (int i = 0; i < 12; ++i)  // a loose pile: boxes over balls, touching as they fall
      Body(0.15 * (i % 4), 0.25 * (i / 4), 0.1 + 0.21 * (i % 3), i % 2 ? dCreateBox(space, 0.2, 0.2, 0.2)
                                                                     : dCreateSphere(space, 0.1));
    dBodyID left = Body(1.5, 0, 0.3, dCreateBox(space, 0.2, 0.2, 0.2));  // a hinged pair whose boxes overlap
    dBodyID right = Body(1.65, 0, 0.3, dCreateBox(space, 0.2, 0.2, 0.2));
    dJointID hinge = dJointCreateHinge(world, 0);
    dJointAttach(hinge, left, right);
    dJointSetHingeAnchor(hinge, 1.575, 0, 0.3);
    dJointSetHingeAxis(hinge, 0, 1, 0);
    dSpaceID nested = dSimpleSpaceCreate(space);  // balls in a space of their own
    for (int i = 0; i < 3; ++i) Body(-1.0, 0.15 * i, 0.1 + 0.2 * i, dCreateSphere(nested, 0.1));

    ssStepperDef def = TestStepperDef();
    ASSERT_EQ(ssSteppingForPolicy(policy, 0, &def.stepping), SS_OK) << ssLastError();
    def.world = world;
    def.space = space;
    def.tuned_step_s = kTunedStepS;
    def.contact_group = contacts;
    def.collide_context = this;
    def.collide = [](void* context, ssStepper* stepper) {
      auto* scene = static_cast<Scene*>(context);
      if (scene->by_rule) {
        ASSERT_EQ(ssStepper_CollideByRule(stepper, &scene->rule, &scene->last), SS_OK) << ssLastError();
        scene->rule_contacts += scene->last.contacts;
      } else {
        dSpaceCollide(scene->space, &scene->hand, HandNear);
      }
    };
    ASSERT_EQ(ssStepper_Create(&def, &stepper), SS_OK) << ssLastError();
    hand = {stepper, world, contacts, surface, max_contacts, skip_connected};
    rule.world = world;
    rule.space = space;
    rule.contact_group = contacts;
    rule.surface = &hand.surface;
    rule.max_contacts = max_contacts;
    rule.skip_connected = skip_connected;
    by_rule = rule_mode;
  }

  std::vector<double> State() const {
    std::vector<double> state;
    for (dBodyID body : bodies) {
      for (const dReal* v : {dBodyGetPosition(body), dBodyGetLinearVel(body), dBodyGetAngularVel(body)})
        state.insert(state.end(), v, v + 3);
      const dReal* q = dBodyGetQuaternion(body);
      state.insert(state.end(), q, q + 4);
    }
    return state;
  }

  ~Scene() {
    ssStepper_Destroy(stepper);
    dJointGroupDestroy(contacts);
    dSpaceDestroy(space);  // destroys its geoms, the nested space's too (cleanup is on)
    dWorldDestroy(world);
  }
};

dContact Surface() {
  dContact surface;
  std::memset(&surface, 0, sizeof surface);
  surface.surface.mode = dContactBounce | dContactSoftCFM | dContactApprox1;
  surface.surface.mu = 0.8;
  surface.surface.bounce = 0.2;
  surface.surface.bounce_vel = 0.1;
  surface.surface.soft_cfm = 1e-4;
  return surface;
}

class ContactRule : public ::testing::TestWithParam<const char*> {
 protected:
  static void SetUpTestSuite() { dInitODE2(0); }
};

TEST_P(ContactRule, StepsTheWorldAsTheNearCallbackItStandsForToTheBit) {
  const double frames_s[] = {1.0 / 60, 1.0 / 30, 1.0 / 45, 1.0 / 15, 1.0 / 144, 0.02, 1.0 / 25};
  for (bool skip_connected : {false, true}) {
    Scene hand, rule;
    hand.Build(Surface(), 4, skip_connected, GetParam(), false);
    rule.Build(Surface(), 4, skip_connected, GetParam(), true);
    ssFrameReport hand_report, rule_report;
    int hand_contacts = 0, rule_contacts = 0;
    for (Scene* scene : {&hand, &rule}) {  // one after the other, each from the same state of ODE's generator
      dRandSetSeed(7);
      for (int frame = 0; frame < 90; ++frame) {
        ssFrameReport& report = scene == &hand ? hand_report : rule_report;
        ASSERT_EQ(ssStepper_Step(scene->stepper, frames_s[frame % 7], &report), SS_OK) << ssLastError();
        (scene == &hand ? hand_contacts : rule_contacts) +=
            report.contacts.by_mapping + report.contacts.handed_to_matched + report.contacts.handed_to_implicit_euler;
      }
    }
    EXPECT_GT(rule_contacts, 90 * 12);  // the pile rests on the ground: contacts at every step
    EXPECT_EQ(rule_contacts, hand_contacts);
    EXPECT_EQ(rule.rule_contacts, rule_contacts);  // each joint made was softened, and counted in the frame report
    std::vector<double> a = hand.State(), b = rule.State();
    ASSERT_EQ(a.size(), b.size());
    EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(double)), 0) << "skip_connected " << skip_connected;
    for (double value : b) ASSERT_TRUE(std::isfinite(value));
  }
}

INSTANTIATE_TEST_SUITE_P(Policies, ContactRule, ::testing::Values("naive", "implicit-euler", "matched", "fixed"),
                         [](const ::testing::TestParamInfo<const char*>& info) {
                           std::string name = info.param;
                           for (char& c : name)
                             if (c == '-') c = '_';
                           return name;
                         });

class ContactRuleRefusals : public OdeTest {};

// Every refusal names the value and makes no joint: the group stays empty and no body gains a joint.
TEST_F(ContactRuleRefusals, NameTheValueAndMakeNoJoint) {
  dWorldSetGravity(world, 0, 0, -9.81);
  dSpaceID space = dSimpleSpaceCreate(0);
  dJointGroupID contacts = dJointGroupCreate(0);
  dCreatePlane(space, 0, 0, 1, 0);
  dBodyID box = MakeBody(1.0, 0, 0, 0.04);
  dGeomSetBody(dCreateBox(space, 0.1, 0.1, 0.1), box);
  ssStepperDef def = TestStepperDef();
  def.world = world;
  def.space = space;
  def.tuned_step_s = kTunedStepS;
  def.contact_group = contacts;
  ssStepper* stepper = nullptr;
  ASSERT_EQ(ssStepper_Create(&def, &stepper), SS_OK) << ssLastError();
  dContact surface = Surface();
  ssContactRule good = ssDefaultContactRule();
  EXPECT_EQ(good.max_contacts, 4);
  EXPECT_EQ(good.skip_connected, 0);
  good.world = world;
  good.space = space;
  good.contact_group = contacts;
  good.surface = &surface;

  struct Case {
    const char* named;
    ssStatus status;
    void (*spoil)(ssContactRule* rule, dContact* surface);
  } cases[] = {
      {"rule.world = NULL", SS_ERROR_OUT_OF_RANGE, [](ssContactRule* r, dContact*) { r->world = 0; }},
      {"rule.space = NULL", SS_ERROR_OUT_OF_RANGE, [](ssContactRule* r, dContact*) { r->space = 0; }},
      {"rule.contact_group = NULL", SS_ERROR_OUT_OF_RANGE, [](ssContactRule* r, dContact*) { r->contact_group = 0; }},
      {"rule.surface = NULL", SS_ERROR_OUT_OF_RANGE, [](ssContactRule* r, dContact*) { r->surface = nullptr; }},
      {"rule.max_contacts = 0", SS_ERROR_OUT_OF_RANGE, [](ssContactRule* r, dContact*) { r->max_contacts = 0; }},
      {"rule.max_contacts = 4097", SS_ERROR_OUT_OF_RANGE,
       [](ssContactRule* r, dContact*) { r->max_contacts = SS_MAX_RULE_CONTACTS + 1; }},
      {"rule.skip_connected = 2", SS_ERROR_OUT_OF_RANGE, [](ssContactRule* r, dContact*) { r->skip_connected = 2; }},
      {"surface.mu = nan", SS_ERROR_NOT_FINITE, [](ssContactRule*, dContact* s) { s->surface.mu = NAN; }},
      {"surface.mu2 = -1", SS_ERROR_OUT_OF_RANGE, [](ssContactRule*, dContact* s) { s->surface.mu2 = -1; }},
      {"surface.bounce = 1.5", SS_ERROR_OUT_OF_RANGE, [](ssContactRule*, dContact* s) { s->surface.bounce = 1.5; }},
      {"surface.bounce_vel = -1", SS_ERROR_OUT_OF_RANGE,
       [](ssContactRule*, dContact* s) { s->surface.bounce_vel = -1; }},
      {"surface.motion1 = inf", SS_ERROR_NOT_FINITE,
       [](ssContactRule*, dContact* s) { s->surface.motion1 = INFINITY; }},
      {"fdir1", SS_ERROR_NOT_FINITE, [](ssContactRule*, dContact* s) { s->fdir1[1] = NAN; }},
      // a tuned softness no spring stands for: refused by ssStepper_SoftenContact at the first contact
      {"cfm = -1", SS_ERROR_OUT_OF_RANGE, [](ssContactRule*, dContact* s) { s->surface.soft_cfm = -1; }},
  };
  for (const Case& c : cases) {
    ssContactRule rule = good;
    dContact spoilt = surface;
    rule.surface = &spoilt;
    c.spoil(&rule, &spoilt);
    if (std::string(c.named) != "cfm = -1") {  // the rule's own values: refused alike without a stepper
      EXPECT_EQ(ssValidateContactRule(&rule), c.status) << c.named;
      EXPECT_NE(std::string(ssLastError()).find(c.named), std::string::npos) << ssLastError();
    }
    ssContactRuleReport report = {1, 1, 1};
    EXPECT_EQ(ssStepper_CollideByRule(stepper, &rule, &report), c.status) << c.named;
    EXPECT_NE(std::string(ssLastError()).find(c.named), std::string::npos) << ssLastError();
    EXPECT_EQ(dBodyGetNumJoints(box), 0) << c.named;
    EXPECT_EQ(report.contacts, 0);
  }
  EXPECT_EQ(ssValidateContactRule(&good), SS_OK) << ssLastError();
  EXPECT_EQ(ssValidateContactRule(nullptr), SS_ERROR_OUT_OF_RANGE);
  EXPECT_EQ(ssStepper_CollideByRule(nullptr, &good, nullptr), SS_ERROR_OUT_OF_RANGE);
  EXPECT_EQ(ssStepper_CollideByRule(stepper, nullptr, nullptr), SS_ERROR_OUT_OF_RANGE);

  // A body of another world in the rule's space: refused before any joint, whichever pair comes first.
  dWorldID other = dWorldCreate();
  dBodyID stranger = dBodyCreate(other);
  dBodySetPosition(stranger, 0.05, 0, 0.04);
  dGeomID stranger_geom = dCreateSphere(space, 0.05);
  dGeomSetBody(stranger_geom, stranger);
  EXPECT_EQ(ssStepper_CollideByRule(stepper, &good, nullptr), SS_ERROR_OUT_OF_RANGE);
  EXPECT_NE(std::string(ssLastError()).find("not of rule.world"), std::string::npos) << ssLastError();
  EXPECT_EQ(dBodyGetNumJoints(box), 0);
  dGeomDestroy(stranger_geom);
  dWorldDestroy(other);

  // Unadopted: no tuned step to read the surface at.
  ssStepperDef bare = TestStepperDef();
  bare.world = world;
  ssStepper* unadopted = nullptr;
  ASSERT_EQ(ssStepper_Create(&bare, &unadopted), SS_OK);
  EXPECT_EQ(ssStepper_CollideByRule(unadopted, &good, nullptr), SS_ERROR_OUT_OF_RANGE);
  EXPECT_NE(std::string(ssLastError()).find("adopt"), std::string::npos) << ssLastError();
  EXPECT_EQ(dBodyGetNumJoints(box), 0);
  ssStepper_Destroy(unadopted);

  // The good rule: the box's four corners on the ground, softened as tuned (naive's step is the tuned one).
  ssContactRuleReport report;
  ASSERT_EQ(ssStepper_CollideByRule(stepper, &good, &report), SS_OK) << ssLastError();
  EXPECT_EQ(report.pairs, 1);
  EXPECT_EQ(report.contacts, 4);
  EXPECT_EQ(report.dropped, 0);
  EXPECT_EQ(dBodyGetNumJoints(box), 4);
  dJointGroupEmpty(contacts);
  EXPECT_EQ(dBodyGetNumJoints(box), 0);
  good.max_contacts = 1;
  ASSERT_EQ(ssStepper_CollideByRule(stepper, &good, &report), SS_OK) << ssLastError();
  EXPECT_EQ(report.contacts, 1);
  dJointGroupEmpty(contacts);
  ssStepper_Destroy(stepper);
  dJointGroupDestroy(contacts);
  dSpaceDestroy(space);
}

}  // namespace

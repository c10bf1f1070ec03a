// Every kind of ODE space, nested in the layouts programs use: adopted through the def, and a body made later in
// any of them found before it steps. The truths: F·dt for a force held over a frame of four substeps, and a NaN
// spin refused by name instead of an abort inside ODE.
#include <gtest/gtest.h>

#include <cmath>
#include <ostream>
#include <string>
#include <vector>

#include "ode_fixture.h"
#include "precision.h"
#include "test_stepping.h"
#include "steadystep/steadystep.h"

namespace {

enum Kind { kSimple, kHash, kSweepAndPrune, kQuadTree };
const char* const kKindNames[] = {"simple", "hash", "sap", "quadtree"};

dSpaceID MakeSpace(Kind kind, dSpaceID parent) {
  switch (kind) {
    case kSimple: return dSimpleSpaceCreate(parent);
    case kHash: return dHashSpaceCreate(parent);
    case kSweepAndPrune: return dSweepAndPruneSpaceCreate(parent, dSAP_AXES_XYZ);
    case kQuadTree: {
      dVector3 centre = {0, 0, 0, 0}, extents = {50, 50, 50, 0};
      return dQuadTreeSpaceCreate(parent, centre, extents, 4);
    }
  }
  return nullptr;
}

// A layout: the root's kind, then the kinds of the spaces nested in it (flat: none), each as a child of the root
// (siblings: statics, dynamics) or each in the one before (a chain).
struct Layout {
  Kind root;
  std::vector<Kind> nested;
  bool chain;
};

std::string Name(const Layout& layout) {
  std::string name = kKindNames[layout.root];
  for (Kind kind : layout.nested) name += std::string(layout.chain ? "_in_" : "_and_") + kKindNames[kind];
  return name;
}

void PrintTo(const Layout& layout, std::ostream* out) { *out << Name(layout); }

bool HasQuadTree(const Layout& layout) {
  if (layout.root == kQuadTree) return true;
  for (Kind kind : layout.nested)
    if (kind == kQuadTree) return true;
  return false;
}

class Spaces : public OdeTest, public ::testing::WithParamInterface<Layout> {
 protected:
  void SetUp() override {
    OdeTest::SetUp();
    dWorldSetGravity(world, 0, 0, 0);
    const Layout& layout = GetParam();
    spaces.push_back(MakeSpace(layout.root, nullptr));
    for (Kind kind : layout.nested) spaces.push_back(MakeSpace(kind, layout.chain ? spaces.back() : spaces[0]));
    for (size_t i = 0; i < spaces.size(); ++i) Body(spaces[i], 3.0 * i);  // one body in each from the start
  }
  void TearDown() override {
    ssStepper_Destroy(stepper);
    dSpaceDestroy(spaces[0]);  // cleans up the nested spaces and every geom
    OdeTest::TearDown();
  }

  dBodyID Body(dSpaceID space, double x) {
    dBodyID body = MakeBody(2.0, x, 0, 0);
    dGeomSetBody(dCreateBox(space, 0.1, 0.1, 0.1), body);
    return body;
  }

  ssStatus Make() {
    ssStepperDef def = TestStepperDef();
    def.world = world;
    def.space = spaces[0];
    def.tuned_step_s = 1.0 / 60;
    return ssStepper_Create(&def, &stepper);
  }

  std::vector<dSpaceID> spaces;
  ssStepper* stepper = nullptr;
};

TEST_P(Spaces, ABodyMadeLaterInAnySpaceGetsItsHeldForceAndItsStateChecked) {
  if (HasQuadTree(GetParam())) {
    // ODE 0.16 cannot list a quadtree space's geoms (dSpaceGetGeom asserts there): refused by name, nothing made.
    EXPECT_EQ(Make(), SS_ERROR_UNSUPPORTED);
    EXPECT_NE(std::string(ssLastError()).find("quadtree"), std::string::npos) << ssLastError();
    EXPECT_EQ(stepper, nullptr);
    return;
  }
  ASSERT_EQ(Make(), SS_OK) << ssLastError();
  ASSERT_EQ(ssStepper_Step(stepper, 1.0 / 60, nullptr), SS_OK) << ssLastError();
  const int first_known = ssStepper_KnownBodyCount(stepper);
  for (size_t s = 0; s < spaces.size(); ++s) {
    SCOPED_TRACE("a body made in space " + std::to_string(s));
    dBodyID later = Body(spaces[s], 100.0 + 3.0 * s);
    const double force = 0.7, frame_s = 4.0 / 60;  // four substeps
    dBodyAddForce(later, force, 0, 0);              // once, before the frame
    ssFrameReport report;
    ASSERT_EQ(ssStepper_Step(stepper, frame_s, &report), SS_OK) << ssLastError();
    ASSERT_EQ(report.steps, 4);
    EXPECT_NEAR(2.0 * dBodyGetLinearVel(later)[0], force * frame_s, IntegratedTolerance(1e-9 * force * frame_s, 1e-6))
        << "the force acted on " << 2.0 * dBodyGetLinearVel(later)[0] / force << " s of the frame's " << frame_s;
    EXPECT_EQ(ssStepper_KnownBodyCount(stepper), first_known + static_cast<int>(s) + 1);
    dBodySetAngularVel(later, NAN, 0, 0);
    EXPECT_EQ(ssStepper_Step(stepper, 1.0 / 60, &report), SS_ERROR_BLOWUP);
    EXPECT_NE(std::string(ssLastError()).find("angular velocity (nan"), std::string::npos) << ssLastError();
    EXPECT_EQ(report.failed_body, later);
    dBodySetAngularVel(later, 0, 0, 0);
    dBodySetLinearVel(later, 0, 0, 0);
    ssStepper_Reset(stepper);
  }
  // A quadtree space nested later in the deepest space is refused by name at the next frame, before anything aborts,
  // and again at every frame until the program takes it out.
  dSpaceID quadtree = MakeSpace(kQuadTree, spaces.back());
  Body(quadtree, 50);
  for (int frame = 0; frame < 2; ++frame) {
    EXPECT_EQ(ssStepper_Step(stepper, 1.0 / 60, nullptr), SS_ERROR_UNSUPPORTED);
    EXPECT_NE(std::string(ssLastError()).find("quadtree"), std::string::npos) << ssLastError();
    ssStepper_Reset(stepper);
  }
  dSpaceRemove(spaces.back(), reinterpret_cast<dGeomID>(quadtree));
  EXPECT_EQ(ssStepper_Step(stepper, 1.0 / 60, nullptr), SS_OK) << ssLastError();
  dSpaceDestroy(quadtree);
}

std::vector<Layout> Layouts() {
  std::vector<Layout> layouts;
  for (int root = kSimple; root <= kQuadTree; ++root) {
    layouts.push_back({static_cast<Kind>(root), {}, false});
    for (int nested = kSimple; nested <= kQuadTree; ++nested) {
      // statics and dynamics: two siblings in the root; and a chain three deep
      layouts.push_back({static_cast<Kind>(root), {static_cast<Kind>(nested), static_cast<Kind>(nested)}, false});
      layouts.push_back({static_cast<Kind>(root), {static_cast<Kind>(nested), kHash, kSweepAndPrune}, true});
    }
  }
  layouts.push_back({kHash, {kSimple, kHash, kSweepAndPrune}, false});  // three siblings of every kind
  return layouts;
}

INSTANTIATE_TEST_SUITE_P(EveryKindAndNesting, Spaces, ::testing::ValuesIn(Layouts()),
                         [](const ::testing::TestParamInfo<Layout>& info) { return Name(info.param); });

}  // namespace

// Two ODE worlds stepped at the same time from two threads, on Debian's ODE 0.16.
//
// Every world uses ODE's process-wide default threading implementation unless it is given its own, and that one
// implementation is not safe to use from two threads at once: stepping two worlds concurrently with it aborts or
// crashes (measured: 10 of 10 runs of a 30-box pile per thread, for dWorldStep and dWorldQuickStep alike). The rule
// shown here: each world gets its own self-threaded implementation (dThreadingAllocateSelfThreadedImplementation +
// dWorldSetStepThreadingImplementation) before it is stepped, detached and freed after the world is destroyed; and
// each thread that uses ODE calls dAllocateODEDataForThread first (ODE's per-thread collision data).
//
// The truth each thread is checked against is stated independently of threads: the same world stepped alone on
// the main thread. dWorldStep uses no random numbers, so the two must be equal bit for bit. dWorldQuickStep
// shuffles its rows with ODE's one process-wide generator, so concurrent QuickSteps draw each other's numbers: the
// test checks what does not depend on the order, that every box comes to rest on the ground.
#include <gtest/gtest.h>
#include <ode/ode.h>

#include <cmath>
#include <string>
#include <thread>
#include <vector>

#include "steadystep/spring.h"
#include "steadystep/status.h"

namespace {

const int kBoxes = 24;
const double kSide = 0.2, kStep = 0.01;

void InitOdeOnce() {
  static const bool done = [] { return dInitODE2(0) != 0; }();
  ASSERT_TRUE(done);
}

struct Pile {
  dWorldID world;
  dSpaceID space;
  dJointGroupID contacts;
  ssSoftness contact_softness;
  std::vector<dBodyID> bodies;
  dThreadingImplementationID threading = nullptr;
};

void NearCallback(void* data, dGeomID a, dGeomID b) {
  Pile* pile = static_cast<Pile*>(data);
  dContact contact[4];
  int count = dCollide(a, b, 4, &contact[0].geom, sizeof contact[0]);
  for (int i = 0; i < count; ++i) {
    contact[i].surface.mode = dContactSoftERP | dContactSoftCFM;
    contact[i].surface.mu = 1.0;
    contact[i].surface.soft_erp = pile->contact_softness.erp;
    contact[i].surface.soft_cfm = pile->contact_softness.cfm;
    dJointAttach(dJointCreateContact(pile->world, pile->contacts, &contact[i]), dGeomGetBody(a), dGeomGetBody(b));
  }
}

// Builds a pile of boxes above a plane; with own_threading the world gets its own threading implementation.
void Build(Pile& pile, bool own_threading) {
  pile.world = dWorldCreate();
  if (own_threading) {
    pile.threading = dThreadingAllocateSelfThreadedImplementation();
    dWorldSetStepThreadingImplementation(pile.world, dThreadingImplementationGetFunctions(pile.threading),
                                         pile.threading);
  }
  dWorldSetGravity(pile.world, 0, 0, -9.81);
  pile.space = dHashSpaceCreate(0);
  pile.contacts = dJointGroupCreate(0);
  dCreatePlane(pile.space, 0, 0, 1, 0);
  // The contact is the spring of the ground, converted once for this step length by the library.
  ASSERT_EQ(ssImplicitEulerSoftness(ssSpring{2e4, 300}, kStep, &pile.contact_softness), SS_OK) << ssLastError();
  for (int i = 0; i < kBoxes; ++i) {
    dBodyID body = dBodyCreate(pile.world);
    dMass mass;
    dMassSetBoxTotal(&mass, 1.0, kSide, kSide, kSide);
    dBodySetMass(body, &mass);
    dBodySetPosition(body, (i % 4) * 0.3, (i / 4 % 3) * 0.3, 0.15 + 0.3 * (i / 12));
    dGeomID geom = dCreateBox(pile.space, kSide, kSide, kSide);
    dGeomSetBody(geom, body);
    pile.bodies.push_back(body);
  }
}

void Step(Pile& pile, bool quick, int steps) {
  for (int n = 0; n < steps; ++n) {
    dSpaceCollide(pile.space, &pile, NearCallback);
    if (quick)
      dWorldQuickStep(pile.world, kStep);
    else
      dWorldStep(pile.world, kStep);
    dJointGroupEmpty(pile.contacts);
  }
}

std::vector<double> State(const Pile& pile) {
  std::vector<double> state;
  for (dBodyID body : pile.bodies) {
    const dReal* p = dBodyGetPosition(body);
    const dReal* v = dBodyGetLinearVel(body);
    state.insert(state.end(), {p[0], p[1], p[2], v[0], v[1], v[2]});
  }
  return state;
}

// Destroys the world first, then its threading implementation (detached so the world never holds a freed one).
void Destroy(Pile& pile) {
  dJointGroupDestroy(pile.contacts);
  dSpaceDestroy(pile.space);
  if (pile.threading != nullptr) dWorldSetStepThreadingImplementation(pile.world, nullptr, nullptr);
  dWorldDestroy(pile.world);
  if (pile.threading != nullptr) dThreadingFreeImplementation(pile.threading);
}

// One thread's whole life with ODE: per-thread data, its own world with its own threading, stepping, clean-up.
void RunOnThread(bool quick, int steps, std::vector<double>* state) {
  dAllocateODEDataForThread(dAllocateMaskAll);
  Pile pile;
  Build(pile, /*own_threading=*/true);
  Step(pile, quick, steps);
  *state = State(pile);
  Destroy(pile);
  dCleanupODEAllDataForThread();
}

TEST(Threads, TwoWorldsStepOnTwoThreadsExactlyAsAlone) {
  InitOdeOnce();
  const int steps = 300;
  Pile alone;
  Build(alone, /*own_threading=*/false);
  Step(alone, /*quick=*/false, steps);
  std::vector<double> expected = State(alone);
  Destroy(alone);

  std::vector<double> first, second;
  std::thread a(RunOnThread, false, steps, &first), b(RunOnThread, false, steps, &second);
  a.join();
  b.join();
  EXPECT_EQ(first, expected);  // bit for bit: dWorldStep is deterministic and the threads share nothing
  EXPECT_EQ(second, expected);
}

TEST(Threads, TwoQuickStepWorldsOnTwoThreadsComeToRest) {
  InitOdeOnce();
  const int steps = 400;  // 4 s: boxes dropped from at most 0.5 m have long settled
  std::vector<double> first, second;
  std::thread a(RunOnThread, true, steps, &first), b(RunOnThread, true, steps, &second);
  a.join();
  b.join();
  for (const std::vector<double>* state : {&first, &second}) {
    ASSERT_EQ(state->size(), 6u * kBoxes);
    for (int i = 0; i < kBoxes; ++i) {
      const double* body = state->data() + 6 * i;
      for (int k = 0; k < 6; ++k) ASSERT_TRUE(std::isfinite(body[k]));
      // Resting on the ground or on one box: centre at half a side or one and a half, within the contact's give.
      double height = body[2];
      bool on_ground = std::abs(height - kSide / 2) < 0.02, on_box = std::abs(height - 1.5 * kSide) < 0.04;
      EXPECT_TRUE(on_ground || on_box) << "box " << i << " at height " << height;
      EXPECT_LT(std::hypot(body[3], body[4], body[5]), 0.05) << "box " << i;
    }
  }
}

}  // namespace

// ssSetLastError (status.h): what code built on the library (the lab) reports is what ssLastError reads, on the thread
// that reported it, cut at 255 bytes; NULL is "".
TEST(Threads, SetLastErrorIsReadOnItsOwnThreadCutAt255Bytes) {
  EXPECT_EQ(ssSetLastError(SS_ERROR_IO, "trace.txt: cannot be opened"), SS_ERROR_IO);
  std::string other_thread;
  std::thread([&] {
    ssSetLastError(SS_ERROR_PARSE, std::string(300, 'x').c_str());
    other_thread = ssLastError();
  }).join();
  EXPECT_STREQ(ssLastError(), "trace.txt: cannot be opened");
  EXPECT_EQ(other_thread, std::string(255, 'x'));
  EXPECT_EQ(ssSetLastError(SS_OK, nullptr), SS_OK);
  EXPECT_STREQ(ssLastError(), "");
}

// Test support: ODE initialised once per test program, and a world torn down with the test.
#ifndef STEADYSTEP_TESTS_ODE_FIXTURE_H
#define STEADYSTEP_TESTS_ODE_FIXTURE_H

#include <gtest/gtest.h>
#include <ode/ode.h>

class OdeTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { dInitODE2(0); }
  void SetUp() override { world = dWorldCreate(); }
  void TearDown() override { dWorldDestroy(world); }

  // A dynamic body of mass_kg (a 0.1 m box's shape, so the inertia is real) at (x, y, z).
  dBodyID MakeBody(double mass_kg, double x = 0, double y = 0, double z = 0) {
    dBodyID body = dBodyCreate(world);
    dMass mass;
    dMassSetBoxTotal(&mass, mass_kg, 0.1, 0.1, 0.1);
    dBodySetMass(body, &mass);
    dBodySetPosition(body, x, y, z);
    return body;
  }

  dWorldID world = nullptr;
};

#endif

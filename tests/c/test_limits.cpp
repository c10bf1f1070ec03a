// The ranges in limits.h hold on the real ODE the tests are built with, in its precision (limits.h has a table for
// each): at every corner of them (both solvers; shortest and longest step; largest |erp|, 0 and 1; cfm 0 and the
// largest; lightest and heaviest mass) a small world steps without ODE aborting and stays finite. ODE aborts the
// whole process on values outside them (or, built without its checks, goes non-finite), so each try runs in a child
// process (tests/c/ode_probe.c) and only its exit status comes back here. The checking helpers refuse by name.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <csignal>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include <ode/ode.h>

#include "steadystep/limits.h"

extern "C" {
#include "ode_bounds.h"
}

namespace {

struct Outcome {
  bool exited = false;
  int code = -1;   // exit status when exited
  int signal = 0;  // the signal that ended it otherwise
};

std::string Number(double value) {
  char text[64];
  std::snprintf(text, sizeof text, "%.17g", value);
  return text;
}

// Runs a probe program in a child (fork + exec, output discarded) and waits for it.
Outcome Run(std::vector<std::string> args) {
  std::vector<char*> argv;
  for (std::string& arg : args) argv.push_back(arg.data());
  argv.push_back(nullptr);
  pid_t child = fork();
  if (child == 0) {
    std::freopen("/dev/null", "w", stdout);
    std::freopen("/dev/null", "w", stderr);
    execv(argv[0], argv.data());
    _exit(127);
  }
  Outcome outcome;
  int status = 0;
  if (child < 0 || waitpid(child, &status, 0) != child) return outcome;
  outcome.exited = WIFEXITED(status);
  if (outcome.exited) outcome.code = WEXITSTATUS(status);
  if (WIFSIGNALED(status)) outcome.signal = WTERMSIG(status);
  return outcome;
}

// The ODE step probe (tests/c/ode_probe.c).
// The inertia (kg·m²) is the mass's unless given: a body of 1 m.
Outcome Probe(const std::string& solver, double step_s, double erp, double cfm, double mass, int steps,
              double speed = 1, double force_n = 0, double runaway_speed = 0, double inertia = 0) {
  return Run({ODE_PROBE, solver, Number(step_s), Number(erp), Number(cfm), Number(mass),
              Number(inertia > 0 ? inertia : mass), std::to_string(steps), Number(speed), Number(force_n),
              Number(runaway_speed)});
}

// The collision space probe (tests/c/space_probe.c): two touching boxes of size_m at position_m, collided once.
Outcome SpaceProbe(const std::string& space, double position_m, double size_m) {
  return Run({SPACE_PROBE, space, Number(position_m), Number(size_m)});
}

// ODE failed: aborted by its own checks (Debian's build), or left a non-finite state (a build without them, as
// CMake's Release builds ODE).
bool OdeFailed(const Outcome& outcome) {
  return outcome.signal == SIGABRT || (outcome.exited && outcome.code == 3);
}

struct Corner {
  const char* solver;
  double step_s, erp, cfm, mass, inertia;
};

// Each mass with the inertia of a body 1 m across (kg·m² equal to kg) and of one 1 mm across (1e-6 of it): single
// precision ODE with its asserts aborts from a principal inertia of about 1e-13 kg·m², whatever the mass.
std::vector<Corner> Corners() {
  std::vector<Corner> corners;
  for (const char* solver : {"quick", "step"})
    for (double step_s : {SS_MIN_STEP_S, SS_MAX_STEP_S})
      for (double erp : {-SS_MAX_ERP, 0.0, 1.0, SS_MAX_ERP})
        for (double cfm : {0.0, SS_MAX_CFM})
          for (double mass : {SS_MIN_MASS_KG, SS_MAX_MASS_KG})
            for (double size_m2 : {1.0, 1e-6}) corners.push_back({solver, step_s, erp, cfm, mass, mass * size_m2});
  return corners;
}

std::string Describe(const Corner& c) {
  return std::string(c.solver) + " h " + Number(c.step_s) + " erp " + Number(c.erp) + " cfm " + Number(c.cfm) +
         " mass " + Number(c.mass) + " inertia " + Number(c.inertia);
}

TEST(Limits, TheProbeSeesOdeFail) {
  // Without this the corner tests could pass with a probe that never reaches ODE's failures.
  Outcome ok = Probe("quick", 1.0 / 60, 0.2, 1e-5, 1, 10);
  EXPECT_TRUE(ok.exited && ok.code == 0) << "exit " << ok.code << " signal " << ok.signal;
  Outcome aborted = Probe("quick", 1e-200, 0.2, 1e-5, 1, 10);
  EXPECT_TRUE(OdeFailed(aborted)) << "exited " << aborted.exited << " code " << aborted.code;
  Outcome heavy = Probe("step", 1.0 / 60, 0.2, 1e-5, 1e300, 10);
  EXPECT_TRUE(OdeFailed(heavy)) << "exited " << heavy.exited << " code " << heavy.code;
}

TEST(Limits, EveryCornerStepsFiniteFromNearRest) {
  // Up to 10 steps, stopping as the stepper does once a body is faster than SS_MAX_SAFE_SPEED: a runaway row (|erp|
  // far above 2, cfm 0) grows by about |erp| a step, and the steps it takes until it is stopped must end finite.
  for (const Corner& c : Corners()) {
    Outcome outcome = Probe(c.solver, c.step_s, c.erp, c.cfm, c.mass, 10, 1, 0, SS_MAX_SAFE_SPEED, c.inertia);
    EXPECT_TRUE(outcome.exited && outcome.code == 0)
        << Describe(c) << ": exit " << outcome.code << " signal " << outcome.signal;
  }
}

TEST(Limits, EveryCornerTakesOneFiniteStepFromTheSafeSpeedWithTheLargestForce) {
  for (const Corner& c : Corners()) {
    Outcome outcome =
        Probe(c.solver, c.step_s, c.erp, c.cfm, c.mass, 1, SS_MAX_SAFE_SPEED, SS_MAX_FORCE_N, 0, c.inertia);
    EXPECT_TRUE(outcome.exited && outcome.code == 0)
        << Describe(c) << ": exit " << outcome.code << " signal " << outcome.signal;
  }
}

TEST(Limits, EveryBoundIsAFiniteNonZeroDReal) {
  // The table is that of the build's precision: each bound survives the one rounding to dReal.
  for (double bound : {SS_MIN_STEP_S, SS_MAX_STEP_S, SS_MAX_ERP, SS_MAX_CFM, SS_MIN_MASS_KG, SS_MAX_MASS_KG,
                       SS_MAX_SAFE_SPEED, SS_MAX_FORCE_N}) {
    const double rounded = static_cast<double>(static_cast<dReal>(bound));
    EXPECT_TRUE(std::isfinite(rounded) && rounded > 0) << bound;
    EXPECT_NEAR(rounded, bound, bound * std::numeric_limits<dReal>::epsilon()) << bound;
  }
}

bool Names(const char* fragment) { return std::string(ssLastError()).find(fragment) != std::string::npos; }

TEST(Limits, TheChecksRefuseByNameOutsideAndAcceptTheEdges) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(ssCheckStepLength("frame_s", SS_MIN_STEP_S), SS_OK);
  EXPECT_EQ(ssCheckStepLength("frame_s", SS_MAX_STEP_S), SS_OK);
  EXPECT_EQ(ssCheckStepLength("frame_s", 1e-200), SS_ERROR_OUT_OF_RANGE);
  EXPECT_TRUE(Names("frame_s = 1e-200 s")) << ssLastError();
  EXPECT_EQ(ssCheckStepLength("frame_s", 1.7e308), SS_ERROR_OUT_OF_RANGE);
  EXPECT_EQ(ssCheckStepLength("frame_s", 0), SS_ERROR_OUT_OF_RANGE);
  EXPECT_EQ(ssCheckStepLength("frame_s", -0.01), SS_ERROR_OUT_OF_RANGE);
  EXPECT_EQ(ssCheckStepLength("frame_s", nan), SS_ERROR_NOT_FINITE);
  EXPECT_TRUE(Names("frame_s = nan")) << ssLastError();

  EXPECT_EQ(ssCheckSoftnessForOde("hinge stop", 0.2, 0), SS_OK);  // a hard row a program tuned
  EXPECT_EQ(ssCheckSoftnessForOde("hinge stop", 1.5, SS_MAX_CFM), SS_OK);
  EXPECT_EQ(ssCheckSoftnessForOde("hinge stop", -SS_MAX_ERP, 1e-5), SS_OK);
  EXPECT_EQ(ssCheckSoftnessForOde("hinge stop", 0.2, 1e307), SS_ERROR_OUT_OF_RANGE);
  EXPECT_TRUE(Names("hinge stop: cfm = 1e+307")) << ssLastError();
  EXPECT_EQ(ssCheckSoftnessForOde("hinge stop", 0.2, -1e-9), SS_ERROR_OUT_OF_RANGE);
  EXPECT_EQ(ssCheckSoftnessForOde("hinge stop", 1e50, 1e-5), SS_ERROR_OUT_OF_RANGE);
  EXPECT_TRUE(Names("hinge stop: erp = 1e+50")) << ssLastError();
  EXPECT_EQ(ssCheckSoftnessForOde("hinge stop", nan, 1e-5), SS_ERROR_NOT_FINITE);
  EXPECT_TRUE(Names("erp = nan")) << ssLastError();
  EXPECT_EQ(ssCheckSoftnessForOde("hinge stop", 0.2, inf), SS_ERROR_NOT_FINITE);
  EXPECT_EQ(ssCheckComputedSoftness("contact", ssSoftness{0.2, 0}), SS_ERROR_OUT_OF_RANGE);
  EXPECT_TRUE(Names("contact: cfm = 0")) << ssLastError();
  EXPECT_EQ(ssCheckComputedSoftness("contact", ssSoftness{0.2, 1e-5}), SS_OK);

  EXPECT_EQ(ssCheckMass("body 3 mass", SS_MIN_MASS_KG), SS_OK);
  EXPECT_EQ(ssCheckMass("body 3 mass", SS_MAX_MASS_KG), SS_OK);
  EXPECT_EQ(ssCheckMass("body 3 mass", 1e300), SS_ERROR_OUT_OF_RANGE);
  EXPECT_TRUE(Names("body 3 mass = 1e+300 kg")) << ssLastError();
  EXPECT_EQ(ssCheckMass("body 3 mass", 1e-320), SS_ERROR_OUT_OF_RANGE);
  EXPECT_EQ(ssCheckMass("body 3 mass", 0), SS_ERROR_OUT_OF_RANGE);
  EXPECT_EQ(ssCheckMass("body 3 mass", -inf), SS_ERROR_NOT_FINITE);
}

// SS_MAX_POSITION_M keeps every collision space finite: ODE's hash space aborts far beyond it (so the probe can
// fail), and no space aborts at it, whatever the geom's size down to a centimetre.
TEST(Limits, CollisionSpacesStayFiniteWithinThePositionBound) {
  for (const char* space : {"simple", "hash", "quadtree", "sap"})
    for (double size_m : {0.01, 1.0, 100.0})
      for (double position_m : {SS_MAX_POSITION_M, -SS_MAX_POSITION_M}) {
        Outcome outcome = SpaceProbe(space, position_m, size_m);
        EXPECT_TRUE(outcome.exited && outcome.code == 0)
            << space << " at " << position_m << " m, boxes of " << size_m << " m: signal " << outcome.signal;
      }
  Outcome beyond = SpaceProbe("hash", 1e9, 0.01);  // 2^31 cells of 1/8 m end at 2.7e8 m
  EXPECT_FALSE(beyond.exited);
  EXPECT_EQ(beyond.signal, SIGABRT);
}

}  // namespace

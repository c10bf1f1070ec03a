// The scenes written as ODE programs are (stack, wall, piston: scene.h) on real ODE, checked against what holds
// independently of the library: the static sag F/k that implicit Euler gives a spring-damper at rest (the tower's
// height, the ram held at its stop by the motor), the free flight of ODE's integrator (the ball before the hit),
// and what each scene is for (a tower that comes to rest and falls asleep, a wall knocked over with hundreds of
// contacts a step, stops hit as limits).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "precision.h"
#include "recorded_run.h"

namespace {

// The last record at or before t.
size_t RecordAt(const RecordedRun& run, double t) {
  auto after = std::upper_bound(run.times.begin(), run.times.end(), t + 1e-9);
  return after == run.times.begin() ? 0 : static_cast<size_t>(after - run.times.begin()) - 1;
}

const char* const kProfiles[] = {"fixed:60", "fixed:30", "uniform:15:45"};
// The policies whose every step is implicit Euler at its own length: a spring at rest sags by F/k under them.
const char* const kImplicitEulerPolicies[] = {"implicit-euler", "fixed"};

}  // namespace

// The tower comes to rest (and falls asleep, under steady frames), standing at the
// sum of its sides less each face's sag: the weight above a face on its four contact points, each a spring of k,
// sags by W / (4 k). Sides and masses as scene.h lists them (bottom to top, default mass 0.1 kg).
TEST(ProgramScenes, StackSleepsStandingOnItsSpringsSag) {
  const double sides_m[] = {0.6, 0.5, 0.3, 0.4, 0.3, 0.3};
  const double masses_kg[] = {20, 2, 0.2, 0.6, 0.1, 0.3};
  ssSceneParams params;
  ASSERT_EQ(ssDefaultSceneParams("stack", &params), SS_OK);
  ASSERT_EQ(params.body_count, 6);
  double height_m = 0, sag_m = 0;
  for (int i = 0; i < 6; ++i) {
    height_m += sides_m[i];
    double above_kg = 0;
    for (int j = i; j < 6; ++j) above_kg += masses_kg[j];
    sag_m += above_kg * params.gravity / (4 * params.spring.stiffness);
  }
  const double top_z_m = height_m - 0.5 * sides_m[5] - sag_m;  // 2.2440 m
  for (const char* policy : kImplicitEulerPolicies) {
    for (const char* profile : kProfiles) {
      RecordedRun run = Record(LabRunDef("stack", profile, policy, 8.0));
      ASSERT_EQ(run.outcome, SS_RUN_COMPLETED) << policy << " " << profile << ": " << run.message;
      EXPECT_LT(run.quantities[2].back(), 1e-4) << policy << " " << profile << ": still moving";
      // 0.2 mm of the 6 mm of sag: QuickStep's 40 iterations leave the forces of a tower 200 times apart in mass
      // short by a few percent at 1/60 s steps (0.13 mm; the 1/1000 s reference stands at top_z_m to 10 um).
      EXPECT_NEAR(run.quantities[1].back(), top_z_m, 2e-4) << policy << " " << profile;
      double pushed_m = 0;
      for (double x : run.quantities[0]) pushed_m = std::max(pushed_m, std::fabs(x));
      EXPECT_GT(pushed_m, 1e-3) << policy << " " << profile << ": the push did not move the top box";
      EXPECT_LT(pushed_m, 0.05) << policy << " " << profile << ": the top box slid off";
    }
  }
}

// Before the hit the ball flies as ODE integrates it: x at constant speed, and z by the semi-implicit Euler
// recurrence of gravity, v_n = v0 - g n h, z_n = z0 + h (v_1 + ... + v_n). After it, the wall is knocked over and
// the ball has lost speed to it; on the way, a step makes hundreds of contacts.
TEST(ProgramScenes, WallIsKnockedOverByTheBallWithHundredsOfContactsAStep) {
  const double x0_m = -3, z0_m = 1, vx_m_per_s = 12, vz_m_per_s = 1.5, h_s = 1.0 / 60;
  const double g = 9.81;
  for (const char* policy : {"implicit-euler", "matched", "exact"}) {
    RecordedRun run = Record(LabRunDef("wall", "fixed:60", policy, 2.0));
    ASSERT_EQ(run.outcome, SS_RUN_COMPLETED) << policy << ": " << run.message;
    const double ball_reaches_wall_s = (-0.2 - 0.25 - x0_m) / vx_m_per_s;  // the wall's face, less the radius
    for (size_t i = 0; run.times[i] < ball_reaches_wall_s - h_s; ++i) {
      double n = static_cast<double>(i + 1);
      EXPECT_NEAR(run.quantities[1][i], x0_m + vx_m_per_s * run.times[i], IntegratedTolerance(1e-12, 1e-5))
          << policy << " t " << run.times[i];
      EXPECT_NEAR(run.quantities[2][i], z0_m + vz_m_per_s * run.times[i] - g * h_s * h_s * n * (n + 1) / 2,
                  IntegratedTolerance(1e-12, 1e-5))
          << policy << " t " << run.times[i];
      // The wall settles onto its contacts (2 mm gaps between courses, the sag of six courses on springs of
      // 3000 N/m, overshooting: about 2 cm, then 1.2 cm) and stands.
      EXPECT_LT(run.quantities[0][i], 0.03) << policy << " t " << run.times[i];
    }
    EXPECT_GT(run.quantities[0].back(), 0.15) << policy << ": the wall still stands";
    double ball_speed_after = (run.quantities[1].back() - run.quantities[1][RecordAt(run, 1.5)]) / 0.5;
    EXPECT_LT(ball_speed_after, 0.5 * vx_m_per_s) << policy;
    const ssSceneServedCounts& contacts = run.counters.contacts;
    double contacts_per_step =
        static_cast<double>(contacts.by_mapping + contacts.handed_to_matched + contacts.handed_to_implicit_euler) /
        run.counters.steps;
    EXPECT_GT(contacts_per_step, 200) << policy;
  }
}

// The motor drives the ram into each stop and holds it there with its whole force F = 40 N until it reverses, each
// second: at rest on a stop of spring k it is F / k beyond it. The arm swings into its own stops at +-0.35 rad.
TEST(ProgramScenes, PistonRamIsHeldAtEachStopByTheMotor) {
  ssSceneParams params;
  ASSERT_EQ(ssDefaultSceneParams("piston", &params), SS_OK);
  const double stop_m = 0.25, force_n = 40, arm_stop_rad = 0.35;
  const double held_m = stop_m + force_n / params.spring.stiffness;
  for (const char* policy : kImplicitEulerPolicies) {
    for (const char* profile : kProfiles) {
      RecordedRun run = Record(LabRunDef("piston", profile, policy, 4.0));
      ASSERT_EQ(run.outcome, SS_RUN_COMPLETED) << policy << " " << profile << ": " << run.message;
      // Just before each reversal; 0.1 mm: the arm, still swinging, pushes the ram by a fraction of a newton.
      EXPECT_NEAR(run.quantities[0][RecordAt(run, 0.95)], held_m, 1e-4) << policy << " " << profile;
      EXPECT_NEAR(run.quantities[0][RecordAt(run, 1.95)], -held_m, 1e-4) << policy << " " << profile;
      EXPECT_NEAR(run.quantities[0][RecordAt(run, 2.95)], held_m, 1e-4) << policy << " " << profile;
      double swing_rad = 0;
      for (double angle : run.quantities[2]) swing_rad = std::max(swing_rad, std::fabs(angle));
      EXPECT_GT(swing_rad, arm_stop_rad) << policy << " " << profile << ": the arm never reached its stops";
    }
  }
}

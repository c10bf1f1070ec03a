// A lab run copied out of the library into plain vectors, so that a scene test states its claims on the records
// with its own arithmetic (interpolation, RMS, the last record before a time) and the run is freed at once.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "steadystep/lab/scene.h"
#include "steadystep/steadystep.h"

struct RecordedRun {
  ssRunOutcome outcome = SS_RUN_NONE;
  ssStatus status = SS_OK;
  std::string message;
  double bound_use = NAN;
  int frames = 0;
  std::vector<double> times;
  std::vector<std::vector<double>> quantities;  // [quantity][record], in the scene's order (scene.h)
  std::vector<double> initial;                   // each quantity before the first step
  ssSceneCounters counters{};

  bool completed() const { return outcome == SS_RUN_COMPLETED; }
};

// The scene under its default parameters, the profile (seed 1) and the lab policy named.
inline ssRunDef LabRunDef(const char* scene, const char* profile, const char* policy, double duration_s) {
  ssRunDef def{};
  def.scene = scene;
  EXPECT_EQ(ssDefaultSceneParams(scene, &def.params), SS_OK) << ssLastError();
  EXPECT_EQ(ssLabStepping(policy, &def.stepping), SS_OK) << policy << ": " << ssLastError();
  def.profile = profile;
  def.seed = 1;
  def.duration_s = duration_s;
  return def;
}

// The lab's fine-step reference of the scene: implicit Euler at 1/1000 s steps, one step a 1 ms frame.
inline ssRunDef LabReferenceDef(const char* scene, double duration_s) {
  ssRunDef def = LabRunDef(scene, "fixed:1000", "implicit-euler", duration_s);
  def.stepping = ssReferenceStepping(1e-3);
  return def;
}

// Executes the run and copies its records; a refused run fails the test and gives an empty record (outcome NONE).
inline RecordedRun Record(const ssRunDef& def) {
  RecordedRun out;
  ssRun* run = nullptr;
  ssStatus status = ssRun_Execute(&def, &run);
  EXPECT_EQ(status, SS_OK) << def.scene << " " << def.profile << ": " << ssLastError();
  if (status != SS_OK || run == nullptr) return out;
  out.outcome = ssRun_Outcome(run);
  out.status = ssRun_Status(run);
  out.message = ssRun_Message(run);
  out.bound_use = ssRun_BoundUse(run);
  out.frames = ssRun_FrameCount(run);
  int count = ssRun_StepCount(run);
  out.times.assign(ssRun_Times(run), ssRun_Times(run) + count);
  int quantities = ssSceneFind(def.scene)->quantity_count;
  for (int q = 0; q < quantities; ++q)
    out.quantities.emplace_back(ssRun_Quantity(run, q), ssRun_Quantity(run, q) + count);
  out.initial.assign(ssRun_Initial(run), ssRun_Initial(run) + quantities);
  out.counters = ssRun_Counters(run);
  ssRun_Destroy(run);
  return out;
}

// Hostile-frame soak: every scene under every policy, fed frames from 1e-12 s to 10 s, hitches, runs of tiny frames,
// a seeded random stretch, and frames that must be refused (NaN, infinities, negative). The promises checked:
//  - nothing aborts: each scene/policy pair runs in a child process (a death-test style fork), so an abort inside
//    ODE shows up as a failed test with the child's output, not as a crash of the test program;
//  - a refused frame is refused by name ("frame_s" in ssLastError) and changes nothing (time and samples the same);
//  - after every frame reported OK, the scene's time and every sampled quantity are finite;
//  - a blow-up is reported (SS_ERROR_BLOWUP or SS_ERROR_SPEED_LIMIT), which ends that pair's run; it is counted;
//  - a scene that leaves its sanity bounds (frames of seconds tear the chain, frames of microseconds make naive's
//    frozen spring gain energy) is broken: an honest outcome, counted and printed with its message, not a failure;
//    the scene steps on (leaving a bound is no error), so the promises above keep being checked.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "steadystep/lab/scene.h"
#include "steadystep/steadystep.h"

namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// The frames, in order: every decade from 1e-12 s to 10 s, a steady run with hitches, bursts of tiny frames,
// alternating extremes, and the hostile values that must be refused, spread between them.
std::vector<double> HostileFrames() {
  std::vector<double> frames;
  for (double frame = 1e-12; frame <= 10.0 * (1 + 1e-9); frame *= 10) frames.push_back(frame);
  frames.push_back(kNan);
  for (int hitch = 0; hitch < 3; ++hitch) {
    for (int i = 0; i < 20; ++i) frames.push_back(1.0 / 60);
    frames.push_back(hitch == 2 ? 2.0 : 0.25);
  }
  frames.push_back(kInf);
  for (int i = 0; i < 50; ++i) frames.push_back(1e-12);
  frames.push_back(-1.0 / 60);
  for (int i = 0; i < 20; ++i) frames.push_back(i % 2 ? 1e-7 : 0.1);
  frames.push_back(-kInf);
  frames.push_back(std::numeric_limits<double>::denorm_min());
  frames.push_back(0.0);
  frames.push_back(-std::numeric_limits<double>::denorm_min());
  for (int i = 0; i < 10; ++i) frames.push_back(1.0 / 30);
  // Then a seeded random stretch: log-uniform in [1e-12, 10] s, with a hostile value one frame in twenty.
  std::mt19937_64 random(20261125);
  std::uniform_real_distribution<double> decade(-12, 1);
  const double hostile[] = {kNan, kInf, -kInf, -1e-3, -10, -std::numeric_limits<double>::max()};
  for (int i = 0; i < 200; ++i)
    frames.push_back(random() % 20 == 0 ? hostile[random() % 6] : std::pow(10.0, decade(random)));
  return frames;
}

bool MustBeRefused(double frame_s) { return !std::isfinite(frame_s) || frame_s < 0; }

struct Tally {
  int frames = 0, refused_hostile = 0, refused_valid = 0, blowups = 0, broken = 0;
};

// The frame being stepped, for the abort handler: an abort inside ODE then names the frame that caused it.
volatile double current_frame_s = 0;

extern "C" void NameFrameAndDie(int) {
  char line[96];
  int length = std::snprintf(line, sizeof line, "aborted while stepping a frame of %.17g s\n", current_frame_s);
  if (length > 0 && write(2, line, static_cast<size_t>(length)) < 0) _exit(135);
  _exit(134);
}

// Runs the frames through one scene under one lab policy; returns the broken promises, one a line ("" when none).
std::string RunSoak(const char* scene_name, const char* policy, Tally* tally) {
  std::ostringstream problems;
  ssSceneParams params;
  if (ssDefaultSceneParams(scene_name, &params) != SS_OK) return std::string("params: ") + ssLastError() + "\n";
  if (params.body_count > 12) params.body_count = 12;  // enough bodies to collide and pile; bounded time
  ssStepping stepping;
  if (ssLabStepping(policy, &stepping) != SS_OK) return std::string("stepping: ") + ssLastError() + "\n";
  ssScene* scene = nullptr;
  if (ssScene_Create(scene_name, &params, &stepping, &scene) != SS_OK)
    return std::string("create: ") + ssLastError() + "\n";
  const int quantities = ssSceneFind(scene_name)->quantity_count;
  for (double frame_s : HostileFrames()) {
    double before[SS_MAX_QUANTITIES] = {0}, after[SS_MAX_QUANTITIES] = {0};
    ssScene_Sample(scene, before);
    double time_before = ssScene_Time(scene);
    current_frame_s = frame_s;
    ssStatus status = ssScene_Frame(scene, frame_s, nullptr);
    ssScene_Sample(scene, after);
    double time_after = ssScene_Time(scene);
    ++tally->frames;
    const bool unchanged = std::memcmp(before, after, sizeof before) == 0 &&
                           std::memcmp(&time_before, &time_after, sizeof(double)) == 0;
    if (MustBeRefused(frame_s)) {
      ++tally->refused_hostile;
      if (status == SS_OK || std::strstr(ssLastError(), "frame_s") == nullptr)
        problems << "frame " << frame_s << " s: " << ssStatusName(status) << " \"" << ssLastError()
                 << "\" (must be refused naming frame_s)\n";
      if (!unchanged) problems << "frame " << frame_s << " s refused but the scene changed\n";
      continue;
    }
    if (status == SS_ERROR_BLOWUP || status == SS_ERROR_SPEED_LIMIT) {
      ++tally->blowups;
      std::printf("  frame %.17g s: %s (reported)\n", frame_s, ssLastError());
      break;  // reported: the promise holds; a blown-up scene has nothing more to show
    }
    if (status != SS_OK) {
      // A valid frame may still be refused (a documented bound), but by name and with nothing changed.
      ++tally->refused_valid;
      std::printf("  frame %.17g s refused: %s\n", frame_s, ssLastError());
      if (ssLastError()[0] == '\0' || !unchanged)
        problems << "frame " << frame_s << " s: " << ssStatusName(status) << " \"" << ssLastError() << "\""
                 << (unchanged ? "" : " and the scene changed") << "\n";
      continue;
    }
    if (tally->broken == 0 && ssScene_Broken(scene) != nullptr) {
      ++tally->broken;
      std::printf("  frame %.17g s: broken, %s\n", frame_s, ssScene_Broken(scene));
    }
    bool finite = std::isfinite(time_after);
    for (int q = 0; q < quantities; ++q) finite = finite && std::isfinite(after[q]);
    if (!finite) {
      problems << "frame " << frame_s << " s reported OK but the scene is not finite: t = " << time_after;
      for (int q = 0; q < quantities; ++q) problems << ", q" << q << " = " << after[q];
      problems << "\n";
      break;
    }
  }
  ssScene_Destroy(scene);
  return problems.str();
}

// The child's whole life: soak, print the figures, exit 0 only when every promise held.
void SoakChild(const char* scene, const char* policy) {
  std::signal(SIGABRT, NameFrameAndDie);
  Tally tally;
  std::string problems = RunSoak(scene, policy, &tally);
  std::printf("soak %s / %s: %d frames, %d hostile refused, %d valid refused, %d blow-ups reported, %s: %s\n",
              scene, policy, tally.frames, tally.refused_hostile, tally.refused_valid, tally.blowups,
              tally.broken ? "broken" : "within its sanity bounds",
              problems.empty() ? "every promise held" : "PROMISES BROKEN");
  std::fflush(stdout);
  std::fputs(problems.c_str(), stderr);
  std::exit(problems.empty() ? 0 : 1);
}

class Soak : public ::testing::TestWithParam<std::tuple<int, int>> {};

// An abort or a broken promise in the child fails here, with the child's stderr.
TEST_P(Soak, HostileFramesNeverAbortAndNeverLie) {
  EXPECT_EXIT(SoakChild(ssSceneInfoAt(std::get<0>(GetParam()))->name, ssSteppingPolicyNameAt(std::get<1>(GetParam()))),
              ::testing::ExitedWithCode(0), "");
}

std::string PairName(const ::testing::TestParamInfo<Soak::ParamType>& info) {
  std::string name = std::string(ssSceneInfoAt(std::get<0>(info.param))->name) + "_" +
                     ssSteppingPolicyNameAt(std::get<1>(info.param));
  for (char& c : name)
    if (c == '-') c = '_';  // test names allow letters, digits and underscores only
  return name;
}

INSTANTIATE_TEST_SUITE_P(EveryScenePolicy, Soak,
                         ::testing::Combine(::testing::Range(0, ssSceneCount()),
                                            ::testing::Range(0, ssSteppingPolicyCount())),
                         PairName);

}  // namespace

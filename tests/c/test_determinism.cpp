// Determinism, as Box2D pins it: a fixed scene run (chain and buggy, 2 s under fixed:60, implicit Euler; the
// oscillator under the matched and exact mappings, which serve its spring, at frames of 1/60 s and of 15-45 fps; the
// pile's contacts, softened for each step) is hashed (FNV-1a over the bytes of every record: time, step length and each quantity after every step) and compared
// with a pinned value for each ODE solver. Any change of trajectory, however small, changes the hash.
// When a change of trajectory is deliberate, the failure prints the new value: replace the pinned one in one edit.
// Each case also runs twice in one process (nothing global leaks between runs). The pinned values are those of
// Debian 12's libode 0.16 (double) on x86-64; the plain and the sanitizer builds give the same ones.
#include <gtest/gtest.h>

#include <cinttypes>
#include <cstdint>
#include <cstdio>
#include <cstring>

#include "test_stepping.h"
#include "steadystep/lab/scene.h"
#include "steadystep/steadystep.h"

namespace {

uint64_t Fnv1a(uint64_t hash, const void* data, size_t size) {
  const unsigned char* bytes = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < size; ++i) {
    hash ^= bytes[i];
    hash *= 0x100000001b3ULL;
  }
  return hash;
}

struct Pinned {
  const char* scene;
  ssSolver solver;
  uint64_t hash;
  ssMapping mapping;    // implicit Euler unless given
  const char* profile;  // fixed:60 unless given
};

uint64_t RunHash(const Pinned& pinned, int* steps_out) {
  const char* scene = pinned.scene;
  ssRunDef def{};
  def.scene = scene;
  EXPECT_EQ(ssDefaultSceneParams(scene, &def.params), SS_OK) << ssLastError();
  def.stepping = TestStepping();  // substeps of at most 1/60 s, implicit Euler at each step's length
  def.stepping.solver = pinned.solver;
  def.stepping.mapping = pinned.mapping;
  def.profile = pinned.profile != nullptr ? pinned.profile : "fixed:60";
  def.seed = 1;
  def.duration_s = 2.0;
  ssRun* run = nullptr;
  EXPECT_EQ(ssRun_Execute(&def, &run), SS_OK) << ssLastError();
  if (run == nullptr) return 0;
  EXPECT_EQ(ssRun_Status(run), SS_OK) << ssRun_Message(run);
  uint64_t hash = 0xcbf29ce484222325ULL;
  const int steps = ssRun_StepCount(run);
  const int quantities = ssSceneFind(scene)->quantity_count;
  for (int i = 0; i < steps; ++i) {
    hash = Fnv1a(hash, &ssRun_Times(run)[i], sizeof(double));
    hash = Fnv1a(hash, &ssRun_StepLengths(run)[i], sizeof(double));
    for (int q = 0; q < quantities; ++q) hash = Fnv1a(hash, &ssRun_Quantity(run, q)[i], sizeof(double));
  }
  *steps_out = steps;
  ssRun_Destroy(run);
  return hash;
}

// The pinned trajectories, one set per precision of ODE's dReal (the single-precision ODE is scripts/ode-single.sh's
// build of Debian's source package). Update a value here when a trajectory change is deliberate (the failure prints
// it); a change in the library usually changes both sets.
#if defined(dSINGLE)
const Pinned kPinned[] = {
    {"chain", SS_SOLVER_QUICK, 0x8721a2369913f0c4ULL, SS_MAPPING_IMPLICIT_EULER, nullptr},
    {"chain", SS_SOLVER_STEP, 0x23c72dcfc41653c7ULL, SS_MAPPING_IMPLICIT_EULER, nullptr},
    {"buggy", SS_SOLVER_QUICK, 0x71cd737eb523113cULL, SS_MAPPING_IMPLICIT_EULER, nullptr},
    {"buggy", SS_SOLVER_STEP, 0x1d64021c13e94d32ULL, SS_MAPPING_IMPLICIT_EULER, nullptr},
    {"oscillator", SS_SOLVER_STEP, 0x7d5ecf09e8ee8bf7ULL, SS_MAPPING_MATCHED, nullptr},
    {"oscillator", SS_SOLVER_STEP, 0x70676d6093b00e91ULL, SS_MAPPING_EXACT, "uniform:15:45"},
    {"oscillator", SS_SOLVER_STEP, 0x7fee7972a952c96aULL, SS_MAPPING_MATCHED, "uniform:15:45"},
    {"pile", SS_SOLVER_QUICK, 0x364b8ad1345077ddULL, SS_MAPPING_IMPLICIT_EULER, nullptr},
};
#else
const Pinned kPinned[] = {
    {"chain", SS_SOLVER_QUICK, 0xc14ceb0ed803b7dfULL, SS_MAPPING_IMPLICIT_EULER, nullptr},
    {"chain", SS_SOLVER_STEP, 0x77d62c6d806702e9ULL, SS_MAPPING_IMPLICIT_EULER, nullptr},
    {"buggy", SS_SOLVER_QUICK, 0xb1c508f0a16d3bf6ULL, SS_MAPPING_IMPLICIT_EULER, nullptr},
    {"buggy", SS_SOLVER_STEP, 0x60dbe3f6626be7ebULL, SS_MAPPING_IMPLICIT_EULER, nullptr},
    {"oscillator", SS_SOLVER_STEP, 0x67a6118f217ec27bULL, SS_MAPPING_MATCHED, nullptr},
    {"oscillator", SS_SOLVER_STEP, 0x9a183e7f8b25486eULL, SS_MAPPING_EXACT, "uniform:15:45"},
    {"oscillator", SS_SOLVER_STEP, 0xd9e46b61be6b773dULL, SS_MAPPING_MATCHED, "uniform:15:45"},
    {"pile", SS_SOLVER_QUICK, 0xfed5b68c67ca25d8ULL, SS_MAPPING_IMPLICIT_EULER, nullptr},
};
#endif

void PrintTo(const Pinned& pinned, std::ostream* out) {
  *out << pinned.scene << (pinned.solver == SS_SOLVER_QUICK ? " quick" : " step");
  if (pinned.mapping != SS_MAPPING_IMPLICIT_EULER) *out << " " << ssMappingName(pinned.mapping);
  if (pinned.profile != nullptr) *out << " " << pinned.profile;
}

class Determinism : public ::testing::TestWithParam<Pinned> {};

TEST_P(Determinism, TrajectoryHashIsPinned) {
  const Pinned& pinned = GetParam();
  int steps = 0, steps_again = 0;
  uint64_t hash = RunHash(pinned, &steps);
  if (pinned.profile == nullptr) {
    EXPECT_EQ(steps, 120) << "2 s at fixed:60 is 120 steps";
  }
  // The same run again in the same process: nothing global (ODE's random generator) leaks between runs.
  EXPECT_EQ(RunHash(pinned, &steps_again), hash);
  char printed[32];
  std::snprintf(printed, sizeof printed, "0x%016" PRIx64 "ULL", hash);
  EXPECT_EQ(hash, pinned.hash) << pinned.scene << " under " << (pinned.solver == SS_SOLVER_QUICK ? "quick" : "step")
                               << ": the trajectory changed. If that is deliberate, pin the new hash in "
                               << "tests/c/test_determinism.cpp: " << printed;
}

std::string CaseName(const ::testing::TestParamInfo<Pinned>& info) {
  std::string name = std::string(info.param.scene) + (info.param.solver == SS_SOLVER_QUICK ? "_quick" : "_step");
  if (info.param.mapping != SS_MAPPING_IMPLICIT_EULER) name += std::string("_") + ssMappingName(info.param.mapping);
  if (info.param.profile != nullptr) name += "_varying";
  return name;
}

INSTANTIATE_TEST_SUITE_P(FixedRuns, Determinism, ::testing::ValuesIn(kPinned), CaseName);

}  // namespace

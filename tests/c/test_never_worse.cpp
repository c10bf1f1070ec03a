// Issue 15, item 1: the accurate mappings never lose to implicit Euler. In each scene written as an ODE program
// (stack, wall, piston: scene.h), under fixed:60, fixed:30 and uniform:15:45, every followed quantity's RMS
// deviation from the fine-step reference (implicit Euler at 1/1000 s steps, the lab's reference) is, under matched
// and exact, at most 1.05 times implicit Euler's, and under fixed-matched and fixed-exact at most 1.05 times
// fixed's (the same 1/60 s steps under every profile). The deviation is computed here, independently of the
// library: the run's samples minus the reference interpolated linearly at their times, RMS, over the reference's
// amplitude (as python/steadystep/metrics.py's rms_deviation).
//
// Durations are short where the claim already shows (the stack's tower settles and its contacts carry their load
// within 2 s; the wall is knocked over within 1.5 s; the ram hits, is held at and leaves its stops within 2 s).
// SS_NEVER_WORSE_SECONDS=10 runs them 10 s instead; the test prints its table either way.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "recorded_run.h"

namespace {

constexpr double kTolerance = 1.05;  // issue 15

double Interpolate(const std::vector<double>& t, const std::vector<double>& y, double at) {
  auto after = std::upper_bound(t.begin(), t.end(), at);
  if (after == t.begin()) return y.front();
  if (after == t.end()) return y.back();
  size_t i = static_cast<size_t>(after - t.begin());
  double w = (at - t[i - 1]) / (t[i] - t[i - 1]);
  return y[i - 1] + w * (y[i] - y[i - 1]);
}

// RMS of (run - reference) at the run's samples within the reference's span, over the reference's max - min.
double Deviation(const RecordedRun& run, const RecordedRun& reference, int quantity) {
  const std::vector<double>& ref = reference.quantities[quantity];
  double amplitude = *std::max_element(ref.begin(), ref.end()) - *std::min_element(ref.begin(), ref.end());
  double sum = 0;
  int n = 0;
  for (size_t i = 0; i < run.times.size(); ++i) {
    if (run.times[i] < reference.times.front() || run.times[i] > reference.times.back()) continue;
    double d = run.quantities[quantity][i] - Interpolate(reference.times, ref, run.times[i]);
    sum += d * d;
    n += 1;
  }
  return std::sqrt(sum / n) / amplitude;
}

double DurationFor(double short_s) {
  const char* seconds = std::getenv("SS_NEVER_WORSE_SECONDS");
  return seconds != nullptr ? std::atof(seconds) : short_s;
}

struct Case {
  const char* scene;
  double duration_s;
};

class NeverWorse : public ::testing::TestWithParam<Case> {};

// The accurate policy and the policy of the same cut whose deviation it must not exceed by more than kTolerance.
struct Pair {
  const char* accurate;
  const char* baseline;
};
const Pair kPairs[] = {{"matched", "implicit-euler"},
                       {"exact", "implicit-euler"},
                       {"fixed-matched", "fixed"},
                       {"fixed-exact", "fixed"}};
const char* const kPolicies[] = {"implicit-euler", "matched", "exact", "fixed", "fixed-matched", "fixed-exact"};
const char* const kProfiles[] = {"fixed:60", "fixed:30", "uniform:15:45"};

TEST_P(NeverWorse, AccurateMappingsWithinToleranceOfImplicitEuler) {
  const Case& c = GetParam();
  double duration_s = DurationFor(c.duration_s);
  const ssSceneInfo* info = ssSceneFind(c.scene);
  ASSERT_NE(info, nullptr);
  RecordedRun reference = Record(LabReferenceDef(c.scene, duration_s));
  ASSERT_TRUE(reference.completed()) << reference.message;
  for (const char* profile : kProfiles) {
    std::vector<std::vector<double>> deviation(std::size(kPolicies));
    std::vector<ssSceneCounters> counters(std::size(kPolicies));
    for (size_t p = 0; p < std::size(kPolicies); ++p) {
      RecordedRun run = Record(LabRunDef(c.scene, profile, kPolicies[p], duration_s));
      ASSERT_TRUE(run.completed()) << c.scene << " " << profile << " " << kPolicies[p] << ": " << run.message;
      for (int q = 0; q < info->quantity_count; ++q) deviation[p].push_back(Deviation(run, reference, q));
      counters[p] = run.counters;
      // every contact softened under an accurate mapping is served by implicit Euler, and counted as handed to it
      const ssSceneServedCounts& contacts = run.counters.contacts;
      if (std::string(kPolicies[p]) != "implicit-euler" && std::string(kPolicies[p]) != "fixed") {
        EXPECT_EQ(contacts.by_mapping + contacts.handed_to_matched, 0) << c.scene << " " << kPolicies[p];
        if (std::string(c.scene) != "piston") {
          EXPECT_GT(contacts.handed_to_implicit_euler, 0) << c.scene;
        }
      }
    }
    auto index = [](const char* policy) {
      for (size_t p = 0; p < std::size(kPolicies); ++p)
        if (std::string(kPolicies[p]) == policy) return p;
      return size_t{0};
    };
    for (size_t p = 0; p < std::size(kPolicies); ++p) {
      std::printf("%s %s %-14s", c.scene, profile, kPolicies[p]);
      for (int q = 0; q < info->quantity_count; ++q) std::printf(" %s %.4f", info->quantity_names[q], deviation[p][q]);
      const ssSceneCounters& n = counters[p];
      std::printf(" | rows served %lld handed %lld, contacts served %lld handed %lld\n",
                  static_cast<long long>(n.rows.by_mapping + n.rows.handed_to_matched),
                  static_cast<long long>(n.rows.handed_to_implicit_euler),
                  static_cast<long long>(n.contacts.by_mapping + n.contacts.handed_to_matched),
                  static_cast<long long>(n.contacts.handed_to_implicit_euler));
    }
    for (const Pair& pair : kPairs) {
      size_t a = index(pair.accurate), b = index(pair.baseline);
      for (int q = 0; q < info->quantity_count; ++q)
        EXPECT_LE(deviation[a][q], kTolerance * deviation[b][q])
            << c.scene << " " << profile << " " << info->quantity_names[q] << ": " << pair.accurate << " "
            << deviation[a][q] << " against " << pair.baseline << " " << deviation[b][q];
    }
  }
}

INSTANTIATE_TEST_SUITE_P(ProgramScenes, NeverWorse,
                         ::testing::Values(Case{"stack", 2.0}, Case{"wall", 1.5}, Case{"piston", 2.0}),
                         [](const ::testing::TestParamInfo<Case>& info) { return std::string(info.param.scene); });

// Where one spring dominates one body the accurate mappings keep serving: the buggy's four suspension rows, whose
// load (a quarter of the chassis' weight) the scene declares, are served by matched and exact at every step of
// every profile; only the world's row (near-rigid, no mass) is handed to implicit Euler.
TEST(NeverWorse, TheBuggysSuspensionStaysServed) {
  for (const char* policy : {"matched", "exact", "fixed-matched", "fixed-exact"}) {
    for (const char* profile : kProfiles) {
      RecordedRun run = Record(LabRunDef("buggy", profile, policy, 1.0));
      ASSERT_TRUE(run.completed()) << run.message;
      const ssSceneCounters& n = run.counters;
      EXPECT_EQ(n.rows.by_mapping + n.rows.handed_to_matched, 4 * n.steps) << policy << " " << profile;
      EXPECT_EQ(n.rows.handed_to_implicit_euler, n.steps) << policy << " " << profile;
    }
  }
}

}  // namespace

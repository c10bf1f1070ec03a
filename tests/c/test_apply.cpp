// Apply against its reference (src/apply_reference.h): random scenarios on twin worlds, through many laws, loads,
// unbinding, rebinding, attachment and mass changes and every mapping, must write the same values into ODE.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "apply_differential.h"

namespace {

TEST(ApplyTest, FastPathsWriteWhatTheReferenceWrites) {
  std::mt19937 random(19);
  ssDifferentialCounts counts = {0, 0, 0, 0};
  const int scenarios = 1500;
  for (int s = 0; s < scenarios; ++s) {
    // lengths from a few operations to the most a scenario reads
    std::vector<uint8_t> bytes(5 + random() % 1500);
    for (auto& byte : bytes) byte = static_cast<uint8_t>(random());
    char message[256] = "";
    ASSERT_EQ(ssApplyDifferential(bytes.data(), bytes.size(), message, sizeof message, &counts), 0)
        << "scenario " << s << ": " << message;
  }
  // the scenarios reached what they are for: many Applies, ODE steps between them (no Apply fails: every law was
  // checked for every step at bind time)
  EXPECT_GT(counts.applies, 20 * scenarios);
  EXPECT_EQ(counts.applies_failed, 0);
  EXPECT_GT(counts.steps, 5 * scenarios);
  RecordProperty("applies", static_cast<int>(counts.applies));
  RecordProperty("compared_values", static_cast<int>(counts.compared_values));
}

}  // namespace

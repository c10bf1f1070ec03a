// Frame-time profiles: reproducibility, the statistics each kind promises, and every malformed spec refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <sys/stat.h>
#include <unistd.h>

#include <random>

#include "steadystep/lab/profile.h"

namespace {

ssProfile* Make(const std::string& spec, uint64_t seed = 1) {
  ssProfile* profile = nullptr;
  ssStatus status = ssProfile_Create(spec.c_str(), seed, &profile);
  EXPECT_EQ(status, SS_OK) << spec << ": " << ssLastError();
  return profile;
}

std::vector<double> Draw(ssProfile* profile, int count) {
  std::vector<double> frames(count);
  for (double& frame : frames) frame = ssProfile_Next(profile);
  return frames;
}

double Mean(const std::vector<double>& values) {
  double sum = 0;
  for (double v : values) sum += v;
  return sum / values.size();
}

std::string TempFile(const std::string& name, const std::string& text) {
  std::string path = ::testing::TempDir() + "steadystep_" + name;
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

// Clears ssLastError() by recording a failure that names nothing a test looks for.
void ssFail_Clear() {
  ssProfile* unused = nullptr;
  ssProfile_Create("unknown-kind", 0, &unused);
}

void ExpectRefused(const std::string& spec, ssStatus expected, const std::string& named) {
  ssProfile* sentinel = reinterpret_cast<ssProfile*>(0x1234);
  ssProfile* profile = sentinel;
  EXPECT_EQ(ssProfile_Create(spec.c_str(), 7, &profile), expected) << spec << ": " << ssLastError();
  EXPECT_EQ(profile, sentinel) << spec << ": *out was written on error";
  EXPECT_NE(std::string(ssLastError()).find(named), std::string::npos)
      << spec << ": message \"" << ssLastError() << "\" does not name " << named;
}

}  // namespace

TEST(Profile, SameSeedSameSequenceOtherSeedAnother) {
  for (const char* spec : {"uniform:15:45", "jitter:60:3", "vsync:60:30"}) {
    ssProfile* a = Make(spec, 42);
    ssProfile* b = Make(spec, 42);
    ssProfile* c = Make(spec, 43);
    std::vector<double> da = Draw(a, 1000), db = Draw(b, 1000), dc = Draw(c, 1000);
    EXPECT_EQ(da, db) << spec;
    EXPECT_NE(da, dc) << spec;
    ssProfile_Destroy(a);
    ssProfile_Destroy(b);
    ssProfile_Destroy(c);
  }
}

TEST(Profile, ResetRestartsTheSequence) {
  for (const char* spec : {"uniform:15:45", "jitter:60:3", "vsync:60:30", "hitch:60:7:0.2"}) {
    ssProfile* profile = Make(spec, 9);
    std::vector<double> first = Draw(profile, 500);
    ssProfile_Reset(profile);
    EXPECT_EQ(Draw(profile, 500), first) << spec;
    EXPECT_STREQ(ssProfile_Spec(profile), spec);
    ssProfile_Destroy(profile);
  }
}

TEST(Profile, FixedIsConstant) {
  ssProfile* profile = Make("fixed:30");
  for (double frame : Draw(profile, 100)) EXPECT_EQ(frame, 1.0 / 30.0);
  ssProfile_Destroy(profile);
}

TEST(Profile, UniformStaysInItsIntervalAroundTheMidpoint) {
  ssProfile* profile = Make("uniform:15:45", 3);
  std::vector<double> frames = Draw(profile, 10000);
  double lo = 1.0 / 45.0, hi = 1.0 / 15.0;
  for (double frame : frames) {
    EXPECT_GE(frame, lo);
    EXPECT_LE(frame, hi);
  }
  // A uniform variable on [lo, hi] has deviation (hi - lo)/sqrt(12); the mean of 10000 is within 4 of its sigmas.
  double sigma_of_mean = (hi - lo) / std::sqrt(12.0) / 100.0;
  EXPECT_NEAR(Mean(frames), 0.5 * (lo + hi), 4 * sigma_of_mean);
  // Both ends of the interval are reached, to a tenth of its width.
  double min = *std::min_element(frames.begin(), frames.end());
  double max = *std::max_element(frames.begin(), frames.end());
  EXPECT_LT(min, lo + 0.1 * (hi - lo));
  EXPECT_GT(max, hi - 0.1 * (hi - lo));
  ssProfile_Destroy(profile);
}

TEST(Profile, JitterHasItsMeanAndStaysWithinThreeDeviations) {
  ssProfile* profile = Make("jitter:60:2", 5);
  std::vector<double> frames = Draw(profile, 10000);
  double mean = 1.0 / 60.0, sigma = 0.002;
  double sum_sq = 0;
  for (double frame : frames) {
    EXPECT_LE(std::fabs(frame - mean), 3 * sigma + 1e-15);
    sum_sq += (frame - mean) * (frame - mean);
  }
  EXPECT_NEAR(Mean(frames), mean, 4 * sigma / 100.0);
  // A normal truncated at 3 deviations keeps 97.3% of the variance.
  EXPECT_NEAR(std::sqrt(sum_sq / frames.size()), sigma * std::sqrt(0.973), 0.05 * sigma);
  ssProfile_Destroy(profile);
}

TEST(Profile, HitchEveryNthFrame) {
  ssProfile* profile = Make("hitch:60:7:0.25");
  std::vector<double> frames = Draw(profile, 700);
  for (size_t i = 0; i < frames.size(); ++i)
    EXPECT_EQ(frames[i], (i + 1) % 7 == 0 ? 0.25 : 1.0 / 60.0) << "frame " << i;
  ssProfile_Destroy(profile);
}

TEST(Profile, VsyncUsesOnlyItsTwoRatesAndBoth) {
  ssProfile* profile = Make("vsync:60:30", 11);
  std::vector<double> frames = Draw(profile, 10000);
  int at_a = 0, at_b = 0, switches = 0;
  for (size_t i = 0; i < frames.size(); ++i) {
    if (frames[i] == 1.0 / 60.0) ++at_a;
    else if (frames[i] == 1.0 / 30.0) ++at_b;
    else ADD_FAILURE() << "frame " << i << " = " << frames[i];
    if (i > 0 && frames[i] != frames[i - 1]) ++switches;
  }
  EXPECT_EQ(frames[0], 1.0 / 60.0);
  EXPECT_GT(at_a, 3000);
  EXPECT_GT(at_b, 3000);
  // Switching with probability 1/10 a frame: about 1000 switches, binomial deviation 30.
  EXPECT_NEAR(switches, 1000, 150);
  ssProfile_Destroy(profile);
}

TEST(Profile, TraceInOrderThenRepeats) {
  std::string path = TempFile("trace_ok.txt", "# recorded frames\n0.016\n\n  0.033  \n# a hitch\n0.1\n");
  ssProfile* profile = Make("trace:" + path);
  std::vector<double> frames = Draw(profile, 7);
  std::vector<double> expected = {0.016, 0.033, 0.1, 0.016, 0.033, 0.1, 0.016};
  EXPECT_EQ(frames, expected);
  ssProfile_Reset(profile);
  EXPECT_EQ(ssProfile_Next(profile), 0.016);
  ssProfile_Destroy(profile);
  std::remove(path.c_str());
}

TEST(Profile, BadSpecsAreRefusedNamingTheField) {
  ExpectRefused("fixed:abc", SS_ERROR_PARSE, "FPS");
  ExpectRefused("fixed:", SS_ERROR_PARSE, "FPS");
  ExpectRefused("fixed", SS_ERROR_PARSE, "FPS");
  ExpectRefused("fixed:30:1", SS_ERROR_PARSE, "extra field");
  ExpectRefused("fixed:30x", SS_ERROR_PARSE, "30x");
  ExpectRefused("fixed: 30", SS_ERROR_PARSE, "FPS");
  ExpectRefused("unknown:1", SS_ERROR_PARSE, "unknown");
  ExpectRefused("", SS_ERROR_PARSE, "unknown kind");
  ExpectRefused("uniform:45:15", SS_ERROR_OUT_OF_RANGE, "MINFPS = 45");
  ExpectRefused("uniform:15", SS_ERROR_PARSE, "MAXFPS");
  ExpectRefused("fixed:0", SS_ERROR_OUT_OF_RANGE, "FPS = 0");
  ExpectRefused("fixed:-3", SS_ERROR_OUT_OF_RANGE, "FPS = -3");
  ExpectRefused("fixed:nan", SS_ERROR_NOT_FINITE, "FPS = nan");
  ExpectRefused("fixed:inf", SS_ERROR_NOT_FINITE, "FPS = inf");
  ExpectRefused("jitter:60:10", SS_ERROR_OUT_OF_RANGE, "SPREAD_MS = 10");
  ExpectRefused("jitter:60:-1", SS_ERROR_OUT_OF_RANGE, "SPREAD_MS = -1");
  ExpectRefused("hitch:60:0:0.1", SS_ERROR_OUT_OF_RANGE, "EVERY = 0");
  ExpectRefused("hitch:60:2.5:0.1", SS_ERROR_OUT_OF_RANGE, "EVERY = 2.5");
  ExpectRefused("hitch:60:5:0", SS_ERROR_OUT_OF_RANGE, "SECONDS = 0");
  ExpectRefused("vsync:60:-30", SS_ERROR_OUT_OF_RANGE, "FPS_B = -30");
  ExpectRefused("trace:", SS_ERROR_PARSE, "FILE");
}

TEST(Profile, NullSpecIsRefused) {
  ssProfile* profile = nullptr;
  EXPECT_EQ(ssProfile_Create(nullptr, 1, &profile), SS_ERROR_OUT_OF_RANGE);
  EXPECT_EQ(profile, nullptr);
  EXPECT_NE(std::string(ssLastError()).find("spec = NULL"), std::string::npos) << ssLastError();
}

TEST(Profile, NullHandlesAndOutputsAreRefusedByName) {
  EXPECT_EQ(ssProfile_Create("fixed:60", 1, nullptr), SS_ERROR_OUT_OF_RANGE);
  EXPECT_NE(std::string(ssLastError()).find("out = NULL"), std::string::npos) << ssLastError();
  EXPECT_TRUE(std::isnan(ssProfile_Next(nullptr)));
  EXPECT_NE(std::string(ssLastError()).find("profile = NULL"), std::string::npos) << ssLastError();
  ssFail_Clear();
  ssProfile_Reset(nullptr);
  EXPECT_NE(std::string(ssLastError()).find("profile = NULL"), std::string::npos) << ssLastError();
  ssFail_Clear();
  EXPECT_STREQ(ssProfile_Spec(nullptr), "");
  EXPECT_NE(std::string(ssLastError()).find("profile = NULL"), std::string::npos) << ssLastError();
  ssProfile_Destroy(nullptr);
}

TEST(Profile, FramesOutsideTheFrameRangeAreRefusedNamingTheField) {
  ExpectRefused("fixed:1e-320", SS_ERROR_OUT_OF_RANGE, "FPS = 9.99989e-321 gives frames of inf s");
  ExpectRefused("fixed:2e-4", SS_ERROR_OUT_OF_RANGE, "FPS = 0.0002");
  ExpectRefused("fixed:1e13", SS_ERROR_OUT_OF_RANGE, "FPS = 1e+13");
  ExpectRefused("uniform:1e-320:30", SS_ERROR_OUT_OF_RANGE, "MINFPS = 9.99989e-321");
  ExpectRefused("uniform:15:1e300", SS_ERROR_OUT_OF_RANGE, "MAXFPS = 1e+300");
  ExpectRefused("hitch:60:1e19:1", SS_ERROR_OUT_OF_RANGE, "EVERY = 1e+19");
  ExpectRefused("hitch:60:-1e300:1", SS_ERROR_OUT_OF_RANGE, "EVERY = -1e+300");
  ExpectRefused("hitch:60:5:1e4", SS_ERROR_OUT_OF_RANGE, "SECONDS = 10000");
  ExpectRefused("hitch:60:5:1e-300", SS_ERROR_OUT_OF_RANGE, "SECONDS = 1e-300");
  ExpectRefused("vsync:60:1e-320", SS_ERROR_OUT_OF_RANGE, "FPS_B = 9.99989e-321");
  ExpectRefused("jitter:3e-4:1e6", SS_ERROR_OUT_OF_RANGE, "SPREAD_MS = 1e+06 gives frames of 6333");
  // the edges themselves are served
  for (const char* spec : {"fixed:2.8e-4", "fixed:1e12", "hitch:60:1e9:3600", "uniform:2.8e-4:1e12"}) {
    ssProfile* profile = Make(spec);
    for (double frame : Draw(profile, 100)) {
      EXPECT_GE(frame, SS_MIN_PROFILE_FRAME_S) << spec;
      EXPECT_LE(frame, SS_MAX_PROFILE_FRAME_S) << spec;
    }
    ssProfile_Destroy(profile);
  }
}

// Random specs of every kind with fields drawn from the whole double range: each is refused by name, or hands out
// only finite frames inside the documented range.
TEST(Profile, EveryAcceptedSpecHandsOutFramesInsideTheRange) {
  std::mt19937_64 rng(5);
  const char* specials[] = {"0", "-0", "1e-320", "1e-300", "1e-13", "1e-12", "1e-3", "0.5", "1", "3", "15", "60",
                            "1e3", "1e9", "1e12", "1e13", "1e19", "1e300", "1.8e308", "nan", "inf", "-1"};
  const size_t special_count = sizeof specials / sizeof specials[0];
  const char* kinds[] = {"fixed", "uniform", "jitter", "hitch", "vsync"};
  const int fields[] = {1, 2, 2, 3, 2};
  int accepted = 0;
  for (int i = 0; i < 20000; ++i) {
    int kind = static_cast<int>(rng() % 5);
    std::string spec = kinds[kind];
    for (int f = 0; f < fields[kind]; ++f) {
      char number[64];
      if (rng() % 2)
        std::snprintf(number, sizeof number, "%s", specials[rng() % special_count]);
      else
        std::snprintf(number, sizeof number, "%.6g", std::pow(10.0, std::uniform_real_distribution<>(-15, 15)(rng)));
      spec += std::string(":") + number;
    }
    ssProfile* profile = nullptr;
    if (ssProfile_Create(spec.c_str(), i, &profile) != SS_OK) {
      EXPECT_EQ(profile, nullptr) << spec;
      EXPECT_NE(std::string(ssLastError()).find(spec.substr(0, spec.find(':'))), std::string::npos)
          << spec << ": " << ssLastError();
      continue;
    }
    ++accepted;
    for (double frame : Draw(profile, 200)) {
      ASSERT_TRUE(std::isfinite(frame)) << spec;
      ASSERT_GE(frame, SS_MIN_PROFILE_FRAME_S) << spec;
      ASSERT_LE(frame, SS_MAX_PROFILE_FRAME_S) << spec;
    }
    ssProfile_Destroy(profile);
  }
  EXPECT_GT(accepted, 1000);
}

TEST(Profile, TraceOfADeviceOrPipeIsRefusedNotRead) {
  ExpectRefused("trace:/dev/zero", SS_ERROR_IO, "not a regular file");
  std::string fifo = ::testing::TempDir() + "steadystep_trace_fifo";
  std::remove(fifo.c_str());
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  ExpectRefused("trace:" + fifo, SS_ERROR_IO, "not a regular file");  // no writer: must not wait for one
  std::remove(fifo.c_str());
  ExpectRefused("trace:" + ::testing::TempDir(), SS_ERROR_IO, "not a regular file");
}

TEST(Profile, TraceLargerThanTheBoundIsRefusedWithoutReadingIt) {
  std::string path = ::testing::TempDir() + "steadystep_trace_huge";
  FILE* file = std::fopen(path.c_str(), "wb");
  ASSERT_NE(file, nullptr);
  ASSERT_EQ(ftruncate(fileno(file), static_cast<off_t>(SS_MAX_TRACE_BYTES) + 1), 0);  // sparse: costs no disk
  std::fclose(file);
  ExpectRefused("trace:" + path, SS_ERROR_IO, "larger than");
  std::remove(path.c_str());
}

TEST(Profile, TraceWithANulByteIsRefused) {
  std::string path = TempFile("trace_nul.txt", std::string("0.016\n0.5\0garbage\n", sizeof "0.016\n0.5\0garbage\n" - 1));
  ExpectRefused("trace:" + path, SS_ERROR_PARSE, "line 2: contains a NUL byte");
  std::remove(path.c_str());
}

TEST(Profile, TraceLinesUpToTheBoundAreReadWithOrWithoutAFinalNewline) {
  std::string last = "0.02" + std::string(507, ' ');  // 511 characters, no newline
  std::string path = TempFile("trace_long_last.txt", "0.016\n" + last);
  ssProfile* profile = Make("trace:" + path);
  EXPECT_EQ(Draw(profile, 2), (std::vector<double>{0.016, 0.02}));
  ssProfile_Destroy(profile);
  std::string at_bound = "0.03" + std::string(SS_MAX_TRACE_LINE_CHARS - 4, ' ');
  TempFile("trace_long_last.txt", at_bound + "\n");
  profile = Make("trace:" + path);
  EXPECT_EQ(ssProfile_Next(profile), 0.03);
  ssProfile_Destroy(profile);
  TempFile("trace_long_last.txt", "0.016\n" + at_bound + " ");
  ExpectRefused("trace:" + path, SS_ERROR_PARSE, "line 2: longer than");
  std::remove(path.c_str());
}

TEST(Profile, TraceDurationsOutsideTheFrameRangeAreRefusedWithTheirLine) {
  for (const char* bad : {"1e-13", "1e4", "1e-320"}) {
    std::string path = TempFile("trace_range.txt", std::string("0.016\n") + bad + "\n");
    ExpectRefused("trace:" + path, SS_ERROR_OUT_OF_RANGE, "line 2");
    std::remove(path.c_str());
  }
}

bool Ascii(const char* text) {
  for (; *text; ++text)
    if (static_cast<unsigned char>(*text) >= 0x80) return false;
  return true;
}

TEST(Profile, MessagesAreAsciiWhateverBytesCameIn) {
  std::string path = TempFile("trace_binary.txt", "0.016\n\xff\xfe\x80garbage\xc3\n");
  ExpectRefused("trace:" + path, SS_ERROR_PARSE, "\\xff\\xfe\\x80garbage\\xc3");
  EXPECT_TRUE(Ascii(ssLastError())) << ssLastError();
  std::remove(path.c_str());
  ExpectRefused("fixed:\xff\xfe", SS_ERROR_PARSE, "\\xff");
  EXPECT_TRUE(Ascii(ssLastError()));
  ExpectRefused("\xe2\x82\xac:1", SS_ERROR_PARSE, "unknown kind");
  EXPECT_TRUE(Ascii(ssLastError()));
  std::string long_spec = "fixed:" + std::string(300, '\xc3');
  ExpectRefused(long_spec, SS_ERROR_PARSE, "FPS");
  EXPECT_TRUE(Ascii(ssLastError()));
  ExpectRefused("trace:/nonexistent/\xff\xfe", SS_ERROR_IO, "\\xff\\xfe");
  EXPECT_TRUE(Ascii(ssLastError()));
}

TEST(Profile, MissingTraceFileIsAnIoErrorNamingThePath) {
  std::string path = ::testing::TempDir() + "steadystep_no_such_trace.txt";
  std::remove(path.c_str());
  ExpectRefused("trace:" + path, SS_ERROR_IO, path);
}

TEST(Profile, MalformedTraceLinesAreRefusedWithTheirNumber) {
  for (const char* bad : {"abc", "0", "-1", "nan", "1e999", "0.016 x"}) {
    std::string path = TempFile("trace_bad.txt", std::string("0.016\n# comment\n") + bad + "\n0.02\n");
    ExpectRefused("trace:" + path, SS_ERROR_PARSE, "line 3");
    std::remove(path.c_str());
  }
}

TEST(Profile, EmptyTraceIsRefused) {
  std::string path = TempFile("trace_empty.txt", "# nothing recorded\n\n");
  ExpectRefused("trace:" + path, SS_ERROR_PARSE, path);
  std::remove(path.c_str());
}

/* Fuzz target: profile specifications (text) and trace files (bytes written to a temporary file). A profile that
 * is made hands out frame times that are finite and > 0, the same sequence again after ssProfile_Reset, and keeps
 * its spec; a refusal says why and leaves the output pointer alone. */
#include <unistd.h>

#include "fuzz_input.h"
#include "steadystep/lab/profile.h"

enum { FRAMES = 256 };

static char trace_path[64];

/* One temporary trace file for the whole process, rewritten by every input. It is unlinked at once and read through
 * /proc/self/fd, so that no file is left behind even when the process dies on a crash; in memory (/dev/shm) when
 * there is one, because rewriting a file on disk made every input wait for the file system. */
static const char* writeTrace(const uint8_t* data, size_t size) {
  static int fd = -1;
  if (fd < 0) {
    char name[64];
    strcpy(name, access("/dev/shm", W_OK) == 0 ? "/dev/shm/steadystep-fuzz-trace-XXXXXX"
                                                : "/tmp/steadystep-fuzz-trace-XXXXXX");
    fd = mkstemp(name);
    if (fd < 0) abort();
    unlink(name);
    snprintf(trace_path, sizeof trace_path, "/proc/self/fd/%d", fd);
  }
  if (ftruncate(fd, 0) != 0 || pwrite(fd, data, size, 0) != (ssize_t)size) abort();
  return trace_path;
}

/* Returns whether the profile was made. */
static int checkProfile(const char* spec, uint64_t seed) {
  ssProfile* const canary = (ssProfile*)&trace_path; /* any address that is not a profile */
  ssProfile* profile = canary;
  ssStatus status = ssProfile_Create(spec, seed, &profile);
  if (status != SS_OK) {
    FUZZ_REQUIRE(ssLastError()[0] != '\0', "ssProfile_Create(\"%s\") refused (%s) without a message", spec,
                 ssStatusName(status));
    FUZZ_REQUIRE(profile == canary, "ssProfile_Create(\"%s\") refused but wrote its output", spec);
    return 0;
  }
  FUZZ_REQUIRE(profile != NULL && profile != canary, "ssProfile_Create(\"%s\") returned OK without a profile", spec);
  FUZZ_REQUIRE(strcmp(ssProfile_Spec(profile), spec) == 0, "spec \"%s\" kept as \"%s\"", spec,
               ssProfile_Spec(profile));
  double first[FRAMES];
  for (int i = 0; i < FRAMES; ++i) {
    first[i] = ssProfile_Next(profile);
    FUZZ_REQUIRE(isfinite(first[i]) && first[i] > 0, "profile \"%s\" seed %llu: frame %d lasts %g s", spec,
                 (unsigned long long)seed, i, first[i]);
  }
  ssProfile_Reset(profile);
  for (int i = 0; i < FRAMES; ++i) {
    double again = ssProfile_Next(profile);
    FUZZ_REQUIRE(memcmp(&again, &first[i], sizeof again) == 0,
                 "profile \"%s\" seed %llu: frame %d is %.17g after a reset, %.17g before", spec,
                 (unsigned long long)seed, i, again, first[i]);
  }
  ssProfile_Destroy(profile);
  return 1;
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzInput in = {data, size};
  uint8_t mode = fuzz_byte(&in);
  uint64_t seed = (uint64_t)(unsigned)fuzzInt(&in);
  if (mode % 2 == 0) {
    /* A spec as text, cut at the first NUL like a C string. trace:FILE is left to the other mode: a fuzzed path
     * could name a device or a huge file, which tests the machine rather than the parser. */
    char spec[512];
    size_t length = in.size < sizeof spec - 1 ? in.size : sizeof spec - 1;
    memcpy(spec, in.data, length);
    spec[length] = '\0';
    if (strncmp(spec, "trace:", 6) == 0) return 0;
    checkProfile(spec, seed);
  } else {
    char spec[96];
    snprintf(spec, sizeof spec, "trace:%s", writeTrace(in.data, in.size));
    int accepted = checkProfile(spec, seed);
    /* A NUL byte is no part of a text file: "0.5\0garbage" must not read as 0.5. */
    FUZZ_REQUIRE(!(accepted && memchr(in.data, '\0', in.size) != NULL), "a trace holding a NUL byte was accepted");
  }
  return 0;
}

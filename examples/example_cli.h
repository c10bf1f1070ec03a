/* What the example programs share besides their physics: their flags, the CSV rows and the wall clock of the
 * stepping loop. Not part of the library; each example includes it so that the programs themselves show only what an
 * ODE program does (and, in the *_steadystep versions, the few lines that adopt it).
 *
 * Flags of every example:
 *   --profile SPEC   frame times from a lab profile (steadystep/profile.h), e.g. fixed:60, uniform:15:45
 *   --duration S     simulated time (s, > 0), default 10 (as `steadystep run`'s --duration)
 *   --seed N         the profile's seed (whole number >= 0), default 1
 *   --quiet          no CSV; print the stepping loop's wall seconds and process CPU seconds to stderr, one line
 *                    "WALL CPU" (for benchmarks: CPU time is what a busy shared machine disturbs least)
 * Adopted programs (EXAMPLE_FLAGS_STEPPER) also take --policy NAME (a preset of stepping.h: naive, implicit-euler, matched, exact, fixed, ...; default
 * implicit-euler) and
 * --max-step S (the longest substep, s, > 0, default 1/60); the stack also takes --boxes N (EXAMPLE_FLAGS_BOXES).
 * Exit codes: 0 every frame stepped, 1 a frame failed, 2 a bad flag. */
#ifndef EXAMPLE_CLI_H
#define EXAMPLE_CLI_H

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <steadystep/lab/profile.h>

enum { EXAMPLE_FLAGS_STEPPER = 1, EXAMPLE_FLAGS_BOXES = 2 };

typedef struct ExampleFlags {
  ssProfile* frames;  /* made from --profile and --seed */
  double duration_s;  /* --duration */
  int quiet;          /* --quiet */
  const char* policy; /* --policy (adopted programs) */
  double max_step_s;  /* --max-step (adopted programs) */
  int boxes;          /* --boxes (stack), > 0 */
} ExampleFlags;

static inline int exampleBadFlag(const char* program, const char* flag, const char* value, const char* why) {
  fprintf(stderr, "%s: %s %s: %s (see --help)\n", program, flag, value, why);
  return 2;
}

static inline int exampleNumber(const char* text, double* out) {
  char* end;
  errno = 0;
  *out = strtod(text, &end);
  return errno == 0 && end != text && *end == '\0' && isfinite(*out);
}

/* Fills flags from argv. Returns 0 to run, 2 for a bad flag (message printed), -1 after printing --help. */
static inline int exampleParseFlags(const char* program, int argc, char** argv, int accepts, ExampleFlags* flags) {
  const char* profile = "uniform:15:45";
  double seed = 1;
  *flags = (ExampleFlags){NULL, 10.0, 0, "implicit-euler", 1.0 / 60.0, 8};
  for (int i = 1; i < argc; ++i) {
    const char* flag = argv[i];
    if (strcmp(flag, "--help") == 0 || strcmp(flag, "-h") == 0) {
      printf("usage: %s [--profile SPEC] [--duration S] [--seed N] [--quiet]%s%s\n"
             "Defaults: uniform:15:45, 10 s, seed 1%s%s. CSV on stdout; --quiet prints the stepping loop's wall\n"
             "and CPU seconds to stderr instead.\n",
             program,
             accepts & EXAMPLE_FLAGS_STEPPER ? " [--policy naive|implicit-euler|matched|exact|fixed|fixed-matched|fixed-exact] [--max-step S]" : "",
             accepts & EXAMPLE_FLAGS_BOXES ? " [--boxes N]" : "",
             accepts & EXAMPLE_FLAGS_STEPPER ? ", policy implicit-euler, max step 1/60 s" : "",
             accepts & EXAMPLE_FLAGS_BOXES ? ", 8 boxes" : "");
      return -1;
    }
    if (strcmp(flag, "--quiet") == 0) {
      flags->quiet = 1;
      continue;
    }
    int stepper_flag = strcmp(flag, "--policy") == 0 || strcmp(flag, "--max-step") == 0;
    int boxes_flag = strcmp(flag, "--boxes") == 0;
    int known = strcmp(flag, "--profile") == 0 || strcmp(flag, "--duration") == 0 || strcmp(flag, "--seed") == 0 ||
                (stepper_flag && (accepts & EXAMPLE_FLAGS_STEPPER)) || (boxes_flag && (accepts & EXAMPLE_FLAGS_BOXES));
    if (!known) return exampleBadFlag(program, flag, "", "unknown flag");
    if (i + 1 >= argc) return exampleBadFlag(program, flag, "", "needs a value");
    const char* value = argv[++i];
    double number = 0;
    if (strcmp(flag, "--profile") == 0) profile = value;
    else if (strcmp(flag, "--policy") == 0) flags->policy = value;
    else if (!exampleNumber(value, &number)) return exampleBadFlag(program, flag, value, "not a finite number");
    else if (strcmp(flag, "--duration") == 0) {
      if (!(number > 0)) return exampleBadFlag(program, flag, value, "must be > 0 s");
      flags->duration_s = number;
    } else if (strcmp(flag, "--seed") == 0) {
      if (number < 0 || number != floor(number) || number > 9e15)
        return exampleBadFlag(program, flag, value, "must be a whole number >= 0");
      seed = number;
    } else if (strcmp(flag, "--max-step") == 0) {
      if (!(number > 0)) return exampleBadFlag(program, flag, value, "must be > 0 s");
      flags->max_step_s = number;
    } else {
      if (number < 1 || number != floor(number) || number > 100000)
        return exampleBadFlag(program, flag, value, "must be a whole number in [1, 100000]");
      flags->boxes = (int)number;
    }
  }
  if (ssProfile_Create(profile, (uint64_t)seed, &flags->frames) != SS_OK)
    return exampleBadFlag(program, "--profile", profile, ssLastError());
  return 0;
}

/* A flag refused after parsing (an adopted program's --policy): frees the profile, returns 2. */
static inline int exampleRefuse(ExampleFlags* flags, const char* program, const char* flag, const char* value,
                                const char* why) {
  ssProfile_Destroy(flags->frames);
  flags->frames = NULL;
  return exampleBadFlag(program, flag, value, why);
}

/* The stepping loop's cost: wall clock and process CPU time (s), from C11's clocks (no POSIX feature macro needed
 * before the program's own includes). */
typedef struct ExampleClock {
  double wall_s, cpu_s;
} ExampleClock;

static inline ExampleClock exampleClock(void) {
  struct timespec now;
  timespec_get(&now, TIME_UTC);
  return (ExampleClock){(double)now.tv_sec + 1e-9 * (double)now.tv_nsec, (double)clock() / CLOCKS_PER_SEC};
}

/* Prints the CSV header unless --quiet. */
static inline void exampleHeader(const ExampleFlags* flags, const char* header) {
  if (!flags->quiet) printf("%s\n", header);
}

/* Prints one CSV row (unless --quiet) at full precision. Returns 0 when a value is not finite: the frame failed. */
static inline int exampleRow(const ExampleFlags* flags, double time_s, int count, const double* values) {
  int finite = 1;
  for (int i = 0; i < count; ++i) finite = finite && isfinite(values[i]);
  if (flags->quiet) return finite;
  printf("%.17g", time_s);
  for (int i = 0; i < count; ++i) printf(",%.17g", values[i]);
  printf("\n");
  return finite;
}

/* After the loop: under --quiet, the time since started to stderr as "WALL CPU" (s); frees the profile. */
static inline void exampleFinish(ExampleFlags* flags, ExampleClock started) {
  ExampleClock now = exampleClock();
  if (flags->quiet) fprintf(stderr, "%.9f %.9f\n", now.wall_s - started.wall_s, now.cpu_s - started.cpu_s);
  ssProfile_Destroy(flags->frames);
  flags->frames = NULL;
}

#endif

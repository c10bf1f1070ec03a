/* steadystep lab: taking part in `steadystep audit` from a C or C++ program (docs/audit.md).
 *
 * The audit runs a program many times with the flags
 *   --profile SPEC   frame times from a lab profile (profile.h), e.g. fixed:60, uniform:15:45
 *   --seed N         the profile's seed, a whole number >= 0
 *   --duration S     simulated seconds, > 0
 *   --policy NAME    a preset of stepping.h (naive, implicit-euler, matched, exact, fixed, ...); a program's own
 *                    stepping (built without the library) is run without it
 * and reads CSV on stdout: a header "t_s,<quantity>_<unit>,...", a row at t = 0, then one row per frame. Optional
 * count columns after the quantities say what each frame did: "steps" (physics steps taken) and the served counts
 * of the frame's report (SS_AUDIT_SERVED_HEADER; -1 on every frame after the t = 0 row: not counted, left out). Exit 0: every frame stepped; 1: a frame failed (after its message
 * on stderr); 2: a bad flag. This header does all of that, so that taking part is a few lines:
 *
 *   ssAuditFlags flags;
 *   int parsed = ssAuditParseFlags("my_game", argc, argv, &flags);   // 0 run, 2 bad flag, -1 after --help
 *   if (parsed != 0) return parsed < 0 ? 0 : parsed;
 *   ssStepping stepping = ssDefaultStepping();                        // then the program's own choices
 *   if (ssAuditStepping(&flags, 1.0 / 60, &stepping) != 0) return 2; // --policy over it, or a named refusal
 *   ... build the world, the registry and the stepper ...
 *   ssAuditHeader(&flags, "t_s,height_m,pitch_rad", 1);              // 1: with the optional count columns
 *   for (double t = 0; ssAuditRunning(&flags, t);) {
 *     double frame_s = ssAuditNextFrame(&flags, t);
 *     ... the frame: input added once a frame, ssStepper_Step(stepper, frame_s, &report) ...
 *     t = report.time_s;                                               // the stepper's clock
 *     ssAuditFrame frame = {report.steps, {...}};                     // the report's counts (ssAuditServed)
 *     if (!ssAuditRow(&flags, t, 2, values, &frame)) { fprintf(stderr, "..."); code = 1; break; }
 *   }
 *   ssAuditFinish(&flags);
 *
 * Logic that depends on time or state runs in the stepper's before_step at ssStepper_CurrentStep's time_s (as
 * examples/wrecking_arm.c does), so that `fixed` can be the same at every frame rate; the program's own stepping runs
 * it once a frame, as it always did.
 *
 * Header-only (static inline): include it in one file of the program and link the lab (steadystep_lab) for the
 * profiles. Not part of the core library: a shipped program keeps its own frame clock. */
#ifndef STEADYSTEP_LAB_AUDIT_FLAGS_H
#define STEADYSTEP_LAB_AUDIT_FLAGS_H

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "steadystep/lab/profile.h"
#include "steadystep/stepping.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct ssAuditFlags {
  const char* program; /* the name messages start with */
  ssProfile* frames;   /* made from --profile and --seed; freed by ssAuditFinish */
  double duration_s;   /* --duration (s), default 10 */
  const char* policy;  /* --policy, or NULL when not given (the program's own stepping) */
  int counts;          /* ssAuditHeader's with_counts: the rows carry the optional count columns */
} ssAuditFlags;

/** The served counts of a frame, as its report gives them (ssFrameReport's rows and contacts, registry.h). */
typedef struct ssAuditServed {
  int rows_by_mapping, rows_handed_to_matched, rows_handed_to_implicit_euler;
  int contacts_by_mapping, contacts_handed_to_matched, contacts_handed_to_implicit_euler;
} ssAuditServed;

/** One frame's counts: the physics steps it took and what served their rows and contacts. */
typedef struct ssAuditFrame {
  int steps;
  ssAuditServed served;
} ssAuditFrame;

/** The optional count columns, in the order ssAuditRow prints them. */
#define SS_AUDIT_SERVED_HEADER                                                                              \
  "steps,rows_by_mapping,rows_handed_to_matched,rows_handed_to_implicit_euler,contacts_by_mapping,"          \
  "contacts_handed_to_matched,contacts_handed_to_implicit_euler"

static inline int ssAuditBadFlag_(const char* program, const char* flag, const char* value, const char* why) {
  fprintf(stderr, "%s: %s %s: %s (see --help)\n", program, flag, value, why);
  return 2;
}

/** Fills flags from argv (program: the name of messages). Returns 0 to run, 2 for a bad or unknown flag (one line
 *  on stderr naming it and its value), -1 after printing --help. Defaults: uniform:15:45, seed 1, 10 s, no policy. */
static inline int ssAuditParseFlags(const char* program, int argc, char** argv, ssAuditFlags* flags) {
  const char* profile = "uniform:15:45";
  double seed = 1;
  *flags = (ssAuditFlags){program, NULL, 10.0, NULL, 0};
  for (int i = 1; i < argc; ++i) {
    const char* flag = argv[i];
    if (strcmp(flag, "--help") == 0 || strcmp(flag, "-h") == 0) {
      printf("usage: %s [--profile SPEC] [--seed N] [--duration S] [--policy NAME]\n"
             "CSV on stdout: t_s and the followed quantities, one row per frame (steadystep audit's protocol).\n",
             program);
      return -1;
    }
    if (strcmp(flag, "--profile") != 0 && strcmp(flag, "--seed") != 0 && strcmp(flag, "--duration") != 0 &&
        strcmp(flag, "--policy") != 0)
      return ssAuditBadFlag_(program, flag, "", "unknown flag");
    if (i + 1 >= argc) return ssAuditBadFlag_(program, flag, "", "needs a value");
    const char* value = argv[++i];
    if (strcmp(flag, "--profile") == 0) {
      profile = value;
      continue;
    }
    if (strcmp(flag, "--policy") == 0) {
      flags->policy = value;
      continue;
    }
    char* end;
    errno = 0;
    double number = strtod(value, &end);
    if (errno != 0 || end == value || *end != '\0' || !isfinite(number))
      return ssAuditBadFlag_(program, flag, value, "not a finite number");
    if (strcmp(flag, "--duration") == 0) {
      if (!(number > 0)) return ssAuditBadFlag_(program, flag, value, "must be > 0 s");
      flags->duration_s = number;
    } else {
      if (number < 0 || number != floor(number) || number > 9e15)
        return ssAuditBadFlag_(program, flag, value, "must be a whole number >= 0");
      seed = number;
    }
  }
  if (ssProfile_Create(profile, (uint64_t)seed, &flags->frames) != SS_OK)
    return ssAuditBadFlag_(program, "--profile", profile, ssLastError());
  return 0;
}

/** Puts --policy's preset (cut, mapping, frozen step) into *stepping, keeping its other fields; naive freezes the
 *  softness at tuned_step_s (s), the step the program was tuned for. No --policy: *stepping unchanged. Returns 0,
 *  or 2 after one line on stderr naming the policy (the profile is freed then). */
static inline int ssAuditStepping(ssAuditFlags* flags, double tuned_step_s, ssStepping* stepping) {
  if (flags->policy == NULL) return 0;
  if (ssSteppingForPolicy(flags->policy, tuned_step_s, stepping) == SS_OK) return 0;
  ssProfile_Destroy(flags->frames);
  flags->frames = NULL;
  return ssAuditBadFlag_(flags->program, "--policy", flags->policy, ssLastError());
}

/** Prints the header: the program's columns ("t_s,..."), then with_counts != 0 the optional count columns. */
static inline void ssAuditHeader(ssAuditFlags* flags, const char* columns, int with_counts) {
  flags->counts = with_counts != 0;
  printf("%s%s%s\n", columns, flags->counts ? "," : "", flags->counts ? SS_AUDIT_SERVED_HEADER : "");
}

/** Whether the run goes on at simulated time time_s (s): a rounding remainder of the duration is its end. */
static inline int ssAuditRunning(const ssAuditFlags* flags, double time_s) {
  return flags->duration_s - time_s > 1e-9 * fmax(1.0, flags->duration_s);
}

/** The next frame's duration (s), the last one shortened to end at the duration. */
static inline double ssAuditNextFrame(ssAuditFlags* flags, double time_s) {
  return fmin(ssProfile_Next(flags->frames), flags->duration_s - time_s);
}

/** Prints one row at full precision: time_s, the count values, and the frame's counts if the header has them
 *  (frame NULL: zeros, for the t = 0 row). Returns 0 when a value is not finite: the frame failed. */
static inline int ssAuditRow(const ssAuditFlags* flags, double time_s, int count, const double* values,
                             const ssAuditFrame* frame) {
  int finite = isfinite(time_s);
  printf("%.17g", time_s);
  for (int i = 0; i < count; ++i) {
    finite = finite && isfinite(values[i]);
    printf(",%.17g", values[i]);
  }
  if (flags->counts) {
    ssAuditFrame none = {0, {0, 0, 0, 0, 0, 0}};
    const ssAuditFrame* f = frame != NULL ? frame : &none;
    printf(",%d,%d,%d,%d,%d,%d,%d", f->steps, f->served.rows_by_mapping, f->served.rows_handed_to_matched,
           f->served.rows_handed_to_implicit_euler, f->served.contacts_by_mapping,
           f->served.contacts_handed_to_matched, f->served.contacts_handed_to_implicit_euler);
  }
  printf("\n");
  return finite;
}

/** After the loop: frees the profile. */
static inline void ssAuditFinish(ssAuditFlags* flags) {
  ssProfile_Destroy(flags->frames);
  flags->frames = NULL;
}

#ifdef __cplusplus
}
#endif

#endif

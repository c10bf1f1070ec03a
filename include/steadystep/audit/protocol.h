/* steadystep: taking part in `steadystep audit` from a C or C++ program built against the installed library alone
 * (docs/audit.md), without the lab. Header-only (static inline): include it in one file of the program; it needs
 * the core (libsteadystep) and ODE, nothing else.
 *
 * The audit runs the program many times with the flags
 *   --profile SPEC         the frame-time profile's name (fixed:60, uniform:15:45, ...), for messages
 *   --seed N               its seed, a whole number >= 0
 *   --duration S           simulated seconds, > 0
 *   --policy NAME          a preset of stepping.h (naive, implicit-euler, ..., fixed); without it the program
 *                          steps on its own, as it does without the library
 *   --max-step-scale F     the largest step is F times the tuned step (0 < F <= 1; default 1): the audit's
 *                          "half-step" diagnosis passes 0.5
 *   --iterations-scale N   QuickStep's iterations times N (a whole number in [1, 100]; default 1): the audit's
 *                          "more-iterations" diagnosis passes 4
 * and hands over the frame durations themselves in a file named by the environment variable
 * STEADYSTEP_AUDIT_FRAMES (one duration in seconds a line, every profile's frames: no profile code is needed here).
 * Run alone, without that variable, the program takes --profile fixed:FPS (every frame 1/FPS s) or trace:FILE (one
 * duration a line, repeated when it runs out) and refuses the random kinds by name.
 *
 * Output: CSV on stdout. The header "t_s,<quantity>_<unit>,...", a row at t = 0, then one row per frame at the
 * stepper's clock (ssFrameReport.time_s), with optional count columns (SS_AUDIT_RUN_COUNTS_HEADER: the frame's
 * steps, what served its rows and contacts, and its steps that made contacts but softened none). Exit 0: every frame
 * stepped; 1: a frame failed (after its message on stderr); 2: a bad flag. So taking part is a few lines:
 *
 *   ssAuditRun run;
 *   int parsed = ssAuditRun_Parse("my_game", argc, argv, &run);      // 0 run, 2 bad flag, -1 after --help
 *   if (parsed != 0) return parsed < 0 ? 0 : parsed;
 *   ssStepperDef def = ssDefaultStepperDef();                        // then the program's own choices
 *   if (ssAuditRun_Stepping(&run, def.tuned_step_s = 1.0 / 60, &def.stepping) != 0) return 2;
 *   ... build the world; ssAuditRun_World(&run, world); make the stepper when run.policy != NULL ...
 *   ssAuditRun_Header(&run, "t_s,height_m,pitch_rad", 1);
 *   ssAuditRun_Row(&run, 0, 2, values, NULL);                       // the t = 0 row
 *   for (double t = 0; ssAuditRun_Running(&run, t);) {
 *     double frame_s = ssAuditRun_NextFrame(&run, t);
 *     ... ssStepper_Step(stepper, frame_s, &report); t = report.time_s;  (own: its loop; t += frame_s)
 *     ssAuditRun_Row(&run, t, 2, values, &report);                    // own: ssAuditRun_OwnRow(..., steps)
 *   }
 *   ssAuditRun_Finish(&run);
 *
 * Logic that depends on time or state belongs in the stepper's before_step at ssStepper_CurrentStep's time_s, so
 * that `fixed` can give the same motion at every frame rate; the program's own stepping runs it as it always did.
 * lab/include/steadystep/lab/audit_flags.h is the lab's version of the same protocol (its own frame-time profiles,
 * no diagnosis flags). */
#ifndef STEADYSTEP_AUDIT_PROTOCOL_H
#define STEADYSTEP_AUDIT_PROTOCOL_H

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <ode/ode.h>

#include "steadystep/stepper.h"
#include "steadystep/stepping.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The environment variable that names the file of frame durations the audit hands over. */
#define SS_AUDIT_RUN_FRAMES_VARIABLE "STEADYSTEP_AUDIT_FRAMES"

/** The optional count columns, in the order ssAuditRun_Row prints them. */
#define SS_AUDIT_RUN_COUNTS_HEADER                                                                           \
  "steps,rows_by_mapping,rows_handed_to_matched,rows_handed_to_implicit_euler,contacts_by_mapping,"          \
  "contacts_handed_to_matched,contacts_handed_to_implicit_euler,unsoftened_contact_steps"

/** One run's flags and frame clock. Filled by ssAuditRun_Parse; the fields are read-only for the program. */
typedef struct ssAuditRun {
  const char* program;     /* the name messages start with */
  const char* profile;     /* --profile, as given */
  double duration_s;       /* --duration (s), default 10 */
  const char* policy;      /* --policy, or NULL: the program's own stepping */
  double max_step_scale;   /* --max-step-scale, in (0, 1], default 1 */
  int iterations_scale;    /* --iterations-scale, in [1, 100], default 1 */
  int counts;              /* ssAuditRun_Header's with_counts: the rows carry the count columns */
  double fixed_frame_s;    /* fixed:FPS alone: every frame 1/FPS s; 0 when frames come from a file */
  FILE* frames;            /* the frames file (STEADYSTEP_AUDIT_FRAMES or trace:FILE), or NULL */
  const char* frames_path; /* its name, for messages */
} ssAuditRun;

static inline int ssAuditRun_Bad_(const char* program, const char* flag, const char* value, const char* why) {
  fprintf(stderr, "%s: %s %s: %s (see --help)\n", program, flag, value, why);
  return 2;
}

/* A whole token as a finite number; 0 when it is not one. */
static inline int ssAuditRun_Number_(const char* text, double* out) {
  char* end;
  errno = 0;
  *out = strtod(text, &end);
  return errno == 0 && end != text && *end == '\0' && isfinite(*out);
}

/* The next duration of the frames file (s), rewinding at its end when rewind_at_end; 0 at its end, -1 for a line
 * that is not a duration (message printed). Blank lines and lines starting with # are skipped. */
static inline double ssAuditRun_ReadFrame_(ssAuditRun* run, int rewind_at_end) {
  char line[256];
  for (int rewound = 0;;) {
    if (fgets(line, sizeof line, run->frames) == NULL) {
      if (!rewind_at_end || rewound || fseek(run->frames, 0, SEEK_SET) != 0) return 0;
      rewound = 1;
      continue;
    }
    size_t length = strcspn(line, "\r\n");
    line[length] = '\0';
    if (length == 0 || line[0] == '#') continue;
    double value;
    if (!ssAuditRun_Number_(line, &value) || !(value > 0)) {
      fprintf(stderr, "%s: frames file %s: '%s' is not a duration in seconds > 0\n", run->program,
              run->frames_path, line);
      return -1;
    }
    return value;
  }
}

/* Opens path as the frames file and checks every line once. Returns 0, or 2 after a message naming it. */
static inline int ssAuditRun_OpenFrames_(ssAuditRun* run, const char* flag, const char* path) {
  run->frames = fopen(path, "r");
  run->frames_path = path;
  if (run->frames == NULL) return ssAuditRun_Bad_(run->program, flag, path, strerror(errno));
  int count = 0;
  double value;
  while ((value = ssAuditRun_ReadFrame_(run, 0)) > 0) ++count;
  if (value < 0 || count == 0 || fseek(run->frames, 0, SEEK_SET) != 0) {
    fclose(run->frames);
    run->frames = NULL;
    return value < 0 ? 2 : ssAuditRun_Bad_(run->program, flag, path, "holds no frame duration");
  }
  return 0;
}

/** Fills run from argv (program: the name of messages). Returns 0 to run, 2 for a bad or unknown flag (one line on
 *  stderr naming it and its value), -1 after printing --help. Defaults: fixed:60, seed 1, 10 s, no policy. */
static inline int ssAuditRun_Parse(const char* program, int argc, char** argv, ssAuditRun* run) {
  memset(run, 0, sizeof *run);
  run->program = program;
  run->profile = "fixed:60";
  run->duration_s = 10.0;
  run->max_step_scale = 1.0;
  run->iterations_scale = 1;
  for (int i = 1; i < argc; ++i) {
    const char* flag = argv[i];
    if (strcmp(flag, "--help") == 0 || strcmp(flag, "-h") == 0) {
      printf("usage: %s [--profile SPEC] [--seed N] [--duration S] [--policy NAME] [--max-step-scale F]\n"
             "       [--iterations-scale N]\n"
             "CSV on stdout: t_s and the followed quantities, one row per frame (steadystep audit's protocol).\n"
             "Frames from the file named by " SS_AUDIT_RUN_FRAMES_VARIABLE ", else fixed:FPS or trace:FILE.\n",
             program);
      return -1;
    }
    if (strcmp(flag, "--profile") != 0 && strcmp(flag, "--seed") != 0 && strcmp(flag, "--duration") != 0 &&
        strcmp(flag, "--policy") != 0 && strcmp(flag, "--max-step-scale") != 0 &&
        strcmp(flag, "--iterations-scale") != 0)
      return ssAuditRun_Bad_(program, flag, "", "unknown flag");
    if (i + 1 >= argc) return ssAuditRun_Bad_(program, flag, "", "needs a value");
    const char* value = argv[++i];
    if (strcmp(flag, "--profile") == 0) {
      run->profile = value;
      continue;
    }
    if (strcmp(flag, "--policy") == 0) {
      run->policy = value;
      continue;
    }
    double number;
    if (!ssAuditRun_Number_(value, &number)) return ssAuditRun_Bad_(program, flag, value, "not a finite number");
    if (strcmp(flag, "--duration") == 0) {
      if (!(number > 0)) return ssAuditRun_Bad_(program, flag, value, "must be > 0 s");
      run->duration_s = number;
    } else if (strcmp(flag, "--seed") == 0) {
      if (number < 0 || number != floor(number) || number > 9e15)
        return ssAuditRun_Bad_(program, flag, value, "must be a whole number >= 0");
    } else if (strcmp(flag, "--max-step-scale") == 0) {
      if (!(number > 0 && number <= 1)) return ssAuditRun_Bad_(program, flag, value, "must be in (0, 1]");
      run->max_step_scale = number;
    } else {
      if (number < 1 || number > 100 || number != floor(number))
        return ssAuditRun_Bad_(program, flag, value, "must be a whole number in [1, 100]");
      run->iterations_scale = (int)number;
    }
  }
  const char* handed = getenv(SS_AUDIT_RUN_FRAMES_VARIABLE);
  if (handed != NULL && handed[0] != '\0') return ssAuditRun_OpenFrames_(run, SS_AUDIT_RUN_FRAMES_VARIABLE, handed);
  if (strncmp(run->profile, "trace:", 6) == 0) return ssAuditRun_OpenFrames_(run, "--profile", run->profile + 6);
  double fps;
  if (strncmp(run->profile, "fixed:", 6) == 0 && ssAuditRun_Number_(run->profile + 6, &fps)) {
    if (!(fps >= 1.0 / 3600 && fps <= 1e12)) return ssAuditRun_Bad_(program, "--profile", run->profile,
                                                                    "the rate must be in [1/3600, 1e12] fps");
    run->fixed_frame_s = 1.0 / fps;
    return 0;
  }
  return ssAuditRun_Bad_(program, "--profile", run->profile,
                         "without the lab only fixed:FPS and trace:FILE; steadystep audit hands every profile's "
                         "frames over in " SS_AUDIT_RUN_FRAMES_VARIABLE);
}

/** Puts --policy's preset (cut, mapping, frozen step, step_seed use) into *stepping, keeping its other fields, and
 *  --max-step-scale times tuned_step_s (s, the step the program was tuned for) as its largest step. No --policy:
 *  *stepping unchanged. Returns 0, or 2 after one line on stderr naming the policy. */
static inline int ssAuditRun_Stepping(ssAuditRun* run, double tuned_step_s, ssStepping* stepping) {
  if (run->policy == NULL) return 0;
  if (ssSteppingForPolicy(run->policy, 0, stepping) != SS_OK)
    return ssAuditRun_Bad_(run->program, "--policy", run->policy, ssLastError());
  if (run->max_step_scale != 1.0) stepping->max_step_s = run->max_step_scale * tuned_step_s;
  return 0;
}

/** Applies --iterations-scale to the world's QuickStep iterations (dWorldSetQuickStepNumIterations). */
static inline void ssAuditRun_World(const ssAuditRun* run, dWorldID world) {
  if (run->iterations_scale != 1)
    dWorldSetQuickStepNumIterations(world, run->iterations_scale * dWorldGetQuickStepNumIterations(world));
}

/** Prints the header: the program's columns ("t_s,..."), then with_counts != 0 the count columns. */
static inline void ssAuditRun_Header(ssAuditRun* run, const char* columns, int with_counts) {
  run->counts = with_counts != 0;
  printf("%s%s%s\n", columns, run->counts ? "," : "", run->counts ? SS_AUDIT_RUN_COUNTS_HEADER : "");
}

/** Whether the run goes on at simulated time time_s (s): a rounding remainder of the duration is its end. */
static inline int ssAuditRun_Running(const ssAuditRun* run, double time_s) {
  return run->duration_s - time_s > 1e-9 * fmax(1.0, run->duration_s);
}

/** The next frame's duration (s), the last one shortened to end at the duration. */
static inline double ssAuditRun_NextFrame(ssAuditRun* run, double time_s) {
  double frame_s = run->frames != NULL ? ssAuditRun_ReadFrame_(run, 1) : run->fixed_frame_s;
  if (!(frame_s > 0)) return nan(""); /* the file changed under the run: the stepper refuses the frame */
  return fmin(frame_s, run->duration_s - time_s);
}

/* Prints time_s, the values and the counts; returns 0 when a value is not finite. */
static inline int ssAuditRun_Print_(const ssAuditRun* run, double time_s, int count, const double* values,
                                    const int counts[8]) {
  int finite = isfinite(time_s);
  printf("%.17g", time_s);
  for (int i = 0; i < count; ++i) {
    finite = finite && isfinite(values[i]);
    printf(",%.17g", values[i]);
  }
  if (run->counts)
    printf(",%d,%d,%d,%d,%d,%d,%d,%d", counts[0], counts[1], counts[2], counts[3], counts[4], counts[5], counts[6],
           counts[7]);
  printf("\n");
  return finite;
}

/** Prints one row at full precision: time_s (s), the count values, and with the count columns the frame's steps,
 *  served counts and unsoftened_contact_steps from report (NULL: zeros, for the t = 0 row). Returns 0 when a value
 *  is not finite: the frame failed. */
static inline int ssAuditRun_Row(const ssAuditRun* run, double time_s, int count, const double* values,
                                 const ssFrameReport* report) {
  int counts[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  if (report != NULL) {
    const ssServedCounts *rows = &report->rows, *contacts = &report->contacts;
    int taken[8] = {report->steps,           rows->by_mapping,          rows->handed_to_matched,
                    rows->handed_to_implicit_euler, contacts->by_mapping, contacts->handed_to_matched,
                    contacts->handed_to_implicit_euler, report->unsoftened_contact_steps};
    memcpy(counts, taken, sizeof counts);
  }
  return ssAuditRun_Print_(run, time_s, count, values, counts);
}

/** A row of the program's own stepping (no library): the physics steps the frame took, nothing served (-1). */
static inline int ssAuditRun_OwnRow(const ssAuditRun* run, double time_s, int count, const double* values,
                                    int steps) {
  int counts[8] = {steps, -1, -1, -1, -1, -1, -1, -1};
  return ssAuditRun_Print_(run, time_s, count, values, counts);
}

/** After the loop: closes the frames file. */
static inline void ssAuditRun_Finish(ssAuditRun* run) {
  if (run->frames != NULL) fclose(run->frames);
  run->frames = NULL;
}

#ifdef __cplusplus
}
#endif

#endif

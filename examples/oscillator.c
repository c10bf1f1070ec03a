/* The article's case with steadystep: one body on a slider whose stop (lo = hi = 0) is a spring-damper, stepped
 * frame by frame under a frame-time profile. Prints CSV: the state at t = 0, then one row per physics step, in the
 * columns of `steadystep run oscillator` (t_s,x_m,v_m_per_s,erp,cfm_m_per_N_s), at full precision.
 *
 *   oscillator --policy implicit-euler --profile uniform:15:45 --seed 3 > run.csv
 *
 * With the same --policy, --profile, --seed, --duration and --max-step it prints what `steadystep run oscillator`
 * prints, number for number (a test compares them): the same defaults (seed 1, 5 s), the same frame loop (the last
 * frame shortened to end at --duration), the same world. Unlike the lab's run, it does not stop at the scene's
 * sanity bounds (scene.h): an ODE program has none; a run that leaves them differs from there on.
 *
 * Read it as a template: make the world, bind the spring once, call ssStepper_Step once per frame. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <steadystep/lab/profile.h>
#include <steadystep/lab/scene.h> /* only for the CSV's column names, so that they are spelled once */
#include <steadystep/steadystep.h>

typedef struct Options {
  const char* policy;
  const char* profile;
  unsigned long long seed;
  double duration_s, stiffness, damping, mass, x0, gravity, reference_fps, max_step_s;
  int use_step;
} Options;

typedef struct Recorder {
  dJointID slider;
  double time_s;
} Recorder;

/* One CSV row at full precision (%.17g round-trips a double): a step length recomputed from t is exact. */
static void printRow(double time_s, dJointID slider) {
  printf("%.17g,%.17g,%.17g,%.17g,%.17g\n", time_s, dJointGetSliderPosition(slider),
         dJointGetSliderPositionRate(slider), dJointGetSliderParam(slider, dParamStopERP),
         dJointGetSliderParam(slider, dParamStopCFM));
}

/* The header: t and the lab oscillator's quantities, each named with its unit by the lab (ssColumnName). */
static void printHeader(void) {
  const ssSceneInfo* info = ssSceneFind("oscillator");
  char name[64];
  ssColumnName("t", "s", name, sizeof name);
  printf("%s", name);
  for (int i = 0; i < info->quantity_count; ++i) {
    ssColumnName(info->quantity_names[i], info->quantity_units[i], name, sizeof name);
    printf(",%s", name);
  }
  printf("\n");
}

static void printStep(void* context, double step_s) {
  Recorder* recorder = context;
  recorder->time_s += step_s;
  printRow(recorder->time_s, recorder->slider);
}

static void usage(FILE* out) {
  fprintf(out,
          "usage: oscillator [--policy naive|implicit-euler|matched|exact|fixed|...] [--profile SPEC] [--seed N]\n"
          "                  [--duration S] [--k N/m] [--c N*s/m] [--mass KG] [--x0 M] [--gravity M/S2]\n"
          "                  [--stepper step|quick] [--reference-fps R] [--max-step S]\n"
          "Profiles: fixed:FPS, uniform:MINFPS:MAXFPS, jitter:FPS:SPREAD_MS, hitch:FPS:EVERY:SECONDS,\n"
          "vsync:FPS_A:FPS_B, trace:FILE. Defaults: implicit-euler, uniform:15:45, seed 1, 5 s, k 40, c 1,\n"
          "mass 1, x0 0.5, gravity 0, quick, reference 30 fps, max step 1/60 s: those of `steadystep run\n"
          "oscillator`, whose flags these are. CSV on stdout: the t = 0 row, then one row per physics step.\n"
          "Exit codes: 0 done, 1 a frame failed (a blow-up: the rows so far are printed), 2 a bad flag.\n");
}

static int parseNumber(const char* flag, const char* text, double* out) {
  char* end;
  errno = 0;
  *out = strtod(text, &end);
  if (errno == 0 && end != text && *end == '\0') return 1;
  fprintf(stderr, "oscillator: %s %s: not a number\n", flag, text);
  return 0;
}

/* Returns 0 on success, 2 on a bad flag (the message already printed), 1 for --help. */
static int parseOptions(int argc, char** argv, Options* o) {
  for (int i = 1; i < argc; ++i) {
    const char* flag = argv[i];
    if (strcmp(flag, "--help") == 0 || strcmp(flag, "-h") == 0) return 1;
    if (i + 1 >= argc) {
      fprintf(stderr, "oscillator: %s needs a value (see --help)\n", flag);
      return 2;
    }
    const char* value = argv[++i];
    double number = 0;
    if (strcmp(flag, "--policy") == 0) o->policy = value;
    else if (strcmp(flag, "--profile") == 0) o->profile = value;
    else if (strcmp(flag, "--stepper") == 0) {
      if (strcmp(value, "step") != 0 && strcmp(value, "quick") != 0) {
        fprintf(stderr, "oscillator: --stepper %s: use step or quick\n", value);
        return 2;
      }
      o->use_step = strcmp(value, "step") == 0;
    } else if (!parseNumber(flag, value, &number)) return 2;
    else if (strcmp(flag, "--seed") == 0) {
      if (number < 0 || number != floor(number)) {
        fprintf(stderr, "oscillator: --seed %s: must be a whole number >= 0\n", value);
        return 2;
      }
      o->seed = (unsigned long long)number;
    } else if (strcmp(flag, "--duration") == 0) o->duration_s = number;
    else if (strcmp(flag, "--k") == 0) o->stiffness = number;
    else if (strcmp(flag, "--c") == 0) o->damping = number;
    else if (strcmp(flag, "--mass") == 0) o->mass = number;
    else if (strcmp(flag, "--x0") == 0) o->x0 = number;
    else if (strcmp(flag, "--gravity") == 0) o->gravity = number;
    else if (strcmp(flag, "--reference-fps") == 0) o->reference_fps = number;
    else if (strcmp(flag, "--max-step") == 0) o->max_step_s = number;
    else {
      fprintf(stderr, "oscillator: unknown flag %s (see --help)\n", flag);
      return 2;
    }
  }
  if (!(o->duration_s > 0) || !isfinite(o->duration_s) || !(o->mass > 0) || !isfinite(o->mass) || !isfinite(o->x0) ||
      !isfinite(o->gravity) || !(o->reference_fps > 0)) {
    fprintf(stderr, "oscillator: --duration, --mass and --reference-fps must be positive and finite; "
                    "--x0 and --gravity finite\n");
    return 2;
  }
  return 0;
}

/* Reports a library error and gives the exit code: 2 for a refused setting, 1 for a frame that failed. */
static int fail(const char* what, ssStatus status) {
  fprintf(stderr, "oscillator: %s: %s: %s\n", what, ssStatusName(status), ssLastError());
  return strcmp(what, "step") == 0 ? 1 : 2;
}

int main(int argc, char** argv) {
  Options o = {"implicit-euler", "uniform:15:45", 1, 5.0, 40.0, 1.0, 1.0, 0.5, 0.0, 30.0, 1.0 / 60.0, 0};
  int parsed = parseOptions(argc, argv, &o);
  if (parsed == 1) {
    usage(stdout);
    return 0;
  }
  if (parsed != 0) return parsed;
  ssStepping stepping = ssDefaultStepping();
  ssStatus status = ssSteppingForPolicy(o.policy, 1.0 / o.reference_fps, &stepping);
  if (status != SS_OK) return fail("--policy", status);
  ssProfile* profile;
  status = ssProfile_Create(o.profile, o.seed, &profile);
  if (status != SS_OK) return fail("--profile", status);

  dInitODE2(0);
  dWorldID world = dWorldCreate();
  dWorldSetGravity(world, -o.gravity, 0, 0); /* along the slider, toward -x */
  dBodyID body = dBodyCreate(world);
  dMass mass;
  dMassSetSphereTotal(&mass, o.mass, 0.1); /* the lab's oscillator: a ball of 0.1 m radius */
  dBodySetMass(body, &mass);
  dJointID slider = dJointCreateSlider(world, 0);
  dJointAttach(slider, body, 0);
  dJointSetSliderAxis(slider, 1, 0, 0);
  dJointSetSliderParam(slider, dParamLoStop, 0); /* lo = hi: the stop is a two-sided spring at x = 0 */
  dJointSetSliderParam(slider, dParamHiStop, 0);
  dBodySetPosition(body, o.x0, 0, 0); /* after the axis: the slider measures from where the body was then */

  /* The one change an ODE program makes: springs instead of ERP/CFM, and the stepper instead of QuickStep. */
  ssRegistry* registry = ssRegistry_Create(world);
  ssSpring spring = {o.stiffness, o.damping};
  status = ssRegistry_BindJoint(registry, slider, SS_PARAM_STOP, 1, spring, o.mass);
  if (status != SS_OK) return fail("--k/--c", status);
  Recorder recorder = {slider, 0.0};
  ssStepperDef def = ssDefaultStepperDef();
  def.world = world;
  def.registry = registry;
  def.stepping = stepping;
  def.stepping.solver = o.use_step ? SS_SOLVER_STEP : SS_SOLVER_QUICK;
  def.stepping.max_step_s = o.max_step_s;
  def.stepping.fixed_step_s = 1.0 / 60; /* as the lab's (steadystep run) */
  def.stepping.max_speed = 100; /* m/s, as the lab's scenes: nothing here moves near that fast unless it exploded */
  def.step_done = printStep;
  def.step_done_context = &recorder;
  ssStepper* stepper;
  status = ssStepper_Create(&def, &stepper);
  if (status != SS_OK) return fail("stepper", status);

  printHeader();
  printRow(0.0, slider); /* the state before the first step */
  int code = 0;
  /* Frame times add up with rounding; a remainder this small is the end, not one more frame of 1e-12 s. */
  const double end_tolerance_s = 1e-9 * fmax(1.0, o.duration_s);
  for (double elapsed_s = 0; o.duration_s - elapsed_s > end_tolerance_s;) {
    double frame_s = fmin(ssProfile_Next(profile), o.duration_s - elapsed_s);
    ssFrameReport report;
    status = ssStepper_Step(stepper, frame_s, &report);
    if (status != SS_OK) {
      code = fail("step", status);
      break;
    }
    elapsed_s += frame_s;
  }
  ssStepper_Destroy(stepper);
  ssRegistry_Destroy(registry);
  ssProfile_Destroy(profile);
  dWorldDestroy(world);
  return code;
}

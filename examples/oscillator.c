/* The article's case with steadystep: one body on a slider whose stop (lo = hi = 0) is a spring-damper, stepped
 * frame by frame under a frame-time profile. Prints CSV, one row per physics step: t,x,v,erp,cfm.
 *
 *   oscillator --policy implicit-euler --profile uniform:15:45 --seed 3 > run.csv
 *
 * Read it as a template: make the world, bind the spring once, call ssStepper_Step once per frame. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <steadystep/lab/profile.h>
#include <steadystep/steadystep.h>

typedef struct Options {
  const char* policy;
  const char* profile;
  unsigned long long seed;
  double seconds, stiffness, damping, mass, x0, gravity, reference_fps, max_step_s;
  int use_step;
} Options;

typedef struct Recorder {
  dJointID slider;
  double time_s;
} Recorder;

static void printStep(void* context, double step_s) {
  Recorder* recorder = context;
  recorder->time_s += step_s;
  printf("%.9g,%.17g,%.17g,%.17g,%.17g\n", recorder->time_s, dJointGetSliderPosition(recorder->slider),
         dJointGetSliderPositionRate(recorder->slider), dJointGetSliderParam(recorder->slider, dParamStopERP),
         dJointGetSliderParam(recorder->slider, dParamStopCFM));
}

static void usage(FILE* out) {
  fprintf(out,
          "usage: oscillator [--policy naive|implicit-euler|matched|exact|fixed|...] [--profile SPEC] [--seed N]\n"
          "                  [--seconds T] [--k N/m] [--c N*s/m] [--mass KG] [--x0 M] [--gravity M/S2]\n"
          "                  [--stepper step|quick] [--reference-fps R] [--max-step S]\n"
          "Profiles: fixed:FPS, uniform:MINFPS:MAXFPS, jitter:FPS:SPREAD_MS, hitch:FPS:EVERY:SECONDS,\n"
          "vsync:FPS_A:FPS_B, trace:FILE. Defaults: spring, uniform:15:45, seed 0, 5 s, k 40, c 1, mass 1,\n"
          "x0 0.5, gravity 0, quick, reference 30 fps, max step 1/60 s.\n");
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
    } else if (strcmp(flag, "--seconds") == 0) o->seconds = number;
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
  if (!(o->seconds > 0) || !isfinite(o->seconds) || !(o->mass > 0) || !isfinite(o->mass) || !isfinite(o->x0) ||
      !isfinite(o->gravity) || !(o->reference_fps > 0)) {
    fprintf(stderr, "oscillator: --seconds, --mass and --reference-fps must be positive and finite; "
                    "--x0 and --gravity finite\n");
    return 2;
  }
  return 0;
}

/* Reports a library error and gives the exit code. */
static int fail(const char* what, ssStatus status) {
  fprintf(stderr, "oscillator: %s: %s: %s\n", what, ssStatusName(status), ssLastError());
  return 2;
}

int main(int argc, char** argv) {
  Options o = {"implicit-euler", "uniform:15:45", 0, 5.0, 40.0, 1.0, 1.0, 0.5, 0.0, 30.0, 1.0 / 60.0, 0};
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
  dMassSetBoxTotal(&mass, o.mass, 0.1, 0.1, 0.1);
  dBodySetMass(body, &mass);
  dJointID slider = dJointCreateSlider(world, 0);
  dJointAttach(slider, body, 0);
  dJointSetSliderAxis(slider, 1, 0, 0);
  dJointSetSliderParam(slider, dParamLoStop, 0); /* lo = hi: the stop is a two-sided spring at x = 0 */
  dJointSetSliderParam(slider, dParamHiStop, 0);
  dBodySetPosition(body, o.x0, 0, 0);

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
  def.stepping.max_speed = 1e6;
  def.step_done = printStep;
  def.step_done_context = &recorder;
  ssStepper* stepper;
  status = ssStepper_Create(&def, &stepper);
  if (status != SS_OK) return fail("stepper", status);

  printf("t,x,v,erp,cfm\n");
  int code = 0;
  for (double time_s = 0; time_s < o.seconds - 1e-12;) {
    double frame_s = fmin(ssProfile_Next(profile), o.seconds - time_s);
    ssFrameReport report;
    status = ssStepper_Step(stepper, frame_s, &report);
    if (status != SS_OK) {
      code = fail("step", status);
      break;
    }
    time_s += report.simulated_s + report.dropped_s;
  }
  ssStepper_Destroy(stepper);
  ssRegistry_Destroy(registry);
  ssProfile_Destroy(profile);
  dWorldDestroy(world);
  return code;
}

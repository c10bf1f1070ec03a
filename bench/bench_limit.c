/* The library's own cost against the physical limit, at 10, 100, 1,000 and 10,000 bodies. The limit is what a
 * program pays that writes every bound parameter by hand for each frame's length (the article's loop): it cannot
 * do less and keep the softness right. Worlds of hanging hinge chains (soft limits and a damper on every motor row,
 * as bench_stepper's) are stepped through the same frames of 1/90 to 1/60 s (one step each), so that every value
 * changes every frame, in two worlds built alike:
 *   by hand  every value written by hand (timed: the limit's cost), then dWorldQuickStep (timed: ODE's cost)
 *   library  ssStepper_Step (implicit Euler, or the mapping named), timed
 * The library's cost is its frames' time less the time of the ODE steps inside them: dWorldQuickStep is defined
 * here, over ODE's, so that the dynamic linker hands the library's call to it and ODE's step is timed inside the
 * very frame (same world, same memory). The older figure, the library's frames less ODE's time in the other world,
 * is printed too: two worlds' steps differ by more than the costs measured from 1,000 bodies on.
 * Parts are timed with the monotonic clock (about 20 ns a read; the thread CPU clock costs 0.4 us a read, more
 * than the limit at 10 bodies): a preemption inside ODE's step lands in both a frame and its step and cancels, and
 * the clock reads' cost is measured and taken off. The worlds are stepped in alternating blocks, in a rotating
 * order, and the whole measurement is repeated: medians are printed.
 *
 *   bench_limit [repeats] [mapping]      (default 7 repeats, implicit-euler; or matched, exact) */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <steadystep/lab/profile.h>
#include <steadystep/steadystep.h>

#include "bench_common.h"

enum { kLinks = 10, kBlock = 20, kMaxRepeats = 64, kSizes = 4, kWays = 2 };
static const int kBodies[kSizes] = {10, 100, 1000, 10000};
static const ssSpring kLimit = {5.0, 0.05}, kFriction = {0.0, 0.01};
static const double kFrame_s = 1.0 / 60.0;
static ssMapping mapping = SS_MAPPING_IMPLICIT_EULER;

static double nowSeconds(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* ODE's own dWorldQuickStep, and the time spent in it (s) and its calls, wherever it is called from. */
static int (*odeQuickStep)(dWorldID, dReal);
static double ode_inside_s;
static long ode_inside_steps;

int dWorldQuickStep(dWorldID world, dReal step_s) {
  double start = nowSeconds();
  int stepped = odeQuickStep(world, step_s);
  ode_inside_s += nowSeconds() - start;
  ode_inside_steps += 1;
  return stepped;
}

static void check(ssStatus status, const char* what) { benchCheck("bench_limit", status, what); }

typedef struct Scene {
  dWorldID world;
  ssRegistry* registry;
  ssStepper* stepper;
  dJointID* hinges;
  int count;
} Scene;

enum { kByHand, kLibrary };
/* the library's part: its frames less the ODE steps inside them, with the clock reads inside them (counted) */
enum { kLimitPart, kOdePart, kLibraryFramesPart, kLibraryOdePart, kParts };

static Scene build(int bodies, int way) {
  Scene scene = {dWorldCreate(), NULL, NULL, malloc((size_t)bodies * sizeof(dJointID)), bodies};
  dWorldSetGravity(scene.world, 0, 0, -9.81);
  dWorldSetQuickStepNumIterations(scene.world, 20);
  dBodyID previous = 0;
  for (int i = 0; i < bodies; ++i) {
    int link = i % kLinks, chain = i / kLinks;
    if (link == 0) previous = 0;
    dBodyID body = dBodyCreate(scene.world);
    dMass mass;
    dMassSetBoxTotal(&mass, 1.0, 0.2, 0.05, 0.05);
    dBodySetMass(body, &mass);
    dBodySetPosition(body, 0.2 * link + 0.1, 1.0 * chain, 0);
    dJointID hinge = dJointCreateHinge(scene.world, 0);
    dJointAttach(hinge, body, previous);
    dJointSetHingeAnchor(hinge, 0.2 * link, 1.0 * chain, 0);
    dJointSetHingeAxis(hinge, 0, 1, 0);
    dJointSetHingeParam(hinge, dParamLoStop, -0.3);
    dJointSetHingeParam(hinge, dParamHiStop, 0.3);
    dJointSetHingeParam(hinge, dParamFMax, 0);
    scene.hinges[i] = hinge;
    previous = body;
  }
  if (way != kLibrary) return scene;
  scene.registry = ssRegistry_Create(scene.world);
  for (int i = 0; i < bodies; ++i) {
    check(ssRegistry_BindJoint(scene.registry, scene.hinges[i], SS_PARAM_STOP, 1, kLimit, 0), "bind stop");
    check(ssRegistry_BindJoint(scene.registry, scene.hinges[i], SS_PARAM_MOTOR, 1, kFriction, 0), "bind motor");
  }
  ssStepperDef def = ssDefaultStepperDef();
  def.world = scene.world;
  def.registry = scene.registry;
  def.stepping.solver = SS_SOLVER_QUICK;
  def.stepping.mapping = mapping;
  def.stepping.max_step_s = kFrame_s;
  def.stepping.max_speed = 1000;
  check(ssStepper_Create(&def, &scene.stepper), "stepper");
  return scene;
}

static void destroy(Scene* scene) {
  ssStepper_Destroy(scene->stepper);
  ssRegistry_Destroy(scene->registry);
  dWorldDestroy(scene->world);
  free(scene->hinges);
}

/* The article's loop: every soft value for a step of h, by hand. */
static void writeByHand(Scene* scene, double h) {
  double limit_erp = h * kLimit.stiffness / (h * kLimit.stiffness + kLimit.damping);
  double limit_cfm = 1.0 / (h * kLimit.stiffness + kLimit.damping);
  double friction_cfm = 1.0 / (h * kFriction.stiffness + kFriction.damping);
  for (int j = 0; j < scene->count; ++j) {
    dJointSetHingeParam(scene->hinges[j], dParamStopERP, limit_erp);
    dJointSetHingeParam(scene->hinges[j], dParamStopCFM, limit_cfm);
    dJointSetHingeParam(scene->hinges[j], dParamCFM, friction_cfm);
  }
}

/* Steps a block of frames, adding the seconds of each timed part to seconds[] and the clock reads inside the
 * library's frames to *library_reads. */
static void stepBlock(Scene* scene, int way, const double* frames_s, int count, double seconds[kParts],
                      long* library_reads) {
  if (way == kLibrary) {
    double inside_s = ode_inside_s;
    long inside_steps = ode_inside_steps;
    double start = nowSeconds();
    for (int i = 0; i < count; ++i) check(ssStepper_Step(scene->stepper, frames_s[i], NULL), "step");
    seconds[kLibraryFramesPart] += nowSeconds() - start;
    seconds[kLibraryOdePart] += ode_inside_s - inside_s;
    if (ode_inside_steps - inside_steps != count) {
      fprintf(stderr, "bench_limit: the library's frames took %ld ODE steps through this benchmark, not %d: the "
              "dynamic linker did not hand it this dWorldQuickStep\n", ode_inside_steps - inside_steps, count);
      exit(1);
    }
    *library_reads += 2 * count; /* each ODE step's two */
    return;
  }
  for (int i = 0; i < count; ++i) {
    double start = nowSeconds();
    writeByHand(scene, frames_s[i]);
    double written = nowSeconds();
    odeQuickStep(scene->world, frames_s[i]);
    seconds[kLimitPart] += written - start;
    seconds[kOdePart] += nowSeconds() - written;
  }
}

/* What one clock read adds to a timed interval (s). */
static double clockCost(void) {
  double start = nowSeconds(), last = start;
  for (int i = 0; i < 10000; ++i) last = nowSeconds();
  return (last - start) / 10000;
}

static int compareDoubles(const void* a, const void* b) {
  double x = *(const double*)a, y = *(const double*)b;
  return (x > y) - (x < y);
}

static double median(double* values, int count) {
  qsort(values, (size_t)count, sizeof(double), compareDoubles);
  return values[count / 2];
}

/* One size: each repeat's seconds per frame of each part, and the clock reads per frame inside the library's. */
static void measure(int bodies, int frames, int repeats, double seconds[kParts][kMaxRepeats],
                    double reads[kMaxRepeats]) {
  for (int r = 0; r < repeats; ++r) {
    Scene scenes[kWays] = {build(bodies, kByHand), build(bodies, kLibrary)};
    double parts[kParts] = {0, 0, 0, 0};
    long library_reads = 0, library_blocks = 0;
    /* one frame each, untimed: what is paid once is not a frame's cost (the stepper lists its bodies and Apply its
     * rows at its first frame, about 1.8 ms at 10,000 bodies; ODE sizes its step's memory at its first step) */
    writeByHand(&scenes[kByHand], kFrame_s);
    odeQuickStep(scenes[kByHand].world, kFrame_s);
    check(ssStepper_Step(scenes[kLibrary].stepper, kFrame_s, NULL), "first step");
    ssProfile* profile = NULL;
    check(ssProfile_Create("uniform:60:90", 1 + (unsigned)r, &profile), "profile");
    double frames_s[kBlock];
    for (int done = 0, block = 0; done < frames; done += kBlock, ++block) {
      for (int i = 0; i < kBlock; ++i) frames_s[i] = ssProfile_Next(profile);
      for (int k = 0; k < kWays; ++k) {
        int w = (k + block + r) % kWays;
        stepBlock(&scenes[w], w, frames_s, kBlock, parts, &library_reads);
      }
      library_blocks += 1;
    }
    for (int p = 0; p < kParts; ++p) seconds[p][r] = parts[p] / frames;
    reads[r] = (double)(library_reads + library_blocks) / frames; /* and about one for each block's own pair */
    ssProfile_Destroy(profile);
    for (int w = 0; w < kWays; ++w) destroy(&scenes[w]);
  }
}

int main(int argc, char** argv) {
  int repeats = argc > 1 ? atoi(argv[1]) : 7;
  if (argc > 2) {
    if (strcmp(argv[2], "matched") == 0) mapping = SS_MAPPING_MATCHED;
    else if (strcmp(argv[2], "exact") == 0) mapping = SS_MAPPING_EXACT;
    else if (strcmp(argv[2], "implicit-euler") != 0) repeats = 0;
  }
  if (repeats <= 0 || repeats > kMaxRepeats || argc > 3) {
    fprintf(stderr, "usage: bench_limit [repeats 1..%d] [implicit-euler|matched|exact]\n", kMaxRepeats);
    return 2;
  }
  odeQuickStep = (int (*)(dWorldID, dReal))dlsym(RTLD_NEXT, "dWorldQuickStep");
  if (odeQuickStep == NULL) {
    fprintf(stderr, "bench_limit: ODE's dWorldQuickStep not found: %s\n", dlerror());
    return 1;
  }
  dInitODE2(0);
  printf("bench_limit: hinge chains of %d links (2 soft rows a hinge), frames of 1/90 to 1/60 s, %s, medians of %d "
         "repeats\ntarget: the library's cost at most 2 times the limit's (writing every bound parameter by hand)\n",
         kLinks, ssMappingName(mapping), repeats);
  printf("  %7s %12s %22s %22s %22s %26s\n", "bodies", "ODE us/frame", "limit's cost us/frame",
         "library's cost us/frame", "library / limit", "(against the other world)");
  for (int s = 0; s < kSizes; ++s) {
    int bodies = kBodies[s];
    /* about the same time at every size: ODE's step grows with the bodies */
    int frames = (int)(400000 / bodies);
    frames = frames < 100 ? 100 : frames > 4000 ? 4000 : frames;
    frames = (frames + kBlock - 1) / kBlock * kBlock;
    static double seconds[kParts][kMaxRepeats];
    double reads[kMaxRepeats];
    measure(bodies, frames, repeats, seconds, reads);
    double clock_s = clockCost();
    /* each repeat's costs, then the median */
    double limit_cost[kMaxRepeats], library_cost[kMaxRepeats], ratio[kMaxRepeats];
    double across_cost[kMaxRepeats], across_ratio[kMaxRepeats];
    for (int r = 0; r < repeats; ++r) {
      limit_cost[r] = seconds[kLimitPart][r] - clock_s;
      library_cost[r] = seconds[kLibraryFramesPart][r] - seconds[kLibraryOdePart][r] - reads[r] * clock_s;
      ratio[r] = library_cost[r] / limit_cost[r];
      /* a frame timed alone holds one read's cost, as ODE's step in the other world does */
      across_cost[r] = seconds[kLibraryFramesPart][r] - (reads[r] - 1) * clock_s - seconds[kOdePart][r];
      across_ratio[r] = across_cost[r] / limit_cost[r];
    }
    double ode_us = 1e6 * median(seconds[kOdePart], repeats);
    double limit_us = 1e6 * median(limit_cost, repeats), library_us = 1e6 * median(library_cost, repeats);
    double middle = median(ratio, repeats), across = median(across_ratio, repeats);
    printf("  %7d %12.2f %14.2f (%4.1f%%) %14.2f (%4.1f%%) %10.2f (%.2f to %.2f) %12.2f (%.2f to %.2f)\n", bodies,
           ode_us, limit_us, 100 * limit_us / ode_us, library_us, 100 * library_us / ode_us, middle, ratio[0],
           ratio[repeats - 1], across, across_ratio[0], across_ratio[repeats - 1]);
  }
  return 0;
}

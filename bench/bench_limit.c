/* The library's own cost against the physical limit, at 10, 100, 1,000 and 10,000 bodies. The limit is what a
 * program pays that writes every bound parameter by hand for each frame's length (the article's loop): it cannot
 * do less and keep the softness right. Worlds of hanging hinge chains (soft limits and a damper on every motor row,
 * as bench_stepper's) are stepped through frames of 1/90 to 1/60 s, so that every value changes every frame, in two
 * worlds that move alike:
 *   by hand  every value written by hand (timed: the limit's cost), then dWorldQuickStep (timed: ODE's cost)
 *   library  ssStepper_Step (implicit Euler, or the mapping named), timed
 * so that the library's cost is the library world's time less ODE's cost in the other. Each part is timed on its
 * own, frame by frame; one clock read's cost is measured and taken off the limit's (ODE's and the library's times
 * hold one each, which cancel). The worlds are stepped in alternating blocks, in a rotating order, and the whole
 * measurement is repeated: medians are printed.
 *
 *   bench_limit [repeats] [mapping]      (default 7 repeats, implicit-euler; or matched, exact) */
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

static double nowSeconds(void) { return benchCpuSeconds(); }

static void check(ssStatus status, const char* what) { benchCheck("bench_limit", status, what); }

typedef struct Scene {
  dWorldID world;
  ssRegistry* registry;
  ssStepper* stepper;
  dJointID* hinges;
  int count;
} Scene;

enum { kByHand, kLibrary };
enum { kLimitPart, kOdePart, kLibraryPart, kParts };

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

/* Steps a block of frames, adding the seconds of each timed part to seconds[]. */
static void stepBlock(Scene* scene, int way, const double* frames_s, int count, double seconds[kParts]) {
  for (int i = 0; i < count; ++i) {
    double start = nowSeconds();
    if (way == kLibrary) {
      check(ssStepper_Step(scene->stepper, frames_s[i], NULL), "step");
      seconds[kLibraryPart] += nowSeconds() - start;
      continue;
    }
    writeByHand(scene, frames_s[i]);
    double written = nowSeconds();
    dWorldQuickStep(scene->world, frames_s[i]);
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

/* One size: each repeat's seconds per frame of each part. */
static void measure(int bodies, int frames, int repeats, double seconds[kParts][kMaxRepeats]) {
  for (int r = 0; r < repeats; ++r) {
    Scene scenes[kWays] = {build(bodies, kByHand), build(bodies, kLibrary)};
    double parts[kParts] = {0, 0, 0};
    ssProfile* profile = NULL;
    check(ssProfile_Create("uniform:60:90", 1 + (unsigned)r, &profile), "profile");
    double frames_s[kBlock];
    for (int done = 0, block = 0; done < frames; done += kBlock, ++block) {
      for (int i = 0; i < kBlock; ++i) frames_s[i] = ssProfile_Next(profile);
      for (int k = 0; k < kWays; ++k) {
        int w = (k + block + r) % kWays;
        stepBlock(&scenes[w], w, frames_s, kBlock, parts);
      }
    }
    for (int p = 0; p < kParts; ++p) seconds[p][r] = parts[p] / frames;
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
  dInitODE2(0);
  printf("bench_limit: hinge chains of %d links (2 soft rows a hinge), frames of 1/90 to 1/60 s, %s, medians of %d "
         "repeats\ntarget: the library's cost at most 2 times the limit's (writing every bound parameter by hand)\n",
         kLinks, ssMappingName(mapping), repeats);
  printf("  %7s %12s %22s %22s %22s\n", "bodies", "ODE us/frame", "limit's cost us/frame",
         "library's cost us/frame", "library / limit");
  for (int s = 0; s < kSizes; ++s) {
    int bodies = kBodies[s];
    /* about the same time at every size: ODE's step grows with the bodies */
    int frames = (int)(400000 / bodies);
    frames = frames < 100 ? 100 : frames > 4000 ? 4000 : frames;
    frames = (frames + kBlock - 1) / kBlock * kBlock;
    static double seconds[kParts][kMaxRepeats];
    measure(bodies, frames, repeats, seconds);
    double clock_s = clockCost();
    /* each repeat's costs, then the median */
    double limit_cost[kMaxRepeats], library_cost[kMaxRepeats], ratio[kMaxRepeats];
    for (int r = 0; r < repeats; ++r) {
      limit_cost[r] = seconds[kLimitPart][r] - clock_s;
      library_cost[r] = seconds[kLibraryPart][r] - seconds[kOdePart][r];
      ratio[r] = library_cost[r] / limit_cost[r];
    }
    double ode_us = 1e6 * median(seconds[kOdePart], repeats);
    double limit_us = 1e6 * median(limit_cost, repeats), library_us = 1e6 * median(library_cost, repeats);
    double low, high, middle = median(ratio, repeats);
    low = ratio[0];
    high = ratio[repeats - 1];
    printf("  %7d %12.2f %14.2f (%4.1f%%) %14.2f (%4.1f%%) %10.2f (%.2f to %.2f)\n", bodies, ode_us, limit_us,
           100 * limit_us / ode_us, library_us, 100 * library_us / ode_us, middle, low, high);
  }
  return 0;
}

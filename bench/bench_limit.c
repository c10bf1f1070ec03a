/* The library's own cost against the physical limit, at 10, 100, 1,000 and 10,000 bodies. The limit is what a
 * program pays that writes every bound parameter by hand for each frame's length (the article's loop): it cannot
 * do less and keep the softness right. Worlds of hanging hinge chains (soft limits and a damper on every motor row,
 * as bench_stepper's) are stepped through the same frames of 1/90 to 1/60 s (one step each), so that every value
 * changes every frame, in two worlds built alike:
 *   by hand  every value written by hand (timed: the limit's cost), then dWorldQuickStep (timed: ODE's cost)
 *   library  ssStepper_Step (implicit Euler, or the mapping named), timed
 * The loop by hand writes the motor row's CFM every frame although, with no stiffness, it never changes; the library
 * skips that write (2 of the 3 values a hinge): at 10 bodies, where the writes' calls are the limit, that makes the
 * limit about 1.5 times what it would be without that write, in the library's favour. It is kept as the article's loop.
 * The library's cost is its frames' time less the time of the ODE steps inside them: dWorldQuickStep is defined
 * here, over ODE's, so that the dynamic linker hands the library's call to it and ODE's step is timed inside the
 * very frame (same world, same memory). The older figure, the library's frames less ODE's time in the other world,
 * is printed too: two worlds' steps differ by more than the costs measured from 1,000 bodies on.
 * What is measured is the thread's CPU time, frame by frame: the parts are timed with the monotonic clock (about
 * 20 ns a read; the thread's CPU clock costs 0.4 to 0.7 us a read, more than the limit at 10 bodies), and a frame
 * counts only when the thread ran through it without waiting for a core: its thread CPU time, read around the frame
 * and outside its timed parts, is at least its wall time (less 1 us). A frame in which the thread waited is left
 * out, not charged to whichever part it waited in; the share of frames counted is printed (at a load above the
 * cores, few frames of 10,000 bodies, 40 ms each, run through). The clock reads' cost is measured (the least of
 * many batches) and taken off. The worlds are stepped in alternating blocks of 20 frames, in a rotating order; each
 * part's cost a frame is the median over the blocks of its mean over the block's counted frames, and the whole
 * measurement is repeated: medians over the repeats are printed. No target: the library does more than the limit
 * by design (the checks it promises of the forces and state before the frame and after each step), so the ratio
 * says what those cost, not how far from a goal it is.
 *
 *   bench_limit [repeats] [mapping]      (default 7 repeats, implicit-euler; or matched, exact) */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <steadystep/lab/profile.h>
#include <steadystep/steadystep.h>

#include "bench_common.h"

static const double kWaitTolerance_s = 1e-6; /* a frame whose wall time exceeds its CPU time by more waited */
enum { kLinks = 10, kBlock = 20, kMaxRepeats = 64, kSizes = 4, kWays = 2, kMaxBlocks = 4000 / kBlock };
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
/* a block's seconds: the by-hand world's writes and ODE steps, the library's frames and the ODE steps inside them */
enum { kLimitPart, kOdePart, kLibraryFramesPart, kLibraryOdePart, kParts };
/* what is printed, a frame's seconds: the limit's cost, ODE's, the library's, the library's against the other world */
enum { kLimitCost, kOdeCost, kLibraryCost, kAcrossCost, kCosts };

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

/* Steps a block of frames, one way, adding the seconds of each timed part of every counted frame to seconds[]:
 * a frame counts when the thread ran through it without waiting for a core (its thread CPU time, read around it
 * outside the timed parts, is at least its wall time). Returns the frames counted. */
static int stepBlock(Scene* scene, int way, const double* frames_s, int count, double seconds[kParts]) {
  int counted = 0;
  for (int i = 0; i < count; ++i) {
    double parts[kParts] = {0, 0, 0, 0};
    double cpu_start = benchCpuSeconds();
    double start = nowSeconds(), end;
    if (way == kLibrary) {
      double inside_s = ode_inside_s;
      long inside_steps = ode_inside_steps;
      check(ssStepper_Step(scene->stepper, frames_s[i], NULL), "step");
      end = nowSeconds();
      parts[kLibraryFramesPart] = end - start;
      parts[kLibraryOdePart] = ode_inside_s - inside_s;
      if (ode_inside_steps - inside_steps != 1) {
        fprintf(stderr, "bench_limit: the library's frame took %ld ODE steps through this benchmark, not 1: the "
                "dynamic linker did not hand it this dWorldQuickStep\n", ode_inside_steps - inside_steps);
        exit(1);
      }
    } else {
      writeByHand(scene, frames_s[i]);
      double written = nowSeconds();
      odeQuickStep(scene->world, frames_s[i]);
      end = nowSeconds();
      parts[kLimitPart] = written - start;
      parts[kOdePart] = end - written;
    }
    if (end - start > benchCpuSeconds() - cpu_start + kWaitTolerance_s) continue; /* it waited for a core */
    for (int p = 0; p < kParts; ++p) seconds[p] += parts[p];
    ++counted;
  }
  return counted;
}

/* What one clock read adds to a timed interval (s): the least over batches, which preemption only lengthens. */
static double clockCost(void) {
  double least = INFINITY;
  for (int batch = 0; batch < 100; ++batch) {
    double start = nowSeconds(), last = start;
    for (int i = 0; i < 1000; ++i) last = nowSeconds();
    least = fmin(least, (last - start) / 1000);
  }
  return least;
}

/* One size: each repeat's costs a frame (s), each the median over its blocks of the mean over the block's counted
 * frames; returns the repeats measured (those with a block in which both ways counted a frame), and the frames
 * counted and stepped in *counted and *stepped. A timed interval holds about one clock read's cost (clock_s): the
 * limit's part one, ODE's step in the other world one; the library's frame its own one and the two of its ODE
 * step, less the one the step's interval holds. */
static int measure(int bodies, int frames, int repeats, double clock_s, double costs[kCosts][kMaxRepeats],
                   long* counted, long* stepped) {
  int measured = 0;
  for (int r = 0; r < repeats; ++r) {
    Scene scenes[kWays] = {build(bodies, kByHand), build(bodies, kLibrary)};
    /* one frame each, untimed: what is paid once is not a frame's cost (the stepper lists its bodies and Apply its
     * rows at its first frame, about 1.8 ms at 10,000 bodies; ODE sizes its step's memory at its first step) */
    writeByHand(&scenes[kByHand], kFrame_s);
    odeQuickStep(scenes[kByHand].world, kFrame_s);
    check(ssStepper_Step(scenes[kLibrary].stepper, kFrame_s, NULL), "first step");
    ssProfile* profile = NULL;
    check(ssProfile_Create("uniform:60:90", 1 + (unsigned)r, &profile), "profile");
    static double per_block[kCosts][kMaxBlocks];
    double frames_s[kBlock];
    int blocks = 0, kept = 0;
    for (int done = 0; done < frames; done += kBlock, ++blocks) {
      for (int i = 0; i < kBlock; ++i) frames_s[i] = ssProfile_Next(profile);
      double parts[kParts] = {0, 0, 0, 0};
      int ran[kWays];
      for (int k = 0; k < kWays; ++k) {
        int w = (k + blocks + r) % kWays;
        ran[w] = stepBlock(&scenes[w], w, frames_s, kBlock, parts);
      }
      *counted += ran[kByHand] + ran[kLibrary];
      *stepped += kWays * kBlock;
      if (ran[kByHand] == 0 || ran[kLibrary] == 0) continue;
      double ode_s = parts[kOdePart] / ran[kByHand] - clock_s;
      per_block[kLimitCost][kept] = parts[kLimitPart] / ran[kByHand] - clock_s;
      per_block[kOdeCost][kept] = ode_s;
      per_block[kLibraryCost][kept] =
          (parts[kLibraryFramesPart] - parts[kLibraryOdePart]) / ran[kLibrary] - 2 * clock_s;
      per_block[kAcrossCost][kept] = parts[kLibraryFramesPart] / ran[kLibrary] - 2 * clock_s - ode_s;
      ++kept;
    }
    if (kept > 0) {
      for (int c = 0; c < kCosts; ++c) costs[c][measured] = benchMedian(per_block[c], kept);
      ++measured;
    }
    ssProfile_Destroy(profile);
    for (int w = 0; w < kWays; ++w) destroy(&scenes[w]);
  }
  return measured;
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
  benchPrintMachine("bench_limit", "before");
  printf("bench_limit: hinge chains of %d links (2 soft rows a hinge), frames of 1/90 to 1/60 s, %s, medians of %d "
         "repeats, this thread's CPU time (frames it ran through); no target: the library's checks of forces and "
         "state are work the limit does not do\n",
         kLinks, ssMappingName(mapping), repeats);
  printf("  %7s %12s %22s %22s %22s %26s %8s\n", "bodies", "ODE us/frame", "limit's cost us/frame",
         "library's cost us/frame", "library / limit", "(against the other world)", "counted");
  for (int s = 0; s < kSizes; ++s) {
    int bodies = kBodies[s];
    /* about the same time at every size: ODE's step grows with the bodies */
    int frames = (int)(400000 / bodies);
    frames = frames < 100 ? 100 : frames > 4000 ? 4000 : frames;
    frames = (frames + kBlock - 1) / kBlock * kBlock;
    static double costs[kCosts][kMaxRepeats];
    long counted = 0, stepped = 0;
    int measured = measure(bodies, frames, repeats, clockCost(), costs, &counted, &stepped);
    if (measured == 0) {
      printf("  %7d  no block in which both ways ran a frame through without waiting for a core (%ld of %ld frames)"
             "\n", bodies, counted, stepped);
      continue;
    }
    double ratio[kMaxRepeats], across_ratio[kMaxRepeats];
    for (int r = 0; r < measured; ++r) {
      ratio[r] = costs[kLibraryCost][r] / costs[kLimitCost][r];
      across_ratio[r] = costs[kAcrossCost][r] / costs[kLimitCost][r];
    }
    double ode_us = 1e6 * benchMedian(costs[kOdeCost], measured);
    double limit_us = 1e6 * benchMedian(costs[kLimitCost], measured);
    double library_us = 1e6 * benchMedian(costs[kLibraryCost], measured);
    double middle = benchMedian(ratio, measured), across = benchMedian(across_ratio, measured);
    printf("  %7d %12.2f %14.2f (%4.1f%%) %14.2f (%4.1f%%) %10.2f (%.2f to %.2f) %12.2f (%.2f to %.2f) %7.1f%%\n",
           bodies, ode_us, limit_us, 100 * limit_us / ode_us, library_us, 100 * library_us / ode_us, middle, ratio[0],
           ratio[measured - 1], across, across_ratio[0], across_ratio[measured - 1], 100.0 * counted / stepped);
  }
  benchPrintMachine("bench_limit", "after");
  return 0;
}

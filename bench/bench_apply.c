/* What each of Apply's caches buys (apply.c lists them, apply_state.h states their invariants): 1000 bodies in
 * hanging hinge chains with a soft stop and a damper on every motor row (2000 rows, as bench_stepper's), bound as
 * springs by the program ("bound": the accurate mappings serve the motors' dampers) or tuned by it with ERP/CFM at
 * 1/60 s and adopted ("adopted": stops beyond the rule, motors near-rigid, none served), one world per
 * configuration (every cache on, each one off alone, all off: Apply's plain path, and the tests' plain reference
 * Apply, tests/c/apply_reference.c), stepped through the same frames. Only Apply is timed, each frame right after the
 * world's dWorldQuickStep (which evicts the registry from the caches, as in a program). The worlds are stepped in
 * alternating blocks in a rotating order, and the measurement is repeated: the median of each world's time over the
 * all-on time is printed (above 1: the cache turned off pays there), with Apply's share of a QuickStep. A first
 * block is stepped untimed: the first Apply computes every row whatever the caches. Built with the core's cache
 * switches (SS_APPLY_SWITCHES), which the shipped library has not.
 *
 *   bench_apply [frames] [repeats]      (default 120 frames, 5 repeats) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "apply_internal.h"
#include "apply_reference.h"
#include "steadystep/steadystep.h"

#include "bench_common.h"

enum { kChains = 50, kLinks = 20, kBlock = 10, kMaxRepeats = 32 };
enum { kConfigs = 11, kReference = kConfigs - 1 };
static const unsigned kDisabled[kConfigs] = {0,
                                             SS_APPLY_SAME_STEP,
                                             SS_APPLY_BY_LAW,
                                             SS_APPLY_BODIES,
                                             SS_APPLY_SHARED,
                                             SS_APPLY_REUSE,
                                             SS_APPLY_SAME_AXIS,
                                             SS_APPLY_SURE_FALLBACK,
                                             SS_APPLY_HANDED_ON,
                                             SS_APPLY_ALL,
                                             SS_APPLY_ALL};
static const char* const kConfigNames[kConfigs] = {"all on",    "-same step", "-by law",  "-bodies",
                                                   "-shared",   "-reuse",     "-same axis", "-fallback",
                                                   "-handed on", "all off",   "reference"};
static const ssSpring kLimit = {5.0, 0.05}, kFriction = {0.0, 0.01};
static const double kFrame_s = 1.0 / 60.0;

static double nowSeconds(void) { return benchCpuSeconds(); }

static void check(ssStatus status, const char* what) { benchCheck("bench_apply", status, what); }

typedef struct Scene {
  dWorldID world;
  ssRegistry* registry;
  double previous_s;
  int reference;          /* stepped by the tests' reference Apply */
  unsigned applied_stamp; /* the reference's */
} Scene;

static Scene build(int adopted, int distinct, int config) {
  Scene scene = {dWorldCreate(), NULL, 0, config == kReference, 0};
  dWorldSetGravity(scene.world, 0, 0, -9.81);
  dWorldSetQuickStepNumIterations(scene.world, 20);
  scene.registry = ssRegistry_Create(scene.world);
  dBodyID heads[kChains];
  for (int chain = 0; chain < kChains; ++chain) {
    dBodyID previous = 0;
    for (int link = 0; link < kLinks; ++link) {
      int index = chain * kLinks + link;
      dBodyID body = dBodyCreate(scene.world);
      if (link == 0) heads[chain] = body;
      dMass mass;
      dMassSetBoxTotal(&mass, distinct ? 1.0 + 0.5 * index / (kChains * kLinks - 1) : 1.0, 0.2, 0.05, 0.05);
      dBodySetMass(body, &mass);
      dBodySetPosition(body, 0.2 * link + 0.1, 1.0 * chain, 0);
      dJointID hinge = dJointCreateHinge(scene.world, 0);
      dJointAttach(hinge, body, previous);
      dJointSetHingeAnchor(hinge, 0.2 * link, 1.0 * chain, 0);
      dJointSetHingeAxis(hinge, 0, 1, 0);
      dJointSetHingeParam(hinge, dParamLoStop, -0.3);
      dJointSetHingeParam(hinge, dParamHiStop, 0.3);
      dJointSetHingeParam(hinge, dParamFMax, 0);
      if (adopted) { /* the program's values for 1/60 s; its motors keep ODE's default CFM */
        ssSoftness limit;
        check(ssImplicitEulerSoftness(kLimit, kFrame_s, &limit), "limit");
        dJointSetHingeParam(hinge, dParamStopERP, limit.erp);
        dJointSetHingeParam(hinge, dParamStopCFM, limit.cfm);
      } else {
        check(ssRegistry_BindJoint(scene.registry, hinge, SS_PARAM_STOP, 1, kLimit, 0), "bind stop");
        check(ssRegistry_BindJoint(scene.registry, hinge, SS_PARAM_MOTOR, 1, kFriction, 0), "bind motor");
      }
      previous = body;
    }
  }
  if (adopted) { /* the world, then each chain through one of its links */
    check(ssRegistry_AdoptWorld(scene.registry, kFrame_s, NULL), "adopt the world");
    for (int chain = 0; chain < kChains; ++chain)
      check(ssRegistry_AdoptBody(scene.registry, heads[chain], NULL), "adopt the chain");
  }
  ssApplyDisableCaches(scene.registry, kDisabled[config]);
  return scene;
}

/* Seconds of Apply over a block; each frame is one step, as a stepper with max_step_s = 1/60 s takes it. */
static double stepBlock(Scene* scene, ssMapping mapping, const double* frames_s, int count) {
  double timed = 0;
  for (int i = 0; i < count; ++i) {
    double start = nowSeconds();
    if (scene->reference)
      check(ssRegistryApplyReference(scene->registry, &scene->applied_stamp, mapping, frames_s[i], scene->previous_s,
                                     NULL),
            "reference apply");
    else
      check(ssRegistry_Apply(scene->registry, mapping, frames_s[i], scene->previous_s, NULL), "apply");
    timed += nowSeconds() - start;
    dWorldQuickStep(scene->world, frames_s[i]);
    scene->previous_s = frames_s[i];
  }
  return timed;
}

static void report(ssMapping mapping, int adopted, int varying, int distinct, int frames, int repeats) {
  static double seconds[kConfigs][kMaxRepeats], ratios[kConfigs][kMaxRepeats], step_s[kMaxRepeats];
  unsigned random = 12345;
  for (int r = 0; r < repeats; ++r) {
    Scene scenes[kConfigs];
    for (int c = 0; c < kConfigs; ++c) scenes[c] = build(adopted, distinct, c), seconds[c][r] = 0;
    double frames_s[kBlock];
    /* a first block untimed: the first Apply computes and writes every row and builds the caches once */
    for (int i = 0; i < kBlock; ++i) frames_s[i] = kFrame_s;
    for (int c = 0; c < kConfigs; ++c) stepBlock(&scenes[c], mapping, frames_s, kBlock);
    for (int done = 0, block = 0; done < frames; done += kBlock, ++block) {
      for (int i = 0; i < kBlock; ++i) {
        random = random * 1664525u + 1013904223u;
        frames_s[i] = varying ? 1.0 / (60.0 + 30.0 * (random >> 8) / 16777216.0) : kFrame_s;
      }
      for (int k = 0; k < kConfigs; ++k) {
        int c = (k + block + r) % kConfigs;
        seconds[c][r] += stepBlock(&scenes[c], mapping, frames_s, kBlock) / frames;
      }
    }
    double start = nowSeconds();
    for (int i = 0; i < kBlock; ++i) dWorldQuickStep(scenes[0].world, kFrame_s);
    step_s[r] = (nowSeconds() - start) / kBlock;
    for (int c = 0; c < kConfigs; ++c) {
      ratios[c][r] = seconds[c][r] / seconds[0][r];
      ssRegistry_Destroy(scenes[c].registry);
      dWorldDestroy(scenes[c].world);
    }
  }
  double apply_us = 1e6 * benchMedian(seconds[0], repeats);
  printf("  %-14s %-8s %-8s %-8s %8.2f %6.2f%%", ssMappingName(mapping), adopted ? "adopted" : "bound",
         varying ? "varying" : "1/60 s", distinct ? "distinct" : "shared", apply_us,
         100 * apply_us / (1e6 * benchMedian(step_s, repeats)));
  for (int c = 1; c < kConfigs; ++c) printf(" %10.2f", benchMedian(ratios[c], repeats));
  printf("\n");
}

int main(int argc, char** argv) {
  int frames = argc > 1 ? atoi(argv[1]) : 120;
  int repeats = argc > 2 ? atoi(argv[2]) : 5;
  if (frames <= 0 || repeats <= 0 || repeats > kMaxRepeats || argc > 3) {
    fprintf(stderr, "usage: bench_apply [frames > 0] [repeats 1..%d]\n", kMaxRepeats);
    return 2;
  }
  dInitODE2(0);
  frames = (frames + kBlock - 1) / kBlock * kBlock;
  benchPrintMachine("bench_apply", "before");
  printf("bench_apply: %d bodies, %d rows, %d frames a repeat, medians of %d repeats; Apply with every cache on "
         "(us a frame of this thread's CPU time, and its share of a QuickStep), and each configuration's Apply time "
         "over that\n",
         kChains * kLinks, 2 * kChains * kLinks, frames, repeats);
  printf("  %-14s %-8s %-8s %-8s %8s %7s", "mapping", "rows", "frames", "masses", "Apply us", "of step");
  for (int c = 1; c < kConfigs; ++c) printf(" %10s", kConfigNames[c]);
  printf("\n");
  for (int m = SS_MAPPING_IMPLICIT_EULER; m <= SS_MAPPING_EXACT; ++m)
    for (int adopted = 0; adopted < 2; ++adopted)
      for (int varying = 0; varying < 2; ++varying)
        for (int distinct = 0; distinct < 2; ++distinct)
          report((ssMapping)m, adopted, varying, distinct, frames, repeats);
  benchPrintMachine("bench_apply", "after");
  return 0;
}

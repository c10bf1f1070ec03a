/* What binding and adopting cost per row as a world grows: worlds of 1,000, 10,000 and 100,000 soft rows (hinge
 * chains, a stop and a motor row on every hinge) are bound row by row with ssRegistry_BindJoint and adopted whole
 * with ssRegistry_Adopt, each into a fresh registry, and one dWorldQuickStep of the same world is timed beside them.
 * The sizes are measured in a rotating order within every repeat, so that all see the same machine; the median of
 * the repeats is printed. Binding is linear when the time per row stays flat across the sizes.
 *
 * Two floors are printed beside, costs a program pays whatever the library does: reading, with ODE's getters, what
 * binding a row must read of the world (the joint's type and bodies, the bodies' world, the row's parameters), whose
 * memory is cold at 100,000 rows (the world is larger than the caches); and first touching fresh memory, as page
 * faults a row (the registry's arrays and index are new memory the kernel hands out one 4 KB page at a time, zeroed)
 * with the time of one fault measured on a fresh mapping.
 *
 * What grows from 10,000 to 100,000 rows is mostly that first touch. A registry of 100,000 rows is 19 MB of joint
 * bindings (192 bytes a row) and a 4 MB index, all fresh at that size, where at 10,000 rows glibc serves the arrays
 * from memory the process freed before; at about 2 us a fault, 70-120 faults a thousand rows are 0.15-0.25 us a row,
 * more than binding a row costs at 1,000 rows. The index's probes stay short (1.3 slots on average at 100,000 rows)
 * and the world's reads, cold at that size, cost 0.04-0.06 us a row against 0.01 (the read column); the rest is cache
 * misses on the larger arrays. The last line prints the time per row less the faults' time, and its spread.
 *
 *   bench_bind [repeats]      (default 5) */
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include <sys/mman.h>
#include <sys/resource.h>

#include <steadystep/steadystep.h>

#include "bench_common.h"

enum { kSizes = 3, kLinks = 50, kMaxRepeats = 64 };
static const int kRows[kSizes] = {1000, 10000, 100000};
static const double kTuned_s = 1.0 / 60.0;
static const ssSpring kLimit = {5.0, 0.05}, kFriction = {0.0, 0.01};

static double nowSeconds(void) { return benchCpuSeconds(); }

static void check(ssStatus status, const char* what) { benchCheck("bench_bind", status, what); }

typedef struct World {
  dWorldID world;
  dSpaceID space;
  dJointID* hinges;
  int hinge_count;
} World;

/* rows / 2 hinges in chains of kLinks boxes hanging from the static world, every box with a geom in one space. */
static World build(int rows) {
  World w = {dWorldCreate(), dSimpleSpaceCreate(0), malloc((size_t)(rows / 2) * sizeof(dJointID)), rows / 2};
  dWorldSetGravity(w.world, 0, 0, -9.81);
  dWorldSetQuickStepNumIterations(w.world, 20);
  dBodyID previous = 0;
  for (int i = 0; i < w.hinge_count; ++i) {
    int link = i % kLinks, chain = i / kLinks;
    if (link == 0) previous = 0;
    dBodyID body = dBodyCreate(w.world);
    dMass mass;
    dMassSetBoxTotal(&mass, 1.0, 0.2, 0.05, 0.05);
    dBodySetMass(body, &mass);
    dBodySetPosition(body, 0.2 * link + 0.1, 1.0 * chain, 0);
    dGeomSetBody(dCreateBox(w.space, 0.2, 0.05, 0.05), body);
    dJointID hinge = dJointCreateHinge(w.world, 0);
    dJointAttach(hinge, body, previous);
    dJointSetHingeAnchor(hinge, 0.2 * link, 1.0 * chain, 0);
    dJointSetHingeAxis(hinge, 0, 1, 0);
    dJointSetHingeParam(hinge, dParamLoStop, -0.3);
    dJointSetHingeParam(hinge, dParamHiStop, 0.3);
    dJointSetHingeParam(hinge, dParamStopERP, 0.4);
    dJointSetHingeParam(hinge, dParamStopCFM, 1e-3);
    dJointSetHingeParam(hinge, dParamCFM, 1e-2);
    w.hinges[i] = hinge;
    previous = body;
  }
  return w;
}

static void destroy(World* w) {
  dSpaceDestroy(w->space);
  dWorldDestroy(w->world);
  free(w->hinges);
}

/* Page faults of this process so far: fresh memory first touched. */
static long minorFaults(void) {
  struct rusage usage;
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_minflt;
}

/* Seconds a page fault costs: the first touch of every page of a fresh anonymous mapping. */
static double secondsPerFault(void) {
  enum { kPages = 4096, kPage = 4096 };
  char* fresh = mmap(NULL, (size_t)kPages * kPage, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (fresh == MAP_FAILED) return 0;
  long faults = minorFaults();
  double start = nowSeconds();
  for (size_t i = 0; i < (size_t)kPages * kPage; i += kPage) fresh[i] = 1;
  double seconds = nowSeconds() - start;
  faults = minorFaults() - faults;
  munmap(fresh, (size_t)kPages * kPage);
  return faults > 0 ? seconds / (double)faults : 0;
}

/* Seconds to read, with ODE's getters, what binding every row reads of the world: the floor of binding. */
static double readWorld(const World* w) {
  volatile double sink = 0;
  double start = nowSeconds();
  for (int i = 0; i < w->hinge_count; ++i) {
    dJointID hinge = w->hinges[i];
    double sum = dJointGetType(hinge) + dJointGetHingeParam(hinge, dParamStopERP) +
                 dJointGetHingeParam(hinge, dParamStopCFM) + dJointGetHingeParam(hinge, dParamCFM);
    for (int side = 0; side < 2; ++side) {
      dBodyID body = dJointGetBody(hinge, side);
      if (body != 0) sum += dBodyGetWorld(body) == w->world;
    }
    sink += sum;
  }
  return nowSeconds() - start;
}

typedef struct Sample {
  double bind_s, adopt_s, step_s, read_s;
  double bind_faults, adopt_faults; /* page faults */
} Sample;

/* Seconds to bind every row by hand, to adopt the whole world, for one QuickStep of it, and to read the world. */
static Sample measure(int rows) {
  Sample sample;
  World w = build(rows);
  long faults = minorFaults();
  ssRegistry* registry = ssRegistry_Create(w.world);
  double start = nowSeconds();
  for (int i = 0; i < w.hinge_count; ++i) {
    check(ssRegistry_BindJoint(registry, w.hinges[i], SS_PARAM_STOP, 1, kLimit, 0), "bind stop");
    check(ssRegistry_BindJoint(registry, w.hinges[i], SS_PARAM_MOTOR, 1, kFriction, 0), "bind motor");
  }
  sample.bind_s = nowSeconds() - start;
  sample.bind_faults = (double)(minorFaults() - faults);
  ssRegistry_Destroy(registry);

  registry = ssRegistry_Create(w.world);
  ssAdoptReport adopted = {0};
  faults = minorFaults();
  start = nowSeconds();
  check(ssRegistry_Adopt(registry, kTuned_s, w.space, &adopted), "adopt");
  sample.adopt_s = nowSeconds() - start;
  sample.adopt_faults = (double)(minorFaults() - faults);
  if (ssRegistry_JointBindingCount(registry) != rows) {
    fprintf(stderr, "bench_bind: adopted %d rows, expected %d\n", ssRegistry_JointBindingCount(registry), rows);
    exit(1);
  }
  ssRegistry_Destroy(registry);
  sample.read_s = readWorld(&w); /* after the registries, so that it warms nothing they read */

  start = nowSeconds();
  dWorldQuickStep(w.world, kTuned_s);
  sample.step_s = nowSeconds() - start;
  destroy(&w);
  return sample;
}

/* The largest of the sizes' values over the smallest. */
static double spread(const double* values) {
  double lo = values[0], hi = values[0];
  for (int s = 1; s < kSizes; ++s) {
    lo = values[s] < lo ? values[s] : lo;
    hi = values[s] > hi ? values[s] : hi;
  }
  return hi / lo;
}

int main(int argc, char** argv) {
  int repeats = argc > 1 ? atoi(argv[1]) : 5;
  if (repeats <= 0 || repeats > kMaxRepeats || argc > 2) {
    fprintf(stderr, "usage: bench_bind [repeats 1..%d]\n", kMaxRepeats);
    return 2;
  }
  dInitODE2(0);
  benchPrintMachine("bench_bind", "before");
  static double bind[kSizes][kMaxRepeats], adopt[kSizes][kMaxRepeats], step[kSizes][kMaxRepeats];
  static double read[kSizes][kMaxRepeats], bind_faults[kSizes][kMaxRepeats], adopt_faults[kSizes][kMaxRepeats];
  double fault_s[kMaxRepeats];
  for (int r = 0; r < repeats; ++r) {
    fault_s[r] = secondsPerFault();
    for (int k = 0; k < kSizes; ++k) {
      int s = (k + r) % kSizes; /* rotate the order of the sizes */
      Sample sample = measure(kRows[s]);
      bind[s][r] = sample.bind_s;
      adopt[s][r] = sample.adopt_s;
      step[s][r] = sample.step_s;
      read[s][r] = sample.read_s;
      bind_faults[s][r] = sample.bind_faults;
      adopt_faults[s][r] = sample.adopt_faults;
    }
  }
  double fault_us = 1e6 * benchMedian(fault_s, repeats);
  printf("bench_bind: hinge chains, a stop and a motor row a hinge; medians of %d repeats, this thread's CPU time\n",
         repeats);
  printf("  %8s %12s %12s %12s %14s %14s %13s %15s\n", "rows", "bind us/row", "adopt us/row", "read us/row",
         "bind faults/k", "adopt faults/k", "QuickStep ms", "bind/QuickStep");
  double bind_us[kSizes], adopt_us[kSizes];
  for (int s = 0; s < kSizes; ++s) {
    double bind_s = benchMedian(bind[s], repeats), adopt_s = benchMedian(adopt[s], repeats);
    double step_s = benchMedian(step[s], repeats);
    bind_us[s] = 1e6 * bind_s / kRows[s];
    adopt_us[s] = 1e6 * adopt_s / kRows[s];
    printf("  %8d %12.3f %12.3f %12.3f %14.1f %14.1f %13.3f %15.3f\n", kRows[s], bind_us[s], adopt_us[s],
           1e6 * benchMedian(read[s], repeats) / kRows[s], 1e3 * benchMedian(bind_faults[s], repeats) / kRows[s],
           1e3 * benchMedian(adopt_faults[s], repeats) / kRows[s], 1e3 * step_s, bind_s / step_s);
  }
  printf("  read: ODE's getters reading what binding reads of each row (the floor); faults/k: page faults a thousand "
         "rows,\n  %.2f us each (a first touch of fresh memory)\n",
         fault_us);
  printf("  largest over smallest time per row: bind %.2f, adopt %.2f (target: within 2)\n", spread(bind_us),
         spread(adopt_us));
  double net_bind[kSizes], net_adopt[kSizes];
  for (int s = 0; s < kSizes; ++s) {
    net_bind[s] = bind_us[s] - fault_us * benchMedian(bind_faults[s], repeats) / kRows[s];
    net_adopt[s] = adopt_us[s] - fault_us * benchMedian(adopt_faults[s], repeats) / kRows[s];
  }
  printf("  less the page faults' time: bind %.3f / %.3f / %.3f us/row (%.2f), adopt %.3f / %.3f / %.3f (%.2f)\n",
         net_bind[0], net_bind[1], net_bind[2], spread(net_bind), net_adopt[0], net_adopt[1], net_adopt[2],
         spread(net_adopt));
  benchPrintMachine("bench_bind", "after");
  return 0;
}

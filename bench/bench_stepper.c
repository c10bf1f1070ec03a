/* What the library costs on top of ODE's own step: 1000 bodies in hanging chains whose hinge limits are soft,
 * stepped through ssStepper_Step versus plain dWorldQuickStep with the same parameters set once, and versus the
 * article's loop written by hand (every value rewritten for each frame, then dWorldQuickStep). Two identical
 * worlds are stepped in alternating blocks so that both see the same machine; the ratio is measured in this run.
 *
 * The order of the worlds rotates from block to block, and the whole measurement is repeated: the median ratio and
 * its range over the repeats are printed.
 *
 * Every link weighs 1 kg by default, so that the rows share two effective masses (a chain's first link and the
 * others), as in a chain, a stack of crates or a field of identical props; with "distinct" every link weighs its
 * own mass (1 to 1.5 kg), as in a ragdoll, so that matched and exact compute every row's softness by itself. Both
 * bind the rows with effective_mass 0: the registry measures each row's mass from its bodies at every Apply. With
 * "given" every link has its own mass too, and each row's mass is given at binding (ssJointEffectiveMass, once), as
 * a program that knows its masses passes them: what the accurate mappings cost without the measuring.
 *
 * Then the accurate mappings against implicit Euler, by thread CPU time in one run, each beside who served the
 * row-steps (ssFrameReport.rows): where they serve every row (1000 bodies on pistons whose two stop springs the program
 * binds, one with its load declared, one free: buildSprings), in the chains bound as above (their stops handed on,
 * their motors' dampers served), and where they serve none (the chains as a program tunes them, adopted: every row
 * handed to implicit Euler). `count` steps one copy untimed for callgrind's instruction count, which no other load
 * disturbs (docs/exact-mappings.md):
 *
 *   bench_stepper [frames] [repeats] [distinct|given]      (default 300 frames, 7 repeats, shared masses)
 *   valgrind --tool=callgrind --toggle-collect=ssStepper_Step bench_stepper count <springs|chains|adopted> <mapping> 40
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <steadystep/lab/profile.h>
#include <steadystep/steadystep.h>

#include "bench_common.h"

enum { kChains = 50, kLinks = 20, kBlock = 20 }; /* 1000 bodies, 1000 hinges, 2000 soft parameter sets with the motors */

static const ssSpring kLimit = {5.0, 0.05}; /* about 6 Hz on a link of 0.0035 kg·m² */
static const ssSpring kFriction = {0.0, 0.01}; /* a pure damper on each hinge motor row */
static const double kFrame_s = 1.0 / 60.0;
static const double kSpringRadius_m = 0.1; /* buildSprings' bodies: solid spheres */
static int distinct_masses; /* every link its own mass (see the top) */
static int given_masses;    /* and each row's effective mass given at binding */

typedef struct Scene {
  dWorldID world;
  ssRegistry* registry;
  ssStepper* stepper;
  dJointID joints[kChains * kLinks]; /* the chains' hinges, or buildSprings' pistons */
  long frames, steps; /* through ssStepper_Step: frames taken and the physics steps they took */
  ssServedCounts rows; /* row-steps through ssStepper_Step, by who served them (ssFrameReport.rows, summed) */
} Scene;

static double nowSeconds(void) { return benchCpuSeconds(); }

static void check(ssStatus status, const char* what) { benchCheck("bench_stepper", status, what); }

/* A stepper for the scene's world and registry: QuickStep, substeps of at most 1/60 s, implicit Euler. */
static ssStepper* makeStepper(const Scene* scene) {
  ssStepperDef def = ssDefaultStepperDef();
  def.world = scene->world;
  def.registry = scene->registry;
  def.stepping.solver = SS_SOLVER_QUICK;
  def.stepping.max_step_s = kFrame_s;
  def.stepping.max_speed = 1000;
  ssStepper* stepper = NULL;
  check(ssStepper_Create(&def, &stepper), "stepper");
  return stepper;
}

/* How build() softens the chains: the values for 1/60 s set once (plain ODE); bound by the program
 * (ssRegistry_BindJoint); or set as a program without the library sets them, its motors left at ODE's default CFM
 * (1e-10, near-rigid), and adopted (ssRegistry_AdoptWorld, then each chain through its first link). */
enum { kSetOnce, kBound, kAdopted };

/* Chains hang from the static world along x, start horizontal, and swing into their limits. */
static Scene build(int how) {
  Scene scene = {dWorldCreate(), NULL, NULL, {0}, 0, 0, {0, 0, 0}};
  dWorldSetGravity(scene.world, 0, 0, -9.81);
  dWorldSetQuickStepNumIterations(scene.world, 20);
  scene.registry = ssRegistry_Create(scene.world);
  ssSoftness limit, friction;
  check(ssImplicitEulerSoftness(kLimit, kFrame_s, &limit), "limit");
  check(ssImplicitEulerSoftness(kFriction, kFrame_s, &friction), "friction");
  for (int chain = 0; chain < kChains; ++chain) {
    dBodyID previous = 0;
    for (int link = 0; link < kLinks; ++link) {
      dBodyID body = dBodyCreate(scene.world);
      dMass mass;
      int index = chain * kLinks + link;
      double mass_kg = distinct_masses ? 1.0 + 0.5 * index / (kChains * kLinks - 1) : 1.0;
      dMassSetBoxTotal(&mass, mass_kg, 0.2, 0.05, 0.05);
      dBodySetMass(body, &mass);
      dBodySetPosition(body, 0.2 * link + 0.1, 1.0 * chain, 0);
      dJointID hinge = dJointCreateHinge(scene.world, 0);
      dJointAttach(hinge, body, previous);
      dJointSetHingeAnchor(hinge, 0.2 * link, 1.0 * chain, 0);
      dJointSetHingeAxis(hinge, 0, 1, 0);
      dJointSetHingeParam(hinge, dParamLoStop, -0.3);
      dJointSetHingeParam(hinge, dParamHiStop, 0.3);
      dJointSetHingeParam(hinge, dParamFMax, 0); /* the motor row only carries the damper's cfm */
      scene.joints[chain * kLinks + link] = hinge;
      if (how == kBound) {
        double stop_kg_m2 = 0, motor_kg_m2 = 0; /* 0: measured at every Apply */
        if (given_masses) {
          check(ssJointEffectiveMass(hinge, SS_PARAM_STOP, 1, &stop_kg_m2), "stop's mass");
          check(ssJointEffectiveMass(hinge, SS_PARAM_MOTOR, 1, &motor_kg_m2), "motor's mass");
        }
        check(ssRegistry_BindJoint(scene.registry, hinge, SS_PARAM_STOP, 1, kLimit, stop_kg_m2), "bind stop");
        check(ssRegistry_BindJoint(scene.registry, hinge, SS_PARAM_MOTOR, 1, kFriction, motor_kg_m2), "bind motor");
      } else { /* what a program without the library does: the values for its one frame rate, set once */
        dJointSetHingeParam(hinge, dParamStopERP, limit.erp);
        dJointSetHingeParam(hinge, dParamStopCFM, limit.cfm);
        if (how == kSetOnce) dJointSetHingeParam(hinge, dParamCFM, friction.cfm);
      }
      previous = body;
    }
  }
  if (how == kAdopted) {
    check(ssRegistry_AdoptWorld(scene.registry, kFrame_s, NULL), "adopt the world");
    for (int chain = 0; chain < kChains; ++chain)
      check(ssRegistry_AdoptBody(scene.registry, dJointGetBody(scene.joints[chain * kLinks], 0), NULL), "adopt");
  }
  scene.stepper = makeStepper(&scene);
  return scene;
}

/* The chains, bound to a stepper or adopted by one (implicit Euler until the stepping says otherwise). */
static Scene buildBoundChains(void) { return build(kBound); }
static Scene buildAdoptedChains(void) { return build(kAdopted); }

/* The scene where the accurate mappings serve every row: 1000 bodies, each held to the static world by a piston
 * along z whose two stops (lo = hi = 0) are the program's own springs, the linear one carrying the body's weight
 * (its load declared, ssRegistry_SetJointLoad) and the angular one free: 2000 rows, as many as the chains bind.
 * Both are the article's oscillator (omega about 6.3 rad/s, sigma 0.5 1/s), so matched's static stiffness stays
 * within the rule's 5 % at every step from 1/90 to 1/60 s. Masses as in build(): 1 kg, or 1 to 1.5 kg. */
static Scene buildSprings(void) {
  Scene scene = {dWorldCreate(), NULL, NULL, {0}, 0, 0, {0, 0, 0}};
  dWorldSetGravity(scene.world, 0, 0, -9.81);
  dWorldSetQuickStepNumIterations(scene.world, 20);
  scene.registry = ssRegistry_Create(scene.world);
  for (int index = 0; index < kChains * kLinks; ++index) {
    double mass_kg = distinct_masses ? 1.0 + 0.5 * index / (kChains * kLinks - 1) : 1.0;
    double inertia_kg_m2 = 0.4 * mass_kg * kSpringRadius_m * kSpringRadius_m; /* a solid sphere's */
    ssSpring linear = {40.0 * mass_kg, 1.0 * mass_kg}, angular = {40.0 * inertia_kg_m2, 1.0 * inertia_kg_m2};
    dBodyID body = dBodyCreate(scene.world);
    dMass mass;
    dMassSetSphereTotal(&mass, mass_kg, kSpringRadius_m);
    dBodySetMass(body, &mass);
    double x = 0.5 * (index % kLinks), y = 1.0 * (index / kLinks);
    dBodySetPosition(body, x, y, 0); /* the stops measure from here: the axis is set with the body at rest */
    dJointID piston = dJointCreatePiston(scene.world, 0);
    dJointAttach(piston, body, 0);
    dJointSetPistonAnchor(piston, x, y, 0);
    dJointSetPistonAxis(piston, 0, 0, 1);
    dJointSetPistonParam(piston, dParamLoStop, 0);
    dJointSetPistonParam(piston, dParamHiStop, 0);
    dJointSetPistonParam(piston, dParamLoStop2, 0);
    dJointSetPistonParam(piston, dParamHiStop2, 0);
    dBodySetPosition(body, x, y, 0.1);     /* released 10 cm up */
    dBodySetAngularVel(body, 0, 0, 1.0); /* and turning about the axis at 1 rad/s */
    scene.joints[index] = piston;
    double linear_kg = 0, angular_kg_m2 = 0; /* 0: measured at every Apply */
    if (given_masses) {
      check(ssJointEffectiveMass(piston, SS_PARAM_STOP, 1, &linear_kg), "linear stop's mass");
      check(ssJointEffectiveMass(piston, SS_PARAM_STOP, 2, &angular_kg_m2), "angular stop's mass");
    }
    check(ssRegistry_BindJoint(scene.registry, piston, SS_PARAM_STOP, 1, linear, linear_kg), "bind linear stop");
    check(ssRegistry_SetJointLoad(scene.registry, piston, SS_PARAM_STOP, 1, -9.81 * mass_kg), "declare weight");
    check(ssRegistry_BindJoint(scene.registry, piston, SS_PARAM_STOP, 2, angular, angular_kg_m2), "bind angular stop");
  }
  scene.stepper = makeStepper(&scene);
  return scene;
}

/* How a world is stepped: plain ODE with the values for 1/60 s set once; the article's loop written by the program
 * itself (every soft value rewritten for the frame's length, then one dWorldQuickStep: the same motion as the
 * stepper's implicit Euler with frames no longer than max_step_s); or through ssStepper_Step. */
enum { kPlain, kByHand, kStepper };

static void addServed(ssServedCounts* sum, const ssServedCounts* counts) {
  sum->by_mapping += counts->by_mapping;
  sum->handed_to_matched += counts->handed_to_matched;
  sum->handed_to_implicit_euler += counts->handed_to_implicit_euler;
}

/* Steps a block of frames and returns the seconds it took. */
static double stepBlock(Scene* scene, int how, const double* frames_s, int count) {
  double start = nowSeconds();
  for (int i = 0; i < count; ++i) {
    if (how == kStepper) {
      ssFrameReport report;
      check(ssStepper_Step(scene->stepper, frames_s[i], &report), "step");
      scene->frames += 1;
      scene->steps += report.steps;
      addServed(&scene->rows, &report.rows);
      continue;
    }
    if (how == kByHand) {
      double h = frames_s[i];
      double limit_erp = h * kLimit.stiffness / (h * kLimit.stiffness + kLimit.damping);
      double limit_cfm = 1.0 / (h * kLimit.stiffness + kLimit.damping);
      double friction_cfm = 1.0 / (h * kFriction.stiffness + kFriction.damping);
      for (int j = 0; j < kChains * kLinks; ++j) {
        dJointSetHingeParam(scene->joints[j], dParamStopERP, limit_erp);
        dJointSetHingeParam(scene->joints[j], dParamStopCFM, limit_cfm);
        dJointSetHingeParam(scene->joints[j], dParamCFM, friction_cfm);
      }
    }
    dWorldQuickStep(scene->world, frames_s[i]);
  }
  return nowSeconds() - start;
}

static void destroyScene(Scene* scene) {
  ssStepper_Destroy(scene->stepper);
  ssRegistry_Destroy(scene->registry);
  dWorldDestroy(scene->world);
}

/* Steps count scenes through the same frames (from profile_spec, or 1/60 s each for NULL) in blocks of kBlock,
 * scene w the way hows[w] says (NULL: all through the stepper), rotating their order each block so that none is
 * always first after the frame times change; adds each scene's seconds to seconds[w]. */
static void stepRotating(Scene* scenes, const int* hows, int count, const char* profile_spec, int frames,
                         double* seconds) {
  ssProfile* profile = NULL;
  if (profile_spec) check(ssProfile_Create(profile_spec, 1, &profile), "profile");
  double frames_s[kBlock];
  for (int done = 0, block = 0; done < frames; done += kBlock, ++block) {
    for (int i = 0; i < kBlock; ++i) frames_s[i] = profile ? ssProfile_Next(profile) : kFrame_s;
    for (int k = 0; k < count; ++k) {
      int w = (k + block) % count;
      seconds[w] += stepBlock(&scenes[w], hows ? hows[w] : kStepper, frames_s, kBlock);
    }
  }
  ssProfile_Destroy(profile);
}

enum { kWorlds = 5 }; /* plain, by hand, implicit Euler, matched, exact */
static const char* const kWorldNames[kWorlds] = {"plain dWorldQuickStep", "the article's loop by hand",
                                                 "ssStepper_Step, impl. Euler", "ssStepper_Step, matched",
                                                 "ssStepper_Step, exact"};
static const int kWorldHow[kWorlds] = {kPlain, kByHand, kStepper, kStepper, kStepper};

/* One repeat: five fresh worlds stepped through the same frames, interleaved block by block so that all five see
 * the same machine. profile = NULL: constant 1/60 s frames. Returns the seconds of each world, and the physics
 * steps a frame the implicit-Euler stepper took. */
static void measure(const char* profile_spec, int frames, double seconds[kWorlds], double* steps_per_frame) {
  Scene scenes[kWorlds] = {build(kSetOnce), build(kSetOnce), build(kBound), build(kBound), build(kBound)};
  ssStepping stepping = ssStepper_Stepping(scenes[3].stepper);
  stepping.mapping = SS_MAPPING_MATCHED;
  check(ssStepper_SetStepping(scenes[3].stepper, &stepping), "matched");
  stepping.mapping = SS_MAPPING_EXACT;
  check(ssStepper_SetStepping(scenes[4].stepper, &stepping), "exact");
  for (int w = 0; w < kWorlds; ++w) seconds[w] = 0;
  stepRotating(scenes, kWorldHow, kWorlds, profile_spec, frames, seconds);
  *steps_per_frame = (double)scenes[2].steps / (double)scenes[2].frames;
  for (int w = 0; w < kWorlds; ++w) destroyScene(&scenes[w]);
}

/* Repeats the measurement and prints, for each stepped world, the median ratio to plain ODE and its range. */
static void report(const char* title, const char* profile_spec, int frames, int repeats) {
  /* ratios[w]: world w against plain ODE; against_hand: implicit Euler against the same loop written by hand, the
   * same motion, so that it measures the library alone when the frames change the motion of the plain world */
  double ratios[kWorlds][64], against_hand[64], plain_us = 0, steps_per_frame = 0;
  for (int r = 0; r < repeats; ++r) {
    double seconds[kWorlds];
    measure(profile_spec, frames, seconds, &steps_per_frame);
    for (int w = 1; w < kWorlds; ++w) ratios[w][r] = seconds[w] / seconds[0];
    against_hand[r] = seconds[2] / seconds[1];
    plain_us += 1e6 * seconds[0] / frames / repeats;
  }
  printf("%s\n  %-28s %8.1f us/frame; the stepper takes %.3f physics steps a frame (plain ODE 1)\n", title,
         kWorldNames[0], plain_us, steps_per_frame);
  for (int w = 1; w < kWorlds; ++w) {
    benchSort(ratios[w], repeats);
    printf("  %-28s median ratio %.3f   (%.3f to %.3f over %d repeats)\n", kWorldNames[w], ratios[w][repeats / 2],
           ratios[w][0], ratios[w][repeats - 1], repeats);
  }
  benchSort(against_hand, repeats);
  printf("  %-28s median ratio %.3f   (%.3f to %.3f) to the loop by hand\n", kWorldNames[2],
         against_hand[repeats / 2], against_hand[0], against_hand[repeats - 1]);
}

/* The interpolation's cost (steadystep/interpolation.h): two worlds under the fixed cut (steps of 1/60 s, implicit
 * Euler) take the same 1/90 to 1/40 s frames, one keeping the poses of its 1000 bodies, the other not
 * (ssStepper_SetInterpolation 0), in alternating blocks; the ratio of their times, median over the repeats. */
static void reportInterpolation(int frames, int repeats) {
  double ratios[64];
  for (int r = 0; r < repeats; ++r) {
    Scene scenes[2] = {build(kBound), build(kBound)}; /* [0] keeps the poses, [1] does not */
    for (int w = 0; w < 2; ++w) {
      ssStepping stepping = ssStepper_Stepping(scenes[w].stepper);
      check(ssSteppingForPolicy("fixed", kFrame_s, &stepping), "fixed");
      stepping.fixed_step_s = kFrame_s;
      check(ssStepper_SetStepping(scenes[w].stepper, &stepping), "fixed");
    }
    check(ssStepper_SetInterpolation(scenes[1].stepper, 0), "interpolation off");
    double seconds[2] = {0, 0};
    stepRotating(scenes, NULL, 2, "uniform:40:90", frames, seconds);
    ratios[r] = seconds[0] / seconds[1];
    for (int w = 0; w < 2; ++w) destroyScene(&scenes[w]);
  }
  benchSort(ratios, repeats);
  printf("fixed steps of 1/60 s, frames of 1/90 to 1/40 s: keeping the poses to draw (target <= 1.01)\n"
         "  %-28s median ratio %.4f   (%.4f to %.4f over %d repeats) to the same without\n",
         "ssStepper_Step, interpolated", ratios[repeats / 2], ratios[0], ratios[repeats - 1], repeats);
}

/* The accurate mappings over implicit Euler in one scene: three copies (implicit Euler, matched, exact) stepped
 * through the same frames in rotating blocks (stepRotating); prints each accurate mapping's median time ratio to
 * implicit Euler's and its range over the repeats, beside who served the row-steps (summed over the repeats). */
static void reportMappings(const char* title, Scene (*buildScene)(void), const char* profile_spec, int frames,
                           int repeats) {
  enum { kCopies = 3 };
  static const ssMapping kMappings[kCopies] = {SS_MAPPING_IMPLICIT_EULER, SS_MAPPING_MATCHED, SS_MAPPING_EXACT};
  double ratios[kCopies][64];
  ssServedCounts served[kCopies] = {{0, 0, 0}};
  for (int r = 0; r < repeats; ++r) {
    Scene scenes[kCopies];
    for (int w = 0; w < kCopies; ++w) {
      scenes[w] = buildScene();
      ssStepping stepping = ssStepper_Stepping(scenes[w].stepper);
      stepping.mapping = kMappings[w];
      check(ssStepper_SetStepping(scenes[w].stepper, &stepping), "mapping");
    }
    double seconds[kCopies] = {0, 0, 0};
    stepRotating(scenes, NULL, kCopies, profile_spec, frames, seconds);
    for (int w = 0; w < kCopies; ++w) {
      ratios[w][r] = seconds[w] / seconds[0];
      addServed(&served[w], &scenes[w].rows);
      destroyScene(&scenes[w]);
    }
  }
  printf("%s\n", title);
  for (int w = 1; w < kCopies; ++w) {
    benchSort(ratios[w], repeats);
    long all = (long)served[w].by_mapping + served[w].handed_to_matched + served[w].handed_to_implicit_euler;
    printf("  %-7s over implicit Euler: median ratio %.3f   (%.3f to %.3f over %d repeats); row-steps %ld: "
           "by_mapping %d, handed_to_matched %d, handed_to_implicit_euler %d\n",
           ssMappingName(kMappings[w]), ratios[w][repeats / 2], ratios[w][0], ratios[w][repeats - 1], repeats, all,
           served[w].by_mapping, served[w].handed_to_matched, served[w].handed_to_implicit_euler);
  }
}

/* bench_stepper count <springs|chains|adopted> <mapping> <frames>: one copy stepped through frames of 1/90 to 1/60 s,
 * untimed, for callgrind's count of ssStepper_Step (--toggle-collect=ssStepper_Step), which no other load disturbs. */
static int countInstructions(int argc, char** argv) {
  static const struct {
    const char* name;
    Scene (*build)(void);
  } kScenes[] = {{"springs", buildSprings}, {"chains", buildBoundChains}, {"adopted", buildAdoptedChains}};
  int scene = -1, frames = argc > 4 ? atoi(argv[4]) : 0;
  for (int i = 0; i < 3; ++i)
    if (argc > 2 && strcmp(argv[2], kScenes[i].name) == 0) scene = i;
  int mapping = -1;
  for (int m = SS_MAPPING_IMPLICIT_EULER; m <= SS_MAPPING_EXACT; ++m)
    if (argc > 3 && strcmp(argv[3], ssMappingName((ssMapping)m)) == 0) mapping = m;
  if (scene < 0 || mapping < 0 || argc != 5 || frames <= 0) {
    fprintf(stderr, "usage: bench_stepper count <springs|chains|adopted> <implicit-euler|matched|exact> <frames>\n");
    return 2;
  }
  dInitODE2(0);
  Scene copy = kScenes[scene].build();
  ssStepping stepping = ssStepper_Stepping(copy.stepper);
  stepping.mapping = (ssMapping)mapping;
  check(ssStepper_SetStepping(copy.stepper, &stepping), "mapping");
  ssProfile* profile = NULL;
  check(ssProfile_Create("uniform:60:90", 1, &profile), "profile");
  for (int i = 0; i < frames; ++i) {
    double frame_s = ssProfile_Next(profile);
    stepBlock(&copy, kStepper, &frame_s, 1);
  }
  printf("%s, %s, %d frames: row-steps by_mapping %d, handed_to_matched %d, handed_to_implicit_euler %d\n",
         kScenes[scene].name, ssMappingName((ssMapping)mapping), frames, copy.rows.by_mapping,
         copy.rows.handed_to_matched, copy.rows.handed_to_implicit_euler);
  ssProfile_Destroy(profile);
  destroyScene(&copy);
  return 0;
}

int main(int argc, char** argv) {
  if (argc > 1 && strcmp(argv[1], "count") == 0) return countInstructions(argc, argv);
  int frames = argc > 1 ? atoi(argv[1]) : 300;
  int repeats = argc > 2 ? atoi(argv[2]) : 7;
  given_masses = argc > 3 && strcmp(argv[3], "given") == 0;
  distinct_masses = given_masses || (argc > 3 && strcmp(argv[3], "distinct") == 0);
  if (frames <= 0 || repeats <= 0 || repeats > 64 || (argc > 3 && !distinct_masses) || argc > 4) {
    fprintf(stderr, "usage: bench_stepper [frames > 0] [repeats 1..64] [distinct|given]\n");
    return 2;
  }
  setvbuf(stdout, NULL, _IOLBF, 0); /* each line as it is measured, into a log too */
  dInitODE2(0);
  benchPrintMachine("bench_stepper", "before");
  frames = (frames + kBlock - 1) / kBlock * kBlock;
  printf("bench_stepper: %d bodies in %d chains, %d soft parameter sets, %d frames a repeat, QuickStep 20 iterations, "
         "%s\ntargets: implicit Euler <= 1.02, matched and exact <= 1.05\n",
         kChains * kLinks, kChains, 2 * kChains * kLinks, frames,
         given_masses      ? "every link its own mass (1 to 1.5 kg), each row's mass given at binding"
         : distinct_masses ? "every link its own mass (1 to 1.5 kg), measured at every Apply"
                           : "links of 1 kg (two effective masses)");
  report("frames of 1/60 s:", NULL, frames, repeats);
  report("frames of 1/90 to 1/60 s (every value rewritten every frame):", "uniform:60:90", frames, repeats);
  /* what a real 60 fps game hands the stepper: frames a little longer or shorter than the tuned step */
  report("frames of 1/60 s with a 2 ms jitter (jitter:60:2; target: at most 1.05 steps a frame):", "jitter:60:2",
         frames, repeats);
  report("a 60 fps game on a 59 Hz display (vsync:60:59; target: at most 1.05 steps a frame):", "vsync:60:59", frames,
         repeats);
  reportInterpolation(frames, repeats);
  reportMappings("the accurate mappings where they serve every row: 1000 bodies on pistons, each with two stop springs "
                 "bound by the program (linear, its load declared; angular, free), frames of 1/90 to 1/60 s",
                 buildSprings, "uniform:60:90", frames, repeats);
  reportMappings("the chains above, bound: their stops handed on (beyond the 5 % rule), their motors' dampers served",
                 buildBoundChains, "uniform:60:90", frames, repeats);
  reportMappings("the accurate mappings where they serve none: the chains as a program tunes them, adopted (stops "
                 "beyond the rule, motors and the world near-rigid), frames of 1/90 to 1/60 s (target: at most 1.01)",
                 buildAdoptedChains, "uniform:60:90", frames, repeats);

  /* the registry alone, every value recomputed and rewritten */
  for (int m = SS_MAPPING_IMPLICIT_EULER; m <= SS_MAPPING_EXACT; ++m) {
    Scene scene = build(kBound);
    double start = nowSeconds();
    for (int i = 0; i < frames; ++i)
      check(ssRegistry_Apply(scene.registry, (ssMapping)m, i % 2 ? kFrame_s : 0.5 * kFrame_s, kFrame_s, NULL),
            "apply");
    printf("ssRegistry_Apply alone, %-7s 2000 sets: %.1f us\n", ssMappingName((ssMapping)m),
           1e6 * (nowSeconds() - start) / frames);
    destroyScene(&scene);
  }
  benchPrintMachine("bench_stepper", "after");
  return 0;
}

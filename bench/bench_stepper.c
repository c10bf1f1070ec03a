/* What the library costs on top of ODE's own step: 1000 bodies in hanging chains whose hinge limits are soft,
 * stepped through ssStepper_Step versus plain dWorldQuickStep with the same parameters set once. Two identical
 * worlds are stepped in alternating blocks so that both see the same machine; the ratio is measured in this run.
 *
 *   bench_stepper [frames]      (default 600 frames, each 1/90 to 1/60 s) */
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include <steadystep/steadystep.h>

enum { kChains = 50, kLinks = 20, kBlock = 20 }; /* 1000 bodies, 1000 hinges, 2000 soft parameter sets with the motors */

static const ssSpring kLimit = {5.0, 0.05}; /* about 6 Hz on a link of 0.0035 kg·m² */
static const ssSpring kFriction = {0.0, 0.01}; /* a pure damper on each hinge motor row */
static const double kFrame_s = 1.0 / 60.0;

typedef struct Scene {
  dWorldID world;
  ssRegistry* registry;
  ssStepper* stepper;
} Scene;

static double nowSeconds(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static void check(ssStatus status, const char* what) {
  if (status == SS_OK) return;
  fprintf(stderr, "bench_stepper: %s: %s\n", what, ssLastError());
  exit(1);
}

/* Chains hang from the static world along x, start horizontal, and swing into their limits. */
static Scene build(int with_stepper) {
  Scene scene = {dWorldCreate(), NULL, NULL};
  dWorldSetGravity(scene.world, 0, 0, -9.81);
  dWorldSetQuickStepNumIterations(scene.world, 20);
  scene.registry = ssRegistry_Create(scene.world);
  ssSoftness limit, friction;
  check(ssSoftnessFromSpring(kLimit, kFrame_s, &limit), "limit");
  check(ssSoftnessFromSpring(kFriction, kFrame_s, &friction), "friction");
  for (int chain = 0; chain < kChains; ++chain) {
    dBodyID previous = 0;
    for (int link = 0; link < kLinks; ++link) {
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
      dJointSetHingeParam(hinge, dParamFMax, 0); /* the motor row only carries the damper's cfm */
      if (with_stepper) {
        check(ssRegistry_BindJoint(scene.registry, hinge, SS_PARAM_STOP, 1, kLimit, 0), "bind stop");
        check(ssRegistry_BindJoint(scene.registry, hinge, SS_PARAM_MOTOR, 1, kFriction, 0), "bind motor");
      } else { /* what a program without the library does: the values for its one frame rate, set once */
        dJointSetHingeParam(hinge, dParamStopERP, limit.erp);
        dJointSetHingeParam(hinge, dParamStopCFM, limit.cfm);
        dJointSetHingeParam(hinge, dParamCFM, friction.cfm);
      }
      previous = body;
    }
  }
  ssStepperDef def = ssDefaultStepperDef();
  def.world = scene.world;
  def.registry = scene.registry;
  def.max_step_s = kFrame_s;
  def.max_speed = 1000;
  check(ssStepper_Create(&def, &scene.stepper), "stepper");
  return scene;
}

/* Steps a block of frames and returns the seconds it took. */
static double stepBlock(Scene* scene, int with_stepper, const double* frames_s, int count) {
  double start = nowSeconds();
  for (int i = 0; i < count; ++i) {
    if (with_stepper) check(ssStepper_Step(scene->stepper, frames_s[i], NULL), "step");
    else dWorldQuickStep(scene->world, frames_s[i]);
  }
  return nowSeconds() - start;
}

typedef struct Ratios {
  double plain_s, spring_s, matched_s;
} Ratios;

/* Steps three fresh worlds through the same frames in alternating blocks. profile = NULL: constant 1/60 s frames. */
static Ratios measure(const char* profile_spec, int frames) {
  Scene plain = build(0), stepped = build(1), matched = build(1);
  check(ssStepper_SetPolicy(matched.stepper, SS_POLICY_MATCHED), "policy");
  ssProfile* profile = NULL;
  if (profile_spec) check(ssProfile_Create(profile_spec, 1, &profile), "profile");
  double frames_s[kBlock];
  Ratios seconds = {0, 0, 0};
  for (int done = 0; done < frames; done += kBlock) {
    for (int i = 0; i < kBlock; ++i) frames_s[i] = profile ? ssProfile_Next(profile) : kFrame_s;
    seconds.plain_s += stepBlock(&plain, 0, frames_s, kBlock);
    seconds.spring_s += stepBlock(&stepped, 1, frames_s, kBlock);
    seconds.matched_s += stepBlock(&matched, 1, frames_s, kBlock);
  }
  ssProfile_Destroy(profile);
  Scene* scenes[] = {&plain, &stepped, &matched};
  for (int i = 0; i < 3; ++i) {
    ssStepper_Destroy(scenes[i]->stepper);
    ssRegistry_Destroy(scenes[i]->registry);
    dWorldDestroy(scenes[i]->world);
  }
  return seconds;
}

static void print(const char* title, Ratios s, int steps) {
  printf("%s\n", title);
  printf("  plain dWorldQuickStep      %8.1f us/step\n", 1e6 * s.plain_s / steps);
  printf("  ssStepper_Step, spring     %8.1f us/step   ratio %.3f (target <= 1.02)\n", 1e6 * s.spring_s / steps,
         s.spring_s / s.plain_s);
  printf("  ssStepper_Step, matched    %8.1f us/step   ratio %.3f (effective masses computed every step)\n",
         1e6 * s.matched_s / steps, s.matched_s / s.plain_s);
}

int main(int argc, char** argv) {
  int frames = argc > 1 ? atoi(argv[1]) : 600;
  if (frames <= 0) {
    fprintf(stderr, "bench_stepper: frames must be a positive whole number\n");
    return 2;
  }
  dInitODE2(0);
  int steps = (frames + kBlock - 1) / kBlock * kBlock;
  printf("bench_stepper: %d bodies in %d chains, %d soft parameter sets, %d frames, QuickStep 20 iterations\n",
         kChains * kLinks, kChains, 2 * kChains * kLinks, steps);
  print("frames of 1/60 s (the same motion in all three worlds):", measure(NULL, frames), steps);
  print("frames of 1/90 to 1/60 s (every value rewritten every step):", measure("uniform:60:90", frames), steps);

  /* the registry alone, every value recomputed and rewritten */
  Scene scene = build(1);
  double start = nowSeconds();
  for (int i = 0; i < steps; ++i)
    check(ssRegistry_Apply(scene.registry, SS_MAPPING_SPRING, i % 2 ? kFrame_s : 0.5 * kFrame_s, 0, NULL), "apply");
  printf("ssRegistry_Apply alone, 2000 sets rewritten: %.1f us/step\n", 1e6 * (nowSeconds() - start) / steps);
  return 0;
}

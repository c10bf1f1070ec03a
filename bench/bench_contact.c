/* What contacts cost through the library: a stack of boxes as examples/stack_ode.c builds it (towers of 8 boxes of
 * 1 kg, contacts softened by a soft CFM tuned at 60 fps, world damping and auto-disable counted in steps), stepped
 * by the program's own loop (collide, dWorldQuickStep of the frame, empty the contacts) and, in an identical world,
 * adopted and stepped by ssStepper_Step under naive (the program's own stepping: whole frames, softness frozen at
 * the tuned step), every contact softened with ssStepper_SoftenContact. The two worlds move alike, so the ratio is
 * the library's cost. They are stepped in alternating blocks, in a rotating order, and the measurement is repeated:
 * the median ratio and its range are printed, for 8 and for 200 boxes.
 *
 *   bench_contact [frames] [repeats]      (default 600 frames, 7 repeats) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include <steadystep/lab/profile.h>
#include <steadystep/steadystep.h>

#include "bench_common.h"

enum { kTowerHeight = 8, kMaxContacts = 4, kBlock = 20, kMaxRepeats = 64 };
static const double kBoxSide = 0.4, kTowerSpacing = 1.0, kTuned_s = 1.0 / 60.0;

typedef struct Stack {
  dWorldID world;
  dSpaceID space;
  dJointGroupID contacts;
  ssRegistry* registry; /* NULL: the program's own loop */
  ssStepper* stepper;
  long contact_count;
} Stack;

static double nowSeconds(void) { return benchCpuSeconds(); }

static void check(ssStatus status, const char* what) { benchCheck("bench_contact", status, what); }

/* The near callback of both worlds: data is the stack; the adopted one softens every contact. */
static void nearCallback(void* data, dGeomID g1, dGeomID g2) {
  Stack* stack = data;
  dBodyID b1 = dGeomGetBody(g1), b2 = dGeomGetBody(g2);
  if ((b1 == 0 || !dBodyIsEnabled(b1)) && (b2 == 0 || !dBodyIsEnabled(b2))) return;
  dContact contact[kMaxContacts];
  int count = dCollide(g1, g2, kMaxContacts, &contact[0].geom, sizeof(dContact));
  for (int i = 0; i < count; ++i) {
    contact[i].surface.mode = dContactSoftCFM | dContactApprox1;
    contact[i].surface.mu = 0.8;
    contact[i].surface.soft_cfm = 1e-4; /* tuned at 60 fps */
    if (stack->stepper != NULL) check(ssStepper_SoftenContact(stack->stepper, &contact[i], b1, b2), "soften");
    dJointAttach(dJointCreateContact(stack->world, stack->contacts, &contact[i]), b1, b2);
  }
  stack->contact_count += count;
}

static void collide(void* context, ssStepper* stepper) {
  (void)stepper;
  Stack* stack = context;
  dSpaceCollide(stack->space, stack, nearCallback);
}

static Stack* build(int boxes, int adopted) {
  Stack* stack = calloc(1, sizeof *stack);
  stack->world = dWorldCreate();
  stack->space = dHashSpaceCreate(0);
  stack->contacts = dJointGroupCreate(0);
  dWorldSetGravity(stack->world, 0, 0, -9.81);
  dWorldSetQuickStepNumIterations(stack->world, 40);
  dWorldSetContactSurfaceLayer(stack->world, 0.001);
  dWorldSetLinearDamping(stack->world, 0.001);
  dWorldSetAngularDamping(stack->world, 0.005);
  dWorldSetAutoDisableFlag(stack->world, 1);
  dWorldSetAutoDisableSteps(stack->world, 20);
  dWorldSetAutoDisableAverageSamplesCount(stack->world, 5);
  dCreatePlane(stack->space, 0, 0, 1, 0);
  int towers = (boxes + kTowerHeight - 1) / kTowerHeight, columns = (int)ceil(sqrt((double)towers));
  dMass mass;
  dMassSetBoxTotal(&mass, 1.0, kBoxSide, kBoxSide, kBoxSide);
  for (int i = 0; i < boxes; ++i) {
    int tower = i / kTowerHeight, level = i % kTowerHeight;
    dBodyID body = dBodyCreate(stack->world);
    dBodySetPosition(body, tower % columns * kTowerSpacing, tower / columns * kTowerSpacing,
                     kBoxSide / 2 + level * (kBoxSide + 0.001));
    dBodySetMass(body, &mass);
    dGeomSetBody(dCreateBox(stack->space, kBoxSide, kBoxSide, kBoxSide), body);
  }
  if (!adopted) return stack;
  stack->registry = ssRegistry_Create(stack->world);
  check(ssRegistry_Adopt(stack->registry, kTuned_s, stack->space, NULL), "adopt");
  ssStepperDef def = ssDefaultStepperDef();
  def.world = stack->world;
  def.registry = stack->registry;
  def.stepping.solver = SS_SOLVER_QUICK;
  check(ssSteppingForPolicy("naive", kTuned_s, &def.stepping), "naive");
  def.stepping.max_step_s = kTuned_s;
  def.collide = collide;
  def.collide_context = stack;
  def.contact_group = stack->contacts;
  check(ssStepper_Create(&def, &stack->stepper), "stepper");
  return stack;
}

static void destroy(Stack* stack) {
  ssStepper_Destroy(stack->stepper);
  ssRegistry_Destroy(stack->registry);
  dJointGroupDestroy(stack->contacts);
  dSpaceDestroy(stack->space);
  dWorldDestroy(stack->world);
  free(stack);
}

static double stepBlock(Stack* stack, const double* frames_s, int count) {
  double start = nowSeconds();
  for (int i = 0; i < count; ++i) {
    if (stack->stepper != NULL) {
      check(ssStepper_Step(stack->stepper, frames_s[i], NULL), "step");
      continue;
    }
    dSpaceCollide(stack->space, stack, nearCallback);
    dWorldQuickStep(stack->world, frames_s[i]);
    dJointGroupEmpty(stack->contacts);
  }
  return nowSeconds() - start;
}

/* The adopted world's time over the program's own, for each repeat; profile NULL: frames of 1/60 s. */
static void report(int boxes, const char* profile_spec, int frames, int repeats) {
  double ratios[kMaxRepeats], own_us = 0;
  long contacts[2] = {0, 0};
  for (int r = 0; r < repeats; ++r) {
    Stack* stacks[2] = {build(boxes, 0), build(boxes, 1)};
    ssProfile* profile = NULL;
    if (profile_spec) check(ssProfile_Create(profile_spec, 1 + (unsigned)r, &profile), "profile");
    double seconds[2] = {0, 0}, frames_s[kBlock];
    for (int done = 0, block = 0; done < frames; done += kBlock, ++block) {
      for (int i = 0; i < kBlock; ++i) frames_s[i] = profile ? ssProfile_Next(profile) : kTuned_s;
      for (int k = 0; k < 2; ++k) {
        int w = (k + block + r) % 2;
        seconds[w] += stepBlock(stacks[w], frames_s, kBlock);
      }
    }
    ratios[r] = seconds[1] / seconds[0];
    own_us += 1e6 * seconds[0] / frames / repeats;
    for (int w = 0; w < 2; ++w) contacts[w] += stacks[w]->contact_count;
    ssProfile_Destroy(profile);
    destroy(stacks[0]);
    destroy(stacks[1]);
  }
  benchSort(ratios, repeats);
  /* the adopted world's numbers are the program's up to rounding (its tuned values go through springs and back), so
   * a large stack may drift into a few other contacts: both counts are printed */
  printf("  %3d boxes, %-16s own loop %7.1f us/frame; contacts/frame %.1f own, %.1f adopted; adopted naive: median "
         "ratio %.3f (%.3f to %.3f)\n",
         boxes, profile_spec ? profile_spec : "frames of 1/60 s", own_us, (double)contacts[0] / frames / repeats,
         (double)contacts[1] / frames / repeats, ratios[repeats / 2], ratios[0], ratios[repeats - 1]);
}

int main(int argc, char** argv) {
  int frames = argc > 1 ? atoi(argv[1]) : 600;
  int repeats = argc > 2 ? atoi(argv[2]) : 7;
  if (frames <= 0 || repeats <= 0 || repeats > kMaxRepeats || argc > 3) {
    fprintf(stderr, "usage: bench_contact [frames > 0] [repeats 1..%d]\n", kMaxRepeats);
    return 2;
  }
  dInitODE2(0);
  frames = (frames + kBlock - 1) / kBlock * kBlock;
  benchPrintMachine("bench_contact", "before");
  printf("bench_contact: box stacks, %d frames a repeat, %d repeats, QuickStep 40 iterations, this thread's CPU "
         "time; target: adopted naive <= 1.02 times the program's own loop\n",
         frames, repeats);
  static const int kBoxes[2] = {8, 200};
  for (int b = 0; b < 2; ++b) {
    report(kBoxes[b], NULL, frames, repeats);
    report(kBoxes[b], "uniform:45:90", frames, repeats);
  }
  benchPrintMachine("bench_contact", "after");
  return 0;
}

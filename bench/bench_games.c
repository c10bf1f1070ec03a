/* What the library costs where games spend it: a field of boxes resting on a plane in a hash space, softened
 * contacts made in the program's near callback, stepped by the program's own loop (dSpaceCollide, dWorldQuickStep,
 * dJointGroupEmpty) and by the same world adopted through its space under `naive` (bit for bit the same motion).
 * Five scenes:
 *  - static: the boxes rest, awake;
 *  - spawning: besides, one projectile made each frame and the one made 60 frames earlier destroyed (dGeomDestroy,
 *    then dBodyDestroy in the program's loop, ssStepper_DestroyBody adopted);
 *  - asleep: the boxes disabled by ODE's auto-disable, the level at rest;
 *  - asleep, spawning: both;
 *  - jointed, spawning: the boxes of each row hinged in pairs, with stops (the adopted rows Apply writes), awake,
 *    and spawning.
 * Projectiles fly up from beside the field and never touch a box, so that a sleeping level stays asleep. The two
 * copies are stepped in alternating blocks, timed by this thread's CPU time; the ratio of adopted to own of each
 * pair of blocks is kept, and their median printed with the interval it lies in with 95 % confidence and the middle
 * half's range.
 *
 * Then the library's share of a frame as the world grows (10 to 100,000 boxes, `implicit-euler`, static boxes): the
 * adopted frame's time over the own frame's, less one. There the boxes are kept in hash spaces of 1,000 nested in the
 * world's, as a large level is kept in chunks: one hash space of n geoms clears n² bits at every collision, which
 * at 100,000 boxes is most of ODE's own frame and would hide the library's share.
 *
 * Under valgrind, `callgrind --toggle-collect=gameFrameOwn` (or gameFrameAdopted) on `bench_games count` counts the
 * instructions of one copy (docs/measurements.md).
 *
 *   bench_games [frames] [repeats] [largest box count]   (default 120 frames, 5 repeats, 100000: about 5 min on
 *   a 2-core machine; 100,000 boxes take four repeats of 10 frames, two in each building order)
 *   bench_games share [frames] [repeats] [largest box count]   the share alone
 *   bench_games count own|adopted <scene 0-5> <boxes> <frames>   one copy, untimed, for callgrind */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <steadystep/steadystep.h>

#include "bench_common.h"

enum { kLifetime = 60, kMaxContacts = 4, kChunk = 1000 };
static const double kFrame_s = 1.0 / 60.0;

typedef struct Game {
  dWorldID world;
  dSpaceID space;
  dSpaceID* chunks; /* the hash spaces of kChunk boxes nested in space, or none */
  int chunk_count;
  dJointGroupID contacts;
  ssStepper* stepper; /* NULL: the program's own loop */
  int spawning;
  dBodyID projectiles[kLifetime];
  long frame;
} Game;

/* A scene: what the boxes do, and how the world keeps them. */
typedef struct Scene {
  const char* name;
  int asleep;   /* ODE's auto-disable on: the boxes fall asleep as the program settles them */
  int spawning; /* a projectile made and one destroyed each frame */
  int chunked;  /* the boxes in hash spaces of kChunk nested in the world's */
  int jointed;  /* each pair of neighbours in a row hinged, with stops the program tuned (a level of ragdolls) */
} Scene;

static void check(ssStatus status, const char* what) { benchCheck("bench_games", status, what); }

static void nearCallback(void* data, dGeomID o1, dGeomID o2) {
  Game* game = data;
  if (dGeomIsSpace(o1) || dGeomIsSpace(o2)) { /* a chunk and the plane: what is inside each chunk comes after */
    dSpaceCollide2(o1, o2, data, nearCallback);
    return;
  }
  dBodyID b1 = dGeomGetBody(o1), b2 = dGeomGetBody(o2);
  if (b1 != 0 && b2 != 0 && dAreConnectedExcluding(b1, b2, dJointTypeContact)) return;
  dContact contact[kMaxContacts];
  for (int i = 0; i < kMaxContacts; ++i) {
    contact[i].surface.mode = dContactSoftCFM | dContactSoftERP | dContactApprox1;
    contact[i].surface.mu = 0.8;
    contact[i].surface.soft_erp = 0.2;
    contact[i].surface.soft_cfm = 1e-4;
  }
  int count = dCollide(o1, o2, kMaxContacts, &contact[0].geom, sizeof(dContact));
  if (game->stepper != NULL) ssStepper_SoftenContacts(game->stepper, contact, count);
  for (int i = 0; i < count; ++i) dJointAttach(dJointCreateContact(game->world, game->contacts, &contact[i]), b1, b2);
}

static void collideAll(Game* game) {
  dSpaceCollide(game->space, game, nearCallback);
  for (int c = 0; c < game->chunk_count; ++c) dSpaceCollide(game->chunks[c], game, nearCallback);
}

static void collide(void* context, ssStepper* stepper) {
  (void)stepper;
  collideAll(context);
}

/* A projectile made age_s ago at the spawning's place for game->frame, fired up at 10 m/s: where and how fast it is
 * now (up for two seconds: gone before it lands). */
static dBodyID makeProjectile(Game* game, double age_s) {
  const double launch_mps = 10.0, gravity_mps2 = 9.81;
  dBodyID body = dBodyCreate(game->world);
  dMass mass;
  dMassSetSphereTotal(&mass, 0.2, 0.1);
  dBodySetMass(body, &mass);
  dBodySetPosition(body, -5.0 - (double)(game->frame % 7), -5.0,
                   1.0 + (launch_mps - 0.5 * gravity_mps2 * age_s) * age_s);
  dBodySetLinearVel(body, 0, 0, launch_mps - gravity_mps2 * age_s);
  dGeomSetBody(dCreateSphere(game->space, 0.1), body);
  return body;
}

/* Hinges the box at place i of a row of side to the one before it: at their middle, turning about y, within stops of
 * 0.2 rad at the program's ERP and CFM (tuned at 60 fps). */
static void hinge(Game* game, dBodyID before, dBodyID body, int i, int side) {
  dJointID joint = dJointCreateHinge(game->world, 0);
  dJointAttach(joint, before, body);
  dJointSetHingeAnchor(joint, i % side - 0.5, i / side, 0.25);
  dJointSetHingeAxis(joint, 0, 1, 0);
  dJointSetHingeParam(joint, dParamLoStop, -0.2);
  dJointSetHingeParam(joint, dParamHiStop, 0.2);
  dJointSetHingeParam(joint, dParamStopERP, 0.3);
  dJointSetHingeParam(joint, dParamStopCFM, 1e-4);
}

/* boxes of 0.5 m on a square grid 1 m apart, resting on the plane z = 0, kept as scene says */
static Game* build(const Scene* scene, int boxes, const char* policy) {
  Game* game = calloc(1, sizeof *game);
  if (game == NULL) exit(1);
  *game = (Game){dWorldCreate(), dHashSpaceCreate(0), NULL, 0, dJointGroupCreate(0), NULL, scene->spawning, {0}, 0};
  const int chunked = scene->chunked, asleep = scene->asleep;
  if (chunked) {
    game->chunk_count = (boxes + kChunk - 1) / kChunk;
    if ((game->chunks = calloc((size_t)game->chunk_count, sizeof *game->chunks)) == NULL) exit(1);
    for (int c = 0; c < game->chunk_count; ++c) game->chunks[c] = dHashSpaceCreate(game->space);
  }
  dWorldSetGravity(game->world, 0, 0, -9.81);
  dWorldSetQuickStepNumIterations(game->world, 10);
  dWorldSetAutoDisableFlag(game->world, asleep);
  dCreatePlane(game->space, 0, 0, 1, 0);
  int side = (int)ceil(sqrt((double)boxes));
  dBodyID before = 0; /* the box made before this one */
  for (int i = 0; i < boxes; ++i) {
    dBodyID body = dBodyCreate(game->world);
    dMass mass;
    dMassSetBoxTotal(&mass, 1.0, 0.5, 0.5, 0.5);
    dBodySetMass(body, &mass);
    dBodySetPosition(body, i % side, i / side, 0.25);
    dGeomSetBody(dCreateBox(chunked ? game->chunks[i / kChunk] : game->space, 0.5, 0.5, 0.5), body);
    if (scene->jointed && i % 2 == 1 && i % side != 0) hinge(game, before, body, i, side); /* pairs within a row */
    before = body;
  }
  /* settled by the program before it is adopted: the boxes sit in their contacts (and fall asleep) */
  for (int i = 0; i < (asleep ? 60 : 5); ++i) {
    collideAll(game);
    dWorldQuickStep(game->world, kFrame_s);
    dJointGroupEmpty(game->contacts);
  }
  /* spawning: the projectiles of the last kLifetime frames in flight, so that every frame measured destroys one */
  for (int slot = 0; scene->spawning && slot < kLifetime; ++slot, ++game->frame)
    game->projectiles[slot] = makeProjectile(game, (kLifetime - slot) * kFrame_s);
  if (policy == NULL) return game;
  ssStepperDef def = ssDefaultStepperDef();
  def.world = game->world;
  def.space = game->space;
  def.tuned_step_s = kFrame_s;
  def.stepping.solver = SS_SOLVER_QUICK;
  check(ssSteppingForPolicy(policy, kFrame_s, &def.stepping), policy);
  def.collide = collide;
  def.collide_context = game;
  def.contact_group = game->contacts;
  check(ssStepper_Create(&def, &game->stepper), "stepper");
  return game;
}

/* The program's spawning: a projectile made, and the one made kLifetime frames ago destroyed. */
static void spawnAndDespawn(Game* game) {
  if (!game->spawning) return;
  int slot = (int)(game->frame % kLifetime);
  dBodyID old = game->projectiles[slot];
  if (old != 0) {
    dGeomDestroy(dBodyGetFirstGeom(old));
    if (game->stepper != NULL) check(ssStepper_DestroyBody(game->stepper, old), "destroy body");
    else dBodyDestroy(old);
  }
  game->projectiles[slot] = makeProjectile(game, 0);
  game->frame += 1;
}

/* A frame of the program's own loop. */
static void ownFrame(Game* game) {
  spawnAndDespawn(game);
  collideAll(game);
  dWorldQuickStep(game->world, kFrame_s);
  dJointGroupEmpty(game->contacts);
}

/* Not inlined: callgrind counts the frames by these names (a warm frame calls the bodies above, and is not counted). */
__attribute__((noinline)) void gameFrameOwn(Game* game) { ownFrame(game); }

/* A frame of the adopted copy. */
static void adoptedFrame(Game* game) {
  spawnAndDespawn(game);
  check(ssStepper_Step(game->stepper, kFrame_s, NULL), "step");
}

__attribute__((noinline)) void gameFrameAdopted(Game* game) { adoptedFrame(game); }

static void destroy(Game* game) {
  ssStepper_Destroy(game->stepper);
  dJointGroupDestroy(game->contacts);
  dSpaceDestroy(game->space); /* and the chunks in it */
  dWorldDestroy(game->world);
  free(game->chunks);
  free(game);
}

enum { kPairs = 10, kWarmFrames = 2 }; /* blocks of each copy a repeat; frames each copy takes untimed first */

/* One pair of copies (own, adopted), built in the order own_first says (the heap lays them out differently: which
 * is built first moves a large world's ratio by several per cent either way, so the repeats take turns), each first
 * stepped kWarmFrames untimed, then through frames in kPairs blocks each, alternating: the ratio adopted / own of
 * each pair of blocks into ratios[0 .. kPairs), the own copy's CPU seconds returned. */
static double measure(const Scene* scene, int boxes, const char* policy, int frames, int own_first, double* ratios) {
  Game* games[2];
  games[!own_first] = build(scene, boxes, own_first ? NULL : policy);
  games[own_first] = build(scene, boxes, own_first ? policy : NULL);
  for (int i = 0; i < kWarmFrames; ++i) gameFrameOwn(games[0]), gameFrameAdopted(games[1]);
  double own_s = 0;
  const int block = frames / kPairs;
  for (int pair = 0; pair < kPairs; ++pair) {
    double seconds[2];
    for (int k = 0; k < 2; ++k) {
      int g = (k + pair) % 2; /* the order alternates: neither is always first */
      double start = benchCpuSeconds();
      for (int i = 0; i < block; ++i) {
        if (g == 0) gameFrameOwn(games[0]);
        else gameFrameAdopted(games[1]);
      }
      seconds[g] = benchCpuSeconds() - start;
    }
    ratios[pair] = seconds[1] / seconds[0];
    own_s += seconds[0];
  }
  destroy(games[0]);
  destroy(games[1]);
  return own_s;
}

/* The median ratio adopted / own over every pair of blocks of the repeats (a burst of another process' load spoils a
 * pair, not the figure), printed with the own frame's time, where the pairs' median lies with 95 % confidence (what
 * the run can tell from 1.02) and the middle half's range (how much one pair says). */
static double reportScene(const Scene* scene, int boxes, const char* policy, int frames, int repeats) {
  static double ratios[64 * kPairs];
  double own_us = 0;
  for (int r = 0; r < repeats; ++r)
    own_us += 1e6 * measure(scene, boxes, policy, frames, r % 2 == 0, &ratios[r * kPairs]) / frames / repeats;
  const int count = repeats * kPairs;
  benchSort(ratios, count);
  double low, high;
  benchMedianInterval(ratios, count, &low, &high);
  printf("  %-22s %6d boxes  own %9.1f us/frame  adopted/own %.4f  (95 %% interval %.4f to %.4f, middle half %.4f "
         "to %.4f)\n", scene->name, boxes, own_us, ratios[count / 2], low, high, ratios[count / 4], ratios[(3 * count) / 4]);
  return ratios[count / 2];
}

static const Scene kScenes[] = {
    {"static", 0, 0, 0, 0},
    {"spawning", 0, 1, 0, 0},
    {"asleep", 1, 0, 0, 0},
    {"asleep, spawning", 1, 1, 0, 0},
    {"jointed, spawning", 0, 1, 0, 1},
    {"static, chunked", 0, 0, 1, 0}}; /* the share's scene, timed under implicit-euler; counted as the others */
enum { kSceneCount = sizeof kScenes / sizeof kScenes[0], kGameScenes = kSceneCount - 1 };

/* bench_games count own|adopted <scene 0-5> <boxes> <frames>: one copy stepped, untimed, for callgrind's counts; as
 * in the timed runs, it first takes kWarmFrames uncounted (the stepper's first frame lists what it adopted: once, not
 * a frame's cost). Each copy is counted in a process of its own, as a program runs alone: stepped one after the
 * other in one process, the second copy's frames allocate from the heap the first's left, and pay for it (at 1,000
 * sleeping boxes with spawning, 0.6 M instructions in 60 frames, whichever copy runs second). */
static int countInstructions(int argc, char** argv) {
  const char* copy = argc > 2 ? argv[2] : "";
  const int adopted = strcmp(copy, "adopted") == 0;
  int scene = argc > 3 ? atoi(argv[3]) : -1, boxes = argc > 4 ? atoi(argv[4]) : 0;
  int frames = argc > 5 ? atoi(argv[5]) : 0;
  if ((!adopted && strcmp(copy, "own") != 0) || scene < 0 || scene >= kSceneCount || boxes <= 0 || frames <= 0) {
    fprintf(stderr, "usage: bench_games count own|adopted <scene 0-%d> <boxes> <frames>\n", kSceneCount - 1);
    return 2;
  }
  dInitODE2(0);
  Game* game = build(&kScenes[scene], boxes, adopted ? "naive" : NULL);
  for (int i = 0; i < kWarmFrames; ++i) adopted ? adoptedFrame(game) : ownFrame(game);
  for (int i = 0; i < frames; ++i) adopted ? gameFrameAdopted(game) : gameFrameOwn(game);
  destroy(game);
  return 0;
}

int main(int argc, char** argv) {
  if (argc > 1 && strcmp(argv[1], "count") == 0) return countInstructions(argc, argv);
  const int share_only = argc > 1 && strcmp(argv[1], "share") == 0;
  if (share_only) argc -= 1, argv += 1;
  int frames = argc > 1 ? atoi(argv[1]) : 120;
  int repeats = argc > 2 ? atoi(argv[2]) : 5;
  int largest = argc > 3 ? atoi(argv[3]) : 100000;
  if (frames <= 0 || repeats <= 0 || repeats > 64 || largest < 10 || argc > 4) {
    fprintf(stderr, "usage: bench_games [share] [frames > 0] [repeats 1..64] [largest box count >= 10]\n");
    return 2;
  }
  frames = (frames + kPairs - 1) / kPairs * kPairs;
  setvbuf(stdout, NULL, _IOLBF, 0); /* each line as it is measured, into a log too */
  dInitODE2(0);
  benchPrintMachine("bench_games", "before");
  printf("bench_games: boxes resting on a plane in a hash space, %d frames of 1/60 s a repeat, thread CPU time\n",
         frames);
  if (!share_only) printf("adopted under naive against the program's own loop (target: at most 1.02)\n");
  for (int boxes = 1000; !share_only && boxes <= 10000; boxes *= 10)
    for (int s = 0; s < kGameScenes; ++s)
      reportScene(&kScenes[s], boxes, "naive", boxes >= 10000 ? (frames / 4 + kPairs - 1) / kPairs * kPairs : frames,
                  repeats);
  printf("the library's share of a frame as the world grows, implicit-euler, static boxes in hash spaces of %d "
         "(target: the share at 100,000 at most 1.5 times the share at 1,000)\n", kChunk);
  for (int boxes = 10; boxes <= largest; boxes *= 10) {
    int scaled = boxes >= 100000 ? kPairs : boxes >= 10000 ? frames / 4 : frames; /* a few seconds a repeat */
    scaled = (scaled + kPairs - 1) / kPairs * kPairs;
    double ratio = reportScene(&kScenes[kGameScenes], boxes, "implicit-euler", scaled, boxes >= 100000 ? 4 : repeats);
    printf("    share %.2f %%\n", 100.0 * (ratio - 1.0));
  }
  benchPrintMachine("bench_games", "after");
  return 0;
}

/* Fuzz target: a program that keeps changing its world, as real ones do, with the stepper adopting it through the
 * def (stepper.h: what is found, what is forgotten, the program's own writes).
 *
 * The input builds a world of spaces of every kind (simple, hash, sweep-and-prune, now and then a quadtree), nested
 * at any depth, with boxes in them, bobs hung on hinges from the boxes, and hinges with stops between boxes; the
 * stepper adopts it through def.space. Then operations, between frames or armed for a step inside a frame (from
 * before_step): frames of any usual length; spawn a box or a bob; destroy a box with its geom by ODE's own calls or
 * any body through ssStepper_DestroyBody; destroy a joint by dJointDestroy or make one (with numbers a spring stands
 * for, or not); rewrite world ERP/CFM, a stop's ERP/CFM or a body's damping; teleport, spin; watch and unwatch;
 * nest a new space, or destroy a nested one with its bodies; reset after a failure, repairing the bodies.
 *
 * Promises checked after every frame: no abort and no sanitizer report (reading what the program destroyed would be
 * a heap-use-after-free); every refusal is a named status with a message; a frame refused is refused again when
 * stepped again with nothing repaired (a later body or a value no spring stands for is never let through on the
 * second look); after a frame that stepped and a frame of 0 s (which looks without stepping), the stepper knows at
 * least every body that a plain walk of the whole graph reaches (the adopted spaces' geoms, not under a quadtree,
 * then joints) plus the watched ones. */
#include <ode/ode.h>

#include "fuzz_input.h"
#include "steadystep/steadystep.h"

enum { MAX_SPACES = 6, MAX_BODIES = 20, MAX_JOINTS = 20, MAX_OPS = 48 };
enum { KIND_SIMPLE, KIND_HASH, KIND_SAP, KIND_QUADTREE };

typedef struct Body {
  dBodyID body;
  dGeomID geom; /* 0: a bob (no geom), destroyed through the stepper only (stepper.h) */
  int space;    /* its geom's space (index), -1 for a bob */
  int watched;
  double built[3]; /* where it was made: the program's repair puts it back there */
} Body;

typedef struct Program {
  dWorldID world;
  dSpaceID spaces[MAX_SPACES];
  int parent[MAX_SPACES]; /* -1: the root */
  int kind[MAX_SPACES];
  int space_count;
  Body bodies[MAX_BODIES];
  int body_count;
  dJointID joints[MAX_JOINTS];
  int joint_count;
  ssStepper* stepper;
  dJointGroupID contacts;
  /* an operation armed for a step of the next frame, run from before_step */
  int armed, armed_step, armed_code, calls;
  int spawned; /* boxes spawned so far: each spawns at a place of its own */
  uint8_t armed_bytes[16];
} Program;

static Program program;
static int verbose = 0;

static int named(ssStatus status) {
  return (int)status >= 0 && strcmp(ssStatusName(status), "unknown status") != 0;
}

static void checkStatus(ssStatus status, const char* what) {
  FUZZ_REQUIRE(named(status), "%s returned an unnamed status %d", what, (int)status);
  FUZZ_REQUIRE(status == SS_OK || ssLastError()[0] != '\0', "%s refused (%s) without a message", what,
               ssStatusName(status));
}

/* ---- the program's world ---- */

static dSpaceID makeSpace(Program* p, int kind, int parent) {
  dSpaceID in = parent >= 0 ? p->spaces[parent] : 0;
  dSpaceID space;
  switch (kind) {
    case KIND_SIMPLE: space = dSimpleSpaceCreate(in); break;
    case KIND_HASH: space = dHashSpaceCreate(in); break;
    case KIND_SAP: space = dSweepAndPruneSpaceCreate(in, dSAP_AXES_XYZ); break;
    default: {
      dVector3 centre = {0, 0, 0, 0}, extents = {20, 20, 20, 0};
      space = dQuadTreeSpaceCreate(in, centre, extents, 3);
    }
  }
  p->spaces[p->space_count] = space;
  p->parent[p->space_count] = parent;
  p->kind[p->space_count] = kind;
  p->space_count += 1;
  return space;
}

/* Whether space i is under a quadtree (itself one included): ODE cannot list it, the stepper refuses it. */
static int underQuadTree(const Program* p, int i) {
  for (; i >= 0; i = p->parent[i])
    if (p->kind[i] == KIND_QUADTREE) return 1;
  return 0;
}

static int quadTreeAnywhere(const Program* p) {
  for (int i = 0; i < p->space_count; ++i)
    if (p->kind[i] == KIND_QUADTREE) return 1;
  return 0;
}

static dBodyID makeBox(Program* p, int space, double x, double z) {
  if (p->body_count == MAX_BODIES) return 0;
  dBodyID body = dBodyCreate(p->world);
  dMass mass;
  dMassSetBoxTotal(&mass, 1.0, 0.2, 0.2, 0.2);
  dBodySetMass(body, &mass);
  dBodySetPosition(body, x, 0, z);
  dGeomID geom = dCreateBox(p->spaces[space], 0.2, 0.2, 0.2);
  dGeomSetBody(geom, body);
  p->bodies[p->body_count++] = (Body){body, geom, space, 0, {x, 0, z}};
  return body;
}

static void setStops(dJointID joint, double erp, double cfm) {
  dJointSetHingeParam(joint, dParamLoStop, -0.3);
  dJointSetHingeParam(joint, dParamHiStop, 0.3);
  dJointSetHingeParam(joint, dParamStopERP, erp);
  dJointSetHingeParam(joint, dParamStopCFM, cfm);
}

static int nearTheLevel(dBodyID body) {
  const dReal* at = dBodyGetPosition(body);
  return fabs(at[0]) <= 100 && fabs(at[1]) <= 100 && fabs(at[2]) <= 100;
}

static dJointID makeHinge(Program* p, dBodyID a, dBodyID b, double erp, double cfm) {
  if (p->joint_count == MAX_JOINTS || a == 0 || !nearTheLevel(a) || (b != 0 && !nearTheLevel(b))) return 0;
  if (b != 0) { /* a program joins what is near, once: a joint far from holding is its own to answer for */
    const dReal *pa = dBodyGetPosition(a), *pb = dBodyGetPosition(b);
    if (fabs(pa[0] - pb[0]) + fabs(pa[1] - pb[1]) + fabs(pa[2] - pb[2]) > 2) return 0;
    if (dAreConnectedExcluding(a, b, dJointTypeContact)) return 0;
  }
  dJointID joint = dJointCreateHinge(p->world, 0);
  dJointAttach(joint, a, b);
  const dReal* at = dBodyGetPosition(a);
  dJointSetHingeAnchor(joint, at[0], at[1], at[2] + 0.1);
  dJointSetHingeAxis(joint, 0, 1, 0);
  setStops(joint, erp, cfm);
  p->joints[p->joint_count++] = joint;
  return joint;
}

/* A bob: a body with no geom, hung on a hinge from a box (reached through its joint). */
static void makeBob(Program* p, int from) {
  if (p->body_count == MAX_BODIES || p->joint_count == MAX_JOINTS || p->bodies[from].geom == 0 ||
      !nearTheLevel(p->bodies[from].body))
    return;
  dBodyID bob = dBodyCreate(p->world);
  dMass mass;
  dMassSetSphereTotal(&mass, 0.5, 0.1);
  dBodySetMass(bob, &mass);
  const dReal* at = dBodyGetPosition(p->bodies[from].body);
  dBodySetPosition(bob, at[0] + 0.3, at[1], at[2]);
  p->bodies[p->body_count++] = (Body){bob, 0, -1, 0, {at[0] + 0.3, at[1], at[2]}};
  makeHinge(p, p->bodies[from].body, bob, 0.3, 1e-4);
}

static void forgetJoint(Program* p, int j) { p->joints[j] = p->joints[--p->joint_count]; }

/* ODE leaves a destroyed body's joints in the world, attached to nothing on its side: the program's list keeps them
 * (they are alive). */
static void forgetBody(Program* p, int i) { p->bodies[i] = p->bodies[--p->body_count]; }

static int boxIndex(const Program* p, uint8_t byte) {
  int boxes = 0;
  for (int i = 0; i < p->body_count; ++i) boxes += p->bodies[i].geom != 0;
  if (boxes == 0) return -1;
  for (int i = 0, k = byte % boxes; i < p->body_count; ++i)
    if (p->bodies[i].geom != 0 && k-- == 0) return i;
  return -1;
}

/* A watched body is the program's to unwatch before ODE destroys it (stepper.h): the stepper may never have seen
 * its geom (made and destroyed between two frames). */
static void unwatch(Program* p, int i) {
  if (p->bodies[i].watched) checkStatus(ssStepper_UnwatchBody(p->stepper, p->bodies[i].body), "unwatch");
  p->bodies[i].watched = 0;
}

/* A box destroyed by ODE's own calls, its geom with it. */
static void destroyBoxPlainly(Program* p, int i) {
  unwatch(p, i);
  dGeomDestroy(p->bodies[i].geom);
  dBodyDestroy(p->bodies[i].body);
  forgetBody(p, i);
}

/* Any body through the stepper, its geom after (a geom without a body is only a static box). */
static void destroyThroughStepper(Program* p, int i) {
  dGeomID geom = p->bodies[i].geom;
  ssStatus status = ssStepper_DestroyBody(p->stepper, p->bodies[i].body);
  checkStatus(status, "ssStepper_DestroyBody");
  if (status != SS_OK) return;
  if (geom != 0) dGeomDestroy(geom);
  forgetBody(p, i);
}

/* A nested space destroyed with everything in it, as a level's part is torn down: the bodies of its geoms (and of
 * the spaces under it) first, by ODE's own calls, then the space, which destroys its geoms and spaces. */
static void destroyNestedSpace(Program* p, int s) {
  if (s <= 0 || s >= p->space_count) return;
  int doomed[MAX_SPACES] = {0};
  for (int i = 0; i < p->space_count; ++i)
    for (int k = i; k >= 0; k = p->parent[k])
      if (k == s) doomed[i] = 1;
  for (int i = 0; i < p->body_count;) {
    if (p->bodies[i].space >= 0 && doomed[p->bodies[i].space]) {
      /* its geom goes with the space. A body in a quadtree is in no space the stepper can list: the stepper may know
       * it (watched, or through a joint) without seeing its geom, so it goes through the stepper (stepper.h) */
      if (underQuadTree(p, p->bodies[i].space)) checkStatus(ssStepper_DestroyBody(p->stepper, p->bodies[i].body),
                                                            "ssStepper_DestroyBody");
      else unwatch(p, i), dBodyDestroy(p->bodies[i].body);
      forgetBody(p, i);
    } else {
      ++i;
    }
  }
  dSpaceDestroy(p->spaces[s]);
  /* compact the spaces, renumbering parents and the bodies' spaces */
  int to[MAX_SPACES], kept = 0;
  for (int i = 0; i < p->space_count; ++i) to[i] = doomed[i] ? -1 : kept++;
  for (int i = 0; i < p->space_count; ++i) {
    if (doomed[i]) continue;
    int j = to[i];
    p->spaces[j] = p->spaces[i];
    p->kind[j] = p->kind[i];
    p->parent[j] = p->parent[i] >= 0 ? to[p->parent[i]] : -1;
  }
  p->space_count = kept;
  for (int i = 0; i < p->body_count; ++i)
    if (p->bodies[i].space >= 0) p->bodies[i].space = to[p->bodies[i].space];
}

/* The bodies a plain walk of the whole graph reaches: geoms of the adopted spaces not under a quadtree, then joints,
 * and the watched ones. */
static int reachable(const Program* p) {
  int reached[MAX_BODIES] = {0}, count = 0;
  for (int i = 0; i < p->body_count; ++i)
    if ((p->bodies[i].geom != 0 && !underQuadTree(p, p->bodies[i].space)) || p->bodies[i].watched) reached[i] = 1;
  for (int changed = 1; changed;) {
    changed = 0;
    for (int j = 0; j < p->joint_count; ++j) {
      dBodyID a = dJointGetBody(p->joints[j], 0), b = dJointGetBody(p->joints[j], 1);
      int ia = -1, ib = -1;
      for (int i = 0; i < p->body_count; ++i) {
        if (p->bodies[i].body == a) ia = i;
        if (p->bodies[i].body == b) ib = i;
      }
      if (ia >= 0 && ib >= 0 && reached[ia] != reached[ib]) reached[ia] = reached[ib] = changed = 1;
    }
  }
  for (int i = 0; i < p->body_count; ++i) count += reached[i];
  return count;
}

/* Moves body i to x (any double: NaN, huge) and every body jointed to it, directly or not, by the same offset. */
static void teleport(Program* p, int i, double x) {
  int moved[MAX_BODIES] = {0};
  moved[i] = 1;
  for (int changed = 1; changed;) {
    changed = 0;
    for (int j = 0; j < p->joint_count; ++j) {
      dBodyID a = dJointGetBody(p->joints[j], 0), b = dJointGetBody(p->joints[j], 1);
      for (int k = 0; k < p->body_count; ++k)
        for (int l = 0; l < p->body_count; ++l)
          if (!moved[l] && moved[k] && ((p->bodies[k].body == a && p->bodies[l].body == b) ||
                                        (p->bodies[k].body == b && p->bodies[l].body == a)))
            moved[l] = changed = 1;
    }
  }
  double offset = x - dBodyGetPosition(p->bodies[i].body)[0];
  for (int k = 0; k < p->body_count; ++k) {
    if (!moved[k] || k == i) continue;
    const dReal* at = dBodyGetPosition(p->bodies[k].body);
    dBodySetPosition(p->bodies[k].body, at[0] + offset, at[1], at[2]);
  }
  const dReal* at = dBodyGetPosition(p->bodies[i].body);
  dBodySetPosition(p->bodies[i].body, x, at[1], at[2]); /* exactly as asked */
}

static void removeOrphans(Program* p);

/* The program repairs its bodies (where they were made, at rest: its saved state) and its numbers (springs), as
 * after a failure it restores a saved state. */
static void repair(Program* p) {
  for (int i = 0; i < p->body_count; ++i) {
    const double* at = p->bodies[i].built;
    dBodySetPosition(p->bodies[i].body, at[0], at[1], at[2]);
    dBodySetRotation(p->bodies[i].body, (dMatrix3){1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0});
    dBodySetLinearVel(p->bodies[i].body, 0, 0, 0);
    dBodySetAngularVel(p->bodies[i].body, 0, 0, 0);
    dBodySetForce(p->bodies[i].body, 0, 0, 0);
    dBodySetTorque(p->bodies[i].body, 0, 0, 0);
    dBodySetLinearDamping(p->bodies[i].body, 0.01);
  }
  for (int j = 0; j < p->joint_count; ++j) setStops(p->joints[j], 0.3, 1e-4);
  dWorldSetERP(p->world, 0.2);
  dWorldSetCFM(p->world, 1e-5);
  for (int s = 1; s < p->space_count;) /* quadtrees out of the adopted spaces */
    if (p->kind[s] == KIND_QUADTREE) destroyNestedSpace(p, s);
    else ++s;
  removeOrphans(p); /* bobs that hung from a box of a quadtree */
}

/* A bob left hanging from nothing a space holds is unknowable (stepper.h: what nothing reaches, it cannot see), so
 * the program takes it down with what it hung from, as a game removes a whole entity: through the stepper, which
 * knew it. */
static void removeOrphans(Program* p) {
  int reached[MAX_BODIES] = {0};
  for (int i = 0; i < p->body_count; ++i) reached[i] = p->bodies[i].geom != 0 || p->bodies[i].watched;
  for (int changed = 1; changed;) {
    changed = 0;
    for (int j = 0; j < p->joint_count; ++j) {
      dBodyID a = dJointGetBody(p->joints[j], 0), b = dJointGetBody(p->joints[j], 1);
      for (int k = 0; k < p->body_count; ++k)
        for (int l = 0; l < p->body_count; ++l)
          if (reached[k] && !reached[l] && ((p->bodies[k].body == a && p->bodies[l].body == b) ||
                                            (p->bodies[k].body == b && p->bodies[l].body == a)))
            reached[l] = changed = 1;
    }
  }
  for (int i = p->body_count - 1; i >= 0; --i)
    if (!reached[i]) destroyThroughStepper(p, i);
}

/* ---- operations ---- */

static const double kFrames[] = {0, 1.0 / 144, 1.0 / 60, 1.0 / 59, 1.0 / 30, 0.05, 1.0 / 15};

/* The operations a program does between frames, or (inside == 1) from before_step. */
static void operate(Program* p, int code, FuzzInput* in, int inside) {
  uint8_t a = fuzz_byte(in), b = fuzz_byte(in);
  switch (code) {
    case 0: /* spawn a box, where the program has room for it: boxes spawned into one another make dWorldStep
             * factor hundreds of contact rows (slow), and two boxes exactly on one another make ODE's own box-box
             * collider assert in the program's dCollide ("*iret != i0", box.cpp), plain ODE's doing */
      if (p->space_count > 0) makeBox(p, a % p->space_count, 0.7 * (p->spawned++ % 40) - 14, 1 + b % 3);
      break;
    case 1: { /* spawn a bob */
      int box = boxIndex(p, a);
      if (box >= 0) makeBob(p, box);
      break;
    }
    case 2: { /* destroy a box with its geom, plainly */
      int box = boxIndex(p, a);
      if (box >= 0) destroyBoxPlainly(p, box);
      break;
    }
    case 3: /* destroy any body through the stepper */
      if (p->body_count > 0) destroyThroughStepper(p, a % p->body_count);
      break;
    case 4: /* destroy a joint plainly */
      if (p->joint_count > 0) {
        int j = a % p->joint_count;
        dJointDestroy(p->joints[j]);
        forgetJoint(p, j);
      }
      break;
    case 5: { /* make a hinge, tuned as a spring or not */
      int x = boxIndex(p, a);
      if (x < 0) break;
      dBodyID other = p->body_count > 0 && b % 3 ? p->bodies[b % p->body_count].body : 0;
      if (other == p->bodies[x].body) other = 0;
      double erp = b % 7 == 0 ? 1.5 : 0.2 + 0.1 * (b % 5), cfm = b % 11 == 0 ? -1e-3 : 1e-5 * (1 + b % 4);
      makeHinge(p, p->bodies[x].body, other, erp, cfm);
      break;
    }
    case 6: { /* rewrite numbers, as from the program's settings: springs, or (between frames, where the stepper
               * looks before ODE steps) values no spring stands for, which it must refuse by name. A program that
               * writes those inside a step hands them to ODE itself: plain ODE aborts on some (cfm 0 in a loop of
               * hinges under dWorldStep), so the callbacks write springs only. */
      double erp = 0.05 + 0.9 * (fuzz_byte(in) / 255.0), cfm = 1e-8 * pow(10, fuzz_byte(in) % 6);
      if (!inside && b % 4 == 0) {
        /* a value no spring stands for, which the stepper must refuse by name. (Values a spring does stand for but
         * plain ODE cannot step, a cfm of 0 or 1e-249 with constraints that repeat one another under dWorldStep, are
         * the program's own doing, aborting its own loop as well: not fuzzed.) */
        static const double bad_erp[] = {-0.5, 1.5, 1e300, NAN, INFINITY, 0.3, 0.3};
        static const double bad_cfm[] = {1e-5, 1e-5, 1e-5, 1e-5, -1, NAN, -INFINITY};
        erp = bad_erp[fuzz_byte(in) % 7];
        cfm = bad_cfm[fuzz_byte(in) % 7];
        if (erp == 0.3 && cfm == 1e-5) cfm = -1;
      }
      if (verbose) fprintf(stderr, "  rewrite %d: erp %g cfm %g\n", a % 3, erp, cfm);
      switch (a % 3) {
        case 0:
          if (isfinite(erp) && isfinite(cfm)) dWorldSetERP(p->world, erp), dWorldSetCFM(p->world, cfm);
          break;
        case 1:
          if (p->joint_count > 0) setStops(p->joints[b % p->joint_count], erp, cfm);
          break;
        default: /* a damping scale: in [0, 1) a program's, else (1.5, NaN, ...) one the stepper refuses */
          if (p->body_count > 0 && isfinite(erp)) dBodySetLinearDamping(p->bodies[b % p->body_count].body, erp);
      }
      break;
    }
    case 7: /* teleport, as a program moves an assembly: the body and all it is jointed to, by one offset */
      if (p->body_count > 0) teleport(p, a % p->body_count, fuzzDouble(in));
      break;
    case 8: /* spin */
      if (p->body_count > 0) dBodySetAngularVel(p->bodies[a % p->body_count].body, fuzzDouble(in), 0, 0);
      break;
    case 9: /* watch or unwatch */
      if (p->body_count > 0) {
        Body* body = &p->bodies[a % p->body_count];
        ssStatus status = body->watched ? ssStepper_UnwatchBody(p->stepper, body->body)
                                        : ssStepper_WatchBody(p->stepper, body->body);
        checkStatus(status, "watch or unwatch");
        if (status == SS_OK) body->watched = !body->watched;
      }
      break;
    case 10: /* nest a space (now and then a quadtree) with a box in it */
      if (p->space_count < MAX_SPACES && p->space_count > 0 && !inside) {
        int kind = b % 13 == 0 ? KIND_QUADTREE : b % 3;
        makeSpace(p, kind, a % p->space_count);
        makeBox(p, p->space_count - 1, 2, 2);
      }
      break;
    case 11: /* destroy a nested space with its bodies */
      if (p->space_count > 1) destroyNestedSpace(p, 1 + a % (p->space_count - 1));
      break;
    default: break;
  }
  if (code == 2 || code == 3 || code == 4 || code == 11) removeOrphans(p);
}

/* The program's collision: contacts softened for the step; one the stepper refuses (not finite) is dropped. */
static void nearCallback(void* data, dGeomID g1, dGeomID g2) {
  Program* p = &program;
  dBodyID b1 = dGeomGetBody(g1), b2 = dGeomGetBody(g2);
  if (b1 != 0 && b2 != 0 && dAreConnectedExcluding(b1, b2, dJointTypeContact)) return;
  /* room for every point a box pair makes (8): with fewer, ODE's box-box collider culls them, and its cullPoints
   * asserts on boxes that hinges with stops have pressed into one another ("*iret != i0"), plain ODE's doing */
  dContact contact[8];
  memset(contact, 0, sizeof contact);
  int count = dCollide(g1, g2, 8, &contact[0].geom, sizeof contact[0]);
  for (int i = 0; i < count; ++i) {
    contact[i].surface.mode = dContactSoftCFM;
    contact[i].surface.mu = 0.5;
    contact[i].surface.soft_cfm = 1e-4;
    ssStatus status = ssStepper_SoftenContact(data, &contact[i], b1, b2);
    checkStatus(status, "ssStepper_SoftenContact");
    if (status == SS_OK) dJointAttach(dJointCreateContact(p->world, p->contacts, &contact[i]), b1, b2);
  }
}

static void collide(void* context, ssStepper* stepper) {
  Program* p = context;
  dSpaceCollide(p->spaces[0], stepper, nearCallback);
}

static void beforeStep(void* context, ssStepper* stepper) {
  Program* p = context;
  ssStepInfo step = ssStepper_CurrentStep(stepper);
  if (!p->armed || step.index != p->armed_step) return;
  p->armed = 0;
  FuzzInput in = {p->armed_bytes, sizeof p->armed_bytes};
  operate(p, p->armed_code, &in, 1);
}

static ssStatus stepFrame(Program* p, double frame_s) {
  ssFrameReport report;
  ssStatus status = ssStepper_Step(p->stepper, frame_s, &report);
  if (verbose) fprintf(stderr, "  frame %g: %s %s\n", frame_s, ssStatusName(status), status ? ssLastError() : "");
  checkStatus(status, "ssStepper_Step");
  return status;
}

static void checkFrame(Program* p, double frame_s) {
  ssStatus status = stepFrame(p, frame_s);
  p->armed = 0;
  if (status != SS_OK) {
    /* nothing repaired: refused again, never let through on the second look */
    ssStatus again = stepFrame(p, frame_s);
    FUZZ_REQUIRE(again != SS_OK, "a frame refused (%s) was taken when stepped again with nothing repaired",
                 ssStatusName(status));
    repair(p);
    ssStepper_Reset(p->stepper);
    return;
  }
  if (stepFrame(p, 0) != SS_OK) return; /* looks at the world without stepping: what the frame made is found */
  int known = ssStepper_KnownBodyCount(p->stepper), reached = reachable(p);
  FUZZ_REQUIRE(known >= reached, "the stepper knows %d bodies, a plain walk of the graph reaches %d", known,
               reached);
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzInput in = {data, size};
  Program* p = &program;
  memset(p, 0, sizeof *p);
  p->world = dWorldCreate();
  dWorldSetGravity(p->world, 0, 0, -9.81);
  p->contacts = dJointGroupCreate(0);
  uint8_t layout = fuzz_byte(&in);
  makeSpace(p, layout % 3, -1);
  for (int s = 0; s < (layout >> 2) % 4; ++s) makeSpace(p, fuzz_byte(&in) % 13 == 0 ? KIND_QUADTREE : layout % 3,
                                                        fuzz_byte(&in) % p->space_count);
  for (int i = 0, boxes = 1 + fuzz_byte(&in) % 6; i < boxes; ++i) makeBox(p, i % p->space_count, 0.5 * i, 1);
  for (int i = 0, bobs = fuzz_byte(&in) % 3; i < bobs; ++i) makeBob(p, i % p->body_count);
  for (int i = 0, hinges = fuzz_byte(&in) % 3; i + 1 < p->body_count && i < hinges; ++i)
    makeHinge(p, p->bodies[i].body, p->bodies[i + 1].body, 0.3, 1e-4);

  ssStepperDef def = ssDefaultStepperDef();
  def.world = p->world;
  def.space = p->spaces[0];
  def.tuned_step_s = 1.0 / 60;
  def.stepping.solver = fuzz_byte(&in) % 2 ? SS_SOLVER_QUICK : SS_SOLVER_STEP;
  static const char* const policies[] = {"naive", "implicit-euler", "fixed", "exact"};
  ssSteppingForPolicy(policies[fuzz_byte(&in) % 4], 0, &def.stepping);
  def.before_step = beforeStep;
  def.before_step_context = p;
  def.collide = collide;
  def.collide_context = p;
  def.contact_group = p->contacts;
  ssStatus made = ssStepper_Create(&def, &p->stepper);
  checkStatus(made, "ssStepper_Create");
  FUZZ_REQUIRE(made == SS_OK || quadTreeAnywhere(p),
               "ssStepper_Create refused (%s) a world with nothing a spring cannot stand for", ssLastError());
  for (int op = 0; made == SS_OK && op < MAX_OPS && !fuzzEmpty(&in); ++op) {
    uint8_t code = fuzz_byte(&in);
    if (verbose) fprintf(stderr, "op %d: %d\n", op, code % 16);
    switch (code % 16) {
      case 12:
      case 13: /* a frame */
        checkFrame(p, kFrames[fuzz_byte(&in) % (sizeof kFrames / sizeof kFrames[0])]);
        break;
      case 14: /* arm an operation for a step of the next frame, then step it */
        p->armed = 1;
        p->armed_step = fuzz_byte(&in) % 3;
        p->armed_code = fuzz_byte(&in) % 10; /* no nesting inside a frame */
        for (size_t i = 0; i < sizeof p->armed_bytes; ++i) p->armed_bytes[i] = fuzz_byte(&in);
        checkFrame(p, 0.05);
        break;
      case 15: /* a reset, with the program's repair */
        repair(p);
        ssStepper_Reset(p->stepper);
        break;
      default: operate(p, code % 16, &in, 0);
    }
  }
  ssStepper_Destroy(p->stepper);
  dJointGroupDestroy(p->contacts);
  dSpaceDestroy(p->spaces[0]); /* every nested space and geom with it */
  dWorldDestroy(p->world);
  return 0;
}

int LLVMFuzzerInitialize(int* argc, char*** argv) {
  (void)argc, (void)argv;
  dInitODE2(0);
  verbose = getenv("FUZZ_VERBOSE") != NULL;
  return 0;
}

/* The stepper: a frame's time becomes physics steps, each with its softness rewritten for its length, the frame's
 * forces put back before each one, and the known bodies checked before and after it. A failure is latched: a broken
 * world is never stepped again until the program says it has repaired it. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "array.h"
#include "contact_memo.h"
#include "error.h"
#include "gears.h"
#include "interpolation_internal.h"
#include "known_bodies.h"
#include "ode_bounds.h"
#include "pointer_set.h"
#include "registry_internal.h"
#include "seen_spaces.h"
#include "steadystep/adopt.h"
#include "steadystep/stepper.h"


/* Frame times are sums of floating-point parts: a frame of exactly 2·max_step_s must not become 3 substeps. */
static const double kStepCountSlack = 1e-9;

struct ssStepper {
  ssStepperDef def;            /* def.registry: the registry in use, the given one or owned_registry */
  ssRegistry* owned_registry;  /* made for def.space when no registry was given */
  double tuned_step_s;         /* 0: none */
  ssAdoptReport adopted;       /* what adoption reached, summed */
  double previous_step_s; /* 0: no usable history */
  double time_s;          /* simulated since ssStepper_Create: every step taken, added in order */
  unsigned long row_order_seed; /* what ODE's generator is set to before each step (stepping.step_seed >= 0) */
  double accumulator_s;   /* FIXED: time not yet stepped */
  double short_frame_s;   /* other policies: frames too short to step, carried */
  dBodyID* watched;
  int watched_count, watched_capacity;
  unsigned watched_generation;
  ssKnownBodies known; /* kept as bodies come and go; rebuilt when the watch list or a known body's joints change */
  ssSeenSpaces seen;   /* def.space and the spaces nested in it, as last seen */
  ssBodyList found;    /* the last look's new bodies, and those refused before: adopted at the next look */
  ssBodyList moved;    /* sleeping bodies the program moved, seen at the last look: checked before collision */
  int apply_due;         /* bindings were added within the frame: the next step applies whatever the mapping */
  int adopt_known_due;   /* the known list was rebuilt: bodies on it the registry has not are adopted (adoptKnown) */
  int relist_due;        /* the known list is listed again at the next look, keeping what stays (joints changed) */
  /* a body was destroyed through the stepper after a joint of its was: no body left may show that joint's loss, so
   * the next look unbinds every bound joint attached to no known body (forgetDestroyed) */
  int lost_joints_due;
  int in_step;           /* inside ssStepper_Step: its callbacks are running */
  int destroy_requested; /* ssStepper_Destroy was called from a callback: done when ssStepper_Step returns */
  int rebase_gears;      /* ssStepper_Reset was called: the next frame has ODE measure its gears afresh (gears.h) */
  ssStepInfo current;
  ssContactCache contact_cache; /* a program softens many contacts with the same numbers */
  ssContactMemo contact_memo;   /* the last contact softened in this step, as given and as written */
  int contacts_outside_frames;  /* softened between frames: counted where no report reads them */
  ssFrameReport* report; /* the frame being stepped, for ssStepper_SoftenContact's counts */
  ssPoseHistory* poses;  /* SS_CUT_FIXED: the known bodies' last two states, to draw (interpolation.c) */
  /* the first failure, latched until ssStepper_Reset */
  ssStatus failed_status;
  char failed_message[256];
};

ssStepperDef ssDefaultStepperDef(void) {
  ssStepperDef def;
  memset(&def, 0, sizeof def);
  def.stepping = ssDefaultStepping();
  return def;
}

static ssStatus validateDef(const ssStepperDef* def) {
  if (def == NULL) return ssFail(SS_ERROR_OUT_OF_RANGE, "def = NULL: a definition is required");
  if (def->world == 0) return ssFail(SS_ERROR_OUT_OF_RANGE, "world = NULL: a world is required");
  if (def->registry != NULL && ssRegistryWorld(def->registry) != def->world)
    return ssFail(SS_ERROR_OUT_OF_RANGE, "registry of world %p: not def.world = %p",
                  (void*)ssRegistryWorld(def->registry), (void*)def->world);
  if (def->space != 0 && def->tuned_step_s == 0)
    return ssFail(SS_ERROR_OUT_OF_RANGE, "tuned_step_s = 0 s: with a space, say which step the program was tuned for");
  if (def->tuned_step_s != 0) {
    ssStatus status = ssCheckStepLength("tuned_step_s", def->tuned_step_s);
    if (status != SS_OK) return status;
  }
  return ssValidateStepping(&def->stepping);
}

/* stepping's max_step_s and fixed_step_s of 0, and a frozen step of SS_FROZEN_AT_TUNED_STEP, stand for the tuned
 * step; the one the cut uses must have one. A frozen step other than the tuned step is refused: the tuned numbers
 * mean their softness at that step alone. */
static ssStatus resolveSteps(ssStepping* stepping, double tuned_step_s) {
  if (stepping->max_step_s == 0) stepping->max_step_s = tuned_step_s;
  if (stepping->fixed_step_s == 0) stepping->fixed_step_s = tuned_step_s;
  if (stepping->frozen_step_s == SS_FROZEN_AT_TUNED_STEP) {
    if (tuned_step_s == 0)
      return ssFail(SS_ERROR_OUT_OF_RANGE, "stepping.frozen_step_s = the tuned step, but there is no tuned step: set "
                                           "def.tuned_step_s, adopt into the registry, or give the step to freeze at");
    stepping->frozen_step_s = tuned_step_s;
  }
  if (stepping->frozen_step_s > 0 && tuned_step_s > 0 && stepping->frozen_step_s != tuned_step_s)
    return ssFail(SS_ERROR_OUT_OF_RANGE, "stepping.frozen_step_s = %.17g s: not the tuned step %.17g s, which the "
                  "adopted numbers were tuned for (pass 0 or the tuned step to ssSteppingForPolicy)",
                  stepping->frozen_step_s, tuned_step_s);
  const char* missing = stepping->cut == SS_CUT_SUBSTEPS && stepping->max_step_s == 0  ? "max_step_s"
                        : stepping->cut == SS_CUT_FIXED && stepping->fixed_step_s == 0 ? "fixed_step_s"
                                                                                        : NULL;
  if (missing == NULL) return SS_OK;
  return ssFail(SS_ERROR_OUT_OF_RANGE,
                "stepping.%s = 0 s (the tuned step), but there is no tuned step: set def.tuned_step_s, adopt into "
                "the registry, or give stepping.%s",
                missing, missing);
}

/* The step length a step's softness is computed for: its own, or the frozen one. */
static double softnessStep(const ssStepping* stepping, double step_s) {
  return stepping->frozen_step_s > 0 ? stepping->frozen_step_s : step_s;
}

static void describeNextStep(ssStepper* stepper) {
  const ssStepping* stepping = &stepper->def.stepping;
  double step_s = stepping->cut == SS_CUT_FIXED ? stepping->fixed_step_s : stepping->max_step_s;
  if (step_s == 0) step_s = stepping->cut == SS_CUT_FIXED ? stepping->max_step_s : stepping->fixed_step_s;
  stepper->current = (ssStepInfo){stepping->mapping, step_s,           softnessStep(stepping, step_s),
                                   stepper->previous_step_s, 0, 1, stepper->time_s};
  stepper->contact_memo.stale = 1;
  stepper->contacts_outside_frames = 0; /* read by nobody: kept from growing without end */
}

/* A seed of its own for ODE's generator (splitmix64's finalizer): nearby seeds give unrelated row orders. */
static unsigned long rowOrderSeed(uint64_t step_seed) {
  uint64_t z = step_seed + 0x9e3779b97f4a7c15u;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
  return (unsigned long)((z ^ (z >> 31)) & 0xffffffffu); /* ODE's generator keeps 32 bits */
}

/* The speed guard: 0 stands for the bound ODE itself needs. */
static void resolveSpeeds(ssStepping* stepping) {
  if (stepping->max_speed == 0) stepping->max_speed = SS_MAX_SAFE_SPEED;
  if (stepping->max_angular_speed == 0) stepping->max_angular_speed = SS_MAX_SAFE_SPEED;
}

static int knownInStep(const ssStepper* stepper);
static void keepKnownInStep(ssStepper* stepper);
static ssStatus refreshKnown(ssStepper* stepper);
static int knownListDue(const ssStepper* stepper);

ssStatus ssStepper_Create(const ssStepperDef* def, ssStepper** out) {
  ssStatus status = ssCheckOdePrecision();
  if (status == SS_OK) status = validateDef(def);
  if (status != SS_OK) return status;
  if (out == NULL) return ssFail(SS_ERROR_OUT_OF_RANGE, "out = NULL: needs somewhere to write the stepper");
  double tuned_step_s = def->tuned_step_s != 0 ? def->tuned_step_s : ssRegistry_TunedStep(def->registry);
  ssStepping stepping = def->stepping;
  if ((status = resolveSteps(&stepping, tuned_step_s)) != SS_OK) return status;
  ssStepper* stepper = calloc(1, sizeof *stepper);
  if (stepper == NULL) return ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory creating a stepper");
  stepper->def = *def;
  stepper->def.stepping = stepping;
  stepper->tuned_step_s = tuned_step_s;
  if (def->space != 0) {
    ssRegistry* registry = def->registry;
    if (registry == NULL && (registry = stepper->owned_registry = ssRegistry_Create(def->world)) == NULL) {
      free(stepper);
      return ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory creating a stepper");
    }
    /* adopted, and the spaces listed as they are: what the program destroys from now on is told by the listing */
    ssBodyList gone = {NULL, 0, 0};
    if ((status = ssRegistry_Adopt(registry, tuned_step_s, def->space, &stepper->adopted)) != SS_OK ||
        (status = ssSeenList(&stepper->seen, def->space, &gone)) != SS_OK) {
      ssRegistry_Destroy(stepper->owned_registry);
      ssSeenFree(&stepper->seen);
      free(stepper);
      return status;
    }
    ssBodyListFree(&gone);
    stepper->def.registry = registry;
    stepper->seen.listed = 0; /* listed in full again at the first frame: a body adoption did not reach is adopted */
  }
  stepper->known.seen_space = def->space; /* a sleeping body moved there is seen by the looks */
  resolveSpeeds(&stepper->def.stepping);
  stepper->row_order_seed = rowOrderSeed(stepping.step_seed);
  stepper->contact_cache = ssContactCacheEmpty();
  describeNextStep(stepper);
  /* the known bodies and their joints listed now, while everything is alive: what the program destroys before the
   * first frame is then told from them (forgetDestroyed) */
  if ((status = refreshKnown(stepper)) != SS_OK) {
    ssStepper_Destroy(stepper);
    return status;
  }
  *out = stepper;
  return SS_OK;
}

static ssStatus forgetDestroyed(ssStepper* stepper, int look_at_joints);
static ssStatus followProgram(ssStepper* stepper, ssFrameReport* report, int every_value);

/* What the stepper adopted goes back to the program's own numbers at the tuned step (the ones it tuned, or wrote
 * since): the world is the program's again, and a stepper made on it next adopts what the program tuned, not what
 * this one last wrote for another step. What the program destroyed is forgotten first. Nothing when it adopted
 * nothing, or when a listing fails (a quadtree space). */
static void restoreTuned(ssStepper* stepper) {
  ssRegistry* registry = stepper->def.registry;
  if (stepper->def.space == 0 || registry == NULL || forgetDestroyed(stepper, 1) != SS_OK) return;
  /* and whatever the joints' signatures told: only joints attached to a body on the known list are written (the
   * list as it is, not built again: building it reads every bound joint) */
  ssPointerSet alive = {NULL, 0, 0};
  ssStatus listed = ssKnownCollectJoints(&stepper->known, &alive);
  if (listed == SS_OK) ssRegistryUnbindJointsNotIn(registry, &alive);
  ssPointerSetFree(&alive);
  if (listed != SS_OK) return;
  ssFrameReport unused = {0};
  /* a value no spring stands for is left as the program set it */
  if (followProgram(stepper, &unused, 1) != SS_OK) return;
  ssRegistry_Apply(registry, SS_MAPPING_IMPLICIT_EULER, stepper->tuned_step_s, 0, NULL);
}

void ssStepper_Destroy(ssStepper* stepper) {
  if (stepper == NULL) return;
  if (stepper->in_step) { /* from its own callback: the frame stops, and ssStepper_Step frees it on return */
    stepper->destroy_requested = 1;
    return;
  }
  restoreTuned(stepper);
  ssRegistry_Destroy(stepper->owned_registry);
  free(stepper->watched);
  ssKnownFree(&stepper->known);
  ssSeenFree(&stepper->seen);
  ssBodyListFree(&stepper->found);
  ssBodyListFree(&stepper->moved);
  ssPoseHistoryDestroy(stepper->poses);
  free(stepper);
}

#define REQUIRE_STEPPER(stepper) \
  if ((stepper) == NULL) return ssFail(SS_ERROR_OUT_OF_RANGE, "stepper = NULL: a stepper is required")

/* Functions that would step or reset the frame being stepped are refused inside it. */
#define REFUSE_IN_STEP(stepper, what)                                                                     \
  if ((stepper)->in_step)                                                                                 \
  return ssFail(SS_ERROR_REENTERED, "%s: called from a callback of the same stepper, inside its frame (%s)", \
                what, "call it between frames")

/* Whether the program watches body. */
static int watched(const ssStepper* stepper, dBodyID body) {
  for (int i = 0; i < stepper->watched_count; ++i)
    if (stepper->watched[i] == body) return 1;
  return 0;
}

/* A body the program destroyed with ODE's own calls (or that lost its geom in the adopted spaces, or that
 * the program destroys through the stepper): forgotten by the
 * known list, the watch list, the registry and the pose history, by its address alone. */
static void forgetBody(ssStepper* stepper, dBodyID body) {
  int was_watched = 0;
  for (int i = 0; i < stepper->watched_count; ++i) {
    if (stepper->watched[i] != body) continue;
    stepper->watched[i--] = stepper->watched[--stepper->watched_count];
    was_watched = 1;
  }
  ssRegistry* registry = stepper->def.registry;
  int in_step = knownInStep(stepper);
  if (registry != NULL && ssRegistryHasBody(registry, body)) ssRegistry_UnbindBody(registry, body);
  /* the known list follows at the cost of the change; a body joined to others may leave some known only through it,
   * so the list is built again then (and after a watch, which the list does not follow) */
  int joined = ssKnownJoined(&stepper->known, body);
  ssKnownForget(&stepper->known, body);
  if (in_step && !joined && !was_watched) keepKnownInStep(stepper);
  else if (was_watched) stepper->watched_generation += 1;
  else stepper->relist_due = 1;
  for (int i = 0; i < stepper->found.count; ++i)
    if (stepper->found.list[i] == body) stepper->found.list[i--] = stepper->found.list[--stepper->found.count];
  ssPoseHistoryForgetBody(stepper->poses, body);
}

ssStatus ssStepper_WatchBody(ssStepper* stepper, dBodyID body) {
  REQUIRE_STEPPER(stepper);
  if (body == 0) return ssFail(SS_ERROR_OUT_OF_RANGE, "body = NULL: a body is required");
  if (dBodyGetWorld(body) != stepper->def.world)
    return ssFail(SS_ERROR_OUT_OF_RANGE, "body %p: of another world (%p), not the stepper's (%p)", (void*)body,
                  (void*)dBodyGetWorld(body), (void*)stepper->def.world);
  if (watched(stepper, body)) return SS_OK;
  if (!ssReserveOne((void**)&stepper->watched, stepper->watched_count, &stepper->watched_capacity, sizeof body))
    return ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory watching a body");
  stepper->watched[stepper->watched_count++] = body;
  stepper->watched_generation += 1;
  return SS_OK;
}

/* Whether a body would stay known without its watch: bound in the registry, or joined (not by a contact) to
 * another body. */
static int bodyKnownOtherwise(const ssStepper* stepper, dBodyID body) {
  if (stepper->def.registry != NULL && ssRegistryHasBody(stepper->def.registry, body)) return 1;
  for (int i = 0, count = dBodyGetNumJoints(body); i < count; ++i)
    if (dJointGetType(dBodyGetJoint(body, i)) != dJointTypeContact) return 1;
  return 0;
}

ssStatus ssStepper_UnwatchBody(ssStepper* stepper, dBodyID body) {
  REQUIRE_STEPPER(stepper);
  if (body == 0) return ssFail(SS_ERROR_OUT_OF_RANGE, "body = NULL: a body is required");
  for (int i = 0; i < stepper->watched_count; ++i) {
    if (stepper->watched[i] != body) continue;
    stepper->watched[i] = stepper->watched[--stepper->watched_count];
    stepper->watched_generation += 1;
    /* the program may destroy it next, in a callback too: a body known through the watch alone leaves the known
     * list and the pose history now. One bound or joined to others stays listed (the list must hold every body whose
     * joints tell what the program destroyed); the pose history starts it again at the next frame. */
    if (!bodyKnownOtherwise(stepper, body)) ssKnownForget(&stepper->known, body);
    ssPoseHistoryForgetBody(stepper->poses, body);
    return SS_OK;
  }
  return ssFail(SS_ERROR_NOT_FOUND, "body %p: not watched", (void*)body);
}

ssStatus ssStepper_DestroyBody(ssStepper* stepper, dBodyID body) {
  REQUIRE_STEPPER(stepper);
  if (body == 0) return ssFail(SS_ERROR_OUT_OF_RANGE, "body = NULL: a body is required");
  ssRegistry* registry = stepper->def.registry;
  if (ssKnownJointsChangedOf(&stepper->known, body)) stepper->lost_joints_due = 1;
  /* ODE leaves the body's joints detached on one side, where some of its getters assert: they are unbound */
  for (int i = registry != NULL ? dBodyGetNumJoints(body) - 1 : -1; i >= 0; --i) {
    dJointID joint = dBodyGetJoint(body, i);
    if (ssRegistryHasJoint(registry, joint)) ssRegistry_UnbindJoint(registry, joint);
  }
  forgetBody(stepper, body); /* at once: inside a frame, the next check must not read it */
  ssSeenForget(&stepper->seen, body); /* its geoms leave the spaces' count, destroyed before or after */
  dBodyDestroy(body);
  return SS_OK;
}

ssStatus ssStepper_DestroyJoint(ssStepper* stepper, dJointID joint) {
  REQUIRE_STEPPER(stepper);
  if (joint == 0) return ssFail(SS_ERROR_OUT_OF_RANGE, "joint = NULL: a joint is required");
  ssRegistry* registry = stepper->def.registry;
  if (registry != NULL && ssRegistryHasJoint(registry, joint)) ssRegistry_UnbindJoint(registry, joint);
  stepper->watched_generation += 1; /* what the joint reached may be known no longer */
  dJointDestroy(joint);
  return SS_OK;
}

static void forgetCarried(ssStepper* stepper) {
  for (int i = 0; i < stepper->known.count; ++i)
    memset(stepper->known.bodies[i].carried_force, 0, sizeof stepper->known.bodies[i].carried_force);
  stepper->known.carrying = 0;
}

void ssStepper_ResetHistory(ssStepper* stepper) {
  if (stepper != NULL) stepper->previous_step_s = 0;
}

void ssStepper_Reset(ssStepper* stepper) {
  if (stepper == NULL) return;
  if (stepper->in_step) {
    ssFail(SS_ERROR_REENTERED, "ssStepper_Reset: called from a callback of the same stepper, inside its frame "
                               "(call it between frames)");
    return;
  }
  stepper->failed_status = SS_OK;
  stepper->failed_message[0] = '\0';
  stepper->previous_step_s = 0;
  stepper->accumulator_s = 0;
  stepper->short_frame_s = 0;
  stepper->rebase_gears = 1;
  forgetCarried(stepper);
  ssPoseHistoryForget(stepper->poses);
  describeNextStep(stepper);
}

ssStatus ssStepper_SetStepping(ssStepper* stepper, const ssStepping* stepping) {
  REQUIRE_STEPPER(stepper);
  REFUSE_IN_STEP(stepper, "ssStepper_SetStepping");
  ssStatus status = ssValidateStepping(stepping);
  if (status != SS_OK) return status;
  ssStepping resolved = *stepping;
  if ((status = resolveSteps(&resolved, stepper->tuned_step_s)) != SS_OK) return status;
  stepper->def.stepping = resolved;
  resolveSpeeds(&stepper->def.stepping);
  stepper->row_order_seed = rowOrderSeed(resolved.step_seed);
  stepper->previous_step_s = 0;
  stepper->accumulator_s = 0;
  stepper->short_frame_s = 0;
  forgetCarried(stepper);
  ssPoseHistoryForget(stepper->poses);
  describeNextStep(stepper);
  return SS_OK;
}

ssPoseHistory** ssStepperPoseSlot(ssStepper* stepper) { return &stepper->poses; }

ssStepping ssStepper_Stepping(const ssStepper* stepper) {
  if (stepper != NULL) return stepper->def.stepping;
  ssFail(SS_ERROR_OUT_OF_RANGE, "stepper = NULL: a stepper is required");
  return ssDefaultStepping();
}

ssStepInfo ssStepper_CurrentStep(const ssStepper* stepper) {
  if (stepper != NULL) return stepper->current;
  ssFail(SS_ERROR_OUT_OF_RANGE, "stepper = NULL: a stepper is required");
  return (ssStepInfo){SS_MAPPING_IMPLICIT_EULER, 0, 0, 0, 0, 0, 0};
}

/* Where a contact served as handed_on says is counted: the frame report's (a contact is never handed to matched),
 * or, outside a frame, a count nobody reads. */
static int* contactCounter(ssStepper* stepper, ssRowFallback handed_on) {
  if (stepper->report == NULL) return &stepper->contacts_outside_frames;
  ssServedCounts* contacts = &stepper->report->contacts;
  return handed_on.to_implicit_euler ? &contacts->handed_to_implicit_euler : &contacts->by_mapping;
}

/* Kept out of line: the usual contact's path then needs no frame of its own. */
#if defined(__GNUC__)
#define SS_OUT_OF_LINE __attribute__((noinline, cold))
#else
#define SS_OUT_OF_LINE
#endif

/* A contact not like the last one: softened by its law (contact.c) and remembered, not counted. */
static SS_OUT_OF_LINE ssStatus softenNewContact(ssStepper* stepper, dContact* contact) {
  double tuned_step_s = ssRegistry_TunedStep(stepper->def.registry);
  if (tuned_step_s == 0)
    return ssFail(SS_ERROR_OUT_OF_RANGE, "tuned step = 0 s: adopt the world first (ssRegistry_Adopt), or soften "
                                         "with a spring of your own (ssContactSoften)");
  dSurfaceParameters* surface = &contact->surface;
  const dSurfaceParameters given = *surface;
  ssSoftness world = ssRegistryTunedWorld(stepper->def.registry);
  ssRowFallback handed_on = {0, 0};
  double erp = (surface->mode & dContactSoftERP) ? surface->soft_erp : world.erp;
  double cfm = (surface->mode & dContactSoftCFM) ? surface->soft_cfm : world.cfm;
  const ssStepInfo* step = &stepper->current;
  ssStatus status = ssContactSoftenCached(&stepper->contact_cache, contact, erp, cfm, tuned_step_s, step->mapping,
                                          step->softness_step_s, &handed_on);
  if (status != SS_OK) return status;
  ssContactMemoTake(&stepper->contact_memo, &given, surface, contactCounter(stepper, handed_on));
  return SS_OK;
}

/* One contact, as the last one or by its law; the memo then describes it (and its count). */
static ssStatus softenOne(ssStepper* stepper, dContact* contact) {
  if (!ssContactMemoFitsOne(&stepper->contact_memo, contact)) return softenNewContact(stepper, contact);
  ssContactMemoWrite(&stepper->contact_memo, contact, 1);
  return SS_OK;
}

/* One contact softened and counted. */
static ssStatus softenCounted(ssStepper* stepper, dContact* contact) {
  ssStatus status = softenOne(stepper, contact);
  if (status == SS_OK) *stepper->contact_memo.counter += 1;
  return status;
}

static SS_OUT_OF_LINE ssStatus softenContactSlowly(ssStepper* stepper, dContact* contact) {
  REQUIRE_STEPPER(stepper);
  if (contact == NULL) return ssFail(SS_ERROR_OUT_OF_RANGE, "contact = NULL: a contact is required");
  return softenCounted(stepper, contact);
}

ssStatus ssStepper_SoftenContact(ssStepper* stepper, dContact* contact, dBodyID body1, dBodyID body2) {
  (void)body1, (void)body2; /* no contact's softness depends on its bodies (contact.c) */
  if (stepper == NULL || contact == NULL || !ssContactMemoFitsOne(&stepper->contact_memo, contact))
    return softenContactSlowly(stepper, contact);
  ssContactMemoWrite(&stepper->contact_memo, contact, 1);
  *stepper->contact_memo.counter += 1;
  return SS_OK;
}

/* A batch not every contact of which is like the last one: each checked on a copy first, so that an error leaves
 * every contact as given, then softened. */
static SS_OUT_OF_LINE ssStatus softenContactsSlowly(ssStepper* stepper, dContact* contacts, int count) {
  REQUIRE_STEPPER(stepper);
  if (count < 0) return ssFail(SS_ERROR_OUT_OF_RANGE, "count = %d contacts: must not be negative", count);
  if (count > 0 && contacts == NULL)
    return ssFail(SS_ERROR_OUT_OF_RANGE, "contacts = NULL with count = %d: the contacts are required", count);
  for (int i = 0; i < count; ++i) {
    dContact copy = contacts[i];
    ssStatus status = softenOne(stepper, &copy);
    if (status != SS_OK) return status;
  }
  for (int i = 0; i < count; ++i) softenCounted(stepper, &contacts[i]); /* as checked: cannot fail */
  return SS_OK;
}

ssStatus ssStepper_SoftenContacts(ssStepper* stepper, dContact* contacts, int count) {
  if (stepper == NULL || count <= 0 || contacts == NULL || !ssContactMemoFits(&stepper->contact_memo, contacts, count))
    return count == 0 && stepper != NULL ? SS_OK : softenContactsSlowly(stepper, contacts, count);
  ssContactMemoWrite(&stepper->contact_memo, contacts, count);
  *stepper->contact_memo.counter += count;
  return SS_OK;
}

/* ---- the bodies the stepper knows ---- */

/* Whether the known list is to be built again (refreshKnown): the registry's bindings or the watch list changed
 * since it was built (and it did not follow), or a body's joints did. Building it reads every bound joint: what the
 * program destroyed is forgotten first (forgetDestroyed). */
static int knownListDue(const ssStepper* stepper) {
  const ssRegistry* registry = stepper->def.registry;
  unsigned generation = registry != NULL ? ssRegistryGeneration(registry) : 0;
  const ssKnownBodies* known = &stepper->known;
  return !known->valid || stepper->relist_due || known->registry_generation != generation ||
         known->watched_generation != stepper->watched_generation;
}

/* Whether the known list holds what the registry and the watch list reach now: a change the list then follows
 * itself (ssKnownAdd, ssKnownForget) keeps it so (keepKnownInStep). */
static int knownInStep(const ssStepper* stepper) { return !knownListDue(stepper); }

static void keepKnownInStep(ssStepper* stepper) {
  const ssRegistry* registry = stepper->def.registry;
  stepper->known.registry_generation = registry != NULL ? ssRegistryGeneration(registry) : 0;
}

/* The known list, built again when it is due (knownListDue). */
static ssStatus refreshKnown(ssStepper* stepper) {
  const ssRegistry* registry = stepper->def.registry;
  unsigned generation = registry != NULL ? ssRegistryGeneration(registry) : 0;
  ssKnownBodies* known = &stepper->known;
  if (!knownListDue(stepper)) return SS_OK;
  stepper->relist_due = 0;
  ssStatus status = ssKnownRebuild(known, registry, stepper->watched, stepper->watched_count);
  if (status != SS_OK) return status;
  known->registry_generation = generation;
  known->watched_generation = stepper->watched_generation;
  /* the list may now reach, through a joint, a body made since: one the stepper adopts before it steps (findNew) */
  stepper->adopt_known_due = stepper->def.space != 0;
  return SS_OK;
}

/* Adopts body and what it reaches, when the stepper adopts (def.space); otherwise the known list reaches it through
 * its joints when rebuilt. A list in step with the registry follows at the cost of what was adopted. */
static ssStatus adoptBody(ssStepper* stepper, dBodyID body) {
  if (stepper->def.space == 0) return SS_OK;
  int in_step = knownInStep(stepper);
  ssStatus status = ssRegistry_AdoptBody(stepper->def.registry, body, &stepper->adopted);
  if (status != SS_OK) return status;
  stepper->apply_due = 1;
  if (in_step && (status = ssKnownAdd(&stepper->known, body)) == SS_OK) keepKnownInStep(stepper);
  return status;
}

/* With def.space: adopts every known body that the registry has not (one reached through a joint made since), with
 * its joints, so that no body joined to the adopted ones steps with the softness the program tuned for one step.
 * Watched bodies are the program's to adopt or not (ssRegistry_AdoptBody): unwatched, they are known no more. */
static ssStatus adoptKnown(ssStepper* stepper) {
  stepper->adopt_known_due = 0;
  ssStatus status = SS_OK;
  int adopted = 0;
  for (int k = 0; k < stepper->known.count && status == SS_OK; ++k) {
    dBodyID body = stepper->known.ids[k];
    if (ssRegistryHasBody(stepper->def.registry, body) || watched(stepper, body)) continue;
    status = adoptBody(stepper, body);
    adopted = 1;
  }
  if (status != SS_OK) stepper->adopt_known_due = 1; /* refused: again at the next look, until repaired */
  return status == SS_OK && adopted ? refreshKnown(stepper) : status;
}

/* Lists the adopted spaces in full: the bodies that held a geom there and hold none now were destroyed with their
 * geoms (or lost them) and are forgotten; the bodies there the registry has not are found. */
static ssStatus listSpaces(ssStepper* stepper) {
  ssBodyList gone = {NULL, 0, 0};
  ssStatus status = ssSeenList(&stepper->seen, stepper->def.space, &gone);
  for (int i = 0; status == SS_OK && i < gone.count; ++i) forgetBody(stepper, gone.list[i]);
  ssBodyListFree(&gone);
  stepper->found.count = stepper->moved.count = 0;
  ssKnownCheckAllOnce(&stepper->known); /* a sleeping body moved is not told from the others */
  const ssPointerMap* held = &stepper->seen.bodies;
  for (size_t i = 0; status == SS_OK && i < held->capacity; ++i) {
    dBodyID body = (dBodyID)held->keys[i];
    if (body == 0 || ssRegistryHasBody(stepper->def.registry, body)) continue;
    if (!ssBodyListPush(&stepper->found, body))
      status = ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory listing the adopted spaces' bodies");
  }
  return status;
}

/* What the program made, moved or destroyed with ODE's own calls since the last look, found by reading only what is
 * alive:
 *  - in the adopted spaces (alive while def.space is): the bodies of new geoms are found (adopted by findNew), the
 *    sleeping bodies the program moved are kept for the checks, and when the spaces' count tells that a geom was
 *    destroyed the spaces are listed in full (listSpaces);
 *  - from the known bodies (alive, since a body with a geom was checked above and one without must be destroyed
 *    with ssStepper_DestroyBody), when their joints changed or a body was forgotten: a bound joint attached to no
 *    known body any more was destroyed (or detached from all), and is unbound without being read. */
static ssStatus forgetDestroyed(ssStepper* stepper, int look_at_joints) {
  int forgot = 0;
  if (stepper->def.space != 0) {
    int known_before = stepper->known.count;
    int looked = ssSeenLook(&stepper->seen, &stepper->found, &stepper->moved);
    if (looked < 0) return ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory looking at the adopted spaces");
    if (looked == 0) {
      ssStatus status = listSpaces(stepper);
      if (status != SS_OK) return status;
    }
    forgot = stepper->known.count < known_before;
  }
  ssRegistry* registry = stepper->def.registry;
  if (registry == NULL || !(forgot || stepper->lost_joints_due ||
                            ((look_at_joints || knownListDue(stepper)) && ssKnownJointsChanged(&stepper->known, NULL))))
    return SS_OK;
  ssPointerSet alive = {NULL, 0, 0};
  ssStatus status = ssKnownCollectJoints(&stepper->known, &alive);
  if (status == SS_OK && ssRegistryUnbindJointsNotIn(registry, &alive) > 0) stepper->apply_due = 1;
  if (status == SS_OK) stepper->lost_joints_due = 0;
  ssPointerSetFree(&alive);
  return status;
}

/* Adopts the bodies found in the adopted spaces that the registry has not (a box spawned after the stepper was made),
 * with what their joints reach. One refused stays found, and is refused again at the next look until repaired. */
static ssStatus adoptFound(ssStepper* stepper) {
  ssStatus status = SS_OK;
  int kept = 0;
  for (int i = 0; i < stepper->found.count; ++i) {
    dBodyID body = stepper->found.list[i];
    if (status == SS_OK && !ssRegistryHasBody(stepper->def.registry, body)) status = adoptBody(stepper, body);
    if (status != SS_OK) stepper->found.list[kept++] = body;
  }
  stepper->found.count = kept;
  return status;
}

/* Finds what was made since the last look, and forgets what was destroyed, before a step: bodies in the adopted
 * spaces, and with look_at_joints the joints attached to known bodies (and the bodies beyond them). */
static ssStatus findNew(ssStepper* stepper, int look_at_joints) {
  ssStatus status = forgetDestroyed(stepper, look_at_joints);
  if (status == SS_OK) status = refreshKnown(stepper);
  if (status == SS_OK && stepper->found.count > 0) status = adoptFound(stepper);
  if (status == SS_OK) status = refreshKnown(stepper);
  if (status == SS_OK && stepper->adopt_known_due) status = adoptKnown(stepper);
  dBodyID changed;
  /* a body whose joints changed: what they reach adopted, then its joints taken as they are (a refusal leaves the
   * change seen, so the next look refuses again until the program repairs it) */
  while (status == SS_OK && look_at_joints && ssKnownJointsChanged(&stepper->known, &changed)) {
    status = adoptBody(stepper, changed);
    stepper->relist_due = 1; /* listed again with what its joints reach now */
    if (status == SS_OK) status = refreshKnown(stepper);
    if (status == SS_OK) ssKnownTakeJointsOf(&stepper->known, changed);
  }
  return status;
}

/* ---- the frame's forces: held from one frame to the next (zero-order hold) ----
 * A force the program adds once a frame is its input for that frame's time, as any input sampled once a frame: it
 * acts at every step until the next frame's forces replace it. The time carried into a frame (FIXED's accumulator,
 * a frame too short to step) belongs to the frames before, so the step that covers it gets their force for that
 * share of its length: F·dt is exact over the run under every cut, and a force that does not change acts as itself,
 * to the bit, at every step. */

/* a + (b - a)·w, and exactly b when w is 1 or b equals a. */
static double blend(double a, double b, double w) { return w >= 1 || a == b ? b : a + (b - a) * w; }

/* Before the frame's step `index` of step_s: each pushed body gets its frame force; the first step, which covers
 * carried_s of the frames before, gets the carried force for that share. The first step of a frame with nothing
 * carried leaves the accumulators as the program set them (a naive stepper is its own stepping bit for bit). */
static void putForces(ssStepper* stepper, int index, double step_s, double carried_s) {
  if (index == 0 && carried_s == 0) return;
  double carried_share = index == 0 ? carried_s / step_s : 0;
  for (int p = 0; p < stepper->known.pushed_count; ++p) {
    ssKnownBody* known = &stepper->known.bodies[stepper->known.pushed[p]];
    double f[6];
    for (int j = 0; j < 6; ++j) f[j] = blend(known->frame_force[j], known->carried_force[j], carried_share);
    dBodySetForce(known->body, f[0], f[1], f[2]);
    dBodySetTorque(known->body, f[3], f[4], f[5]);
  }
}

/* A frame that takes no step: its time joins the carried time, and its force the carried force (their mean, by
 * time), and the accumulators are emptied so that the program's next additions are not counted twice. */
static void carryForces(ssStepper* stepper, double carried_s, double frame_s) {
  double share = carried_s + frame_s > 0 ? frame_s / (carried_s + frame_s) : 0;
  for (int p = 0; p < stepper->known.pushed_count; ++p) {
    ssKnownBody* known = &stepper->known.bodies[stepper->known.pushed[p]];
    for (int j = 0; j < 6; ++j) known->carried_force[j] = blend(known->carried_force[j], known->frame_force[j], share);
    stepper->known.carrying = 1;
    dBodySetForce(known->body, 0, 0, 0);
    dBodySetTorque(known->body, 0, 0, 0);
  }
}

/* After a frame's steps: the time it leaves unstepped (remaining_s) carries its force; every body that carried a
 * force was pushed (ssKnownStartFrame), so no other body carries one. */
static void holdForces(ssStepper* stepper, double remaining_s) {
  for (int p = 0; p < stepper->known.pushed_count; ++p) {
    ssKnownBody* known = &stepper->known.bodies[stepper->known.pushed[p]];
    if (remaining_s > 0) memcpy(known->carried_force, known->frame_force, sizeof known->carried_force);
    else memset(known->carried_force, 0, sizeof known->carried_force);
  }
  stepper->known.carrying = remaining_s > 0 && stepper->known.pushed_count > 0;
}

/* ---- the program's own writes ---- */

/* Values the program wrote into what the registry rewrites (registry_internal.h, ssRegistryFollowProgram), taken as
 * newly tuned; the next step applies whatever the mapping. The bodies' numbers are read unless every step's are
 * written for the tuned step (naive's softness, frozen there: a program's write then stays as written, and is
 * followed when the stepping changes, before Apply writes for another step). */
static ssStatus followProgram(ssStepper* stepper, ssFrameReport* report, int every_value) {
  if (stepper->def.registry == NULL) return SS_OK;
  int followed = 0;
  const ssStepping* stepping = &stepper->def.stepping;
  int bodies = every_value || stepping->frozen_step_s <= 0 ||
               stepping->frozen_step_s != ssRegistry_TunedStep(stepper->def.registry);
  ssStatus status = ssRegistryFollowProgram(stepper->def.registry, bodies, &followed);
  report->program_writes += followed;
  if (followed > 0) stepper->apply_due = 1;
  return status;
}

/* ---- the checks at the boundary ---- */

static ssStatus latch(ssStepper* stepper, ssStatus status) {
  stepper->failed_status = status;
  snprintf(stepper->failed_message, sizeof stepper->failed_message, "%s", ssLastError());
  stepper->previous_step_s = 0;
  return status;
}

/* Every known body ODE steps: its state and forces (as asked) within limits.h and the stepping's speeds. only_stepped:
 * nothing but ODE's step ran since the last check, and the bodies it stepped are read, no sleeping one. */
static ssStatus checkKnown(ssStepper* stepper, int forces, int only_stepped, const char* when, int index, int steps,
                           double step_s, ssFrameReport* report) {
  const ssStepping* stepping = &stepper->def.stepping;
  ssBodyBounds bounds = {stepping->max_speed, stepping->max_angular_speed, forces, step_s};
  dBodyID failed = 0;
  ssStatus status = ssKnownCheck(&stepper->known, &bounds, when, index + 1, steps, stepper->moved.list,
                                 stepper->moved.count, only_stepped, &failed);
  if (status != SS_OK) report->failed_body = failed;
  return status;
}

/* Before ODE's step, with its forces in the accumulators: the geared bodies' turn (ssKnownCheckGearsInStep). */
static ssStatus checkGearsInStep(ssStepper* stepper, double step_s, int index, int steps, ssFrameReport* report) {
  dBodyID failed = 0;
  ssStatus status = ssKnownCheckGearsInStep(&stepper->known, step_s, index + 1, steps, &failed);
  if (status != SS_OK) report->failed_body = failed;
  return status;
}

/* The registry's Apply for a step; *applied says who served the rows (counted for every step they serve). */
static ssStatus apply(ssStepper* stepper, ssMapping mapping, double step_s, double previous_step_s,
                      ssApplyReport* applied, ssFrameReport* report) {
  *applied = (ssApplyReport){{0, 0, 0}, 0};
  if (stepper->def.registry == NULL) return SS_OK;
  ssStatus status = ssRegistry_Apply(stepper->def.registry, mapping, step_s, previous_step_s, applied);
  if (status != SS_OK) return status;
  report->row_writes += applied->row_writes;
  return SS_OK;
}

static void addServed(ssServedCounts* sum, const ssServedCounts* counts) {
  sum->by_mapping += counts->by_mapping;
  sum->handed_to_matched += counts->handed_to_matched;
  sum->handed_to_implicit_euler += counts->handed_to_implicit_euler;
}

/* A step refused at the boundary: nothing was stepped, and the world is left as it was before the step (the
 * contacts made for it removed, the known bodies' accumulators as the program left them for the frame, or empty
 * after an earlier step). */
static ssStatus refuseStep(ssStepper* stepper, ssStatus status, int index) {
  if (stepper->def.contact_group) dJointGroupEmpty(stepper->def.contact_group);
  ssKnownResetAccumulators(&stepper->known, index == 0);
  return latch(stepper, status);
}

static int softenedContacts(const ssFrameReport* report) {
  const ssServedCounts* c = &report->contacts;
  return c->by_mapping + c->handed_to_matched + c->handed_to_implicit_euler;
}

/* Whether a contact joint is attached to a known body (ODE puts a new joint at the head of its body's list): asked
 * only of a step whose collision softened nothing, to tell a program that forgot ssStepper_SoftenContact. */
static int knownBodyTouches(const ssStepper* stepper) {
  for (int k = 0; k < stepper->known.count; ++k) {
    dJointID first = dBodyGetJoint(stepper->known.ids[k], 0);
    if (first != 0 && dJointGetType(first) == dJointTypeContact) return 1;
  }
  return 0;
}

/* The damping and auto-disable of the bodies that woke since the last step, for this step: Apply wrote every awake
 * body, and leaves a sleeping one as the program set it until it wakes (ssRegistryWriteBodies). What the program set
 * while one slept is followed first. A body ODE woke through a joint in its step is written before the next one.
 * Errors, with the woken bodies kept for the next try: those of ssRegistryFollowWoken. */
static ssStatus writeWoken(ssStepper* stepper, double softness_step_s, ssFrameReport* report) {
  int count, followed = 0;
  const dBodyID* woken = ssKnownTakeWoken(&stepper->known, &count);
  if (count == 0 || stepper->def.registry == NULL) return SS_OK;
  ssStatus status = ssRegistryFollowWoken(stepper->def.registry, woken, count, &followed);
  if (status != SS_OK) {
    stepper->known.woken_count = count; /* taken back: the list is as it was */
    return status;
  }
  report->program_writes += followed;
  ssRegistryWriteWoken(stepper->def.registry, woken, count, softness_step_s);
  return SS_OK;
}

/* ODE's step, with its generator set to the stepping's seed for it and put back after it (stepping.step_seed). */
static int odeStep(ssStepper* stepper, double step_s) {
  const ssStepping* stepping = &stepper->def.stepping;
  dWorldID world = stepper->def.world;
  if (stepping->step_seed < 0)
    return stepping->solver == SS_SOLVER_STEP ? dWorldStep(world, step_s) : dWorldQuickStep(world, step_s);
  unsigned long program_seed = dRandGetSeed();
  uint64_t time_bits;
  memcpy(&time_bits, &stepper->time_s, sizeof time_bits);
  dRandSetSeed(rowOrderSeed(stepper->row_order_seed ^ time_bits));
  int stepped = stepping->solver == SS_SOLVER_STEP ? dWorldStep(world, step_s) : dWorldQuickStep(world, step_s);
  dRandSetSeed(program_seed);
  return stepped;
}

/* Takes a frame's `steps` steps of step_s: everything else about them (mapping, the softness' step, history)
 * follows from the stepping. carried_s is the time of earlier frames the first step covers (putForces). Errors of
 * Apply leave the world as the previous step left it; a failed check latches. */
static ssStatus takeSteps(ssStepper* stepper, int steps, double step_s, double carried_s, ssFrameReport* report) {
  const ssStepperDef* def = &stepper->def;
  const ssStepping* stepping = &def->stepping;
  ssMapping mapping = stepping->mapping;
  double softness_step_s = softnessStep(stepping, step_s);
  /* implicit Euler depends on h alone, equal for all the frame's steps; the accurate mappings on the bodies too */
  int apply_every_step = mapping != SS_MAPPING_IMPLICIT_EULER;
  int use_history = mapping == SS_MAPPING_EXACT && stepping->frozen_step_s == 0;
  if (stepping->quick_iterations > 0) dWorldSetQuickStepNumIterations(def->world, stepping->quick_iterations);
  ssApplyReport applied;
  for (int i = 0; i < steps; ++i) {
    double previous_step_s = use_history ? stepper->previous_step_s : 0;
    /* what the last step's callbacks made or destroyed (joints too, where there are callbacks, or where the last
     * check woke a body with a joint attached while it slept) */
    int callbacks = def->before_step || def->collide || def->step_done;
    int joints_due = ssKnownTakeJointsDue(&stepper->known);
    ssStatus status = i == 0 ? SS_OK : findNew(stepper, callbacks || joints_due);
    /* values the program set in the last step's callbacks */
    if (status == SS_OK && i > 0 && callbacks) status = followProgram(stepper, report, 0);
    if (status != SS_OK) return status;
    putForces(stepper, i, step_s, carried_s);
    if (i == 0 || apply_every_step || stepper->apply_due) {
      stepper->apply_due = 0;
      if ((status = apply(stepper, mapping, softness_step_s, previous_step_s, &applied, report)) != SS_OK)
        return status;
    }
    stepper->current = (ssStepInfo){mapping, step_s, softness_step_s, previous_step_s, i, steps, stepper->time_s};
    stepper->contact_memo.stale = 1;
    if (def->before_step) def->before_step(def->before_step_context, stepper);
    /* what before_step destroyed with ODE's own calls is forgotten before anything reads it */
    if (def->before_step && !stepper->destroy_requested && (status = forgetDestroyed(stepper, 1)) != SS_OK)
      return refuseStep(stepper, status, i);
    /* the boundary before collision: a state before_step (or the last step's step_done) set reaches the program's
     * dSpaceCollide next, and a position far out of range aborts ODE's spaces there (forces wait for the check
     * before the step: collision reads none) */
    int acted = def->before_step || (i > 0 && def->step_done);
    if (acted && def->collide && !stepper->destroy_requested &&
        ((status = refreshKnown(stepper)) != SS_OK ||
         (status = checkKnown(stepper, 0, 0, "before the collision of", i, steps, step_s, report)) != SS_OK))
      return refuseStep(stepper, status, i);
    if (!stepper->destroy_requested && def->collide) {
      int softened_before = softenedContacts(report);
      def->collide(def->collide_context, stepper);
      if (def->space != 0 && def->contact_group != 0 && softenedContacts(report) == softened_before &&
          knownBodyTouches(stepper))
        report->unsoftened_contact_steps += 1;
    }
    if (stepper->destroy_requested) { /* the frame stops here: this step is not taken */
      if (def->contact_group) dJointGroupEmpty(def->contact_group);
      return SS_OK;
    }
    /* the boundary: whatever the program or its callbacks did, ODE gets a state and forces it can step. Without
     * callbacks only the stepper wrote since the last check (after the last step, or before the frame): the
     * frame's checked forces spread over its steps, and load corrections within SS_MAX_FORCE_N. step_done ran
     * after the last step's check */
    if ((acted || def->collide) &&
        ((status = refreshKnown(stepper)) != SS_OK || /* what the callbacks bound or watched */
         (status = checkKnown(stepper, 1, 0, "before", i, steps, step_s, report)) != SS_OK))
      return refuseStep(stepper, status, i);
    /* the check woke a body with a joint attached while it slept: the joint and what it reaches are adopted and
     * written for this step, which is the first ODE steps them in, and checked */
    if (ssKnownTakeJointsDue(&stepper->known)) {
      if ((status = findNew(stepper, 1)) == SS_OK && stepper->apply_due) {
        stepper->apply_due = 0;
        status = apply(stepper, mapping, softness_step_s, previous_step_s, &applied, report);
      }
      if (status == SS_OK) status = checkKnown(stepper, 1, 0, "before", i, steps, step_s, report);
      if (status != SS_OK) return refuseStep(stepper, status, i);
    }
    if (i == steps - 1 && stepping->cut == SS_CUT_FIXED) ssPoseHistoryBeforeLastStep(stepper->poses);
    if ((status = checkGearsInStep(stepper, step_s, i, steps, report)) != SS_OK ||
        (status = writeWoken(stepper, softness_step_s, report)) != SS_OK)
      return refuseStep(stepper, status, i);
    int stepped = odeStep(stepper, step_s);
    if (def->contact_group) dJointGroupEmpty(def->contact_group);
    /* what the program adds or moves next lands before the spaces' first geoms now */
    ssSeenMark(&stepper->seen);
    if (!stepped) return latch(stepper, ssFail(SS_ERROR_OUT_OF_MEMORY, "ODE ran out of memory in its step"));
    report->steps += 1;
    addServed(&report->rows, &applied.rows);
    report->step_s = step_s;
    report->simulated_s += step_s;
    stepper->time_s += step_s;
    report->time_s = stepper->time_s;
    if ((status = checkKnown(stepper, 0, 1, "after", i, steps, step_s, report)) != SS_OK) return latch(stepper, status);
    stepper->previous_step_s = use_history ? step_s : 0;
    if (def->step_done) def->step_done(def->step_done_context, step_s);
    if (stepper->destroy_requested) return SS_OK;
  }
  return SS_OK;
}

/* x, or 0 for a negative x (fmax(x, 0) without a call into libm). */
static double atLeastZero(double x) { return x > 0 ? x : 0; }

/* WHOLE_FRAME: one step of the frame. SUBSTEPS: one step up to (1 + max_step_slack)·max_step_s, else n equal
 * substeps no longer than max_step_s, at most max_steps_per_frame (a longer frame, a breakpoint or a hitch, is cut
 * off like the fixed cut's: the rest is dropped, and reported). A frame too short to step waits for the next one. */
static ssStatus stepFrame(ssStepper* stepper, double frame_s, ssFrameReport* report) {
  const ssStepping* stepping = &stepper->def.stepping;
  double carried_s = stepper->short_frame_s;
  double total_s = frame_s + carried_s;
  if (total_s < SS_MIN_STEP_S) {
    stepper->short_frame_s = total_s;
    report->carried_s = total_s;
    carryForces(stepper, carried_s, frame_s);
    return SS_OK;
  }
  int steps = 1;
  double step_s = total_s;
  if (stepping->cut == SS_CUT_SUBSTEPS && total_s > stepping->max_step_s * (1 + stepping->max_step_slack)) {
    double count = ceil(total_s / stepping->max_step_s - kStepCountSlack);
    if (count > stepping->max_steps_per_frame) {
      steps = stepping->max_steps_per_frame;
      step_s = stepping->max_step_s;
      report->dropped_s = total_s - steps * step_s;
    } else if (count > 1) {
      steps = (int)count;
      step_s = total_s / steps;
    }
  }
  stepper->short_frame_s = 0;
  ssStatus status = takeSteps(stepper, steps, step_s, carried_s, report);
  holdForces(stepper, 0);
  return status;
}

/* FIXED: constant steps from an accumulator, capped against the spiral of death. */
static ssStatus stepFixed(ssStepper* stepper, double frame_s, ssFrameReport* report) {
  const ssStepping* stepping = &stepper->def.stepping;
  double step_s = stepping->fixed_step_s;
  ssStatus status = ssPoseHistoryBeginFrame(&stepper->poses, stepper->known.ids, stepper->known.count);
  if (status != SS_OK) return status;
  double carried_s = stepper->accumulator_s;
  double accumulator_s = carried_s + frame_s;
  double due = floor(accumulator_s / step_s + kStepCountSlack);
  int cap = stepping->max_steps_per_frame;
  if (due > cap) {
    report->dropped_s = (due - cap) * step_s;
    accumulator_s -= report->dropped_s;
    due = cap;
  }
  if (due == 0) {
    carryForces(stepper, carried_s, frame_s);
  } else {
    status = takeSteps(stepper, (int)due, step_s, carried_s, report);
  }
  stepper->accumulator_s = atLeastZero(accumulator_s - report->steps * step_s);
  if (due > 0) holdForces(stepper, stepper->accumulator_s);
  report->carried_s = stepper->accumulator_s;
  report->interpolation = fmin(stepper->accumulator_s / step_s, nextafter(1.0, 0.0));
  ssPoseHistoryEndFrame(stepper->poses, report->steps, report->interpolation);
  return status;
}

/* Before the frame, in one pass over the known bodies: joints made since the last frame found, every known body's
 * state and forces checked before any callback runs (a collide callback's dSpaceCollide is where a body beyond
 * SS_MAX_POSITION_M would abort), and the frame's forces read. Nothing is touched on an error. */
static ssStatus startFrame(ssStepper* stepper, ssFrameReport* report) {
  const ssStepping* stepping = &stepper->def.stepping;
  ssBodyBounds bounds = {stepping->max_speed, stepping->max_angular_speed, 1, 0};
  ssStatus status = findNew(stepper, 0);
  /* with callbacks the first step's boundary checks every body after them: a sleeping one is read there */
  const int sleepers_later = stepper->def.before_step != NULL || stepper->def.collide != NULL;
  for (int joints_changed = 1; status == SS_OK && joints_changed;) {
    dBodyID failed = 0;
    status = ssKnownStartFrame(&stepper->known, &bounds, stepper->moved.list, stepper->moved.count, sleepers_later,
                               &failed, &joints_changed);
    if (status != SS_OK) {
      report->failed_body = failed;
      return latch(stepper, status);
    }
    if (joints_changed) status = findNew(stepper, 1);
  }
  if (status == SS_OK) status = followProgram(stepper, report, 0);
  /* after the check, on the list it passed: the bodies are those the program repaired, within every bound */
  if (status == SS_OK && stepper->rebase_gears) {
    ssGearsRebase(stepper->known.geared, stepper->known.geared_count);
    stepper->rebase_gears = 0;
  }
  return status;
}

ssStatus ssStepper_Step(ssStepper* stepper, double frame_s, ssFrameReport* report) {
  /* from its own callback: refused, and the frame's report left alone */
  if (stepper != NULL) REFUSE_IN_STEP(stepper, "ssStepper_Step");
  ssFrameReport local;
  if (report == NULL) report = &local;
  static const ssFrameReport kNothingYet; /* copied in a few moves (zeroing in place compiles to a slow rep stos) */
  *report = kNothingYet;
  REQUIRE_STEPPER(stepper);
  if (stepper->failed_status != SS_OK)
    return ssFail(SS_ERROR_FAILED, "an earlier frame failed (%s): repair or restore the bodies, then call "
                                   "ssStepper_Reset", stepper->failed_message);
  /* any frame from 0 up is taken: one shorter than SS_MIN_STEP_S (0 included) waits for the next, with its forces */
  if (!(frame_s >= 0 && frame_s <= SS_MAX_FRAME_S)) { /* false for a NaN too; named below */
    ssStatus refused = ssCheckNonNegative("frame_s", "s", frame_s);
    if (refused == SS_OK)
      refused = ssFail(SS_ERROR_OUT_OF_RANGE, "frame_s = %g s: must be at most SS_MAX_FRAME_S = %g s", frame_s,
                       (double)SS_MAX_FRAME_S);
    return refused;
  }
  report->time_s = stepper->time_s;
  ssStatus status = startFrame(stepper, report);
  if (status != SS_OK) return status;
  stepper->report = report;
  stepper->in_step = 1;
  status = stepper->def.stepping.cut == SS_CUT_FIXED ? stepFixed(stepper, frame_s, report)
                                                      : stepFrame(stepper, frame_s, report);
  stepper->in_step = 0;
  stepper->report = NULL;
  if (stepper->destroy_requested) {
    ssStepper_Destroy(stepper);
    return status;
  }
  describeNextStep(stepper); /* between frames, ssStepper_CurrentStep tells the next step, at the stepper's time */
  return status;
}

ssAdoptReport ssStepper_Adopted(const ssStepper* stepper) {
  if (stepper != NULL) return stepper->adopted;
  ssFail(SS_ERROR_OUT_OF_RANGE, "stepper = NULL: a stepper is required");
  return (ssAdoptReport){0};
}

int ssStepper_KnownBodyCount(ssStepper* stepper) {
  if (stepper == NULL) {
    ssFail(SS_ERROR_OUT_OF_RANGE, "stepper = NULL: a stepper is required");
    return -1;
  }
  return refreshKnown(stepper) == SS_OK ? stepper->known.count : -1;
}

/* The stepper: a frame's time becomes physics steps, each with its softness rewritten for its length, the frame's
 * forces put back before each one, and the known bodies checked after it. A failure is latched: a broken world is
 * never stepped again until the program says it has repaired it. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "array.h"
#include "error.h"
#include "interpolation_internal.h"
#include "ode_bounds.h"
#include "registry_internal.h"
#include "steadystep/adopt.h"
#include "steadystep/stepper.h"

/* Frame times are sums of floating-point parts: a frame of exactly 2·max_step_s must not become 3 substeps. */
static const double kStepCountSlack = 1e-9;

/* A body whose forces the stepper keeps over a frame and whose state it checks. */
typedef struct KnownBody {
  dBodyID body;
  double frame_force[6]; /* force (N) and torque (N·m) the program added for this frame */
  double carried[6];     /* momentum (N·s, N·m·s) of frames that took no step, delivered with the next steps */
} KnownBody;

struct ssStepper {
  ssStepperDef def;            /* def.registry: the registry in use, the given one or owned_registry */
  ssRegistry* owned_registry;  /* made for def.space when no registry was given */
  double tuned_step_s;         /* 0: none */
  ssAdoptReport adopted;       /* what adoption reached, summed */
  double previous_step_s; /* 0: no usable history */
  double accumulator_s;   /* FIXED: time not yet stepped */
  double short_frame_s;   /* other policies: frames too short to step, carried */
  dBodyID* watched;
  int watched_count, watched_capacity;
  unsigned watched_generation;
  /* the registry's bodies and the watched ones, each once, sorted; rebuilt when either set changes */
  KnownBody* known;
  dBodyID* known_ids; /* known[i].body, packed: the checks after every step read nothing else */
  int known_count;
  int carrying; /* whether any known body may carry momentum: without, the forces' capture reads no carried */
  unsigned known_registry_generation, known_watched_generation;
  int known_valid;
  int* pushed; /* indices into known of the bodies with a force or carried momentum this frame */
  int pushed_count;
  ssStepInfo current;
  /* a program softens many contacts with the same tuned numbers: the last ones' law is kept */
  ssSoftness contact_tuned;
  ssRowLaw contact_law;
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
    return ssFail(SS_ERROR_OUT_OF_RANGE, "registry of world %p: not def.world = %p", (void*)ssRegistryWorld(def->registry),
                  (void*)def->world);
  if (def->space != 0 && def->tuned_step_s == 0)
    return ssFail(SS_ERROR_OUT_OF_RANGE, "tuned_step_s = 0 s: with a space, say which step the program was tuned for");
  if (def->tuned_step_s != 0) {
    ssStatus status = ssCheckStepLength("tuned_step_s", def->tuned_step_s);
    if (status != SS_OK) return status;
  }
  return ssValidateStepping(&def->stepping);
}

/* stepping's max_step_s and fixed_step_s of 0 stand for the tuned step; the one the cut uses must have one. */
static ssStatus resolveSteps(ssStepping* stepping, double tuned_step_s) {
  if (stepping->max_step_s == 0) stepping->max_step_s = tuned_step_s;
  if (stepping->fixed_step_s == 0) stepping->fixed_step_s = tuned_step_s;
  const char* missing = stepping->cut == SS_CUT_SUBSTEPS && stepping->max_step_s == 0  ? "max_step_s"
                        : stepping->cut == SS_CUT_FIXED && stepping->fixed_step_s == 0 ? "fixed_step_s"
                                                                                        : NULL;
  if (missing == NULL) return SS_OK;
  return ssFail(SS_ERROR_OUT_OF_RANGE, "stepping.%s = 0 s (the tuned step), but there is no tuned step: set "
                                       "def.tuned_step_s, adopt into the registry, or give stepping.%s", missing, missing);
}

/* The step length a step's softness is computed for: its own, or the frozen one. */
static double softnessStep(const ssStepping* stepping, double step_s) {
  return stepping->frozen_step_s > 0 ? stepping->frozen_step_s : step_s;
}

static void describeNextStep(ssStepper* stepper) {
  const ssStepping* stepping = &stepper->def.stepping;
  double step_s = stepping->cut == SS_CUT_FIXED ? stepping->fixed_step_s : stepping->max_step_s;
  if (step_s == 0) step_s = stepping->cut == SS_CUT_FIXED ? stepping->max_step_s : stepping->fixed_step_s;
  stepper->current =
      (ssStepInfo){stepping->mapping, step_s, softnessStep(stepping, step_s), stepper->previous_step_s, 0, 1};
}

/* The speed guard: 0 stands for the bound ODE itself needs. */
static void resolveSpeeds(ssStepping* stepping) {
  if (stepping->max_speed == 0) stepping->max_speed = SS_MAX_SAFE_SPEED;
  if (stepping->max_angular_speed == 0) stepping->max_angular_speed = SS_MAX_SAFE_SPEED;
}

ssStatus ssStepper_Create(const ssStepperDef* def, ssStepper** out) {
  ssStatus status = validateDef(def);
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
      return ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory creating the stepper's registry");
    }
    if ((status = ssRegistry_Adopt(registry, tuned_step_s, def->space, &stepper->adopted)) != SS_OK) {
      ssRegistry_Destroy(stepper->owned_registry);
      free(stepper);
      return status;
    }
    stepper->def.registry = registry;
  }
  resolveSpeeds(&stepper->def.stepping);
  stepper->contact_tuned = (ssSoftness){NAN, NAN};
  describeNextStep(stepper);
  *out = stepper;
  return SS_OK;
}

void ssStepper_Destroy(ssStepper* stepper) {
  if (stepper == NULL) return;
  ssRegistry_Destroy(stepper->owned_registry);
  free(stepper->watched);
  free(stepper->known);
  free(stepper->known_ids);
  free(stepper->pushed);
  ssPoseHistory_Destroy(stepper->poses);
  free(stepper);
}

#define REQUIRE_STEPPER(stepper) \
  if ((stepper) == NULL) return ssFail(SS_ERROR_OUT_OF_RANGE, "stepper = NULL: a stepper is required")

ssStatus ssStepper_WatchBody(ssStepper* stepper, dBodyID body) {
  REQUIRE_STEPPER(stepper);
  if (body == 0) return ssFail(SS_ERROR_OUT_OF_RANGE, "body = NULL: a body is required");
  for (int i = 0; i < stepper->watched_count; ++i)
    if (stepper->watched[i] == body) return SS_OK;
  if (!ssReserveOne((void**)&stepper->watched, stepper->watched_count, &stepper->watched_capacity, sizeof body))
    return ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory watching a body");
  stepper->watched[stepper->watched_count++] = body;
  stepper->watched_generation += 1;
  return SS_OK;
}

ssStatus ssStepper_UnwatchBody(ssStepper* stepper, dBodyID body) {
  REQUIRE_STEPPER(stepper);
  if (body == 0) return ssFail(SS_ERROR_OUT_OF_RANGE, "body = NULL: a body is required");
  for (int i = 0; i < stepper->watched_count; ++i) {
    if (stepper->watched[i] != body) continue;
    stepper->watched[i] = stepper->watched[--stepper->watched_count];
    stepper->watched_generation += 1;
    return SS_OK;
  }
  return ssFail(SS_ERROR_NOT_FOUND, "body %p: not watched", (void*)body);
}

ssStatus ssStepper_DestroyBody(ssStepper* stepper, dBodyID body) {
  REQUIRE_STEPPER(stepper);
  if (body == 0) return ssFail(SS_ERROR_OUT_OF_RANGE, "body = NULL: a body is required");
  for (int i = 0; i < stepper->watched_count; ++i)
    if (stepper->watched[i] == body) stepper->watched[i--] = stepper->watched[--stepper->watched_count];
  ssRegistry* registry = stepper->def.registry;
  if (registry != NULL) {
    if (ssRegistryHasBody(registry, body)) ssRegistry_UnbindBody(registry, body);
    /* ODE leaves the body's joints detached on one side, where some of its getters assert: they are unbound */
    for (int i = dBodyGetNumJoints(body) - 1; i >= 0; --i) {
      dJointID joint = dBodyGetJoint(body, i);
      if (ssRegistryHasJoint(registry, joint)) ssRegistry_UnbindJoint(registry, joint);
    }
  }
  stepper->watched_generation += 1; /* the known list is rebuilt without it before it is read again */
  dBodyDestroy(body);
  return SS_OK;
}

ssStatus ssStepper_DestroyJoint(ssStepper* stepper, dJointID joint) {
  REQUIRE_STEPPER(stepper);
  if (joint == 0) return ssFail(SS_ERROR_OUT_OF_RANGE, "joint = NULL: a joint is required");
  ssRegistry* registry = stepper->def.registry;
  if (registry != NULL && ssRegistryHasJoint(registry, joint)) ssRegistry_UnbindJoint(registry, joint);
  stepper->watched_generation += 1;
  dJointDestroy(joint);
  return SS_OK;
}

static void forgetCarried(ssStepper* stepper) {
  for (int i = 0; i < stepper->known_count; ++i) memset(stepper->known[i].carried, 0, sizeof stepper->known[i].carried);
  stepper->carrying = 0;
}

void ssStepper_ResetHistory(ssStepper* stepper) {
  if (stepper != NULL) stepper->previous_step_s = 0;
}

void ssStepper_Reset(ssStepper* stepper) {
  if (stepper == NULL) return;
  stepper->failed_status = SS_OK;
  stepper->failed_message[0] = '\0';
  stepper->previous_step_s = 0;
  stepper->accumulator_s = 0;
  stepper->short_frame_s = 0;
  forgetCarried(stepper);
  ssPoseHistory_Forget(stepper->poses);
  describeNextStep(stepper);
}

ssStatus ssStepper_SetStepping(ssStepper* stepper, const ssStepping* stepping) {
  REQUIRE_STEPPER(stepper);
  ssStatus status = ssValidateStepping(stepping);
  if (status != SS_OK) return status;
  ssStepping resolved = *stepping;
  if ((status = resolveSteps(&resolved, stepper->tuned_step_s)) != SS_OK) return status;
  stepper->def.stepping = resolved;
  resolveSpeeds(&stepper->def.stepping);
  stepper->previous_step_s = 0;
  stepper->accumulator_s = 0;
  stepper->short_frame_s = 0;
  ssPoseHistory_Forget(stepper->poses);
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
  return (ssStepInfo){SS_MAPPING_IMPLICIT_EULER, 0, 0, 0, 0, 0};
}

ssStatus ssStepper_SoftenContact(ssStepper* stepper, dContact* contact, dBodyID body1, dBodyID body2) {
  REQUIRE_STEPPER(stepper);
  if (contact == NULL) return ssFail(SS_ERROR_OUT_OF_RANGE, "contact = NULL: a contact is required");
  double tuned_step_s = ssRegistry_TunedStep(stepper->def.registry);
  if (tuned_step_s == 0)
    return ssFail(SS_ERROR_OUT_OF_RANGE, "tuned step = 0 s: adopt the world first (ssRegistry_Adopt), or soften "
                                         "with a spring of your own (ssContactSoften)");
  ssSoftness world = ssRegistryTunedWorld(stepper->def.registry);
  const dSurfaceParameters* surface = &contact->surface;
  double erp = (surface->mode & dContactSoftERP) ? surface->soft_erp : world.erp;
  double cfm = (surface->mode & dContactSoftCFM) ? surface->soft_cfm : world.cfm;
  if (erp != stepper->contact_tuned.erp || cfm != stepper->contact_tuned.cfm) {
    ssRowLaw law;
    ssStatus status = ssRowLawFromTuned("contact", erp, cfm, tuned_step_s, &law);
    if (status != SS_OK) return status;
    stepper->contact_tuned = (ssSoftness){erp, cfm};
    stepper->contact_law = law;
  }
  const ssStepInfo* step = &stepper->current;
  ssRowFallback handed_on;
  ssStatus status = ssContactSoftenLaw(contact, body1, body2, &stepper->contact_law, step->mapping,
                                       step->softness_step_s, step->previous_step_s, &handed_on);
  if (status != SS_OK) return status;
  if (stepper->report != NULL) {
    ssServedCounts* contacts = &stepper->report->contacts;
    if (handed_on.to_implicit_euler) contacts->handed_to_implicit_euler += 1;
    else if (handed_on.exact_to_matched) contacts->handed_to_matched += 1;
    else contacts->by_mapping += 1;
  }
  return SS_OK;
}

static int compareKnown(const void* a, const void* b) {
  uintptr_t x = (uintptr_t)((const KnownBody*)a)->body, y = (uintptr_t)((const KnownBody*)b)->body;
  return (x > y) - (x < y);
}

typedef struct KnownList {
  KnownBody* bodies;
  int count, capacity;
} KnownList;

static void appendKnown(void* context, dBodyID body) {
  KnownList* list = context;
  if (list->count < list->capacity) list->bodies[list->count++] = (KnownBody){.body = body};
}

/* The known bodies, each once, sorted; rebuilt only when the registry's bindings or the watch list changed. Momentum
 * carried for a body that stays known is kept. */
static ssStatus refreshKnown(ssStepper* stepper) {
  const ssRegistry* registry = stepper->def.registry;
  unsigned generation = registry != NULL ? ssRegistryGeneration(registry) : 0;
  if (stepper->known_valid && stepper->known_registry_generation == generation &&
      stepper->known_watched_generation == stepper->watched_generation)
    return SS_OK;
  int most = stepper->watched_count;
  if (registry != NULL) most += 2 * ssRegistry_JointBindingCount(registry) + ssRegistryBodyBindingCount(registry);
  KnownList list = {calloc((size_t)(most > 0 ? most : 1), sizeof(KnownBody)), 0, most};
  int* pushed = calloc((size_t)(most > 0 ? most : 1), sizeof(int));
  dBodyID* ids = calloc((size_t)(most > 0 ? most : 1), sizeof(dBodyID));
  if (list.bodies == NULL || pushed == NULL || ids == NULL) {
    free(list.bodies);
    free(pushed);
    free(ids);
    return ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory listing the known bodies");
  }
  if (registry != NULL) ssRegistry_VisitBodies(registry, appendKnown, &list);
  for (int i = 0; i < stepper->watched_count; ++i) appendKnown(&list, stepper->watched[i]);
  qsort(list.bodies, (size_t)list.count, sizeof(KnownBody), compareKnown);
  int unique = 0;
  for (int i = 0; i < list.count; ++i) {
    if (unique > 0 && list.bodies[unique - 1].body == list.bodies[i].body) continue;
    KnownBody* kept = &list.bodies[unique++];
    *kept = list.bodies[i];
    const KnownBody* old = stepper->known_valid ? bsearch(kept, stepper->known, (size_t)stepper->known_count,
                                                          sizeof(KnownBody), compareKnown)
                                                : NULL;
    if (old != NULL) memcpy(kept->carried, old->carried, sizeof kept->carried);
    ids[unique - 1] = kept->body;
  }
  free(stepper->known);
  free(stepper->known_ids);
  free(stepper->pushed);
  stepper->known = list.bodies;
  stepper->known_ids = ids;
  stepper->known_count = unique;
  stepper->pushed = pushed;
  stepper->known_registry_generation = generation;
  stepper->known_watched_generation = stepper->watched_generation;
  stepper->known_valid = 1;
  return SS_OK;
}

static int anyNonZero(const double* values) {
  return values[0] != 0 || values[1] != 0 || values[2] != 0 || values[3] != 0 || values[4] != 0 || values[5] != 0;
}

/* Reads the forces the program added for this frame, and lists the bodies that have one or carried momentum. A
 * force ODE cannot step (non-finite, or beyond SS_MAX_FORCE_N) refuses the frame before anything is touched. */
static ssStatus captureForces(ssStepper* stepper) {
  stepper->pushed_count = 0;
  for (int i = 0; i < stepper->known_count; ++i) {
    const dReal* force = dBodyGetForce(stepper->known_ids[i]);
    const dReal* torque = dBodyGetTorque(stepper->known_ids[i]);
    double f[6] = {force[0], force[1], force[2], torque[0], torque[1], torque[2]};
    KnownBody* known = &stepper->known[i];
    if (!anyNonZero(f) && !(stepper->carrying && anyNonZero(known->carried))) continue;
    for (int j = 0; j < 6; ++j)
      if (!(fabs(f[j]) <= SS_MAX_FORCE_N))
        return ssFail(isfinite(f[j]) ? SS_ERROR_OUT_OF_RANGE : SS_ERROR_NOT_FINITE,
                      "body %p: %s %g N or N·m added for the frame: must be finite and at most SS_MAX_FORCE_N = %g",
                      (void*)known->body, j < 3 ? "force" : "torque", f[j], SS_MAX_FORCE_N);
    memcpy(known->frame_force, f, sizeof f);
    stepper->pushed[stepper->pushed_count++] = i;
  }
  return SS_OK;
}

/* Before each of a frame's `steps` steps of step_s: each pushed body gets the force that delivers its frame's
 * momentum F·frame_s (plus what was carried) evenly over the frame's simulated time. */
static void putForces(ssStepper* stepper, double frame_s, int steps, double step_s) {
  double simulated_s = steps * step_s;
  for (int p = 0; p < stepper->pushed_count; ++p) {
    KnownBody* known = &stepper->known[stepper->pushed[p]];
    double f[6];
    for (int j = 0; j < 6; ++j) f[j] = (known->frame_force[j] * frame_s + known->carried[j]) / simulated_s;
    dBodySetForce(known->body, f[0], f[1], f[2]);
    dBodySetTorque(known->body, f[3], f[4], f[5]);
  }
}

/* A frame that takes no step: its forces' momentum waits for the next steps, and the accumulators are emptied so
 * that the program's next additions are not counted twice. */
static void carryForces(ssStepper* stepper, double frame_s) {
  for (int p = 0; p < stepper->pushed_count; ++p) {
    KnownBody* known = &stepper->known[stepper->pushed[p]];
    for (int j = 0; j < 6; ++j) known->carried[j] += known->frame_force[j] * frame_s;
    stepper->carrying = 1;
    dBodySetForce(known->body, 0, 0, 0);
    dBodySetTorque(known->body, 0, 0, 0);
  }
}

/* After a frame's steps: every body that carried momentum was pushed for them (captureForces), so none carries now. */
static void clearCarried(ssStepper* stepper) {
  for (int p = 0; p < stepper->pushed_count; ++p)
    memset(stepper->known[stepper->pushed[p]].carried, 0, sizeof stepper->known[0].carried);
  stepper->carrying = 0;
}

/* Checks one body after a step; returns SS_OK or records the failure. A runaway is stopped while its numbers are
 * still finite: ODE 0.16 aborts inside the next step when a rotation becomes non-finite (dxNormalize4). */
static ssStatus checkBody(const ssStepper* stepper, dBodyID body) {
  const dReal* position = dBodyGetPosition(body);
  const dReal* velocity = dBodyGetLinearVel(body);
  const dReal* spin = dBodyGetAngularVel(body);
  /* a NaN or an infinity anywhere makes the sum non-finite: one test for nine numbers */
  double sum = position[0] + position[1] + position[2] + velocity[0] + velocity[1] + velocity[2] + spin[0] + spin[1] +
               spin[2];
  double speed2 = velocity[0] * velocity[0] + velocity[1] * velocity[1] + velocity[2] * velocity[2];
  double spin2 = spin[0] * spin[0] + spin[1] * spin[1] + spin[2] * spin[2];
  double max_speed = stepper->def.stepping.max_speed, max_spin = stepper->def.stepping.max_angular_speed;
  if (isfinite(sum) && speed2 <= max_speed * max_speed && spin2 <= max_spin * max_spin) return SS_OK;
  if (!isfinite(sum) || !isfinite(speed2) || !isfinite(spin2))
    return ssFail(SS_ERROR_BLOWUP, "body %p: position or velocity is not finite", (void*)body);
  if (speed2 > max_speed * max_speed)
    return ssFail(SS_ERROR_SPEED_LIMIT, "body %p: speed %g m/s is above max_speed = %g m/s", (void*)body,
                  sqrt(speed2), max_speed);
  return ssFail(SS_ERROR_SPEED_LIMIT, "body %p: angular speed %g rad/s is above max_angular_speed = %g rad/s",
                (void*)body, sqrt(spin2), max_spin);
}

static ssStatus latch(ssStepper* stepper, ssStatus status) {
  stepper->failed_status = status;
  snprintf(stepper->failed_message, sizeof stepper->failed_message, "%s", ssLastError());
  stepper->previous_step_s = 0;
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

/* Takes a frame's `steps` steps of step_s: everything else about them (mapping, the softness' step, history)
 * follows from the stepping. Errors of Apply leave the world as the previous step left it; a failed check
 * latches. */
static ssStatus takeSteps(ssStepper* stepper, int steps, double step_s, double frame_s, ssFrameReport* report) {
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
    putForces(stepper, frame_s, steps, step_s);
    if (i == 0 || apply_every_step) {
      ssStatus status = apply(stepper, mapping, softness_step_s, previous_step_s, &applied, report);
      if (status != SS_OK) return status;
    }
    stepper->current = (ssStepInfo){mapping, step_s, softness_step_s, previous_step_s, i, steps};
    if (def->before_step) def->before_step(def->before_step_context, stepper);
    if (def->collide) def->collide(def->collide_context, stepper);
    if (i == steps - 1 && stepping->cut == SS_CUT_FIXED) ssPoseHistory_BeforeLastStep(stepper->poses);
    int stepped = stepping->solver == SS_SOLVER_STEP ? dWorldStep(def->world, step_s)
                                                      : dWorldQuickStep(def->world, step_s);
    if (def->contact_group) dJointGroupEmpty(def->contact_group);
    if (!stepped) return latch(stepper, ssFail(SS_ERROR_OUT_OF_MEMORY, "ODE ran out of memory in its step"));
    report->steps += 1;
    addServed(&report->rows, &applied.rows);
    report->step_s = step_s;
    report->simulated_s += step_s;
    for (int k = 0; k < stepper->known_count; ++k) {
      ssStatus status = checkBody(stepper, stepper->known_ids[k]);
      if (status != SS_OK) {
        report->failed_body = stepper->known_ids[k];
        return latch(stepper, status);
      }
    }
    stepper->previous_step_s = use_history ? step_s : 0;
    if (def->step_done) def->step_done(def->step_done_context, step_s);
  }
  return SS_OK;
}

/* WHOLE_FRAME: one step of the frame. SUBSTEPS: n equal substeps no longer than max_step_s. A frame too short to
 * step waits for the next one. */
static ssStatus stepFrame(ssStepper* stepper, double frame_s, ssFrameReport* report) {
  const ssStepping* stepping = &stepper->def.stepping;
  double total_s = frame_s + stepper->short_frame_s;
  if (total_s < SS_MIN_STEP_S) {
    stepper->short_frame_s = total_s;
    report->carried_s = total_s;
    carryForces(stepper, frame_s);
    return SS_OK;
  }
  int steps = 1;
  if (stepping->cut == SS_CUT_SUBSTEPS) {
    double count = ceil(total_s / stepping->max_step_s - kStepCountSlack);
    if (count > (double)INT32_MAX) /* max_step_s >= SS_MIN_STEP_S and frame_s <= SS_MAX_FRAME_S: never */
      return ssFail(SS_ERROR_OUT_OF_RANGE, "frame_s = %g s: more than %d substeps of max_step_s = %g s", frame_s,
                    INT32_MAX, stepping->max_step_s);
    steps = count < 1 ? 1 : (int)count;
  }
  stepper->short_frame_s = 0;
  double step_s = total_s / steps;
  if (stepping->cut == SS_CUT_SUBSTEPS && steps > stepping->max_steps_per_frame) {
    /* a long frame (a breakpoint, a hitch) is cut off like the fixed cut's: the rest is dropped, and reported */
    steps = stepping->max_steps_per_frame;
    step_s = stepping->max_step_s;
    report->dropped_s = total_s - steps * step_s;
  }
  ssStatus status = takeSteps(stepper, steps, step_s, fmax(frame_s - report->dropped_s, 0), report);
  clearCarried(stepper);
  return status;
}

/* FIXED: constant steps from an accumulator, capped against the spiral of death. */
static ssStatus stepFixed(ssStepper* stepper, double frame_s, ssFrameReport* report) {
  const ssStepping* stepping = &stepper->def.stepping;
  double step_s = stepping->fixed_step_s;
  ssStatus status = ssPoseHistory_BeginFrame(&stepper->poses, stepper->known_ids, stepper->known_count);
  if (status != SS_OK) return status;
  double accumulator_s = stepper->accumulator_s + frame_s;
  double due = floor(accumulator_s / step_s + kStepCountSlack);
  int cap = stepping->max_steps_per_frame;
  if (due > cap) {
    report->dropped_s = (due - cap) * step_s;
    accumulator_s -= report->dropped_s;
    due = cap;
  }
  if (due == 0) {
    carryForces(stepper, frame_s);
  } else {
    status = takeSteps(stepper, (int)due, step_s, fmax(frame_s - report->dropped_s, 0), report);
    clearCarried(stepper);
  }
  stepper->accumulator_s = fmax(accumulator_s - report->steps * step_s, 0);
  report->carried_s = stepper->accumulator_s;
  report->interpolation = fmin(stepper->accumulator_s / step_s, nextafter(1.0, 0.0));
  ssPoseHistory_EndFrame(stepper->poses, report->steps, report->interpolation);
  return status;
}

ssStatus ssStepper_Step(ssStepper* stepper, double frame_s, ssFrameReport* report) {
  ssFrameReport local;
  if (report == NULL) report = &local;
  memset(report, 0, sizeof *report);
  REQUIRE_STEPPER(stepper);
  if (stepper->failed_status != SS_OK)
    return ssFail(SS_ERROR_FAILED, "an earlier frame failed (%s): repair or restore the bodies, then call "
                                   "ssStepper_Reset", stepper->failed_message);
  /* any frame from 0 up is taken: one shorter than SS_MIN_STEP_S waits for the next */
  ssStatus status = ssCheckNonNegative("frame_s", "s", frame_s);
  if (status == SS_OK && frame_s > SS_MAX_FRAME_S)
    status = ssFail(SS_ERROR_OUT_OF_RANGE, "frame_s = %g s: must be at most SS_MAX_FRAME_S = %g s", frame_s,
                    (double)SS_MAX_FRAME_S);
  if (status != SS_OK || frame_s == 0) return status;
  if ((status = refreshKnown(stepper)) != SS_OK) return status;
  if ((status = captureForces(stepper)) != SS_OK) return status;
  stepper->report = report;
  status = stepper->def.stepping.cut == SS_CUT_FIXED ? stepFixed(stepper, frame_s, report)
                                                      : stepFrame(stepper, frame_s, report);
  stepper->report = NULL;
  return status;
}

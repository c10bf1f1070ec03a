/* Internal: the bodies a stepper knows, and the checks at its boundary with ODE.
 *
 * Known: the registry's bodies (bound, adopted), the watched ones, and every body reachable from those through
 * joints other than contacts (a bob hung by a hinge from a known body is known whether or not it was bound), each
 * once, found through an index by address. Bodies come and go one at a time (ssKnownAdd, ssKnownForget) at the cost
 * of the change; the list is built whole (ssKnownRebuild) only when the watch list changes or joints do. Their
 * forces are kept over a frame and their state and forces are checked before every physics step. ODE attaches a new
 * joint at the head of a body's list, so a body's first joint, kept here, changes when a joint is attached to it:
 * that is how joints made since the list was built are found, for one read a body. */
#ifndef STEADYSTEP_KNOWN_BODIES_H
#define STEADYSTEP_KNOWN_BODIES_H

#include <stdint.h>

#include <ode/ode.h>

#include "pointer_set.h"
#include "steadystep/registry.h"
#include "steadystep/status.h"

typedef struct ssKnownBody {
  dBodyID body;
  int pushed;            /* has a frame force or a carried force this frame */
  double frame_force[6]; /* force (N) and torque (N·m) the program added for this frame */
  /* the force and torque held over the time carried into this frame (FIXED's accumulator, a frame too short to
   * step): the mean of the forces of the frames that time came from */
  double carried_force[6];
} ssKnownBody;

/* Where ODE keeps a body's checked values: its getters return pointers into the body, which stay put for its life,
 * so they are read once when the body is listed and the checks at every step load the values with no call. */
typedef struct ssBodyValues {
  const dReal* position;
  const dReal* linear_vel;
  const dReal* angular_vel;
  const dReal* force;  /* the force accumulator (N) */
  const dReal* torque; /* the torque accumulator (N·m) */
  /* the bound on the position's coordinates, as ssKnownCheck compares it (a magnitude's bits): SS_MAX_POSITION_M less
   * the farthest offset of the body's geoms (dGeomSetOffsetPosition) when it was listed, so that no geom of it lies
   * beyond SS_MAX_POSITION_M either */
  uint64_t position_bound;
} ssBodyValues;

/* A body's joints other than contacts, as the stepper last saw them: ODE attaches a new joint at the head of its
 * body's list, so a joint attached since changes the first, and one destroyed or detached the count. */
typedef struct ssJointSignature {
  dJointID first;
  int count;
  int total; /* every joint of the body then, contacts too */
} ssJointSignature;

typedef struct ssKnownBodies {
  ssKnownBody* bodies;    /* at a step, read for pushed bodies only (and for all while a force is carried) */
  dBodyID* ids;           /* bodies[i].body, packed */
  ssBodyValues* values;   /* bodies[i]'s values, packed: the checks read nothing else */
  ssJointSignature* joints; /* each body's joints when listed */
  /* whether ODE stepped the body at the last check or would step it next (enabled, or woken through its joints):
   * a body ODE has disabled since is checked once more, then no more until it wakes; a few bytes longer than the
   * list, the end of a run of sleepers (known_bodies.c) */
  unsigned char* awake;
  /* whether the program could move the body while it sleeps without the stepper's looks seeing it (no geom of it in
   * seen_space, where ODE puts a moved geom at the head): such a body is checked asleep too */
  unsigned char* moves_unseen;
  unsigned* reached;  /* the check that last met the body through joints (ssKnownCheck's walk) */
  /* the bodies ODE steps, as the last check found them: [0, stepped_count) of queue, marked first, then those the
   * wake walk reached. While stepped_valid (no body listed or forgotten since, none told to be checked once more),
   * a check after ODE's step alone reads these and what the walk reaches from them, and no sleeping body */
  int* queue;
  int stepped_count, stepped_valid;
  /* the frame's start passed over the bodies asleep at the check before (sleepers_later): the next full check reads
   * them, and starts those it finds awake */
  int sleepers_unread;
  unsigned checks;    /* checks made, numbering them for reached */
  /* bodies found awake that were asleep at the check before (woken by the program, or by ODE through a joint), not
   * yet taken (ssKnownTakeWoken): their damping and auto-disable are written for the step when they wake */
  dBodyID* woken;
  int woken_count, woken_capacity;
  /* a body passed over asleep with no joint but contacts (its joints are not read while it sleeps: ODE steps none)
   * was found woken with a joint attached since: the stepper finds it before the step (ssKnownTakeJointsDue) */
  int joints_due;
  ssPointerMap index; /* body -> its place in the arrays above */
  dSpaceID seen_space; /* the space whose heads the stepper looks at (its def.space, with those nested), or 0 */
  int count, capacity;
  /* how many are listed with a joint besides contacts, and how many could move unseen: with neither, the frame's
   * start has nothing to read of a body asleep at the last check (with callbacks), and finds the awake ones alone */
  int joined_count, unseen_count;
  int* pushed; /* indices into bodies of those with pushed set, and only those */
  int pushed_count;
  int carrying; /* whether any body may carry a force */
  dBodyID* geared; /* the listed bodies a transmission joint gears (ODE aborts when one turns by pi in a step) */
  int geared_count;
  int valid;
  unsigned registry_generation, watched_generation; /* of the sets the list was built from */
} ssKnownBodies;

void ssKnownFree(ssKnownBodies* known);

/* Builds the list again from the registry's bodies (registry may be NULL) and the watched ones, with what they reach
 * through joints; a body that stays known keeps its frame force and carried force. Errors, with the list as it
 * was: SS_ERROR_OUT_OF_MEMORY. */
ssStatus ssKnownRebuild(ssKnownBodies* known, const ssRegistry* registry, const dBodyID* watched, int watched_count);

/* Adds body (alive, not 0) and every body it reaches through joints other than contacts, those not listed yet: at
 * the cost of what is added. Errors: SS_ERROR_OUT_OF_MEMORY, with the bodies added before it listed. */
ssStatus ssKnownAdd(ssKnownBodies* known, dBodyID body);

/* Has every listed body checked at the next check, asleep or not (the spaces were listed in full: a sleeping body
 * the program moved is not told from the others). */
void ssKnownCheckAllOnce(ssKnownBodies* known);

/* Whether body is listed with joints other than contacts (bodies may be known through it). */
int ssKnownJoined(const ssKnownBodies* known, dBodyID body);

/* Takes body off the list at once (it is about to be destroyed): the last body takes its place. */
void ssKnownForget(ssKnownBodies* known, dBodyID body);

/* Whether a body's joints differ from those listed (a joint was attached, detached or destroyed since), giving the
 * first such body (body may be NULL). A body asleep at the last check with no joint but contacts is not read: a joint
 * attached to it is found when it wakes (ssKnownTakeJointsDue). */
int ssKnownJointsChanged(const ssKnownBodies* known, dBodyID* body);

/* Whether body's joints differ from those listed with it, or body is not listed. */
int ssKnownJointsChangedOf(const ssKnownBodies* known, dBodyID body);

/* Adds every joint of every listed body (contacts aside) to joints: the joints alive and attached to a known body.
 * Errors: SS_ERROR_OUT_OF_MEMORY. */
ssStatus ssKnownCollectJoints(const ssKnownBodies* known, ssPointerSet* joints);

/* Takes body's joints as they are now, once the stepper followed their change (adopted what they reach). */
void ssKnownTakeJointsOf(ssKnownBodies* known, dBodyID body);

/* Sets the force and torque accumulators of every listed body ODE steps (pushed or awake) to its frame force
 * (with_frame_forces) or to zero; a sleeping body's are left for the step that wakes it. */
void ssKnownResetAccumulators(const ssKnownBodies* known, int with_frame_forces);

/* Whether a check found a body woken, passed over asleep with no joint, with a joint attached since: the caller then
 * looks at the joints (ssKnownJointsChanged finds it) before ODE steps it. Cleared by the call. */
int ssKnownTakeJointsDue(ssKnownBodies* known);

/* The bodies that woke since the last call (known->woken), the list emptied: *count of them, valid until the next
 * check. */
const dBodyID* ssKnownTakeWoken(ssKnownBodies* known, int* count);

/* What a check reads of a body, and its bounds. */
typedef struct ssBodyBounds {
  double max_speed, max_angular_speed; /* m/s, rad/s */
  int forces;                          /* the force and torque accumulators, within SS_MAX_FORCE_N */
  /* > 0: the step (s) just taken or about to be: a body geared by a transmission joint turns less than
   * SS_MAX_GEAR_TURN_RAD in it (ODE 0.16 aborts when a gear turns by pi or more between two steps) */
  double gear_step_s;
} ssBodyBounds;

/* Checks the listed bodies ODE steps: in one pass over the packed values (a second names the first failure) every
 * enabled body, every body disabled since the last check (ODE stepped it before it fell asleep), then every disabled
 * body joined (contacts too) to one of those, which ODE wakes in its step; the bodies of also[also_count] (a sleeping
 * body the program moved, which collision reads); and every sleeping body the program could move unseen (moves_unseen).
 * Any other body asleep and alone is not read: ODE neither steps it nor lets its joints act. Checked: its position
 * within SS_MAX_POSITION_M, velocities finite and within the bounds, a geared body's turn within a step
 * (bounds->gear_step_s), and with bounds->forces its accumulators. On the first failure records the message (the body,
 * the quantity, its value, "`when` step `step` of `steps`", formatted then only), sets *failed to the body and returns
 * SS_ERROR_BLOWUP (a state not finite), SS_ERROR_POSITION_LIMIT, SS_ERROR_SPEED_LIMIT, SS_ERROR_NOT_FINITE (a force or
 * torque) or SS_ERROR_OUT_OF_RANGE (one beyond SS_MAX_FORCE_N). only_stepped says that nothing but ODE's step ran
 * since the last check (no program code could enable or move a body): then the bodies that check found ODE stepping
 * are read, and the walk from them, not every body (stepped_valid). A body found woken that slept with no joint has
 * its joints read: one attached since sets joints_due (ssKnownTakeJointsDue). */
ssStatus ssKnownCheck(ssKnownBodies* known, const ssBodyBounds* bounds, const char* when, int step, int steps,
                      const dBodyID* also, int also_count, int only_stepped, dBodyID* failed);

/* Just before ODE's step `step` of `steps`, of step_s, with its forces in the accumulators: every geared body's
 * turn within SS_MAX_GEAR_TURN_RAD at the spin and speed its force and torque can give it in the step (the checks
 * bound it at the spin it has). On the first failure sets *failed and returns SS_ERROR_SPEED_LIMIT, named. */
ssStatus ssKnownCheckGearsInStep(const ssKnownBodies* known, double step_s, int step, int steps, dBodyID* failed);

/* Before a frame, one pass: *joints_changed says whether a body's joints changed, or a body found woken (marked, or
 * reached by the walk) has a joint attached while it slept (then nothing is checked: the caller lists the bodies again
 * and calls again, and the marks and forces read are made again); else the bodies ODE steps are
 * checked as ssKnownCheck with state and forces (also: sleeping bodies the program moved), and, all passing, the
 * accumulators of those it steps become their frame force (pushed marks a force or a carried force). A sleeping body's
 * force waits in its accumulator, as in ODE, and acts in the step that wakes it. sleepers_later: a full check
 * (ssKnownCheck) follows before the first step, after the program's callbacks; the bodies asleep at the last check are
 * then not read here but there (the joints of those with any are: what was destroyed must be known first), and one
 * found awake there is started there. Collision reads no sleeping body the program did not move, and those it moved
 * are in also. */
ssStatus ssKnownStartFrame(ssKnownBodies* known, const ssBodyBounds* bounds, const dBodyID* also, int also_count,
                           int sleepers_later, dBodyID* failed, int* joints_changed);

#endif

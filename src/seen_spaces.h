/* Internal: the adopted spaces as the stepper last saw them, and what the program changed in them since, found at
 * the cost of the change.
 *
 * ODE keeps a simple or hash space's geoms in a list and puts a geom at its head when it is added, and again when it
 * moves (dGeomMoved: a body stepped or set). After a step the stepper marks each space's first geom, the marker:
 * whatever the program adds or moves before the next step lands in front of it, and nothing behind it is new. A look
 * walks the heads only, as far as what changed. What no walk sees, a geom the program destroyed, shows in the count:
 * the spaces hold as many geoms as at the last listing, plus those found since, less those the stepper removed, or
 * something was destroyed with ODE's own calls, and the spaces are listed in full. A body destroyed that way and
 * another made at its address before the look leave the count as it was and are taken for one (ODE's API tells no
 * freed handle from a live one). The mark keeps the first geoms, not the first alone: a body destroyed through the
 * stepper leaves them, and the next kept is the marker, so destroying what ODE stepped last costs no full walk. A
 * sweep-and-prune space reorders its geoms as they move (dSpaceGetGeom lists the moved ones first) and is listed at
 * every look. */
#ifndef STEADYSTEP_SEEN_SPACES_H
#define STEADYSTEP_SEEN_SPACES_H

#include <ode/ode.h>

#include "pointer_set.h"
#include "steadystep/status.h"

/* A growable list of bodies. */
typedef struct ssBodyList {
  dBodyID* list;
  int count, capacity;
} ssBodyList;

/* How many of a space's first geoms a mark keeps: a program destroys what is oldest, and ODE steps the newest body
 * first, so the first geoms after a step are those most often destroyed before the next (ssSeenForget). */
enum { SS_SEEN_HEAD = 8 };

typedef struct ssSeenSpace {
  dSpaceID space;
  /* the first geoms after the last step, less those whose bodies the stepper destroyed since: head[0] is the marker
   * and head[1] the geom behind it (0: none, the list ended there), by which a marker that moved since shows */
  dGeomID head[SS_SEEN_HEAD];
  dBodyID head_bodies[SS_SEEN_HEAD]; /* their bodies then (0: static, or a nested space) */
  int head_count;                    /* under 2: no marker (the whole list is head) */
  int sweep_and_prune;
} ssSeenSpace;

typedef struct ssSeenSpaces {
  ssSeenSpace* spaces; /* the root space first, then those nested in it at any depth */
  int count, capacity;
  int listed;          /* 0: the next look lists in full */
  long geoms;          /* the geoms the spaces hold, as the listing and the looks since account for them */
  ssPointerMap bodies; /* each body with a geom in the spaces -> how many of its geoms are there */
} ssSeenSpaces;

void ssSeenFree(ssSeenSpaces* seen);
void ssBodyListFree(ssBodyList* list);

/* Appends body to list: 1, or 0 when out of memory (the list as it was). */
int ssBodyListPush(ssBodyList* list, dBodyID body);

/* Lists root and every space nested in it, and the bodies their geoms hold: *gone gets the bodies of the last
 * listing that hold no geom there now (destroyed with their geoms, or moved out), and the listing replaces the last.
 * Reads the spaces and their geoms only. Errors, remembering nothing (the next look lists again):
 * SS_ERROR_UNSUPPORTED for a space ODE cannot list (a quadtree: ssCheckSpaceListable), SS_ERROR_OUT_OF_MEMORY. */
ssStatus ssSeenList(ssSeenSpaces* seen, dSpaceID root, ssBodyList* gone);

/* Walks the spaces' heads: *found gets the bodies with a geom there that the listing had not (appended), *moved the
 * sleeping bodies the program moved (replaced). Returns 1 when the counts tell that nothing else changed (the new
 * bodies then belong to the listing), 0 when the spaces must be listed in full (ssSeenList), -1 when out of memory. */
int ssSeenLook(ssSeenSpaces* seen, ssBodyList* found, ssBodyList* moved);

/* After a step: each space's marker set to its first geom, with those behind it (SS_SEEN_HEAD in all). */
void ssSeenMark(ssSeenSpaces* seen);

/* body, about to be destroyed through the stepper: its geoms there leave the count (destroyed before or after), and
 * leave the heads: a space whose marker it held takes the next geom kept as its marker (walked whole at the next look
 * when none is left). */
void ssSeenForget(ssSeenSpaces* seen, dBodyID body);

#endif

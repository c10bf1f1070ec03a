/* The adopted spaces as last seen (seen_spaces.h): a full listing when the counts require it, otherwise a walk of
 * each space's head, up to the geom that was first after the last step. */
#include "seen_spaces.h"

#include <stdlib.h>

#include "array.h"
#include "error.h"
#include "ode_bounds.h"

void ssSeenFree(ssSeenSpaces* seen) {
  free(seen->spaces);
  ssPointerMapFree(&seen->bodies);
  *seen = (ssSeenSpaces){0};
}

void ssBodyListFree(ssBodyList* list) {
  free(list->list);
  *list = (ssBodyList){NULL, 0, 0};
}

int ssBodyListPush(ssBodyList* list, dBodyID body) {
  if (!ssReserveOne((void**)&list->list, list->count, &list->capacity, sizeof body)) return 0;
  list->list[list->count++] = body;
  return 1;
}

static int spaceListed(const ssSeenSpaces* seen, dSpaceID space) {
  for (int k = 0; k < seen->count; ++k)
    if (seen->spaces[k].space == space) return 1;
  return 0;
}

/* How many of body's geoms lie in the listed spaces. */
static int geomsHeld(const ssSeenSpaces* seen, dBodyID body) {
  int held = 0;
  for (dGeomID geom = dBodyGetFirstGeom(body); geom != 0; geom = dBodyGetNextGeom(geom))
    held += dGeomGetSpace(geom) != 0 && spaceListed(seen, dGeomGetSpace(geom));
  return held;
}

static long geomsNow(const ssSeenSpaces* seen) {
  long geoms = 0;
  for (int i = 0; i < seen->count; ++i) geoms += dSpaceGetNumGeoms(seen->spaces[i].space);
  return geoms;
}

/* Breadth first (the list is the queue); bodies -> their geoms counted there. */
static ssStatus listInto(ssSeenSpaces* seen, dSpaceID root, ssPointerMap* bodies) {
  seen->count = 0;
  if (!ssReserveOne((void**)&seen->spaces, 0, &seen->capacity, sizeof *seen->spaces))
    return ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory listing the adopted spaces");
  seen->spaces[seen->count++] = (ssSeenSpace){.space = root};
  for (int walked = 0; walked < seen->count; ++walked) {
    dSpaceID space = seen->spaces[walked].space;
    ssStatus status = ssCheckSpaceListable(walked == 0 ? "def.space" : "nested space", space);
    if (status != SS_OK) return status;
    seen->spaces[walked].sweep_and_prune = dSpaceGetClass(space) == dSweepAndPruneSpaceClass;
    for (int i = 0, geoms = dSpaceGetNumGeoms(space); i < geoms; ++i) {
      dGeomID geom = dSpaceGetGeom(space, i);
      if (dGeomIsSpace(geom)) {
        if (spaceListed(seen, (dSpaceID)geom)) continue;
        if (!ssReserveOne((void**)&seen->spaces, seen->count, &seen->capacity, sizeof *seen->spaces))
          return ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory listing the adopted spaces");
        seen->spaces[seen->count++] = (ssSeenSpace){.space = (dSpaceID)geom};
        continue;
      }
      dBodyID body = dGeomGetBody(geom);
      if (body != 0 && ssPointerMapPut(bodies, body, ssPointerMapGet(bodies, body, 0) + 1) < 0)
        return ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory listing the adopted spaces' bodies");
    }
  }
  return SS_OK;
}

ssStatus ssSeenList(ssSeenSpaces* seen, dSpaceID root, ssBodyList* gone) {
  ssPointerMap bodies = {NULL, NULL, 0, 0};
  ssStatus status = listInto(seen, root, &bodies);
  for (size_t i = 0; status == SS_OK && i < seen->bodies.capacity; ++i) {
    dBodyID body = (dBodyID)seen->bodies.keys[i];
    if (body != 0 && ssPointerMapGet(&bodies, body, 0) == 0 && !ssBodyListPush(gone, body))
      status = ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory listing the adopted spaces' bodies");
  }
  if (status != SS_OK) { /* nothing remembered: the next look lists again */
    ssPointerMapFree(&bodies);
    seen->listed = 0;
    seen->count = seen->count > 0 ? 1 : 0;
    return status;
  }
  ssPointerMapFree(&seen->bodies);
  seen->bodies = bodies;
  seen->geoms = geomsNow(seen);
  seen->listed = 1;
  ssSeenMark(seen);
  return SS_OK;
}

/* The head of one space: up to its marker (the whole list when there is none). Returns 1, or 0 when the space must be
 * listed (a new nested space, a static geom moved or added, the marker moved), -1 when out of memory. *added counts
 * the geoms of the bodies met that the listing does not account for. */
static int walkHead(ssSeenSpaces* seen, ssSeenSpace* space, ssBodyList* found, ssBodyList* moved, long* added) {
  const dGeomID marker_geom = space->head_count >= 2 ? space->head[0] : 0;
  for (int i = 0, geoms = dSpaceGetNumGeoms(space->space); i < geoms; ++i) {
    dGeomID geom = dSpaceGetGeom(space->space, i);
    /* what lies behind the marker was there at the mark, unless it moved: then another follows it. The marker's own
     * move does not show when it was first already, so its body is taken as moved too */
    int marker = geom == marker_geom;
    if (marker && (space->head[1] != (i + 1 < geoms ? dSpaceGetGeom(space->space, i + 1) : 0) ||
                   space->head_bodies[0] != dGeomGetBody(geom)))
      return 0;
    if (dGeomIsSpace(geom)) {
      if (!spaceListed(seen, (dSpaceID)geom)) return 0;
      if (marker) return 1;
      continue;
    }
    dBodyID body = dGeomGetBody(geom);
    if (body == 0) return marker; /* a static geom added or moved, or one whose body was taken from it */
    if (ssPointerMapGet(&seen->bodies, body, 0) > 0) { /* listed: moved (a geom added to it shows in the count) */
      if (!dBodyIsEnabled(body) && !ssBodyListPush(moved, body)) return -1;
    } else { /* new: all its geoms there counted at its first (its next ones find it listed) */
      int held = geomsHeld(seen, body);
      *added += held;
      if (ssPointerMapPut(&seen->bodies, body, held) < 0 || !ssBodyListPush(found, body)) return -1;
    }
    if (marker) return 1;
  }
  return marker_geom == 0; /* a marker not met was destroyed (or taken out of the space) */
}

int ssSeenLook(ssSeenSpaces* seen, ssBodyList* found, ssBodyList* moved) {
  moved->count = 0;
  if (!seen->listed) return 0;
  long added = 0;
  int looked = 1;
  for (int i = 0; looked == 1 && i < seen->count; ++i)
    looked = seen->spaces[i].sweep_and_prune ? 0 : walkHead(seen, &seen->spaces[i], found, moved, &added);
  if (looked != 1) return looked;
  long now = geomsNow(seen);
  if (now != seen->geoms + added) return 0; /* a geom destroyed with ODE's own calls, or one added unseen */
  seen->geoms = now;
  return 1;
}

void ssSeenMark(ssSeenSpaces* seen) {
  for (int s = 0; s < seen->count; ++s) {
    ssSeenSpace* space = &seen->spaces[s];
    if (space->sweep_and_prune) continue; /* listed at every look */
    /* the first geoms, and a 0 after the last when the list ends within SS_SEEN_HEAD */
    const int geoms = dSpaceGetNumGeoms(space->space), kept = geoms < SS_SEEN_HEAD ? geoms + 1 : SS_SEEN_HEAD;
    for (int i = 0; i < kept; ++i) {
      dGeomID geom = i < geoms ? dSpaceGetGeom(space->space, i) : 0;
      space->head[i] = geom;
      space->head_bodies[i] = geom != 0 && !dGeomIsSpace(geom) ? dGeomGetBody(geom) : 0;
    }
    space->head_count = kept;
  }
}

void ssSeenForget(ssSeenSpaces* seen, dBodyID body) {
  /* the body's geoms leave each head, destroyed before or after: the geoms kept behind them follow each other, so
   * the first left is a marker, with the one behind it (a geom of the body still there shows as static and is
   * listed) */
  for (int s = 0; s < seen->count; ++s) {
    ssSeenSpace* space = &seen->spaces[s];
    int kept = 0;
    for (int i = 0; i < space->head_count; ++i) {
      if (space->head[i] != 0 && space->head_bodies[i] == body) continue;
      space->head[kept] = space->head[i];
      space->head_bodies[kept++] = space->head_bodies[i];
    }
    space->head_count = kept;
  }
  int held = ssPointerMapGet(&seen->bodies, body, 0);
  if (held == 0) return;
  seen->geoms -= held;
  ssPointerMapRemove(&seen->bodies, body);
}

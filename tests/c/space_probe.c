/* A child process for test_limits: collides two overlapping boxes far from the origin in one of ODE's spaces and
 * reports whether ODE kept going. ODE's hash space aborts the process once a geom's cell index leaves the integer
 * range (`aabbBound < dMaxIntExact`), so the test runs this program in a child and reads its exit status; that is
 * what SS_MAX_POSITION_M (limits.h) bounds.
 *
 * Usage: space_probe simple|hash|quadtree|sap POSITION_M SIZE_M
 *   two boxes of SIZE_M (m) on a side, their centres at (POSITION_M, POSITION_M, POSITION_M) and half a size
 *   further along x, each on a body, collided once with dSpaceCollide and then stepped once with dWorldQuickStep.
 * Exit status: 0 and "contacts N" when ODE returned, 2 for a bad command line; an abort inside ODE ends it by
 * SIGABRT. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <ode/ode.h>

static int contacts;

static void near(void* data, dGeomID a, dGeomID b) {
  (void)data;
  dContactGeom geoms[4];
  contacts += dCollide(a, b, 4, geoms, sizeof geoms[0]);
}

int main(int argc, char** argv) {
  char* end = NULL;
  double position = argc == 4 ? strtod(argv[2], &end) : 0;
  double size = argc == 4 && end != argv[2] && *end == '\0' ? strtod(argv[3], &end) : 0;
  if (argc != 4 || *end != '\0' || !(size > 0)) {
    fprintf(stderr, "usage: space_probe simple|hash|quadtree|sap POSITION_M SIZE_M\n");
    return 2;
  }
  dInitODE2(0);
  dSpaceID space;
  if (strcmp(argv[1], "simple") == 0) space = dSimpleSpaceCreate(0);
  else if (strcmp(argv[1], "hash") == 0) space = dHashSpaceCreate(0);
  else if (strcmp(argv[1], "sap") == 0) space = dSweepAndPruneSpaceCreate(0, dSAP_AXES_XYZ);
  else if (strcmp(argv[1], "quadtree") == 0) {
    dVector3 centre = {0, 0, 0, 0}, extents = {100, 100, 100, 0};
    space = dQuadTreeSpaceCreate(0, centre, extents, 6);
  } else {
    fprintf(stderr, "space_probe: unknown space %s\n", argv[1]);
    return 2;
  }
  dWorldID world = dWorldCreate();
  for (int i = 0; i < 2; ++i) {
    dBodyID body = dBodyCreate(world);
    dGeomID box = dCreateBox(space, size, size, size);
    dGeomSetBody(box, body);
    dBodySetPosition(body, position + 0.5 * size * i, position, position);
  }
  dSpaceCollide(space, NULL, near);
  dWorldQuickStep(world, 1.0 / 60);
  printf("contacts %d\n", contacts);
  return 0;
}

/* A chain of links on hinge joints, pinned at one end and released horizontal, so it swings down under gravity and
 * its links fold against their soft hinge limits.
 *
 * The first hinge (to the static world) is free; every hinge between two links has stops at +-CHAIN_LIMIT_RAD,
 * soft with the scene's spring. A hinge's five rigid rows read the world's ERP/CFM at every step, so the world is
 * bound too, to a stiff spring: otherwise those rows would keep a fixed ERP/CFM and be the one part whose
 * stiffness still changed with the frame time. */
#include <math.h>
#include <stdlib.h>

#include "lab_error.h"
#include "scene_internal.h"

#define CHAIN_LINK_M 0.25         /* link length along the chain */
#define CHAIN_THICK_M 0.04        /* link cross-section */
#define CHAIN_LIMIT_RAD 0.4
#define CHAIN_PIVOT_HEIGHT_M 2.5  /* higher than the hanging chain is long at the default count */
/* Sanity bound: a hinge's two anchors at most a fifth of a link (0.05 m) apart. The rigid rows are a stiff spring
 * (chain_world_spring), so they do open under the swing: by 5 mm in the fine-step reference and up to 2 cm under
 * the mapped policies at 15-60 fps (measured in test_bounds.cpp). A fifth of a link is a hinge
 * visibly torn open: policy naive, its softness frozen for 1/30 s, opens them beyond that at 30 fps, and under
 * 2 s frames the chain falls apart. */
#define CHAIN_MAX_GAP_OF_LINK 0.2

/* The rigid rows: per kg about 50 Hz and critically damped, far stiffer than anything the scene moves at. */
static const ssSpring chain_world_spring = {.stiffness = 1e5, .damping = 630};

typedef struct Chain {
  int count;
  dBodyID* links;
  dJointID* hinges; /* hinges[i] holds links[i] to links[i - 1], hinges[0] to the world */
} Chain;

static void destroy(void* state) {
  Chain* chain = state;
  free(chain->links);
  free(chain->hinges);
  free(chain);
}

static ssStatus build(const ssSceneWorld* world, const ssSceneParams* params, void** state) {
  Chain* chain = calloc(1, sizeof *chain);
  dBodyID* links = calloc((size_t)params->body_count, sizeof *links);
  dJointID* hinges = calloc((size_t)params->body_count, sizeof *hinges);
  if (chain == NULL || links == NULL || hinges == NULL) {
    free(chain);
    free(links);
    free(hinges);
    return ssLabFail(SS_ERROR_OUT_OF_MEMORY, "chain: out of memory for %d links", params->body_count);
  }
  chain->count = params->body_count;
  chain->links = links;
  chain->hinges = hinges;
  *state = chain;
  dWorldSetGravity(world->world, 0, 0, -params->gravity);
  ssStatus status = ssRegistry_BindWorld(world->registry, chain_world_spring, params->mass);
  for (int i = 0; status == SS_OK && i < chain->count; ++i) {
    dBodyID link = dBodyCreate(world->world);
    dMass mass;
    dMassSetBoxTotal(&mass, params->mass, CHAIN_LINK_M, CHAIN_THICK_M, CHAIN_THICK_M);
    dBodySetMass(link, &mass);
    dBodySetPosition(link, (i + 0.5) * CHAIN_LINK_M, 0, CHAIN_PIVOT_HEIGHT_M);
    links[i] = link;
    dJointID hinge = dJointCreateHinge(world->world, 0);
    dJointAttach(hinge, link, i == 0 ? 0 : links[i - 1]);
    dJointSetHingeAnchor(hinge, i * CHAIN_LINK_M, 0, CHAIN_PIVOT_HEIGHT_M);
    dJointSetHingeAxis(hinge, 0, 1, 0);
    hinges[i] = hinge;
    if (i == 0) continue;
    dJointSetHingeParam(hinge, dParamLoStop, -CHAIN_LIMIT_RAD);
    dJointSetHingeParam(hinge, dParamHiStop, CHAIN_LIMIT_RAD);
    status = ssRegistry_BindJoint(world->registry, hinge, SS_PARAM_STOP, 1, params->spring, 0);
  }
  if (status != SS_OK) {
    destroy(chain);
    *state = NULL;
  }
  return status;
}

static void sample(const void* state, double* out) {
  const Chain* chain = state;
  dVector3 end;
  dBodyGetRelPointPos(chain->links[chain->count - 1], 0.5 * CHAIN_LINK_M, 0, 0, end);
  out[0] = end[0];
  out[1] = end[2];
}

/* The widest gap between a hinge's anchor on its link and its anchor on the previous link (or the world). */
static double check(const void* state, char* worst, size_t size) {
  const Chain* chain = state;
  const double bound_m = CHAIN_MAX_GAP_OF_LINK * CHAIN_LINK_M;
  double widest_m = -INFINITY;
  int widest = 0;
  for (int i = 0; i < chain->count; ++i) {
    dVector3 on_link, on_previous;
    dJointGetHingeAnchor(chain->hinges[i], on_link);
    dJointGetHingeAnchor2(chain->hinges[i], on_previous);
    double gap_m = sqrt((on_link[0] - on_previous[0]) * (on_link[0] - on_previous[0]) +
                        (on_link[1] - on_previous[1]) * (on_link[1] - on_previous[1]) +
                        (on_link[2] - on_previous[2]) * (on_link[2] - on_previous[2]));
    if (gap_m > widest_m) {
      widest_m = gap_m;
      widest = i;
    }
  }
  ssBoundMessage(worst, size, "hinge %d: anchors %.6g m apart, bound %g m (%g of a %g m link)", widest, widest_m, bound_m,
           CHAIN_MAX_GAP_OF_LINK, CHAIN_LINK_M);
  return widest_m / bound_m;
}

/* The pivot, then the far end of each link: the chain as a polyline. */
static int points(const void* state, const ssStepper* drawn_by, double* xyz, int capacity) {
  const Chain* chain = state;
  for (int i = 0; i <= chain->count && i < capacity; ++i) {
    const double rel[3] = {(i == 0 ? -0.5 : 0.5) * CHAIN_LINK_M, 0, 0};
    ssScenePointOnBody(drawn_by, chain->links[i == 0 ? 0 : i - 1], rel, &xyz[3 * i]);
  }
  return chain->count + 1;
}

const ssSceneDesc ssChainScene = {
    .info = {.name = "chain",
             .description = "a chain on hinges with soft limits, released horizontal to swing down under gravity",
             .quantity_count = 2,
             .quantity_names = {"end x", "end z"},
             .quantity_units = {"m", "m"}},
    /* Angular: N*m/rad and N*m*s/rad. */
    .defaults = {.spring = {.stiffness = 20, .damping = 0.2}, .mass = 1, .x0 = 0, .gravity = 9.81, .body_count = 8},
    .max_body_count = 1000,
    .build = build,
    .sample = sample,
    .check = check,
    .points = points,
    .destroy = destroy,
};

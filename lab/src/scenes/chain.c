/* A chain of links on hinge joints, pinned at one end and released horizontal, so it swings down under gravity and
 * its links fold against their soft hinge limits.
 *
 * The first hinge (to the static world) is free; every hinge between two links has stops at +-CHAIN_LIMIT_RAD,
 * soft with the scene's spring. A hinge's five rigid rows read the world's ERP/CFM at every step, so the world is
 * bound too, to a stiff spring: otherwise those rows would keep a fixed ERP/CFM and be the one part whose
 * stiffness still changed with the frame time. */
#include <stdlib.h>

#include "error.h"
#include "scene_internal.h"

#define CHAIN_LINK_M 0.25         /* link length along the chain */
#define CHAIN_THICK_M 0.04        /* link cross-section */
#define CHAIN_LIMIT_RAD 0.4
#define CHAIN_PIVOT_HEIGHT_M 2.5  /* higher than the hanging chain is long at the default count */

/* The rigid rows: per kg about 50 Hz and critically damped, far stiffer than anything the scene moves at. */
static const ssSpring chain_world_spring = {.stiffness = 1e5, .damping = 630};

typedef struct Chain {
  int count;
  dBodyID* links;
} Chain;

static void destroy(void* state) {
  Chain* chain = state;
  free(chain->links);
  free(chain);
}

static ssStatus build(const ssSceneWorld* world, const ssSceneParams* params, void** state) {
  Chain* chain = calloc(1, sizeof *chain);
  dBodyID* links = calloc((size_t)params->body_count, sizeof *links);
  if (chain == NULL || links == NULL) {
    free(chain);
    free(links);
    return ssFail(SS_ERROR_OUT_OF_MEMORY, "chain: out of memory for %d links", params->body_count);
  }
  chain->count = params->body_count;
  chain->links = links;
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

/* The pivot, then the far end of each link: the chain as a polyline. */
static int points(const void* state, double* xyz, int capacity) {
  const Chain* chain = state;
  for (int i = 0; i <= chain->count && i < capacity; ++i) {
    dVector3 point;
    if (i == 0) {
      dBodyGetRelPointPos(chain->links[0], -0.5 * CHAIN_LINK_M, 0, 0, point);
    } else {
      dBodyGetRelPointPos(chain->links[i - 1], 0.5 * CHAIN_LINK_M, 0, 0, point);
    }
    for (int k = 0; k < 3; ++k) xyz[3 * i + k] = point[k];
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
    .points = points,
    .destroy = destroy,
};

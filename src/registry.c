/* The registry's bindings: springs and rates bound to ODE's per-step numbers, found through an index (binding_index.h).
 * Apply, which writes them for each step, is apply.c. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "binding_index.h"
#include "error.h"
#include "joint_rows.h"
#include "ode_bounds.h"
#include "pointer_set.h"
#include "registry_internal.h"
#include "steadystep/adopt.h"
#include "steadystep/registry.h"

/* What the program bound, and nothing derived from it: Apply keeps what it computes and writes in its own state
 * (apply.c), which it rebuilds whenever rows_revision changes. */
struct ssRegistry {
  dWorldID world;
  int world_bound;
  ssRowLaw world_law;
  double world_mass;
  double tuned_step_s;    /* adoption's tuned step; 0 before any */
  ssSoftness tuned_world; /* the world's ERP/CFM as adopted (contacts without soft modes stand for these) */
  ssJointRowBinding* joints;
  int joint_count, joint_capacity;
  ssBodyBinding* bodies;
  int body_count, body_capacity;
  /* bodies[0 .. bodies_passed) were passed by a write for bodies_passed_step_s: written for it, or asleep then (a
   * sleeping body is written before the step it wakes for, ssRegistryWriteWoken), except the places in
   * bodies_changed, changed since (bound again, followed, or the last binding moved there by an unbinding). A write
   * at that step passes only those and what was added since; more changes than the list holds lower bodies_passed
   * to the first of them instead */
  int bodies_passed;
  double bodies_passed_step_s;
  int bodies_changed[16];
  int bodies_changed_count;
  ssBindingIndex joint_index; /* (joint, rowTag) -> position in joints */
  ssBindingIndex body_index;  /* (body, 0) -> position in bodies */
  unsigned generation;    /* changes whenever the set of bound joints or bodies does */
  unsigned revision;      /* changes whenever any binding does */
  unsigned rows_revision; /* changes whenever a joint row's or the world's binding does (Apply builds its rows from
                           * these: a body adopted or followed each frame rebuilds none) */
  unsigned last_stamp; /* the last stamp given to a joint row's binding */
  ssRegistryAttachment apply; /* Apply's state (apply.c) */
};

/* A joint row's or the world's binding changed: Apply's rows are built again (rows_revision). */
static void rowsChanged(ssRegistry* registry) {
  registry->revision += 1;
  registry->rows_revision += 1;
}

/* The binding at place i changed: passed again at the next write whatever its step. */
static void bodyChangedAt(ssRegistry* registry, int i) {
  enum { kChangedMax = sizeof registry->bodies_changed / sizeof registry->bodies_changed[0] };
  if (i >= registry->bodies_passed) return;
  if (registry->bodies_changed_count < kChangedMax) {
    registry->bodies_changed[registry->bodies_changed_count++] = i;
    return;
  }
  for (int c = 0; c < registry->bodies_changed_count; ++c)
    if (registry->bodies_changed[c] < i) i = registry->bodies_changed[c];
  registry->bodies_passed = i;
  registry->bodies_changed_count = 0;
}

/* Refuses a body of another world than the registry's (0, the static world, is everyone's): the registry's writes
 * for it would be read by a world the registry never steps. */
static ssStatus requireRegistryWorld(const ssRegistry* registry, const char* what, dBodyID body) {
  if (body == 0 || dBodyGetWorld(body) == registry->world) return SS_OK;
  return ssFail(SS_ERROR_OUT_OF_RANGE, "%s: body %p is of world %p, not of the registry's world %p", what,
                (void*)body, (void*)dBodyGetWorld(body), (void*)registry->world);
}

ssRegistry* ssRegistry_Create(dWorldID world) {
  if (world == 0) {
    ssFail(SS_ERROR_OUT_OF_RANGE, "world = NULL: a world is required");
    return NULL;
  }
  ssRegistry* registry = calloc(1, sizeof *registry);
  if (registry == NULL) {
    ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory creating a registry");
    return NULL;
  }
  registry->world = world;
  return registry;
}

void ssRegistry_Destroy(ssRegistry* registry) {
  if (registry == NULL) return;
  if (registry->apply.free_state != NULL) registry->apply.free_state(registry->apply.state);
  free(registry->joints);
  free(registry->bodies);
  ssIndexFree(&registry->joint_index);
  ssIndexFree(&registry->body_index);
  free(registry);
}

void ssRegistryBindWorldLaw(ssRegistry* registry, ssRowLaw law, double effective_mass) {
  rowsChanged(registry);
  registry->world_bound = 1;
  registry->world_law = law;
  registry->world_mass = effective_mass > 0 ? effective_mass : 1.0;
}

ssStatus ssRegistry_BindWorld(ssRegistry* registry, ssSpring spring, double effective_mass) {
  REQUIRE_REGISTRY(registry);
  ssRowLaw law = ssRowLawOfSpring(spring);
  ssStatus status = ssValidateSpring(spring);
  if (status == SS_OK) status = ssCheckLawForEveryStep("world", &law);
  if (status == SS_OK) status = ssCheckNonNegative("effective_mass", "kg", effective_mass);
  if (status != SS_OK) return status;
  ssRegistryBindWorldLaw(registry, law, effective_mass);
  return SS_OK;
}

static int reserve(void** items, int count, int more, int* capacity, size_t size);

static int reserveJoints(ssRegistry* registry, int more) {
  return ssIndexReserve(&registry->joint_index, (size_t)registry->joint_count + (size_t)more) &&
         reserve((void**)&registry->joints, registry->joint_count, more, &registry->joint_capacity,
                 sizeof(ssJointRowBinding));
}

/* A joint row's tag in the index: its parameter set and axis (1..3). */
static int rowTag(ssJointParam param, int axis) { return 4 * (int)param + axis; }

static ssJointRowBinding* findJoint(ssRegistry* registry, dJointID joint, ssJointParam param, int axis) {
  int position = ssIndexFind(&registry->joint_index, joint, rowTag(param, axis));
  return position >= 0 ? &registry->joints[position] : NULL;
}

int ssRegistryHasJoint(const ssRegistry* registry, dJointID joint) {
  for (int param = SS_PARAM_JOINT; param <= SS_PARAM_SUSPENSION; ++param)
    for (int axis = 1; axis <= 3; ++axis)
      if (ssIndexFind(&registry->joint_index, joint, rowTag((ssJointParam)param, axis)) >= 0) return 1;
  return 0;
}

/* After the joints array was compacted: every position in the index again. */
static void reindexJoints(ssRegistry* registry) {
  ssIndexClear(&registry->joint_index);
  for (int i = 0; i < registry->joint_count; ++i) {
    const ssJointRowBinding* binding = &registry->joints[i];
    ssIndexPut(&registry->joint_index, binding->joint, rowTag(binding->param, binding->axis), i);
  }
}

int ssRegistryHasJointRow(ssRegistry* registry, dJointID joint, ssJointParam param, int axis) {
  return findJoint(registry, joint, param, axis) != NULL;
}

/* A fresh binding of a joint row, with a stamp of its own. */
static ssJointRowBinding newBinding(ssRegistry* registry, dJointID joint, int joint_type, ssJointParam param,
                                    int axis, ssRowLaw law, double effective_mass) {
  return (ssJointRowBinding){.joint = joint,
                             .law = law,
                             .effective_mass = effective_mass,
                             .load = 0,
                             .stamp = ++registry->last_stamp,
                             .joint_type = joint_type,
                             .param = param,
                             .axis = axis};
}

/* Appends a row not bound yet, with room reserved. */
static void appendJoint(ssRegistry* registry, dJointID joint, int joint_type, ssJointParam param, int axis,
                        ssRowLaw law, double effective_mass) {
  ssIndexPut(&registry->joint_index, joint, rowTag(param, axis), registry->joint_count);
  registry->joints[registry->joint_count++] = newBinding(registry, joint, joint_type, param, axis, law, effective_mass);
  registry->generation += 1;
}

ssStatus ssRegistryBindJointLaw(ssRegistry* registry, dJointID joint, ssJointParam param, int axis, ssRowLaw law,
                                double effective_mass) {
  rowsChanged(registry);
  int joint_type = dJointGetType(joint);
  ssJointRowBinding* existing = findJoint(registry, joint, param, axis);
  if (existing != NULL) {
    *existing = newBinding(registry, joint, joint_type, param, axis, law, effective_mass);
    return SS_OK;
  }
  if (!reserveJoints(registry, 1))
    return ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory binding a joint");
  appendJoint(registry, joint, joint_type, param, axis, law, effective_mass);
  return SS_OK;
}

void ssRegistryAppendJointLaw(ssRegistry* registry, dJointID joint, int joint_type, ssJointParam param, int axis,
                              ssRowLaw law) {
  rowsChanged(registry);
  appendJoint(registry, joint, joint_type, param, axis, law, 0);
}

ssStatus ssRegistry_BindJoint(ssRegistry* registry, dJointID joint, ssJointParam param, int axis, ssSpring spring,
                              double effective_mass) {
  REQUIRE_REGISTRY(registry);
  if (joint == 0) return ssFail(SS_ERROR_OUT_OF_RANGE, "joint = NULL: a joint is required");
  if (ssJointParamName(param) == NULL) return ssFail(SS_ERROR_UNSUPPORTED, "param = %d: unknown", (int)param);
  if (!ssJointSupports(joint, param, axis))
    return ssFail(SS_ERROR_UNSUPPORTED, "axis = %d: a %s joint has no %s parameters on it", axis,
                  ssJointTypeName(joint), ssJointParamName(param));
  ssRowLaw law = ssRowLawOfSpring(spring);
  ssStatus status = ssValidateSpring(spring);
  if (status == SS_OK) status = ssCheckLawForEveryStep("joint", &law);
  if (status == SS_OK) status = ssCheckNonNegative("effective_mass", "kg", effective_mass);
  /* ODE 0.16 has no getter for a joint's world: its bodies tell */
  for (int side = 0; side < 2 && status == SS_OK; ++side)
    status = requireRegistryWorld(registry, "joint", dJointGetBody(joint, side));
  if (status != SS_OK) return status;
  return ssRegistryBindJointLaw(registry, joint, param, axis, law, effective_mass);
}

ssStatus ssRegistry_SetJointLoad(ssRegistry* registry, dJointID joint, ssJointParam param, int axis, double load) {
  REQUIRE_REGISTRY(registry);
  ssStatus status = ssCheckFinite("load", "N or N·m", load);
  if (status == SS_OK && fabs(load) > SS_MAX_FORCE_N)
    status = ssFail(SS_ERROR_OUT_OF_RANGE, "load = %g N or N·m: must be at most SS_MAX_FORCE_N = %g in size", load,
                    SS_MAX_FORCE_N);
  if (status != SS_OK) return status;
  ssJointRowBinding* binding = findJoint(registry, joint, param, axis);
  if (binding == NULL)
    return ssFail(SS_ERROR_NOT_FOUND, "joint %p, param %d, axis %d: not bound", (void*)joint, (int)param, axis);
  if (!ssJointRowHasDirection(joint, param, axis))
    return ssFail(SS_ERROR_UNSUPPORTED, "a %s joint's %s rows have no single direction to carry a load",
                  ssJointTypeName(joint), ssJointParamName(param));
  binding->load = load;
  rowsChanged(registry);
  return SS_OK;
}

ssStatus ssRegistry_UnbindJoint(ssRegistry* registry, dJointID joint) {
  REQUIRE_REGISTRY(registry);
  int kept = 0;
  for (int i = 0; i < registry->joint_count; ++i)
    if (registry->joints[i].joint != joint) registry->joints[kept++] = registry->joints[i];
  if (kept == registry->joint_count) return ssFail(SS_ERROR_NOT_FOUND, "joint %p: not bound", (void*)joint);
  registry->joint_count = kept;
  reindexJoints(registry);
  registry->generation += 1;
  rowsChanged(registry);
  return SS_OK;
}

int ssRegistryUnbindJointsNotIn(ssRegistry* registry, const ssPointerSet* alive) {
  int kept = 0;
  for (int i = 0; i < registry->joint_count; ++i)
    if (ssPointerSetHas(alive, registry->joints[i].joint)) registry->joints[kept++] = registry->joints[i];
  int unbound = registry->joint_count - kept;
  if (unbound == 0) return 0;
  registry->joint_count = kept;
  reindexJoints(registry);
  registry->generation += 1;
  rowsChanged(registry);
  return unbound;
}

ssBodyBinding* ssRegistryFindBody(ssRegistry* registry, dBodyID body) {
  int position = ssIndexFind(&registry->body_index, body, 0);
  return position >= 0 ? &registry->bodies[position] : NULL;
}

static int reserveBodies(ssRegistry* registry, int more) {
  return ssIndexReserve(&registry->body_index, (size_t)registry->body_count + (size_t)more) &&
         reserve((void**)&registry->bodies, registry->body_count, more, &registry->body_capacity,
                 sizeof(ssBodyBinding));
}

int ssRegistryHasBody(ssRegistry* registry, dBodyID body) { return ssRegistryFindBody(registry, body) != NULL; }

/* The binding of body (0: the world's defaults), created empty if absent; NULL when out of memory. */
static ssBodyBinding* bodyBinding(ssRegistry* registry, dBodyID body) {
  ssBodyBinding* binding = ssRegistryFindBody(registry, body);
  if (binding != NULL) return binding;
  if (!reserveBodies(registry, 1)) return NULL;
  ssIndexPut(&registry->body_index, body, 0, registry->body_count);
  binding = &registry->bodies[registry->body_count++];
  registry->generation += 1;
  registry->revision += 1;
  memset(binding, 0, sizeof *binding);
  binding->body = body;
  binding->written_step_s = NAN;
  return binding;
}

void ssRegistryAppendBody(ssRegistry* registry, const ssBodyBinding* binding) {
  ssIndexPut(&registry->body_index, binding->body, 0, registry->body_count);
  registry->bodies[registry->body_count++] = *binding;
  registry->generation += 1;
  registry->revision += 1;
}

ssStatus ssRegistry_BindDamping(ssRegistry* registry, dBodyID body, double linear_rate_per_s,
                                double angular_rate_per_s) {
  REQUIRE_REGISTRY(registry);
  ssStatus status = ssCheckNonNegative("linear_rate_per_s", "1/s", linear_rate_per_s);
  if (status == SS_OK) status = ssCheckNonNegative("angular_rate_per_s", "1/s", angular_rate_per_s);
  if (status == SS_OK) status = requireRegistryWorld(registry, "damping", body);
  if (status != SS_OK) return status;
  ssBodyBinding* binding = bodyBinding(registry, body);
  if (binding == NULL) return ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory binding damping");
  bodyChangedAt(registry, (int)(binding - registry->bodies));
  binding->has_damping = 1;
  binding->linear_rate_per_s = linear_rate_per_s;
  binding->angular_rate_per_s = angular_rate_per_s;
  binding->tuned.damping_step_s = 0;
  binding->written_step_s = NAN;
  registry->revision += 1;
  return SS_OK;
}

ssStatus ssRegistry_BindAutoDisable(ssRegistry* registry, dBodyID body, double idle_time_s, double average_window_s) {
  REQUIRE_REGISTRY(registry);
  ssStatus status = ssCheckPositive("idle_time_s", "s", idle_time_s);
  if (status == SS_OK) status = ssCheckNonNegative("average_window_s", "s", average_window_s);
  if (status == SS_OK) status = requireRegistryWorld(registry, "auto-disable", body);
  if (status != SS_OK) return status;
  ssBodyBinding* binding = bodyBinding(registry, body);
  if (binding == NULL) return ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory binding auto-disable");
  bodyChangedAt(registry, (int)(binding - registry->bodies));
  binding->has_auto_disable = 1;
  binding->idle_time_s = idle_time_s;
  binding->average_window_s = average_window_s;
  binding->tuned.auto_disable_step_s = 0;
  binding->average_samples_written = 0;
  binding->written_step_s = NAN;
  registry->revision += 1;
  return SS_OK;
}

ssStatus ssRegistry_UnbindBody(ssRegistry* registry, dBodyID body) {
  REQUIRE_REGISTRY(registry);
  int position = ssIndexFind(&registry->body_index, body, 0);
  if (position < 0) return ssFail(SS_ERROR_NOT_FOUND, "body %p: not bound", (void*)body);
  ssIndexRemove(&registry->body_index, body, 0);
  registry->bodies[position] = registry->bodies[--registry->body_count];
  bodyChangedAt(registry, position); /* the last binding moved there */
  if (position < registry->body_count) ssIndexPut(&registry->body_index, registry->bodies[position].body, 0, position);
  registry->generation += 1;
  registry->revision += 1;
  return SS_OK;
}

/* The body's numbers for a step of step_s: at the step adoption read them for, the program's own; otherwise what the
 * rates and seconds stand for at this step. */
static void writeBody(ssBodyBinding* binding, dWorldID world, double step_s) {
  dBodyID body = binding->body;
  ssBodyWritten values;
  ssBodyWrittenFor(binding, step_s, &values);
  if (binding->has_damping) {
    if (body) {
      dBodySetLinearDamping(body, values.linear_scale);
      dBodySetAngularDamping(body, values.angular_scale);
    } else {
      dWorldSetLinearDamping(world, values.linear_scale);
      dWorldSetAngularDamping(world, values.angular_scale);
    }
  }
  if (binding->has_auto_disable) {
    if (body) {
      dBodySetAutoDisableSteps(body, values.idle_steps);
      dBodySetAutoDisableTime(body, values.idle_time_s);
      if (values.average_samples != binding->average_samples_written)
        dBodySetAutoDisableAverageSamplesCount(body, (unsigned)values.average_samples);
    } else {
      dWorldSetAutoDisableSteps(world, values.idle_steps);
      dWorldSetAutoDisableTime(world, values.idle_time_s);
      if (values.average_samples != binding->average_samples_written)
        dWorldSetAutoDisableAverageSamplesCount(world, (unsigned)values.average_samples);
    }
    binding->average_samples_written = values.average_samples;
  }
  binding->written_step_s = step_s;
  binding->written = values;
}

void ssRegistryWriteWoken(ssRegistry* registry, const dBodyID* bodies, int count, double step_s) {
  for (int i = 0; i < count; ++i) {
    ssBodyBinding* binding = ssRegistryFindBody(registry, bodies[i]);
    if (binding == NULL || binding->written_step_s == step_s) continue;
    writeBody(binding, registry->world, step_s);
    if (step_s != registry->bodies_passed_step_s) bodyChangedAt(registry, (int)(binding - registry->bodies));
  }
}

/* The binding at place i, for a write at step_s: written unless it was for step_s already, or it sleeps (written when
 * it wakes, as the program's writes to it are followed then, follow.c). */
static void passBody(ssRegistry* registry, int i, double step_s) {
  ssBodyBinding* binding = &registry->bodies[i];
  if (binding->written_step_s != step_s && (binding->body == 0 || dBodyIsEnabled(binding->body)))
    writeBody(binding, registry->world, step_s);
}

void ssRegistryWriteBodies(ssRegistry* registry, double step_s) {
  /* at the step of the last pass, only what changed or was added since: a sleeping level is not walked again */
  int from = 0;
  if (step_s == registry->bodies_passed_step_s) {
    from = registry->bodies_passed;
    for (int c = 0; c < registry->bodies_changed_count; ++c) {
      int i = registry->bodies_changed[c]; /* a place an unbinding emptied since is past the end */
      if (i < from && i < registry->body_count) passBody(registry, i, step_s);
    }
  }
  for (int i = from; i < registry->body_count; ++i) passBody(registry, i, step_s);
  registry->bodies_passed = registry->body_count;
  registry->bodies_passed_step_s = step_s;
  registry->bodies_changed_count = 0;
}

dWorldID ssRegistryWorld(const ssRegistry* registry) { return registry->world; }

static int reserve(void** items, int count, int more, int* capacity, size_t size) {
  if (count + more <= *capacity) return 1;
  int wanted = *capacity ? 2 * *capacity : 8; /* doubling: bodies bound one by one cost O(1) each */
  if (wanted < count + more) wanted = count + more;
  void* larger = realloc(*items, (size_t)wanted * size);
  if (larger == NULL) return 0;
  *items = larger;
  *capacity = wanted;
  return 1;
}

ssStatus ssRegistryReserve(ssRegistry* registry, int more_joints, int more_bodies) {
  if (!reserveJoints(registry, more_joints) || !reserveBodies(registry, more_bodies))
    return ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory reserving %d joint rows and %d bodies", more_joints,
                  more_bodies);
  return SS_OK;
}

double ssRegistry_TunedStep(const ssRegistry* registry) { return registry != NULL ? registry->tuned_step_s : 0; }

void ssRegistrySetTuned(ssRegistry* registry, double tuned_step_s, ssSoftness tuned_world) {
  rowsChanged(registry);
  registry->tuned_step_s = tuned_step_s;
  registry->tuned_world = tuned_world;
}


ssSoftness ssRegistryTunedWorld(const ssRegistry* registry) { return registry->tuned_world; }

int ssRegistryWorldBound(const ssRegistry* registry, ssRowLaw* law) {
  if (registry->world_bound && law != NULL) *law = registry->world_law;
  return registry->world_bound;
}


int ssRegistry_JointBindingCount(const ssRegistry* registry) { return registry != NULL ? registry->joint_count : 0; }

int ssRegistryBodyBindingCount(const ssRegistry* registry) { return registry->body_count; }

unsigned ssRegistryGeneration(const ssRegistry* registry) { return registry->generation; }

const ssJointRowBinding* ssRegistryJointRowAt(const ssRegistry* registry, int i) { return &registry->joints[i]; }

unsigned ssRegistryLastStamp(const ssRegistry* registry) { return registry->last_stamp; }

unsigned ssRegistryRevision(const ssRegistry* registry) { return registry->revision; }

unsigned ssRegistryRowsRevision(const ssRegistry* registry) { return registry->rows_revision; }

void ssRegistryFollowJointLaw(ssRegistry* registry, int i, ssRowLaw law) {
  registry->joints[i].law = law;
  rowsChanged(registry);
}

void ssRegistryFollowWorldLaw(ssRegistry* registry, ssRowLaw law) {
  registry->world_law = law;
  if (registry->tuned_step_s > 0) registry->tuned_world = law.tuned; /* contacts without soft modes */
  rowsChanged(registry);
}

void ssRegistryFollowBody(ssRegistry* registry, int i, const ssBodyBinding* binding) {
  registry->bodies[i] = *binding;
  bodyChangedAt(registry, i);
  registry->revision += 1;
}

ssRegistryAttachment* ssRegistryApplyAttachment(ssRegistry* registry) { return &registry->apply; }

ssBodyBinding* ssRegistryBodyAt(ssRegistry* registry, int i) { return &registry->bodies[i]; }

double ssRegistryWorldMass(const ssRegistry* registry) { return registry->world_mass; }

/* Every bound body, with repeats, without allocating. */
static void visitBodiesRepeated(const ssRegistry* registry, void (*visit)(void* context, dBodyID body),
                                void* context) {
  for (int i = 0; i < registry->joint_count; ++i)
    for (int side = 0; side < 2; ++side) {
      dBodyID body = dJointGetBody(registry->joints[i].joint, side);
      if (body != 0) visit(context, body);
    }
  for (int i = 0; i < registry->body_count; ++i)
    if (registry->bodies[i].body != 0) visit(context, registry->bodies[i].body);
}

typedef struct BodyList {
  dBodyID* bodies;
  int count;
} BodyList;

static void appendBody(void* context, dBodyID body) {
  BodyList* list = context;
  list->bodies[list->count++] = body;
}

void ssRegistry_VisitBodies(const ssRegistry* registry, void (*visit)(void* context, dBodyID body), void* context) {
  if (registry == NULL || visit == NULL) return;
  size_t most = 2 * (size_t)registry->joint_count + (size_t)registry->body_count;
  BodyList list = {malloc((most ? most : 1) * sizeof(dBodyID)), 0};
  if (list.bodies == NULL) { /* rather a body twice than none */
    visitBodiesRepeated(registry, visit, context);
    return;
  }
  visitBodiesRepeated(registry, appendBody, &list);
  qsort(list.bodies, (size_t)list.count, sizeof(dBodyID), ssCompareHandles);
  for (int i = 0; i < list.count; ++i)
    if (i == 0 || list.bodies[i] != list.bodies[i - 1]) visit(context, list.bodies[i]);
  free(list.bodies);
}

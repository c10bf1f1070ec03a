/* The registry: bindings of springs and rates to ODE's per-step numbers, written for each step length.
 * Apply works in two passes, compute then write, so that an error leaves every ODE object as it was. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "array.h"
#include "error.h"
#include "joint_rows.h"
#include "registry_internal.h"
#include "steadystep/registry.h"

typedef struct JointBinding {
  dJointID joint;
  ssJointParam param;
  int axis;
  ssSpring spring;
  double effective_mass; /* 0: computed from the bodies at each Apply */
  ssSoftness pending;    /* computed in Apply's first pass */
  ssSoftness written;    /* last written: the registry owns the row, so an unchanged value is not written again */
  double load; /* the steady force or torque the row carries (ssRegistry_SetJointLoad); 0 = none declared */
  /* The spring mapping needs the mass only for the Nyquist report: it is refreshed every few Applies there. */
  double report_mass;
  int report_mass_age;
} JointBinding;

typedef struct BodyBinding {
  dBodyID body; /* 0: the world's defaults */
  int has_damping;
  double linear_rate_per_s, angular_rate_per_s;
  int has_auto_disable;
  double idle_time_s, average_window_s;
  int average_samples_written; /* ODE restarts its average whenever the count is set: write it only on change */
} BodyBinding;

struct ssRegistry {
  dWorldID world;
  int world_bound;
  ssSpring world_spring;
  double world_mass;
  ssSoftness world_pending;
  JointBinding* joints;
  int joint_count, joint_capacity;
  BodyBinding* bodies;
  int body_count, body_capacity;
  unsigned generation; /* changes whenever the set of bound joints or bodies does */
};

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
  free(registry->joints);
  free(registry->bodies);
  free(registry);
}

ssStatus ssRegistry_BindWorld(ssRegistry* registry, ssSpring spring, double effective_mass) {
  ssStatus status = ssValidateSpring(spring);
  if (status == SS_OK) status = ssCheckNonNegative("effective_mass", "kg", effective_mass);
  if (status != SS_OK) return status;
  registry->world_bound = 1;
  registry->world_spring = spring;
  registry->world_mass = effective_mass > 0 ? effective_mass : 1.0;
  return SS_OK;
}

ssStatus ssRegistry_BindJoint(ssRegistry* registry, dJointID joint, ssJointParam param, int axis, ssSpring spring,
                              double effective_mass) {
  if (joint == 0) return ssFail(SS_ERROR_OUT_OF_RANGE, "joint = NULL: a joint is required");
  if (ssJointParamName(param) == NULL) return ssFail(SS_ERROR_UNSUPPORTED, "param = %d: unknown", (int)param);
  if (!ssJointSupports(joint, param, axis))
    return ssFail(SS_ERROR_UNSUPPORTED, "axis = %d: a %s joint has no %s parameters on it", axis,
                  ssJointTypeName(joint), ssJointParamName(param));
  ssStatus status = ssValidateSpring(spring);
  if (status == SS_OK) status = ssCheckNonNegative("effective_mass", "kg", effective_mass);
  if (status != SS_OK) return status;

  JointBinding binding = {joint, param, axis, spring, effective_mass, {0, 0}, {NAN, NAN}, 0, NAN, 0};
  for (int i = 0; i < registry->joint_count; ++i) {
    JointBinding* existing = &registry->joints[i];
    if (existing->joint == joint && existing->param == param && existing->axis == axis) {
      *existing = binding;
      return SS_OK;
    }
  }
  if (!ssReserveOne((void**)&registry->joints, registry->joint_count, &registry->joint_capacity, sizeof binding))
    return ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory binding a joint");
  registry->joints[registry->joint_count++] = binding;
  registry->generation += 1;
  return SS_OK;
}

ssStatus ssRegistry_SetJointLoad(ssRegistry* registry, dJointID joint, ssJointParam param, int axis, double load) {
  ssStatus status = ssCheckFinite("load", "N or N·m", load);
  if (status != SS_OK) return status;
  for (int i = 0; i < registry->joint_count; ++i) {
    JointBinding* binding = &registry->joints[i];
    if (binding->joint != joint || binding->param != param || binding->axis != axis) continue;
    if (!ssJointRowHasDirection(joint, param, axis))
      return ssFail(SS_ERROR_UNSUPPORTED, "a %s joint's %s rows have no single direction to carry a load",
                    ssJointTypeName(joint), ssJointParamName(param));
    binding->load = load;
    return SS_OK;
  }
  return ssFail(SS_ERROR_NOT_FOUND, "joint %p, param %d, axis %d: not bound", (void*)joint, (int)param, axis);
}

ssStatus ssRegistry_UnbindJoint(ssRegistry* registry, dJointID joint) {
  int kept = 0;
  for (int i = 0; i < registry->joint_count; ++i)
    if (registry->joints[i].joint != joint) registry->joints[kept++] = registry->joints[i];
  if (kept == registry->joint_count) return ssFail(SS_ERROR_NOT_FOUND, "joint %p: not bound", (void*)joint);
  registry->joint_count = kept;
  registry->generation += 1;
  return SS_OK;
}

/* The binding of body (0: the world's defaults), created empty if absent; NULL when out of memory. */
static BodyBinding* bodyBinding(ssRegistry* registry, dBodyID body) {
  for (int i = 0; i < registry->body_count; ++i)
    if (registry->bodies[i].body == body) return &registry->bodies[i];
  if (!ssReserveOne((void**)&registry->bodies, registry->body_count, &registry->body_capacity, sizeof(BodyBinding)))
    return NULL;
  BodyBinding* binding = &registry->bodies[registry->body_count++];
  registry->generation += 1;
  memset(binding, 0, sizeof *binding);
  binding->body = body;
  return binding;
}

ssStatus ssRegistry_BindDamping(ssRegistry* registry, dBodyID body, double linear_rate_per_s,
                                double angular_rate_per_s) {
  ssStatus status = ssCheckNonNegative("linear_rate_per_s", "1/s", linear_rate_per_s);
  if (status == SS_OK) status = ssCheckNonNegative("angular_rate_per_s", "1/s", angular_rate_per_s);
  if (status != SS_OK) return status;
  BodyBinding* binding = bodyBinding(registry, body);
  if (binding == NULL) return ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory binding damping");
  binding->has_damping = 1;
  binding->linear_rate_per_s = linear_rate_per_s;
  binding->angular_rate_per_s = angular_rate_per_s;
  return SS_OK;
}

ssStatus ssRegistry_BindAutoDisable(ssRegistry* registry, dBodyID body, double idle_time_s, double average_window_s) {
  ssStatus status = ssCheckPositive("idle_time_s", "s", idle_time_s);
  if (status == SS_OK) status = ssCheckNonNegative("average_window_s", "s", average_window_s);
  if (status != SS_OK) return status;
  BodyBinding* binding = bodyBinding(registry, body);
  if (binding == NULL) return ssFail(SS_ERROR_OUT_OF_MEMORY, "out of memory binding auto-disable");
  binding->has_auto_disable = 1;
  binding->idle_time_s = idle_time_s;
  binding->average_window_s = average_window_s;
  binding->average_samples_written = 0;
  return SS_OK;
}

ssStatus ssRegistry_UnbindBody(ssRegistry* registry, dBodyID body) {
  for (int i = 0; i < registry->body_count; ++i) {
    if (registry->bodies[i].body != body) continue;
    registry->bodies[i] = registry->bodies[--registry->body_count];
    registry->generation += 1;
    return SS_OK;
  }
  return ssFail(SS_ERROR_NOT_FOUND, "body %p: not bound", (void*)body);
}

/* Prefixes the current message with what failed, so that a caller of Apply learns which binding it was. */
static ssStatus failBinding(ssStatus status, const JointBinding* binding) {
  char cause[200];
  strncpy(cause, ssLastError(), sizeof cause - 1);
  cause[sizeof cause - 1] = '\0';
  if (binding == NULL) return ssFail(status, "world ERP/CFM: %s", cause);
  return ssFail(status, "%s joint %p, %s axis %d: %s", ssJointTypeName(binding->joint), (void*)binding->joint,
                ssJointParamName(binding->param), binding->axis, cause);
}

/* How many Applies of the spring mapping reuse a computed effective mass for the Nyquist report. */
enum { kReportMassRefresh = 16 };

/* w·h > π, i.e. k·h² > π²·m: the natural frequency is above half the step rate. */
static int overNyquist(ssSpring spring, double mass, double step_s) {
  return spring.stiffness * step_s * step_s > M_PI * M_PI * mass;
}

ssStatus ssSoftnessOrMatched(ssMapping mapping, ssSpring spring, double mass, double step_s,
                             double previous_step_s, int* fell_back, ssSoftness* out) {
  *fell_back = 0;
  ssStatus status = ssSoftnessFor(mapping, spring, mass, step_s, previous_step_s, out);
  if (status == SS_ERROR_NO_FINITE_MAPPING && mapping == SS_MAPPING_EXACT && spring.damping > 0) {
    status = ssMatchedSoftness(spring, mass, step_s, out);
    *fell_back = status == SS_OK;
  }
  return status;
}

/* The softness of one spring for this step, counting exact's fallbacks in the report. */
static ssStatus softnessFor(ssMapping mapping, ssSpring spring, double mass, double step_s, double previous_step_s,
                            ssApplyReport* report, ssSoftness* out) {
  int fell_back;
  ssStatus status = ssSoftnessOrMatched(mapping, spring, mass, step_s, previous_step_s, &fell_back, out);
  report->rows_exact_fallback += fell_back;
  return status;
}

/* The binding's mass for this Apply: given, or computed (every time where the mapping depends on it). NAN when the
 * spring mapping cannot have one, which only skips the Nyquist report. */
static ssStatus bindingMass(JointBinding* binding, ssMapping mapping, double* mass) {
  if (binding->effective_mass > 0) {
    *mass = binding->effective_mass;
    return SS_OK;
  }
  if (mapping == SS_MAPPING_SPRING && binding->report_mass_age > 0) {
    binding->report_mass_age -= 1;
    *mass = binding->report_mass;
    return SS_OK;
  }
  ssStatus status = ssJointEffectiveMass(binding->joint, binding->param, binding->axis, mass);
  if (status != SS_OK && mapping != SS_MAPPING_SPRING) return status;
  if (status != SS_OK) *mass = NAN;
  binding->report_mass = *mass;
  binding->report_mass_age = kReportMassRefresh;
  return SS_OK;
}

/* Whether two bindings drive rows along the same axis of the same joint (a stop and a motor). */
static int sharesRow(const JointBinding* a, const JointBinding* b) {
  int a_limit = a->param == SS_PARAM_STOP || a->param == SS_PARAM_MOTOR;
  int b_limit = b->param == SS_PARAM_STOP || b->param == SS_PARAM_MOTOR;
  return a->joint == b->joint && a->axis == b->axis && a_limit && b_limit;
}

ssStatus ssRegistry_Apply(ssRegistry* registry, ssMapping mapping, double step_s, double previous_step_s,
                          ssApplyReport* report) {
  ssStatus status = ssCheckPositive("step_s", "s", step_s);
  if (status == SS_OK) status = ssCheckNonNegative("previous_step_s", "s", previous_step_s);
  if (status != SS_OK) return status;
  if (ssMappingName(mapping) == NULL) return ssFail(SS_ERROR_UNSUPPORTED, "mapping = %d: unknown", (int)mapping);

  ssApplyReport counts = {0, 0, 0};
  if (registry->world_bound) {
    status = softnessFor(mapping, registry->world_spring, registry->world_mass, step_s, previous_step_s, &counts,
                         &registry->world_pending);
    if (status != SS_OK) return failBinding(status, NULL);
    counts.rows_over_nyquist += overNyquist(registry->world_spring, registry->world_mass, step_s);
  }
  /* Programs bind many rows to a few springs: under the spring mapping each one's softness is computed once. */
  enum { kCacheSize = 4 };
  ssSpring cached_spring[kCacheSize];
  ssSoftness cached_softness[kCacheSize];
  int cached = 0;
  double last_mass = NAN;
  for (int i = 0; i < registry->joint_count; ++i) {
    JointBinding* binding = &registry->joints[i];
    double mass;
    const JointBinding* before = i > 0 ? &registry->joints[i - 1] : NULL;
    if (before != NULL && sharesRow(before, binding) && binding->effective_mass == before->effective_mass) {
      mass = last_mass; /* a stop and a motor on one axis move the same mass: computed once */
    } else {
      status = bindingMass(binding, mapping, &mass);
      if (status != SS_OK) return failBinding(status, binding);
    }
    last_mass = mass;
    int hit = -1;
    for (int j = 0; j < cached && hit < 0; ++j)
      if (cached_spring[j].stiffness == binding->spring.stiffness && cached_spring[j].damping == binding->spring.damping)
        hit = j;
    if (hit >= 0) {
      binding->pending = cached_softness[hit];
    } else {
      status = softnessFor(mapping, binding->spring, mass, step_s, previous_step_s, &counts, &binding->pending);
      if (status != SS_OK) return failBinding(status, binding);
      if (mapping == SS_MAPPING_SPRING) {
        int slot = cached < kCacheSize ? cached++ : i % kCacheSize;
        cached_spring[slot] = binding->spring;
        cached_softness[slot] = binding->pending;
      }
    }
    counts.rows_over_nyquist += overNyquist(binding->spring, mass, step_s); /* false for a NAN mass */
  }

  /* Second pass: nothing below can fail. */
  if (registry->world_bound) {
    dWorldSetERP(registry->world, registry->world_pending.erp);
    dWorldSetCFM(registry->world, registry->world_pending.cfm);
    counts.rows_written += 1;
  }
  for (int i = 0; i < registry->joint_count; ++i) {
    JointBinding* binding = &registry->joints[i];
    if (binding->pending.erp == binding->written.erp && binding->pending.cfm == binding->written.cfm) continue;
    ssJointWriteSoftness(binding->joint, binding->param, binding->axis, binding->pending.erp, binding->pending.cfm);
    binding->written = binding->pending;
  }
  if (mapping != SS_MAPPING_SPRING) {
    for (int i = 0; i < registry->joint_count; ++i) {
      const JointBinding* binding = &registry->joints[i];
      if (binding->load == 0 || binding->spring.stiffness == 0) continue;
      /* the step's static stiffness is k' = erp/(h·cfm): this force puts the rest position back at load/k */
      double static_stiffness = binding->pending.erp / (step_s * binding->pending.cfm);
      ssJointAddRowForce(binding->joint, binding->param, binding->axis,
                         binding->load * (static_stiffness / binding->spring.stiffness - 1));
    }
  }
  counts.rows_written += registry->joint_count;
  for (int i = 0; i < registry->body_count; ++i) {
    BodyBinding* binding = &registry->bodies[i];
    dBodyID body = binding->body;
    if (binding->has_damping) {
      /* ODE scales velocity by (1 - scale) once per step: this scale removes the same fraction per second */
      double linear = -expm1(-binding->linear_rate_per_s * step_s);
      double angular = -expm1(-binding->angular_rate_per_s * step_s);
      if (body) {
        dBodySetLinearDamping(body, linear);
        dBodySetAngularDamping(body, angular);
      } else {
        dWorldSetLinearDamping(registry->world, linear);
        dWorldSetAngularDamping(registry->world, angular);
      }
    }
    if (binding->has_auto_disable) {
      double steps = ceil(binding->idle_time_s / step_s);
      int idle_steps = steps < INT32_MAX ? (int)steps : INT32_MAX;
      double samples = fmax(1.0, ceil(binding->average_window_s / step_s));
      int average_samples = samples < 1e6 ? (int)samples : 1000000;
      if (body) {
        dBodySetAutoDisableSteps(body, idle_steps);
        dBodySetAutoDisableTime(body, binding->idle_time_s);
        if (average_samples != binding->average_samples_written)
          dBodySetAutoDisableAverageSamplesCount(body, (unsigned)average_samples);
      } else {
        dWorldSetAutoDisableSteps(registry->world, idle_steps);
        dWorldSetAutoDisableTime(registry->world, binding->idle_time_s);
        if (average_samples != binding->average_samples_written)
          dWorldSetAutoDisableAverageSamplesCount(registry->world, (unsigned)average_samples);
      }
      binding->average_samples_written = average_samples;
    }
  }
  if (report != NULL) *report = counts;
  return SS_OK;
}

int ssRegistry_JointBindingCount(const ssRegistry* registry) { return registry->joint_count; }

int ssRegistryBodyBindingCount(const ssRegistry* registry) { return registry->body_count; }

unsigned ssRegistryGeneration(const ssRegistry* registry) { return registry->generation; }

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

static int compareBodies(const void* a, const void* b) {
  uintptr_t x = (uintptr_t) * (const dBodyID*)a, y = (uintptr_t) * (const dBodyID*)b;
  return (x > y) - (x < y);
}

void ssRegistry_VisitBodies(const ssRegistry* registry, void (*visit)(void* context, dBodyID body), void* context) {
  size_t most = 2 * (size_t)registry->joint_count + (size_t)registry->body_count;
  BodyList list = {malloc((most ? most : 1) * sizeof(dBodyID)), 0};
  if (list.bodies == NULL) { /* rather a body twice than none */
    visitBodiesRepeated(registry, visit, context);
    return;
  }
  visitBodiesRepeated(registry, appendBody, &list);
  qsort(list.bodies, (size_t)list.count, sizeof(dBodyID), compareBodies);
  for (int i = 0; i < list.count; ++i)
    if (i == 0 || list.bodies[i] != list.bodies[i - 1]) visit(context, list.bodies[i]);
  free(list.bodies);
}

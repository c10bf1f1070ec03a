/* The differential check of Apply (apply_differential.h). */
#include "apply_differential.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include <ode/ode.h>

#include "apply_internal.h"
#include "apply_reference.h"
#include "joint_rows.h"
#include "registry_internal.h"
#include "row_law.h"
#include "steadystep/steadystep.h"

enum { kBodies = 6, kJoints = 8, kLaws = 24, kMaxOps = 400 };

typedef struct Twin {
  dWorldID world;
  ssRegistry* registry;
  dBodyID bodies[kBodies];
  dJointID joints[kJoints];
  unsigned applied_stamp; /* the reference's */
} Twin;

typedef struct Reader {
  const uint8_t* data;
  size_t size, at;
} Reader;

static unsigned next(Reader* reader) { return reader->at < reader->size ? reader->data[reader->at++] : 0; }

static const double kSteps[] = {1.0 / 240, 1.0 / 120, 1.0 / 90, 1.0 / 60, 1.0 / 45, 1.0 / 30, 0.05, 0.004};
static const double kMasses[] = {0.5, 1.0, 2.0, 7.5, 20.0, 0.05};
static const double kEffectiveMasses[] = {0, 0, 0, 0.1, 1.0, 50.0};
static const double kLoads[] = {0, -9.81, 25.0, -400.0, 3e4, 1e6};

/* More laws than Apply's table holds: springs stiff and soft (some above Nyquist at the longer steps), dampers,
 * undamped springs, hard rows with finite and infinite rates, and the world's own. */
static ssRowLaw lawAt(int index) {
  ssRowLaw law = ssRowLawOfSpring((ssSpring){0, 0});
  switch (index % 6) {
    case 0: law = ssRowLawOfSpring((ssSpring){5.0 * (1 + index), 0.05 * (1 + index % 5)}); break;
    case 1: /* every other one read from a program's erp/cfm tuned at 1/60 s (adoption), one of the steps */
      if (index % 12 == 7) ssRowLawFromTuned("law", 0.3 + 0.01 * index, 1e-4 * (1 + index % 5), 1.0 / 60, &law);
      else law = ssRowLawOfSpring((ssSpring){400.0 + 97.0 * index, 12.0});
      break;
    case 2: law = ssRowLawOfSpring((ssSpring){0.0, 0.01 * (1 + index)}); break;        /* a damper */
    case 3: law = ssRowLawOfSpring((ssSpring){1e5 * (1 + index % 3), 30.0 + index}); break; /* above Nyquist */
    case 4: law = ssRowLawOfSpring((ssSpring){50.0 + index, 0.0}); break;              /* undamped */
    case 5:
      law = (ssRowLaw){.hard = 1, .hard_rate_per_s = index % 4 == 1 ? INFINITY : 2.0 + index}; /* hard */
      break;
  }
  return law;
}

static dJointID makeJoint(dWorldID world, int index, dBodyID a, dBodyID b) {
  dJointID joint = 0;
  switch (index % 6) {
    case 0: joint = dJointCreateHinge(world, 0); break;
    case 1: joint = dJointCreateSlider(world, 0); break;
    case 2: joint = dJointCreateHinge2(world, 0); break;
    case 3: joint = dJointCreateUniversal(world, 0); break;
    case 4: joint = dJointCreateBall(world, 0); break;
    case 5: joint = dJointCreatePiston(world, 0); break;
  }
  dJointAttach(joint, a, b);
  switch (index % 6) {
    case 0:
      dJointSetHingeAnchor(joint, 0.1 * index, 0, 1);
      dJointSetHingeAxis(joint, 0, 1, 0);
      dJointSetHingeParam(joint, dParamLoStop, -0.2);
      dJointSetHingeParam(joint, dParamHiStop, 0.2);
      break;
    case 1: dJointSetSliderAxis(joint, 0, 0, 1); break;
    case 2:
      dJointSetHinge2Anchor(joint, 0, 0.1 * index, 1);
      dJointSetHinge2Axes(joint, (dReal[]){0, 0, 1}, (dReal[]){0, 1, 0});
      break;
    case 3:
      dJointSetUniversalAnchor(joint, 0.1, 0.1 * index, 1);
      dJointSetUniversalAxis1(joint, 1, 0, 0);
      dJointSetUniversalAxis2(joint, 0, 1, 0);
      break;
    case 4: dJointSetBallAnchor(joint, 0, 0, 1 + 0.1 * index); break;
    case 5: dJointSetPistonAnchor(joint, 0, 0.1 * index, 1); dJointSetPistonAxis(joint, 1, 0, 0); break;
  }
  return joint;
}

static int isHinge2(int joint) { return joint % 6 == 2; }

static void buildTwin(Twin* twin) {
  twin->world = dWorldCreate();
  dWorldSetGravity(twin->world, 0, 0, -9.81);
  dWorldSetQuickStepNumIterations(twin->world, 10);
  twin->registry = ssRegistry_Create(twin->world);
  twin->applied_stamp = 0;
  for (int i = 0; i < kBodies; ++i) {
    twin->bodies[i] = dBodyCreate(twin->world);
    dMass mass;
    dMassSetBoxTotal(&mass, kMasses[i % 6], 0.2, 0.1 + 0.02 * i, 0.1);
    dBodySetMass(twin->bodies[i], &mass);
    dBodySetPosition(twin->bodies[i], 0.1 * i, 0.05 * i, 1.0 + 0.1 * i);
  }
  for (int j = 0; j < kJoints; ++j)
    twin->joints[j] = makeJoint(twin->world, j, twin->bodies[j % kBodies], twin->bodies[(j + 1) % kBodies]);
}

static void destroyTwin(Twin* twin) {
  ssRegistry_Destroy(twin->registry);
  dWorldDestroy(twin->world);
}

/* The rows joint j has, in a fixed order; returns their number. */
static int rowsOf(dJointID joint, ssJointParam params[12], int axes[12]) {
  int count = 0;
  for (int param = SS_PARAM_JOINT; param <= SS_PARAM_SUSPENSION; ++param)
    for (int axis = 1; axis <= 3; ++axis)
      if (ssJointSupports(joint, (ssJointParam)param, axis)) {
        params[count] = (ssJointParam)param;
        axes[count++] = axis;
      }
  return count;
}

static int same(double a, double b) { return a == b || (isnan(a) && isnan(b)); }

typedef struct Check {
  char* message;
  size_t message_size;
  int op;
  ssDifferentialCounts* counts;
} Check;

static int differ(Check* check, const char* what, int index, double fast, double reference) {
  snprintf(check->message, check->message_size, "operation %d: %s %d: Apply %.17g, reference %.17g", check->op, what,
           index, fast, reference);
  return 1;
}

/* Every parameter, world value and force the twins hold after an Apply. */
static int compareWritten(Check* check, const Twin* fast, const Twin* reference) {
  if (!same(dWorldGetERP(fast->world), dWorldGetERP(reference->world)))
    return differ(check, "world erp", 0, dWorldGetERP(fast->world), dWorldGetERP(reference->world));
  if (!same(dWorldGetCFM(fast->world), dWorldGetCFM(reference->world)))
    return differ(check, "world cfm", 0, dWorldGetCFM(fast->world), dWorldGetCFM(reference->world));
  for (int j = 0; j < kJoints; ++j) {
    ssJointParam params[12];
    int axes[12], rows = rowsOf(fast->joints[j], params, axes);
    for (int r = 0; r < rows; ++r) {
      double erp[2], cfm[2];
      ssJointReadSoftness(fast->joints[j], params[r], axes[r], &erp[0], &cfm[0]);
      ssJointReadSoftness(reference->joints[j], params[r], axes[r], &erp[1], &cfm[1]);
      check->counts->compared_values += 2;
      if (!same(erp[0], erp[1])) return differ(check, "erp of joint", j * 100 + r, erp[0], erp[1]);
      if (!same(cfm[0], cfm[1])) return differ(check, "cfm of joint", j * 100 + r, cfm[0], cfm[1]);
    }
  }
  for (int i = 0; i < kBodies; ++i) {
    const dReal* f[2] = {dBodyGetForce(fast->bodies[i]), dBodyGetForce(reference->bodies[i])};
    const dReal* t[2] = {dBodyGetTorque(fast->bodies[i]), dBodyGetTorque(reference->bodies[i])};
    for (int k = 0; k < 3; ++k) {
      if (!same(f[0][k], f[1][k])) return differ(check, "load force on body", i, f[0][k], f[1][k]);
      if (!same(t[0][k], t[1][k])) return differ(check, "load torque on body", i, t[0][k], t[1][k]);
    }
    double damping[2] = {dBodyGetLinearDamping(fast->bodies[i]), dBodyGetLinearDamping(reference->bodies[i])};
    if (!same(damping[0], damping[1])) return differ(check, "linear damping of body", i, damping[0], damping[1]);
    check->counts->compared_values += 7;
  }
  return 0;
}

static int compareStates(Check* check, const Twin* fast, const Twin* reference) {
  for (int i = 0; i < kBodies; ++i) {
    const dReal* p[2] = {dBodyGetPosition(fast->bodies[i]), dBodyGetPosition(reference->bodies[i])};
    const dReal* v[2] = {dBodyGetLinearVel(fast->bodies[i]), dBodyGetLinearVel(reference->bodies[i])};
    for (int k = 0; k < 3; ++k) {
      if (!same(p[0][k], p[1][k])) return differ(check, "position of body", i, p[0][k], p[1][k]);
      if (!same(v[0][k], v[1][k])) return differ(check, "velocity of body", i, v[0][k], v[1][k]);
    }
  }
  return 0;
}

/* A body that ran away is put back, in both twins alike: ODE must never be handed a non-finite state. */
static void rescue(Twin* twin) {
  for (int i = 0; i < kBodies; ++i) {
    dBodyID body = twin->bodies[i];
    const dReal* p = dBodyGetPosition(body);
    const dReal* v = dBodyGetLinearVel(body);
    const dReal* w = dBodyGetAngularVel(body);
    double sum = p[0] + p[1] + p[2] + v[0] + v[1] + v[2] + w[0] + w[1] + w[2];
    double speed = fabs(v[0]) + fabs(v[1]) + fabs(v[2]) + fabs(w[0]) + fabs(w[1]) + fabs(w[2]);
    if (isfinite(sum) && speed < 100 && fabs(p[0]) + fabs(p[1]) + fabs(p[2]) < 100) continue;
    dBodySetPosition(body, 0.1 * i, 0.05 * i, 1.0 + 0.1 * i);
    dBodySetLinearVel(body, 0, 0, 0);
    dBodySetAngularVel(body, 0, 0, 0);
    dMatrix3 identity;
    dRSetIdentity(identity);
    dBodySetRotation(body, identity);
  }
}

/* One operation, the same on both twins (t = 0: the fast one, 1: the reference). */
typedef struct Operation {
  unsigned kind, a, b, c, d;
} Operation;

static void bindRow(Twin* twin, const Operation* op) {
  dJointID joint = twin->joints[op->a % kJoints];
  ssJointParam params[12];
  int axes[12], rows = rowsOf(joint, params, axes);
  if (rows == 0) return;
  int r = (int)(op->b % (unsigned)rows);
  ssRowLaw law = lawAt((int)(op->c % kLaws));
  if (ssCheckLawForEveryStep("joint", &law) != SS_OK) return;
  ssRegistryBindJointLaw(twin->registry, joint, params[r], axes[r], law, kEffectiveMasses[op->d % 6]);
}

static void setLoad(Twin* twin, const Operation* op) {
  dJointID joint = twin->joints[op->a % kJoints];
  ssJointParam params[12];
  int axes[12], rows = rowsOf(joint, params, axes);
  if (rows == 0) return;
  int r = (int)(op->b % (unsigned)rows);
  ssRegistry_SetJointLoad(twin->registry, joint, params[r], axes[r], kLoads[op->c % 6] * (op->d % 2 ? -1 : 1));
}

static void attach(Twin* twin, const Operation* op) {
  int j = (int)(op->a % kJoints);
  dBodyID first = twin->bodies[op->b % kBodies];
  dBodyID second = op->c % 4 == 0 && !isHinge2(j) ? 0 : twin->bodies[op->c % kBodies];
  if (second == first) second = isHinge2(j) ? twin->bodies[(op->b + 1) % kBodies] : 0;
  dJointAttach(twin->joints[j], first, second);
}

static void changeBody(Twin* twin, const Operation* op) {
  dBodyID body = twin->bodies[op->a % kBodies];
  switch (op->b % 4) {
    case 0: {
      dMass mass;
      dMassSetBoxTotal(&mass, kMasses[op->c % 6], 0.1 + 0.05 * (op->d % 3), 0.1, 0.15);
      dBodySetMass(body, &mass);
      break;
    }
    case 1: dBodySetKinematic(body); break;
    case 2: dBodySetDynamic(body); break;
    case 3: dBodySetPosition(body, 0.05 * (op->c % 7), 0.1 * (op->d % 5), 1.0); break;
  }
}

static void bindBody(Twin* twin, const Operation* op) {
  dBodyID body = op->a % 7 == 6 ? 0 : twin->bodies[op->a % kBodies];
  if (op->b % 3 == 0) {
    if (body != 0) ssRegistry_UnbindBody(twin->registry, body);
    return;
  }
  ssRegistry_BindDamping(twin->registry, body, 0.1 * (op->c % 9), 0.05 * (op->d % 5));
}

int ssApplyDifferential(const uint8_t* data, size_t size, char* message, size_t message_size,
                        ssDifferentialCounts* counts) {
  static int ode_ready = 0;
  if (!ode_ready) dInitODE2(0), ode_ready = 1;
  ssDifferentialCounts local = {0, 0, 0, 0};
  Check check = {message, message_size, 0, counts != NULL ? counts : &local};
  Twin twins[2];
  buildTwin(&twins[0]);
  buildTwin(&twins[1]);
  Reader reader = {data, size, 0};
  double last_step_s = 1.0 / 60;
  int failed = 0;
  for (int n = 0; n < kMaxOps && reader.at < reader.size && !failed; ++n) {
    check.op = n;
    Operation op = {next(&reader) % 12, next(&reader), next(&reader), next(&reader), next(&reader)};
    if (op.kind == 6 || op.kind == 7) { /* Apply: the most frequent */
      ssMapping mapping = (ssMapping)(op.a % 3);
      double step_s = kSteps[op.b % 8];
      double previous_s = op.c % 4 == 0 ? 0 : op.c % 4 == 1 ? step_s : kSteps[op.c % 8];
      if (op.d % 5 == 0) step_s = last_step_s; /* repeated steps: the same-step shortcut and reuse */
      ssApplyReport reports[2];
      memset(reports, 0, sizeof reports);
      ssStatus fast = ssRegistry_Apply(twins[0].registry, mapping, step_s, previous_s, &reports[0]);
      ssStatus reference = ssRegistryApplyReference(twins[1].registry, &twins[1].applied_stamp, mapping, step_s, previous_s, &reports[1]);
      check.counts->applies += 1;
      check.counts->applies_failed += fast != SS_OK;
      if (fast != reference) {
        failed = differ(&check, "status of Apply, mapping", (int)mapping, fast, reference);
        break;
      }
      last_step_s = step_s;
      if (fast == SS_OK) failed = compareWritten(&check, &twins[0], &twins[1]);
      if (fast == SS_OK && !failed) {
        const ssServedCounts* rows[2] = {&reports[0].rows, &reports[1].rows};
        if (reports[0].row_writes != reports[1].row_writes)
          failed = differ(&check, "row_writes, mapping", (int)mapping, reports[0].row_writes, reports[1].row_writes);
        else if (rows[0]->by_mapping != rows[1]->by_mapping)
          failed = differ(&check, "rows.by_mapping, mapping", (int)mapping, rows[0]->by_mapping, rows[1]->by_mapping);
        else if (rows[0]->handed_to_matched != rows[1]->handed_to_matched)
          failed = differ(&check, "rows.handed_to_matched, mapping", (int)mapping, rows[0]->handed_to_matched,
                          rows[1]->handed_to_matched);
        else if (rows[0]->handed_to_implicit_euler != rows[1]->handed_to_implicit_euler)
          failed = differ(&check, "rows.handed_to_implicit_euler, mapping", (int)mapping,
                          rows[0]->handed_to_implicit_euler, rows[1]->handed_to_implicit_euler);
      }
      continue;
    }
    if (op.kind == 8) { /* an ODE step of both: the masses and attachments the next Apply sees move on */
      unsigned long seed = dRandGetSeed(); /* QuickStep reorders its rows at random: both twins alike */
      for (int t = 0; t < 2; ++t) {
        dRandSetSeed(seed);
        dWorldQuickStep(twins[t].world, last_step_s);
        rescue(&twins[t]);
      }
      check.counts->steps += 1;
      failed = compareStates(&check, &twins[0], &twins[1]);
      continue;
    }
    if (op.kind == 11) { /* some of Apply's caches off, or all on again: the values written stay the same */
      ssApplyDisableCaches(twins[0].registry, op.a % 2 ? 0 : op.b & SS_APPLY_ALL);
      continue;
    }
    for (int t = 0; t < 2; ++t) {
      Twin* twin = &twins[t];
      switch (op.kind) {
        case 0:
        case 1: bindRow(twin, &op); break;
        case 2: ssRegistry_UnbindJoint(twin->registry, twin->joints[op.a % kJoints]); break;
        case 3: setLoad(twin, &op); break;
        case 4: attach(twin, &op); break;
        case 5: changeBody(twin, &op); break;
        case 9: bindBody(twin, &op); break;
        case 10: {
          ssRowLaw law = lawAt((int)(op.a % kLaws));
          if (!law.hard) ssRegistry_BindWorld(twin->registry, law.spring, kEffectiveMasses[op.b % 6]);
          break;
        }
      }
    }
    /* forces added for loads last one step: cleared alike when no step took them */
    if (op.kind == 5)
      for (int t = 0; t < 2; ++t)
        for (int i = 0; i < kBodies; ++i) {
          dBodySetForce(twins[t].bodies[i], 0, 0, 0);
          dBodySetTorque(twins[t].bodies[i], 0, 0, 0);
        }
  }
  destroyTwin(&twins[0]);
  destroyTwin(&twins[1]);
  return failed;
}

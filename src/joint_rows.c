/* Which joint of ODE 0.16 has which soft parameters, from the sources in ode/src/joints: Set*Param silently ignores a
 * parameter its joint does not have, so the registry checks here instead of writing into nothing. */
#include "joint_rows.h"

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "error.h"

const char* ssJointTypeName(dJointID joint) {
  switch (dJointGetType(joint)) {
    case dJointTypeBall: return "ball";
    case dJointTypeHinge: return "hinge";
    case dJointTypeSlider: return "slider";
    case dJointTypeContact: return "contact";
    case dJointTypeUniversal: return "universal";
    case dJointTypeHinge2: return "hinge-2";
    case dJointTypeFixed: return "fixed";
    case dJointTypeNull: return "null";
    case dJointTypeAMotor: return "angular motor";
    case dJointTypeLMotor: return "linear motor";
    case dJointTypePlane2D: return "plane-2D";
    case dJointTypePR: return "PR";
    case dJointTypePU: return "PU";
    case dJointTypePiston: return "piston";
    case dJointTypeDBall: return "double ball";
    case dJointTypeDHinge: return "double hinge";
    case dJointTypeTransmission: return "transmission";
    default: return "unknown";
  }
}

const char* ssJointParamName(ssJointParam param) {
  switch (param) {
    case SS_PARAM_JOINT: return "joint";
    case SS_PARAM_STOP: return "stop";
    case SS_PARAM_MOTOR: return "motor";
    case SS_PARAM_SUSPENSION: return "suspension";
  }
  return NULL;
}

/* The number of limit/motor axes a joint type has (0: none). */
static int limitAxisCount(dJointID joint) {
  switch (dJointGetType(joint)) {
    case dJointTypeHinge:
    case dJointTypeSlider: return 1;
    case dJointTypeUniversal:
    case dJointTypeHinge2:
    case dJointTypePR:
    case dJointTypePiston: return 2;
    case dJointTypePU:
    case dJointTypePlane2D: return 3;
    case dJointTypeAMotor: return dJointGetAMotorNumAxes(joint);
    case dJointTypeLMotor: return dJointGetLMotorNumAxes(joint);
    default: return 0;
  }
}

int ssJointSupports(dJointID joint, ssJointParam param, int axis) {
  if (joint == 0) return 0;
  switch (param) {
    case SS_PARAM_JOINT:
      if (axis != 1) return 0;
      switch (dJointGetType(joint)) {
        case dJointTypeBall:
        case dJointTypeFixed:
        case dJointTypeDBall:
        case dJointTypeDHinge:
        case dJointTypeTransmission: return 1;
        default: return 0;
      }
    case SS_PARAM_STOP:
    case SS_PARAM_MOTOR: return axis >= 1 && axis <= limitAxisCount(joint);
    case SS_PARAM_SUSPENSION: return axis == 1 && dJointGetType(joint) == dJointTypeHinge2;
  }
  return 0;
}

/* ODE's parameter number for a set on an axis: groups are 0x100 apart (dParamGroup). */
static int groupParam(int param, int axis) { return param + (axis - 1) * dParamGroup; }

/* ODE's setter for a joint type's parameters, and in *number the number of param on axis for it; NULL for a type
 * without soft parameters. */
static ssParamSetter setterOf(int type, int axis, int param, int* number) {
  *number = param;
  switch (type) {
    case dJointTypeBall: return dJointSetBallParam;
    case dJointTypeFixed: return dJointSetFixedParam;
    case dJointTypeDBall: return dJointSetDBallParam;
    case dJointTypeDHinge: return dJointSetDHingeParam;
    case dJointTypeTransmission: return dJointSetTransmissionParam;
    case dJointTypeHinge: return dJointSetHingeParam;
    case dJointTypeSlider: return dJointSetSliderParam;
    case dJointTypePlane2D: /* one function per axis instead of groups */
      return axis == 1 ? dJointSetPlane2DXParam : axis == 2 ? dJointSetPlane2DYParam : dJointSetPlane2DAngleParam;
    default: break;
  }
  *number = groupParam(param, axis);
  switch (type) {
    case dJointTypeUniversal: return dJointSetUniversalParam;
    case dJointTypeHinge2: return dJointSetHinge2Param;
    case dJointTypePR: return dJointSetPRParam;
    case dJointTypePU: return dJointSetPUParam;
    case dJointTypePiston: return dJointSetPistonParam;
    case dJointTypeAMotor: return dJointSetAMotorParam;
    case dJointTypeLMotor: return dJointSetLMotorParam;
    default: return NULL;
  }
}

/* ODE's parameter numbers of a set's erp and cfm; erp -1 for a motor row, which has no position error (its cfm
 * alone is a damper toward the motor's speed). 0 for an unknown set. */
static int softnessParams(ssJointParam param, int* erp_param, int* cfm_param) {
  switch (param) {
    case SS_PARAM_JOINT: *erp_param = dParamERP, *cfm_param = dParamCFM; return 1;
    case SS_PARAM_STOP: *erp_param = dParamStopERP, *cfm_param = dParamStopCFM; return 1;
    case SS_PARAM_MOTOR: *erp_param = -1, *cfm_param = dParamCFM; return 1;
    case SS_PARAM_SUSPENSION: *erp_param = dParamSuspensionERP, *cfm_param = dParamSuspensionCFM; return 1;
  }
  return 0;
}

static double getParam(dJointID joint, int axis, int param) {
  switch (dJointGetType(joint)) {
    case dJointTypeBall: return dJointGetBallParam(joint, param);
    case dJointTypeFixed: return dJointGetFixedParam(joint, param);
    case dJointTypeDBall: return dJointGetDBallParam(joint, param);
    case dJointTypeDHinge: return dJointGetDHingeParam(joint, param);
    case dJointTypeTransmission: return dJointGetTransmissionParam(joint, param);
    case dJointTypeHinge: return dJointGetHingeParam(joint, param);
    case dJointTypeSlider: return dJointGetSliderParam(joint, param);
    case dJointTypeUniversal: return dJointGetUniversalParam(joint, groupParam(param, axis));
    case dJointTypeHinge2: return dJointGetHinge2Param(joint, groupParam(param, axis));
    case dJointTypePR: return dJointGetPRParam(joint, groupParam(param, axis));
    case dJointTypePU: return dJointGetPUParam(joint, groupParam(param, axis));
    case dJointTypePiston: return dJointGetPistonParam(joint, groupParam(param, axis));
    case dJointTypeAMotor: return dJointGetAMotorParam(joint, groupParam(param, axis));
    case dJointTypeLMotor: return dJointGetLMotorParam(joint, groupParam(param, axis));
    default: return NAN; /* plane-2D has setters only */
  }
}

ssParamGetter ssRowGetterOfType(int joint_type) {
  switch (joint_type) {
    case dJointTypeBall: return dJointGetBallParam;
    case dJointTypeFixed: return dJointGetFixedParam;
    case dJointTypeDBall: return dJointGetDBallParam;
    case dJointTypeDHinge: return dJointGetDHingeParam;
    case dJointTypeTransmission: return dJointGetTransmissionParam;
    case dJointTypeHinge: return dJointGetHingeParam;
    case dJointTypeSlider: return dJointGetSliderParam;
    case dJointTypeUniversal: return dJointGetUniversalParam;
    case dJointTypeHinge2: return dJointGetHinge2Param;
    case dJointTypePR: return dJointGetPRParam;
    case dJointTypePU: return dJointGetPUParam;
    case dJointTypePiston: return dJointGetPistonParam;
    case dJointTypeAMotor: return dJointGetAMotorParam;
    case dJointTypeLMotor: return dJointGetLMotorParam;
    default: return NULL;
  }
}

void ssJointReadSoftness(dJointID joint, ssJointParam param, int axis, double* erp, double* cfm) {
  int erp_param, cfm_param;
  if (!softnessParams(param, &erp_param, &cfm_param)) {
    *erp = *cfm = NAN;
    return;
  }
  *erp = erp_param >= 0 ? getParam(joint, axis, erp_param) : 0;
  *cfm = getParam(joint, axis, cfm_param);
}

int ssJointLimitAxisCount(dJointID joint) { return limitAxisCount(joint); }

void ssJointRowWriterOfType(int joint_type, ssJointParam param, int axis, ssRowWriter* out) {
  int erp_param, cfm_param;
  *out = (ssRowWriter){NULL, -1, -1};
  if (!softnessParams(param, &erp_param, &cfm_param)) return;
  out->set = setterOf(joint_type, axis, cfm_param, &out->cfm_number);
  if (erp_param >= 0) setterOf(joint_type, axis, erp_param, &out->erp_number);
}

void ssJointRowWriterOf(dJointID joint, ssJointParam param, int axis, ssRowWriter* out) {
  ssJointRowWriterOfType(dJointGetType(joint), param, axis, out);
}

static int isDynamic(dBodyID body) { return body != 0 && !dBodyIsKinematic(body); }

/* Whether the six off-diagonal entries are all zero (of either sign), as `== 0` says, by their bits at once. */
static int offDiagonalZero(double a, double b, double c, double d, double e, double f) {
  uint64_t bits[6];
  const double values[6] = {a, b, c, d, e, f};
  memcpy(bits, values, sizeof bits);
  return ((bits[0] | bits[1] | bits[2] | bits[3] | bits[4] | bits[5]) << 1) == 0;
}

void ssBodyInverseOf(dBodyID body, ssBodyInverse* out) {
  /* every field written without memset, whose startup costs more than the rest on the registry's path */
  out->dynamic = isDynamic(body);
  out->principal = 0;
  if (!out->dynamic) {
    out->inverse_mass = 0;
    for (int i = 0; i < 9; ++i) out->inverse_inertia[i] = 0;
    out->position[0] = out->position[1] = out->position[2] = 0;
    return;
  }
  dMass mass;
  dBodyGetMass(body, &mass);
  out->inverse_mass = 1.0 / mass.mass;
  const dReal* p = dBodyGetPosition(body);
  out->position[0] = p[0], out->position[1] = p[1], out->position[2] = p[2];
  /* I_body⁻¹ by its adjugate; a singular or indefinite inertia resists no rotation here (its inverse counts 0) */
  const dReal* I = mass.I; /* rows of 4 */
  double a00 = I[0], a01 = I[1], a02 = I[2], a10 = I[4], a11 = I[5], a12 = I[6], a20 = I[8], a21 = I[9],
         a22 = I[10];
  const dReal* R = dBodyGetRotation(body); /* rows of 4 */
  if (offDiagonalZero(a01, a02, a10, a12, a20, a21)) {
    /* principal axes along the body's (boxes, spheres, capsules, cylinders): I_world⁻¹ = R·diag(1/I)·Rᵀ, kept as
     * ODE's R and 1/I, not multiplied out (ssInverseInertiaAlong: d·I⁻¹d = Σ_k (Rᵀd)_k²/I_k, the same quantity):
     * the registry asks this of every body at every Apply of an accurate mapping, and most bodies serve one or two
     * rows, whose few products cost less than the matrix's */
    if (!(a00 > 0 && a11 > 0 && a22 > 0)) {
      for (int i = 0; i < 9; ++i) out->inverse_inertia[i] = 0;
      return;
    }
    out->principal = 1;
    out->rotation = R;
    out->inverse_principal[0] = 1.0 / a00;
    out->inverse_principal[1] = 1.0 / a11;
    out->inverse_principal[2] = 1.0 / a22;
    return;
  }
  double c0 = a11 * a22 - a12 * a21, c1 = a12 * a20 - a10 * a22, c2 = a10 * a21 - a11 * a20;
  double det = a00 * c0 + a01 * c1 + a02 * c2;
  if (!(det > 0)) {
    for (int i = 0; i < 9; ++i) out->inverse_inertia[i] = 0;
    return;
  }
  double inv_det = 1.0 / det;
  double body_inverse[3][3] = {
      {c0 * inv_det, (a02 * a21 - a01 * a22) * inv_det, (a01 * a12 - a02 * a11) * inv_det},
      {c1 * inv_det, (a00 * a22 - a02 * a20) * inv_det, (a02 * a10 - a00 * a12) * inv_det},
      {c2 * inv_det, (a01 * a20 - a00 * a21) * inv_det, (a00 * a11 - a01 * a10) * inv_det}};
  /* world frame: R·I_body⁻¹·Rᵀ */
  double r_inverse[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      r_inverse[i][j] =
          R[4 * i] * body_inverse[0][j] + R[4 * i + 1] * body_inverse[1][j] + R[4 * i + 2] * body_inverse[2][j];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      out->inverse_inertia[3 * i + j] =
          r_inverse[i][0] * R[4 * j] + r_inverse[i][1] * R[4 * j + 1] + r_inverse[i][2] * R[4 * j + 2];
}

ssBodyInverseBound ssBodyInverseBoundOf(dBodyID body) {
  if (!isDynamic(body)) return (ssBodyInverseBound){0, 0};
  dMass mass;
  dBodyGetMass(body, &mass);
  ssBodyInverseBound out = {mass.mass > 0 && mass.mass < INFINITY ? 1.0 / mass.mass : NAN, 0};
  const dReal* I = mass.I; /* rows of 4 */
  double a00 = I[0], a01 = I[1], a02 = I[2], a10 = I[4], a11 = I[5], a12 = I[6], a20 = I[8], a21 = I[9],
         a22 = I[10];
  if (offDiagonalZero(a01, a02, a10, a12, a20, a21)) {
    /* ssBodyInverseOf's Σ b_k²/I_k with |b| = 1 is at least 1/max I_k; an inertia it counts 0 is 0 here too */
    const double most = a00 > a11 ? (a00 > a22 ? a00 : a22) : (a11 > a22 ? a11 : a22);
    if (a00 > 0 && a11 > 0 && a22 > 0) out.angular = 1.0 / most;
    return out;
  }
  /* Turned axes: a symmetric inertia whose leading minors are surely positive is positive definite, its largest
   * eigenvalue is at most its largest Gershgorin row sum `high`, and its smallest at least det/high²: above
   * high/10⁴, ssBodyInverseOf's adjugate is within roundings far below the callers' margin */
  double high = fmax(fabs(a00) + fabs(a01) + fabs(a02), fmax(fabs(a10) + fabs(a11) + fabs(a12),
                                                            fabs(a20) + fabs(a21) + fabs(a22)));
  double minor = a00 * a11 - a01 * a10, det = a00 * (a11 * a22 - a12 * a21) - a01 * (a10 * a22 - a12 * a20) +
                                              a02 * (a10 * a21 - a11 * a20);
  int symmetric = a01 == a10 && a02 == a20 && a12 == a21;
  int definite = a00 > 0 && minor > 1e-12 * high * high && det > 1e-4 * high * high * high;
  out.angular = symmetric && high < INFINITY && definite ? 1.0 / high : NAN;
  return out;
}

double ssRowEffectiveMass(dBodyID body1, dBodyID body2, const dReal* direction, const dReal* point, int angular) {
  ssRowGeometry row = {{direction[0], direction[1], direction[2]}, {0, 0, 0}, angular, point != NULL};
  if (point != NULL) row.point[0] = point[0], row.point[1] = point[1], row.point[2] = point[2];
  dBodyID bodies[2] = {body1, body2};
  double inverse = 0;
  for (int i = 0; i < 2; ++i) {
    ssBodyInverse body;
    ssBodyInverseOf(bodies[i], &body);
    inverse += ssRowInverseMass(&body, &row);
  }
  return inverse > 0 ? 1.0 / inverse : 0;
}

/* As rowGeometry's *angular, known without ODE's getters (test_apply.cpp compares the two for every row). */
int ssJointRowIsAngular(int type, ssJointParam param, int axis) {
  switch (type) {
    case dJointTypeHinge:
    case dJointTypeUniversal:
    case dJointTypeAMotor: return 1;
    case dJointTypeHinge2: return param != SS_PARAM_SUSPENSION;
    case dJointTypePR: return axis == 2;
    case dJointTypePU: return axis == 1 || axis == 2;
    case dJointTypePiston: return axis == 2;
    case dJointTypePlane2D: return axis == 3;
    default: return 0;
  }
}

/* The row's direction, whether it is angular, and (for a linear row whose point matters) its point. */
static int rowGeometry(dJointID joint, int type, ssJointParam param, int axis, dVector3 direction, dVector3 point,
                       int* angular, int* has_point) {
  *angular = 0;
  *has_point = 0;
  switch (type) {
    case dJointTypeHinge: dJointGetHingeAxis(joint, direction); *angular = 1; return 1;
    case dJointTypeSlider: dJointGetSliderAxis(joint, direction); return 1;
    case dJointTypeUniversal:
      if (axis == 1) dJointGetUniversalAxis1(joint, direction);
      else dJointGetUniversalAxis2(joint, direction);
      *angular = 1;
      return 1;
    case dJointTypeHinge2:
      if (param == SS_PARAM_SUSPENSION) {
        /* the suspension moves the wheel's anchor along axis 1: the chassis' rotation takes part */
        dJointGetHinge2Axis1(joint, direction);
        dJointGetHinge2Anchor2(joint, point);
        *has_point = 1;
        return 1;
      }
      if (axis == 1) dJointGetHinge2Axis1(joint, direction);
      else dJointGetHinge2Axis2(joint, direction);
      *angular = 1;
      return 1;
    case dJointTypePR:
      if (axis == 1) dJointGetPRAxis1(joint, direction);
      else {
        dJointGetPRAxis2(joint, direction);
        *angular = 1;
      }
      return 1;
    case dJointTypePU:
      if (axis == 1) dJointGetPUAxis1(joint, direction);
      else if (axis == 2) dJointGetPUAxis2(joint, direction);
      else {
        dJointGetPUAxis3(joint, direction);
        return 1;
      }
      *angular = 1;
      return 1;
    case dJointTypePiston:
      dJointGetPistonAxis(joint, direction);
      *angular = axis == 2;
      return 1;
    /* a motor's axes can be fewer than when the row was bound */
    case dJointTypeAMotor:
      if (axis > dJointGetAMotorNumAxes(joint)) return 0;
      dJointGetAMotorAxis(joint, axis - 1, direction);
      *angular = 1;
      return 1;
    case dJointTypeLMotor:
      if (axis > dJointGetLMotorNumAxes(joint)) return 0;
      dJointGetLMotorAxis(joint, axis - 1, direction);
      return 1;
    case dJointTypePlane2D:
      direction[0] = axis == 1;
      direction[1] = axis == 2;
      direction[2] = axis == 3;
      *angular = axis == 3;
      return 1;
    case dJointTypeBall:
    case dJointTypeFixed:
    case dJointTypeDBall:
    case dJointTypeDHinge:
      /* several rows at once: the pair's reduced mass, as if each row were along the line of centres */
      direction[0] = 1;
      direction[1] = direction[2] = 0;
      return 1;
    default: return 0; /* transmission couples rotations through gear geometry: the program must give a mass */
  }
}

int ssJointRowGeometry(dJointID joint, int type, ssJointParam param, int axis, ssRowGeometry* out) {
  dVector3 direction = {0, 0, 0, 0}, point = {0, 0, 0, 0};
  int angular, has_point;
  if (!rowGeometry(joint, type, param, axis, direction, point, &angular, &has_point)) return 0;
  *out = (ssRowGeometry){{direction[0], direction[1], direction[2]}, {point[0], point[1], point[2]}, angular,
                         has_point};
  return 1;
}

ssStatus ssJointEffectiveMass(dJointID joint, ssJointParam param, int axis, double* mass) {
  if (joint == 0) return ssFail(SS_ERROR_OUT_OF_RANGE, "joint = NULL: a joint is required");
  if (mass == NULL) return ssFail(SS_ERROR_OUT_OF_RANGE, "mass = NULL: needs somewhere to write the mass");
  if (!ssJointSupports(joint, param, axis))
    return ssFail(SS_ERROR_UNSUPPORTED, "a %s joint has no %s parameters on axis %d", ssJointTypeName(joint),
                  ssJointParamName(param) ? ssJointParamName(param) : "such", axis);
  /* ODE's axis getters need the joint's first body (some assert on it): a detached joint has no row to measure */
  if (dJointGetBody(joint, 0) == 0)
    return ssFail(SS_ERROR_OUT_OF_RANGE, "the %s joint has no dynamic body attached", ssJointTypeName(joint));
  dVector3 direction = {0, 0, 0, 0}, point = {0, 0, 0, 0};
  int angular, has_point;
  if (!rowGeometry(joint, dJointGetType(joint), param, axis, direction, point, &angular, &has_point))
    return ssFail(SS_ERROR_UNSUPPORTED, "the effective mass of a %s joint's rows is not defined: give it",
                  ssJointTypeName(joint));
  double value = ssRowEffectiveMass(dJointGetBody(joint, 0), dJointGetBody(joint, 1), direction,
                                    has_point ? point : NULL, angular);
  if (!(value > 0) || !isfinite(value))
    return ssFail(SS_ERROR_OUT_OF_RANGE, "the %s joint's %s row on axis %d has no dynamic body attached",
                  ssJointTypeName(joint), ssJointParamName(param), axis);
  *mass = value;
  return SS_OK;
}

int ssJointRowHasDirection(dJointID joint, ssJointParam param, int axis) {
  return param != SS_PARAM_JOINT && ssJointSupports(joint, param, axis);
}

void ssJointAddRowForce(dJointID joint, ssJointParam param, int axis, double force_or_torque) {
  if (dJointGetBody(joint, 0) == 0) return; /* detached: no row, and ODE's getters would assert */
  dVector3 direction = {0, 0, 0, 0}, point = {0, 0, 0, 0};
  int angular, has_point;
  if (!rowGeometry(joint, dJointGetType(joint), param, axis, direction, point, &angular, &has_point)) return;
  for (int side = 0; side < 2; ++side) {
    dBodyID body = dJointGetBody(joint, side);
    if (!isDynamic(body)) continue;
    double f = side == 0 ? force_or_torque : -force_or_torque;
    if (angular) dBodyAddTorque(body, f * direction[0], f * direction[1], f * direction[2]);
    else if (has_point)
      dBodyAddForceAtPos(body, f * direction[0], f * direction[1], f * direction[2], point[0], point[1], point[2]);
    else dBodyAddForce(body, f * direction[0], f * direction[1], f * direction[2]);
  }
}

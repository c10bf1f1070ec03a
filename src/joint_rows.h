/* Internal: what ODE 0.16's joint types offer as soft rows, how to write them and what mass they move. */
#ifndef STEADYSTEP_JOINT_ROWS_H
#define STEADYSTEP_JOINT_ROWS_H

#include <ode/ode.h>

#include "steadystep/registry.h"

/* A short name of the joint's type for messages ("hinge", "slider", ...). */
const char* ssJointTypeName(dJointID joint);

/* A short name of a parameter set for messages ("stop", "motor", ...), or NULL for an unknown value. */
const char* ssJointParamName(ssJointParam param);

/* How to write one row's softness, resolved once (a joint's type never changes): ODE's setter for the joint's type
 * and the parameter numbers of erp (-1: none, a motor row) and cfm. set is NULL for a row without softness. The
 * joint must support param on axis (ssJointSupports). */
typedef void (*ssParamSetter)(dJointID joint, int parameter, dReal value);
typedef struct ssRowWriter {
  ssParamSetter set;
  int erp_number, cfm_number;
} ssRowWriter;

void ssJointRowWriterOf(dJointID joint, ssJointParam param, int axis, ssRowWriter* out);
/* The same for a joint whose type (dJointGetType) was read already. */
void ssJointRowWriterOfType(int joint_type, ssJointParam param, int axis, ssRowWriter* out);

/* Writes the row's softness through its writer (MOTOR rows write only cfm): what the registry does for every row at
 * every Apply. */
static inline void ssRowWrite(const ssRowWriter* writer, dJointID joint, double erp, double cfm) {
  if (writer->set == NULL) return;
  if (writer->erp_number >= 0) writer->set(joint, writer->erp_number, erp);
  writer->set(joint, writer->cfm_number, cfm);
}

/* ODE's getter for a joint type's parameters, taking the numbers of the type's ssRowWriter; NULL for plane-2D, whose
 * parameters ODE 0.16 cannot read back, and for types without soft parameters. */
typedef dReal (*ssParamGetter)(dJointID joint, int parameter);
ssParamGetter ssRowGetterOfType(int joint_type);

/* Reads the row's softness as ODE holds it (MOTOR rows: erp 0 and the motor's cfm). NAN for plane-2D, which ODE 0.16
 * cannot read back. */
void ssJointReadSoftness(dJointID joint, ssJointParam param, int axis, double* erp, double* cfm);

/* The number of limit/motor axes of the joint's type (0: none). */
int ssJointLimitAxisCount(dJointID joint);

/* What a body opposes to a row's motion, read once per step and shared by all the rows on it: inverse mass (1/kg),
 * inverse inertia and centre (m). The inverse inertia is, for a body whose inertia is diagonal in its own frame
 * (principal 1: boxes, spheres, capsules, cylinders), ODE's rotation R of the body (rows of 4; valid until the body
 * moves) and the inverses of its principal moments (1/(kg·m²)): I_world⁻¹ = R·diag(inverse_principal)·Rᵀ;
 * otherwise (principal 0) I_world⁻¹ itself (row-major 3x3). All 0 for the static world (body 0) and kinematic
 * bodies (dynamic 0); the inertia part is 0 for an inertia that is not positive definite. */
typedef struct ssBodyInverse {
  int dynamic;
  int principal;
  double inverse_mass;
  union {
    double inverse_inertia[9]; /* principal 0 */
    struct {
      const dReal* rotation;
      double inverse_principal[3];
    }; /* principal 1: with the fields above, in the first cache line of the registry's BodyCache */
  };
  double position[3];
} ssBodyInverse;

void ssBodyInverseOf(dBodyID body, ssBodyInverse* out);

/* Lower bounds of what a body opposes to a row whatever the row's unit direction and the body's rotation:
 * ssRowInverseMass of a linear row is at least `linear` (1/kg), of an angular row at least `angular` (1/(kg·m²)),
 * within roundings below SS_MASS_BOUND_MARGIN of either. Both 0 for the static world and kinematic bodies, which
 * oppose nothing; NAN where no bound is sure: a mass that is not positive and finite, an inertia with off-diagonal terms that is not
 * symmetric, or not surely positive definite with its eigenvalues within a factor 10⁴. Apply bounds the masses of
 * a law's rows with them, reading no axis (ssSurelyFailsUpToMass). */
typedef struct ssBodyInverseBound {
  double linear, angular;
} ssBodyInverseBound;

ssBodyInverseBound ssBodyInverseBoundOf(dBodyID body);

/* How much above 1/(the sum of its bodies' bounds) a row's measured mass can be: the roundings of ODE's axes and
 * rotations, which are unit and orthonormal to a few units in the last place of dReal (hundreds of times below). */
#if defined(dDOUBLE)
#define SS_MASS_BOUND_MARGIN 1e-9
#else
#define SS_MASS_BOUND_MARGIN 1e-4
#endif

/* Whether the row of a joint of ODE type `type` is angular (its geometry's `angular`), known without ODE's getters. */
int ssJointRowIsAngular(int type, ssJointParam param, int axis);

/* A row's unit direction (world frame), whether it is angular, and for a linear row whose point matters (hinge-2
 * suspension) that point (m). */
typedef struct ssRowGeometry {
  double direction[3];
  double point[3];
  int angular;
  int has_point;
} ssRowGeometry;

/* The geometry of a row of a joint of ODE type `type` that supports param on axis (checked at bind time), whose first
 * body the caller found attached (ODE's axis getters assert on it). 0 when the row has none to measure: a motor has
 * fewer axes now, or the type's mass is not defined (transmission). */
int ssJointRowGeometry(dJointID joint, int type, ssJointParam param, int axis, ssRowGeometry* out);

/* d·I⁻¹d in the world frame. For principal axes, with b = Rᵀd (d in the body's frame), Σ_k b_k²/I_k: that is
 * dᵀ·R·diag(1/I)·Rᵀ·d itself, for any R, in exact arithmetic (only the roundings differ from forming the matrix). */
static inline double ssInverseInertiaAlong(const ssBodyInverse* body, const double* d) {
  if (body->principal) {
    const dReal* R = body->rotation;
    const double d0 = d[0], d1 = d[1], d2 = d[2];
    const double b0 = R[0] * d0 + R[4] * d1 + R[8] * d2;
    const double b1 = R[1] * d0 + R[5] * d1 + R[9] * d2;
    const double b2 = R[2] * d0 + R[6] * d1 + R[10] * d2;
    return b0 * b0 * body->inverse_principal[0] + b1 * b1 * body->inverse_principal[1] +
           b2 * b2 * body->inverse_principal[2];
  }
  const double* M = body->inverse_inertia;
  return d[0] * (M[0] * d[0] + M[1] * d[1] + M[2] * d[2]) + d[1] * (M[3] * d[0] + M[4] * d[1] + M[5] * d[2]) +
         d[2] * (M[6] * d[0] + M[7] * d[1] + M[8] * d[2]);
}

/* One body's share of the row's inverse effective mass: 1/m + (r x d)·I⁻¹(r x d) (linear) or d·I⁻¹d (angular).
 * Inline: the registry asks it of every row's bodies at every Apply of an accurate mapping. */
static inline double ssRowInverseMass(const ssBodyInverse* body, const ssRowGeometry* row) {
  if (!body->dynamic) return 0;
  if (row->angular) return ssInverseInertiaAlong(body, row->direction);
  double inverse = body->inverse_mass;
  if (row->has_point) {
    const double* p = body->position;
    double r[3] = {row->point[0] - p[0], row->point[1] - p[1], row->point[2] - p[2]};
    const double* d = row->direction;
    double rxd[3] = {r[1] * d[2] - r[2] * d[1], r[2] * d[0] - r[0] * d[2], r[0] * d[1] - r[1] * d[0]};
    inverse += ssInverseInertiaAlong(body, rxd);
  }
  return inverse;
}

/* The effective mass of a row along (linear) or about (angular) the unit direction `direction` through world point
 * `point` (linear rows only), from body1 and body2 (0 for the static world): 1 / the sum of ssRowInverseMass over
 * both. Returns 0 when no dynamic body is attached. */
double ssRowEffectiveMass(dBodyID body1, dBodyID body2, const dReal* direction, const dReal* point, int angular);

/* Whether a row has one direction that a load along it can be declared for (every limit, motor and suspension row;
 * not the several rows of SS_PARAM_JOINT). */
int ssJointRowHasDirection(dJointID joint, ssJointParam param, int axis);

/* Adds force_or_torque (N or N·m) along the row to its first body and the opposite to its second, for the coming
 * step: at the row's point for a linear row that has one (hinge-2 suspension), at the centres otherwise. */
void ssJointAddRowForce(dJointID joint, ssJointParam param, int axis, double force_or_torque);

#endif

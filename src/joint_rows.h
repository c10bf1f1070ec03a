/* Internal: what ODE 0.16's joint types offer as soft rows, how to write them and what mass they move. */
#ifndef STEADYSTEP_JOINT_ROWS_H
#define STEADYSTEP_JOINT_ROWS_H

#include <ode/ode.h>

#include "steadystep/registry.h"

/* A short name of the joint's type for messages ("hinge", "slider", ...). */
const char* ssJointTypeName(dJointID joint);

/* A short name of a parameter set for messages ("stop", "motor", ...), or NULL for an unknown value. */
const char* ssJointParamName(ssJointParam param);

/* Writes the row's softness. The joint must support param on axis (ssJointSupports). MOTOR rows write only cfm. */
void ssJointWriteSoftness(dJointID joint, ssJointParam param, int axis, double erp, double cfm);

/* Reads the row's softness as ODE holds it (MOTOR rows: erp 0 and the motor's cfm). NAN for plane-2D, which ODE 0.16
 * cannot read back. */
void ssJointReadSoftness(dJointID joint, ssJointParam param, int axis, double* erp, double* cfm);

/* The number of limit/motor axes of the joint's type (0: none). */
int ssJointLimitAxisCount(dJointID joint);

/* What a body opposes to a row's motion, read once per step and shared by all the rows on it: inverse mass (1/kg),
 * world-frame inverse inertia (1/(kg·m²), row-major 3x3) and centre (m). All 0 for the static world (body 0) and
 * kinematic bodies (dynamic 0); the inertia part is 0 for an inertia that is not positive definite. */
typedef struct ssBodyInverse {
  double inverse_mass;
  double inverse_inertia[9];
  double position[3];
  int dynamic;
} ssBodyInverse;

void ssBodyInverseOf(dBodyID body, ssBodyInverse* out);

/* A row's unit direction (world frame), whether it is angular, and for a linear row whose point matters (hinge-2
 * suspension) that point (m). */
typedef struct ssRowGeometry {
  double direction[3];
  double point[3];
  int angular;
  int has_point;
} ssRowGeometry;

/* The geometry of a row of a joint that supports param on axis (checked at bind time). 0 when the row has none to
 * measure: the joint is detached from its first body, a motor has fewer axes now, or the type's mass is not defined
 * (transmission). */
int ssJointRowGeometry(dJointID joint, ssJointParam param, int axis, ssRowGeometry* out);

/* One body's share of the row's inverse effective mass: 1/m + (r x d)·I⁻¹(r x d) (linear) or d·I⁻¹d (angular). */
double ssRowInverseMass(const ssBodyInverse* body, const ssRowGeometry* row);

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

// Test support: ODE's own getters and setters of a joint's parameter number on an axis, written independently of
// the library's (src/joint_rows.c), so that tests read back what the library wrote through another path.
#ifndef STEADYSTEP_TESTS_JOINT_PARAMS_H
#define STEADYSTEP_TESTS_JOINT_PARAMS_H

#include <gtest/gtest.h>
#include <ode/ode.h>

#include <cmath>

inline double GetParam(dJointID joint, int param, int axis) {
  int grouped = param + (axis - 1) * dParamGroup;
  switch (dJointGetType(joint)) {
    case dJointTypeBall: return dJointGetBallParam(joint, param);
    case dJointTypeFixed: return dJointGetFixedParam(joint, param);
    case dJointTypeDBall: return dJointGetDBallParam(joint, param);
    case dJointTypeDHinge: return dJointGetDHingeParam(joint, param);
    case dJointTypeTransmission: return dJointGetTransmissionParam(joint, param);
    case dJointTypeHinge: return dJointGetHingeParam(joint, param);
    case dJointTypeSlider: return dJointGetSliderParam(joint, param);
    case dJointTypeUniversal: return dJointGetUniversalParam(joint, grouped);
    case dJointTypeHinge2: return dJointGetHinge2Param(joint, grouped);
    case dJointTypePR: return dJointGetPRParam(joint, grouped);
    case dJointTypePU: return dJointGetPUParam(joint, grouped);
    case dJointTypePiston: return dJointGetPistonParam(joint, grouped);
    case dJointTypeAMotor: return dJointGetAMotorParam(joint, grouped);
    case dJointTypeLMotor: return dJointGetLMotorParam(joint, grouped);
    default: ADD_FAILURE() << "no getter for joint type " << dJointGetType(joint); return NAN;
  }
}

inline void SetParam(dJointID joint, int param, int axis, double value) {
  int grouped = param + (axis - 1) * dParamGroup;
  switch (dJointGetType(joint)) {
    case dJointTypeBall: dJointSetBallParam(joint, param, value); break;
    case dJointTypeFixed: dJointSetFixedParam(joint, param, value); break;
    case dJointTypeDBall: dJointSetDBallParam(joint, param, value); break;
    case dJointTypeDHinge: dJointSetDHingeParam(joint, param, value); break;
    case dJointTypeTransmission: dJointSetTransmissionParam(joint, param, value); break;
    case dJointTypeHinge: dJointSetHingeParam(joint, param, value); break;
    case dJointTypeSlider: dJointSetSliderParam(joint, param, value); break;
    case dJointTypeUniversal: dJointSetUniversalParam(joint, grouped, value); break;
    case dJointTypeHinge2: dJointSetHinge2Param(joint, grouped, value); break;
    case dJointTypePR: dJointSetPRParam(joint, grouped, value); break;
    case dJointTypePU: dJointSetPUParam(joint, grouped, value); break;
    case dJointTypePiston: dJointSetPistonParam(joint, grouped, value); break;
    case dJointTypeAMotor: dJointSetAMotorParam(joint, grouped, value); break;
    case dJointTypeLMotor: dJointSetLMotorParam(joint, grouped, value); break;
    default: ADD_FAILURE() << "no setter for joint type " << dJointGetType(joint);
  }
}

#endif

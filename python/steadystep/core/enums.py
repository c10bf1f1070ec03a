"""The library's enums as Python enums, with the values of the C headers (read through cffi, never typed again).

Each member is an IntEnum, so it passes wherever C takes the enum and compares equal to the C constant.
tests/python/test_api.py checks that every C enumerator has its member here.
"""

from __future__ import annotations

from enum import IntEnum

from steadystep.core._native import lib


class FrameCut(IntEnum):
    """How a frame's time becomes physics steps (stepping.h, ssFrameCut)."""

    WHOLE_FRAME = lib.SS_CUT_WHOLE_FRAME  # one step of the whole frame, as ODE programs usually do
    SUBSTEPS = lib.SS_CUT_SUBSTEPS        # ceil(frame / max_step_s) equal substeps: the article's cap on the step
    FIXED = lib.SS_CUT_FIXED              # steps of fixed_step_s from an accumulator ("fix your timestep")


class Mapping(IntEnum):
    """How a spring becomes ODE's ERP/CFM for one step (spring.h, ssMapping)."""

    IMPLICIT_EULER = lib.SS_MAPPING_IMPLICIT_EULER  # the article's: erp = hk/(hk+c), cfm = 1/(hk+c)
    MATCHED = lib.SS_MAPPING_MATCHED                # exact poles at a constant step (needs c > 0 and a mass)
    EXACT = lib.SS_MAPPING_EXACT                    # exact samples under any sequence of steps


class Solver(IntEnum):
    """Which ODE solver a step calls (stepping.h, ssSolver)."""

    UNSET = lib.SS_SOLVER_UNSET  # not said: refused (a program says which ODE step it calls)
    QUICK = lib.SS_SOLVER_QUICK  # dWorldQuickStep, with the world's own iterations and SOR w
    STEP = lib.SS_SOLVER_STEP    # dWorldStep, the direct solver


class JointParam(IntEnum):
    """Which soft parameter set of a joint a binding drives (registry.h, ssJointParam)."""

    JOINT = lib.SS_PARAM_JOINT            # dParamERP/CFM: ball, fixed, double ball, double hinge, transmission
    STOP = lib.SS_PARAM_STOP              # dParamStopERP/StopCFM: a limit on one axis (lo = hi: a bilateral spring)
    MOTOR = lib.SS_PARAM_MOTOR            # dParamCFM of a limit/motor axis: a damper toward the motor's velocity
    SUSPENSION = lib.SS_PARAM_SUSPENSION  # dParamSuspensionERP/CFM: hinge-2 suspension along axis 1


class Status(IntEnum):
    """What a library call returned (status.h, ssStatus); SteadystepError.code holds one of these values."""

    OK = lib.SS_OK
    NOT_FINITE = lib.SS_ERROR_NOT_FINITE
    OUT_OF_RANGE = lib.SS_ERROR_OUT_OF_RANGE
    NO_SPRING = lib.SS_ERROR_NO_SPRING
    NO_FINITE_MAPPING = lib.SS_ERROR_NO_FINITE_MAPPING
    UNSUPPORTED = lib.SS_ERROR_UNSUPPORTED
    NOT_FOUND = lib.SS_ERROR_NOT_FOUND
    IO = lib.SS_ERROR_IO
    PARSE = lib.SS_ERROR_PARSE
    BLOWUP = lib.SS_ERROR_BLOWUP
    SPEED_LIMIT = lib.SS_ERROR_SPEED_LIMIT
    OUT_OF_MEMORY = lib.SS_ERROR_OUT_OF_MEMORY
    FAILED = lib.SS_ERROR_FAILED
    POSITION_LIMIT = lib.SS_ERROR_POSITION_LIMIT
    REENTERED = lib.SS_ERROR_REENTERED

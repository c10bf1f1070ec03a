"""Springs and softness: thin wrappers over the C conversions of spring.h (SI units throughout).

A spring is (k N/m, c N·s/m); softness is ODE's (erp, cfm) for one step of h seconds. For angular rows read
N·m/rad, N·m·s/rad and kg·m². Every bad input raises SteadystepError naming the value.
"""

from __future__ import annotations

from typing import NamedTuple

from steadystep._native import SteadystepError, check, ffi, lib

MAPPINGS = {"spring": lib.SS_MAPPING_SPRING, "matched": lib.SS_MAPPING_MATCHED, "exact": lib.SS_MAPPING_EXACT}


class Spring(NamedTuple):
    """A spring-damper: stiffness k (N/m) and damping c (N·s/m)."""

    stiffness: float
    damping: float


class Softness(NamedTuple):
    """ODE's softness of one constraint row for one step: erp (non-dimensional) and cfm (m/(N·s))."""

    erp: float
    cfm: float


def _spring(spring: Spring | tuple[float, float]) -> dict:
    k, c = spring
    return {"stiffness": float(k), "damping": float(c)}


def softness_from_spring(spring: Spring | tuple[float, float], step_s: float) -> Softness:
    """The article's mapping at step step_s (s): erp = hk/(hk+c), cfm = 1/(hk+c)."""
    out = ffi.new("ssSoftness*")
    check(lib.ssSoftnessFromSpring(_spring(spring), float(step_s), out))
    return Softness(out.erp, out.cfm)


def spring_from_softness(softness: Softness | tuple[float, float], step_s: float) -> Spring:
    """The spring that erp, cfm tuned at a fixed step step_s (s) stand for: k = erp/(h·cfm), c = (1-erp)/cfm."""
    erp, cfm = softness
    out = ffi.new("ssSpring*")
    check(lib.ssSpringFromSoftness({"erp": float(erp), "cfm": float(cfm)}, float(step_s), out))
    return Spring(out.stiffness, out.damping)


def spring_from_frequency(frequency_hz: float, damping_ratio: float, mass: float) -> Spring:
    """k = m·w², c = 2·zeta·m·w with w = 2π·frequency_hz, for a row of effective mass `mass` (kg)."""
    out = ffi.new("ssSpring*")
    check(lib.ssSpringFromFrequency(float(frequency_hz), float(damping_ratio), float(mass), out))
    return Spring(out.stiffness, out.damping)


def frequency_from_spring(spring: Spring | tuple[float, float], mass: float) -> tuple[float, float]:
    """The undamped natural frequency (Hz) and damping ratio of a spring on mass (kg)."""
    frequency = ffi.new("double*")
    ratio = ffi.new("double*")
    check(lib.ssFrequencyFromSpring(_spring(spring), float(mass), frequency, ratio))
    return frequency[0], ratio[0]


def matched_softness(spring: Spring | tuple[float, float], mass: float, step_s: float) -> Softness:
    """The matched mapping: erp, cfm whose discrete poles are exp(s·h) of the spring's exact poles (needs c > 0)."""
    out = ffi.new("ssSoftness*")
    check(lib.ssMatchedSoftness(_spring(spring), float(mass), float(step_s), out))
    return Softness(out.erp, out.cfm)


def exact_softness(spring: Spring | tuple[float, float], mass: float, step_s: float,
                   previous_step_s: float = 0.0) -> Softness:
    """The exact mapping: ODE's step after one of previous_step_s (0 = no history) lands on the exact sample."""
    out = ffi.new("ssSoftness*")
    check(lib.ssExactSoftness(_spring(spring), float(mass), float(step_s), float(previous_step_s), out))
    return Softness(out.erp, out.cfm)


def softness_for(mapping: str, spring: Spring | tuple[float, float], mass: float, step_s: float,
                 previous_step_s: float = 0.0) -> Softness:
    """Any mapping by name ("spring", "matched", "exact")."""
    if mapping not in MAPPINGS:
        raise SteadystepError("unsupported", f"mapping = {mapping!r}: must be one of {', '.join(MAPPINGS)}")
    out = ffi.new("ssSoftness*")
    check(lib.ssSoftnessFor(MAPPINGS[mapping], _spring(spring), float(mass), float(step_s),
                            float(previous_step_s), out))
    return Softness(out.erp, out.cfm)

"""Springs and softness: thin wrappers over the C conversions of spring.h (SI units throughout).

A spring is (k N/m, c N·s/m); softness is ODE's (erp, cfm) for one step of h seconds. For angular rows read
N·m/rad, N·m·s/rad and kg·m². Every bad input raises SteadystepError naming the value, and so does a result that
is not finite (whatever the library returned): every number returned here is finite.
"""

from __future__ import annotations

import math
from typing import NamedTuple

from steadystep._native import SteadystepError, check, ffi, lib, number, shown

MAPPINGS = {"implicit-euler": lib.SS_MAPPING_IMPLICIT_EULER, "matched": lib.SS_MAPPING_MATCHED, "exact": lib.SS_MAPPING_EXACT}


class Spring(NamedTuple):
    """A spring-damper: stiffness k (N/m) and damping c (N·s/m)."""

    stiffness: float
    damping: float


class Softness(NamedTuple):
    """ODE's softness of one constraint row for one step: erp (non-dimensional) and cfm (m/(N·s))."""

    erp: float
    cfm: float


def _spring(spring: Spring | tuple[float, float]) -> dict:
    try:
        k, c = spring
    except (TypeError, ValueError):
        raise SteadystepError("out of range", f"spring = {shown(spring)}: must be a pair (k N/m, c N·s/m)") from None
    return {"stiffness": number("k", k, "N/m"), "damping": number("c", c, "N·s/m")}


def _given(what: str, inputs: dict) -> str:
    return f"{what}(" + ", ".join(f"{name} = {value:g}" for name, value in inputs.items()) + ")"


def _checked(what: str, inputs: dict, status: int, outputs) -> None:
    """Raises SteadystepError for a failure of the library, and for a result that is not finite; the message starts
    with the call and every input, since the library's message names the value it checked last, which is not
    always the one at fault (a mass that makes the matched step's numbers overflow)."""
    try:
        check(status)
    except SteadystepError as error:
        raise SteadystepError(error.status, f"{_given(what, inputs)}: {error.message}", error.code) from None
    for name, value in outputs().items():
        if not math.isfinite(value):
            raise SteadystepError("not finite", f"{_given(what, inputs)}: {name} = {value}: the result is not finite")


def softness_from_spring(spring: Spring | tuple[float, float], step_s: float) -> Softness:
    """The article's mapping at step step_s (s): erp = hk/(hk+c), cfm = 1/(hk+c)."""
    spring, step_s = _spring(spring), number("step_s", step_s, "s")
    out = ffi.new("ssSoftness*")
    _checked("softness_from_spring", {"k": spring["stiffness"], "c": spring["damping"], "step_s": step_s},
             lib.ssSoftnessFromSpring(spring, step_s, out), lambda: {"erp": out.erp, "cfm": out.cfm})
    return Softness(out.erp, out.cfm)


def spring_from_softness(softness: Softness | tuple[float, float], step_s: float) -> Spring:
    """The spring that erp, cfm tuned at a fixed step step_s (s) stand for: k = erp/(h·cfm), c = (1-erp)/cfm."""
    try:
        erp, cfm = softness
    except (TypeError, ValueError):
        raise SteadystepError("out of range", f"softness = {shown(softness)}: must be a pair (erp, cfm)") from None
    erp, cfm, step_s = number("erp", erp), number("cfm", cfm, "m/(N·s)"), number("step_s", step_s, "s")
    out = ffi.new("ssSpring*")
    _checked("spring_from_softness", {"erp": erp, "cfm": cfm, "step_s": step_s},
             lib.ssSpringFromSoftness({"erp": erp, "cfm": cfm}, step_s, out),
             lambda: {"stiffness": out.stiffness, "damping": out.damping})
    return Spring(out.stiffness, out.damping)


def spring_from_frequency(frequency_hz: float, damping_ratio: float, mass: float) -> Spring:
    """k = m·w², c = 2·zeta·m·w with w = 2π·frequency_hz, for a row of effective mass `mass` (kg)."""
    inputs = {"frequency_hz": number("frequency_hz", frequency_hz, "Hz"),
              "damping_ratio": number("damping_ratio", damping_ratio), "mass": number("mass", mass, "kg")}
    out = ffi.new("ssSpring*")
    _checked("spring_from_frequency", inputs, lib.ssSpringFromFrequency(*inputs.values(), out),
             lambda: {"stiffness": out.stiffness, "damping": out.damping})
    return Spring(out.stiffness, out.damping)


def frequency_from_spring(spring: Spring | tuple[float, float], mass: float) -> tuple[float, float]:
    """The undamped natural frequency (Hz) and damping ratio of a spring on mass (kg)."""
    spring, mass = _spring(spring), number("mass", mass, "kg")
    frequency = ffi.new("double*")
    ratio = ffi.new("double*")
    _checked("frequency_from_spring", {"k": spring["stiffness"], "c": spring["damping"], "mass": mass},
             lib.ssFrequencyFromSpring(spring, mass, frequency, ratio),
             lambda: {"frequency_hz": frequency[0], "damping_ratio": ratio[0]})
    return frequency[0], ratio[0]


def matched_softness(spring: Spring | tuple[float, float], mass: float, step_s: float) -> Softness:
    """The matched mapping: erp, cfm whose discrete poles are exp(s·h) of the spring's exact poles (needs c > 0)."""
    spring, mass, step_s = _spring(spring), number("mass", mass, "kg"), number("step_s", step_s, "s")
    out = ffi.new("ssSoftness*")
    _checked("matched_softness", {"k": spring["stiffness"], "c": spring["damping"], "mass": mass, "step_s": step_s},
             lib.ssMatchedSoftness(spring, mass, step_s, out), lambda: {"erp": out.erp, "cfm": out.cfm})
    return Softness(out.erp, out.cfm)


def exact_softness(spring: Spring | tuple[float, float], mass: float, step_s: float,
                   previous_step_s: float = 0.0) -> Softness:
    """The exact mapping: ODE's step after one of previous_step_s (0 = no history) lands on the exact sample."""
    return _mapped("exact_softness", lib.ssExactSoftness, spring, mass, step_s, previous_step_s)


def softness_for(mapping: str, spring: Spring | tuple[float, float], mass: float, step_s: float,
                 previous_step_s: float = 0.0) -> Softness:
    """Any mapping by name ("implicit-euler", "matched", "exact")."""
    if not isinstance(mapping, str) or mapping not in MAPPINGS:
        raise SteadystepError("unsupported", f"mapping = {shown(mapping)}: must be one of {', '.join(MAPPINGS)}")
    return _mapped(f"softness_for[{mapping}]", lambda *args: lib.ssSoftnessFor(MAPPINGS[mapping], *args), spring,
                   mass, step_s, previous_step_s)


def _mapped(what: str, function, spring, mass, step_s, previous_step_s) -> Softness:
    spring = _spring(spring)
    inputs = {"k": spring["stiffness"], "c": spring["damping"], "mass": number("mass", mass, "kg"),
              "step_s": number("step_s", step_s, "s"), "previous_step_s": number("previous_step_s", previous_step_s,
                                                                                 "s")}
    out = ffi.new("ssSoftness*")
    _checked(what, inputs, function(spring, inputs["mass"], inputs["step_s"], inputs["previous_step_s"], out),
             lambda: {"erp": out.erp, "cfm": out.cfm})
    return Softness(out.erp, out.cfm)

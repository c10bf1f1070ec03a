"""Springs and softness: thin wrappers over the C conversions of spring.h (SI units throughout).

A spring is (k N/m, c N·s/m); softness is ODE's (erp, cfm) for one step of h seconds. For angular rows read
N·m/rad, N·m·s/rad and kg·m². Every bad input raises SteadystepError naming the value, and so does a result that
is not finite (whatever the library returned): every number returned here is finite.

Every number may also be a numpy array (k and c of a spring too): the arrays are broadcast together, each element
is converted as a scalar would be, and the result holds arrays of the broadcast shape (Softness(erp=array,
cfm=array), ...). A bad element raises SteadystepError naming its index and value. Lists and tuples are not arrays
here (a spring is a pair): pass np.asarray(...) to convert many.
"""

from __future__ import annotations

import math
import sys
from typing import NamedTuple

from steadystep.core._native import SteadystepError, check, ffi, lib, number, shown, text
from steadystep.core.enums import Mapping, Status

# The mappings by the library's names for them (ssMappingName: "implicit-euler", "matched", "exact").
MAPPINGS = {text(lib.ssMappingName(mapping)): int(mapping) for mapping in Mapping}


class Spring(NamedTuple):
    """A spring-damper: stiffness k (N/m) and damping c (N·s/m)."""

    stiffness: float
    damping: float


class Softness(NamedTuple):
    """ODE's softness of one constraint row for one step: erp (non-dimensional) and cfm (m/(N·s))."""

    erp: float
    cfm: float


def spring_fields(spring: Spring | tuple[float, float]) -> dict:
    """The C ssSpring's fields of a (k N/m, c N·s/m) pair, each checked as a number; the binding's one reading."""
    try:
        k, c = spring
    except (TypeError, ValueError):
        raise SteadystepError(Status.OUT_OF_RANGE,
                              f"spring = {shown(spring)}: must be a pair (k N/m, c N·s/m)") from None
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
        raise SteadystepError(error.code, f"{_given(what, inputs)}: {error.message}") from None
    for name, value in outputs().items():
        if not math.isfinite(value):
            raise SteadystepError(Status.NOT_FINITE,
                                  f"{_given(what, inputs)}: {name} = {value}: the result is not finite")


def _implicit_euler_softness(spring: Spring | tuple[float, float], step_s: float) -> Softness:
    """The article's mapping at step step_s (s): erp = hk/(hk+c), cfm = 1/(hk+c)."""
    spring, step_s = spring_fields(spring), number("step_s", step_s, "s")
    out = ffi.new("ssSoftness*")
    _checked("implicit_euler_softness", {"k": spring["stiffness"], "c": spring["damping"], "step_s": step_s},
             lib.ssImplicitEulerSoftness(spring, step_s, out), lambda: {"erp": out.erp, "cfm": out.cfm})
    return Softness(out.erp, out.cfm)


def _spring_from_softness(softness: Softness | tuple[float, float], step_s: float) -> Spring:
    """The spring that erp, cfm tuned at a fixed step step_s (s) stand for: k = erp/(h·cfm), c = (1-erp)/cfm."""
    try:
        erp, cfm = softness
    except (TypeError, ValueError):
        raise SteadystepError(Status.OUT_OF_RANGE, f"softness = {shown(softness)}: must be a pair (erp, cfm)") from None
    erp, cfm, step_s = number("erp", erp), number("cfm", cfm, "m/(N·s)"), number("step_s", step_s, "s")
    out = ffi.new("ssSpring*")
    _checked("spring_from_softness", {"erp": erp, "cfm": cfm, "step_s": step_s},
             lib.ssSpringFromSoftness({"erp": erp, "cfm": cfm}, step_s, out),
             lambda: {"stiffness": out.stiffness, "damping": out.damping})
    return Spring(out.stiffness, out.damping)


def _spring_from_frequency(frequency_hz: float, damping_ratio: float, mass: float) -> Spring:
    """k = m·w², c = 2·zeta·m·w with w = 2π·frequency_hz, for a row of effective mass `mass` (kg)."""
    inputs = {"frequency_hz": number("frequency_hz", frequency_hz, "Hz"),
              "damping_ratio": number("damping_ratio", damping_ratio), "mass": number("mass", mass, "kg")}
    out = ffi.new("ssSpring*")
    _checked("spring_from_frequency", inputs, lib.ssSpringFromFrequency(*inputs.values(), out),
             lambda: {"stiffness": out.stiffness, "damping": out.damping})
    return Spring(out.stiffness, out.damping)


def _frequency_from_spring(spring: Spring | tuple[float, float], mass: float) -> tuple[float, float]:
    """The undamped natural frequency (Hz) and damping ratio of a spring on mass (kg)."""
    spring, mass = spring_fields(spring), number("mass", mass, "kg")
    frequency = ffi.new("double*")
    ratio = ffi.new("double*")
    _checked("frequency_from_spring", {"k": spring["stiffness"], "c": spring["damping"], "mass": mass},
             lib.ssFrequencyFromSpring(spring, mass, frequency, ratio),
             lambda: {"frequency_hz": frequency[0], "damping_ratio": ratio[0]})
    return frequency[0], ratio[0]


def _matched_softness(spring: Spring | tuple[float, float], mass: float, step_s: float) -> Softness:
    """The matched mapping: erp, cfm whose discrete poles are exp(s·h) of the spring's exact poles (needs c > 0)."""
    spring, mass, step_s = spring_fields(spring), number("mass", mass, "kg"), number("step_s", step_s, "s")
    out = ffi.new("ssSoftness*")
    _checked("matched_softness", {"k": spring["stiffness"], "c": spring["damping"], "mass": mass, "step_s": step_s},
             lib.ssMatchedSoftness(spring, mass, step_s, out), lambda: {"erp": out.erp, "cfm": out.cfm})
    return Softness(out.erp, out.cfm)


def _exact_softness(spring: Spring | tuple[float, float], mass: float, step_s: float,
                   previous_step_s: float = 0.0) -> Softness:
    """The exact mapping: ODE's step after one of previous_step_s (0 = no history) lands on the exact sample."""
    return _mapped("exact_softness", lib.ssExactSoftness, spring, mass, step_s, previous_step_s)


def _softness_for(mapping: str, spring: Spring | tuple[float, float], mass: float, step_s: float,
                 previous_step_s: float = 0.0) -> Softness:
    """Any mapping by name ("implicit-euler", "matched", "exact")."""
    if not isinstance(mapping, str) or mapping not in MAPPINGS:
        raise SteadystepError(Status.UNSUPPORTED, f"mapping = {shown(mapping)}: must be one of {', '.join(MAPPINGS)}")
    return _mapped(f"softness_for[{mapping}]", lambda *args: lib.ssSoftnessFor(MAPPINGS[mapping], *args), spring,
                   mass, step_s, previous_step_s)


def _mapped(what: str, function, spring, mass, step_s, previous_step_s) -> Softness:
    spring = spring_fields(spring)
    inputs = {"k": spring["stiffness"], "c": spring["damping"], "mass": number("mass", mass, "kg"),
              "step_s": number("step_s", step_s, "s"), "previous_step_s": number("previous_step_s", previous_step_s,
                                                                                 "s")}
    out = ffi.new("ssSoftness*")
    _checked(what, inputs, function(spring, inputs["mass"], inputs["step_s"], inputs["previous_step_s"], out),
             lambda: {"erp": out.erp, "cfm": out.cfm})
    return Softness(out.erp, out.cfm)


# ---- elementwise over numpy arrays ---------------------------------------------------------------------------------

def _is_array(value) -> bool:
    # numpy is imported only by a program that has arrays to convert: without it loaded, nothing is an array (and
    # `import steadystep` stays without numpy's import time).
    numpy = sys.modules.get("numpy")
    return numpy is not None and isinstance(value, numpy.ndarray) and value.ndim > 0


def _elementwise(scalar, result_type, names: tuple[str, ...], *values):
    """scalar(*values) when every value is a scalar; else scalar on every element of the broadcast arrays, its
    results gathered into arrays of the broadcast shape (as result_type, or a tuple)."""
    if not any(_is_array(value) for value in values):
        return scalar(*values)
    import numpy as np
    try:
        shape = np.broadcast_shapes(*(np.shape(value) for value in values))
    except ValueError:
        shapes = ", ".join(f"{name} {np.shape(value)}" for name, value in zip(names, values))
        raise SteadystepError(Status.OUT_OF_RANGE, f"shapes {shapes}: cannot be broadcast together") from None
    columns = [np.broadcast_to(value, shape) if _is_array(value) else None for value in values]
    outputs = None
    for index in np.ndindex(shape):
        element = [value if column is None else column[index].item() for value, column in zip(values, columns)]
        try:
            result = scalar(*element)
        except SteadystepError as error:
            raise SteadystepError(error.code, f"at index {index}: {error.message}") from None
        if outputs is None:
            outputs = [np.empty(shape) for _ in result]
        for output, number_ in zip(outputs, result):
            output[index] = number_
    if outputs is None:  # an empty array: as many empty results as the scalar function returns
        outputs = [np.empty(shape) for _ in range(2)]
    return result_type(*outputs)


def _pair(value, what: str, names: str):
    """A pair (a Spring, a Softness, a tuple) as its two members, so that each may be an array."""
    if isinstance(value, (str, bytes)):
        return value  # refused by the scalar function, which names its members
    try:
        first, second = value
    except (TypeError, ValueError):
        raise SteadystepError(Status.OUT_OF_RANGE, f"{what} = {shown(value)}: must be a pair ({names})") from None
    return first, second


def implicit_euler_softness(spring: Spring | tuple[float, float], step_s: float) -> Softness:
    """The article's mapping at step step_s (s): erp = hk/(hk+c), cfm = 1/(hk+c); spring is (k N/m, c N·s/m)."""
    if isinstance(spring, (str, bytes)):
        return _implicit_euler_softness(spring, step_s)
    k, c = _pair(spring, "spring", "k N/m, c N·s/m")
    return _elementwise(lambda k, c, h: _implicit_euler_softness((k, c), h), Softness, ("k", "c", "step_s"),
                        k, c, step_s)


def spring_from_softness(softness: Softness | tuple[float, float], step_s: float) -> Spring:
    """The spring (k N/m, c N·s/m) that erp, cfm (m/(N·s)) tuned at a fixed step step_s (s) stand for:
    k = erp/(h·cfm), c = (1-erp)/cfm."""
    erp, cfm = _pair(softness, "softness", "erp, cfm")
    return _elementwise(lambda erp, cfm, h: _spring_from_softness((erp, cfm), h), Spring, ("erp", "cfm", "step_s"),
                        erp, cfm, step_s)


def spring_from_frequency(frequency_hz: float, damping_ratio: float, mass: float) -> Spring:
    """k = m·w² (N/m), c = 2·zeta·m·w (N·s/m) with w = 2π·frequency_hz (Hz), for a row of effective mass `mass`
    (kg); damping_ratio is non-dimensional (1 = critical)."""
    return _elementwise(_spring_from_frequency, Spring, ("frequency_hz", "damping_ratio", "mass"), frequency_hz,
                        damping_ratio, mass)


def frequency_from_spring(spring: Spring | tuple[float, float], mass: float) -> tuple[float, float]:
    """The undamped natural frequency (Hz) and damping ratio of a spring (k N/m, c N·s/m) on mass (kg)."""
    if isinstance(spring, (str, bytes)):
        return _frequency_from_spring(spring, mass)
    k, c = _pair(spring, "spring", "k N/m, c N·s/m")
    return _elementwise(lambda k, c, m: _frequency_from_spring((k, c), m), lambda *pair: tuple(pair),
                        ("k", "c", "mass"), k, c, mass)


def matched_softness(spring: Spring | tuple[float, float], mass: float, step_s: float) -> Softness:
    """The matched mapping for a row of effective mass `mass` (kg) at step_s (s): erp, cfm whose discrete poles are
    exp(s·h) of the spring's exact poles (needs c > 0)."""
    if isinstance(spring, (str, bytes)):
        return _matched_softness(spring, mass, step_s)
    k, c = _pair(spring, "spring", "k N/m, c N·s/m")
    return _elementwise(lambda k, c, m, h: _matched_softness((k, c), m, h), Softness, ("k", "c", "mass", "step_s"),
                        k, c, mass, step_s)


def exact_softness(spring: Spring | tuple[float, float], mass: float, step_s: float,
                   previous_step_s: float = 0.0) -> Softness:
    """The exact mapping (mass in kg, steps in s): ODE's step after one of previous_step_s (0 = no history) lands
    on the exact solution's sample."""
    if isinstance(spring, (str, bytes)):
        return _exact_softness(spring, mass, step_s, previous_step_s)
    k, c = _pair(spring, "spring", "k N/m, c N·s/m")
    return _elementwise(lambda k, c, m, h, p: _exact_softness((k, c), m, h, p), Softness,
                        ("k", "c", "mass", "step_s", "previous_step_s"), k, c, mass, step_s, previous_step_s)


def softness_for(mapping: str, spring: Spring | tuple[float, float], mass: float, step_s: float,
                 previous_step_s: float = 0.0) -> Softness:
    """Any mapping by name ("implicit-euler", "matched", "exact"); mass in kg, steps in s."""
    if isinstance(spring, (str, bytes)):
        return _softness_for(mapping, spring, mass, step_s, previous_step_s)
    k, c = _pair(spring, "spring", "k N/m, c N·s/m")
    return _elementwise(lambda k, c, m, h, p: _softness_for(mapping, (k, c), m, h, p), Softness,
                        ("k", "c", "mass", "step_s", "previous_step_s"), k, c, mass, step_s, previous_step_s)

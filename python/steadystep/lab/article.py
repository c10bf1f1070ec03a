"""The article's own model of a spring-damper, independent of ODE and of the C library.

A body of mass m (kg) on a spring k (N/m) with a damper c (N·s/m), extension x (m), velocity v (m/s):

- equations 4 and 5 of "Tweaking ODE for variable time steps", one step of h seconds (h may change every step):
      x' = x (1 - k h²/2m) + v (1 - c h/2m) h          (4: second-order Taylor with the force at the start)
      v' = v (1 - c h/m) - (k/m) x h                   (5: explicit Euler for the velocity)
  The article itself calls this approximation "not optimal": it is there to compare step lengths, not to be right.
- the exact solution for weak damping (c / 2√(mk) < 1), the article's form:
      x(t) = C e^{-c t/2m} sin(ω t + α),  ω = √(k/m - (c/2m)²),
  with C and α from the initial state: x0 = C sin α, v0 = C (ω cos α - (c/2m) sin α).
- the implicit-Euler step, m (v' - v)/h = -k (x + h v') - c v', x' = x + h v': what ODE's step solves under the
  article's erp/cfm mapping (not the article's equations; kept beside them for comparison with real ODE).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from steadystep.core._native import SteadystepError, number, shown
from steadystep.core.enums import Status


class Oscillator(NamedTuple):
    """A lone spring-damper: mass (kg), stiffness (N/m), damping (N·s/m)."""

    mass: float
    stiffness: float
    damping: float

    @property
    def decay_rate(self) -> float:
        """c / 2m (1/s): the envelope e^{-rate·t}. Every property raises SteadystepError for an oscillator that
        _validate refuses (a mass that is not positive, a number that is not finite)."""
        _validate(self)
        return self.damping / (2.0 * self.mass)

    @property
    def angular_frequency(self) -> float:
        """ω = √(k/m - (c/2m)²) (rad/s), the damped angular frequency. SteadystepError when damping is critical
        or stronger (nothing oscillates)."""
        rate = self.decay_rate
        square = self.stiffness / self.mass - rate * rate  # inf rather than OverflowError when huge
        if not square > 0:
            raise SteadystepError(Status.OUT_OF_RANGE, f"k/m - (c/2m)^2 = {square:g} 1/s^2: no damped oscillation")
        return math.sqrt(square)

    @property
    def damping_ratio(self) -> float:
        """c / 2√(mk), non-dimensional."""
        _validate(self)
        return self.damping / (2.0 * math.sqrt(self.mass) * math.sqrt(self.stiffness))  # √m√k: m·k may underflow


# The article's kind of spring (issue 4): 1 kg, 40 N/m, 1 N·s/m, released at rest from 0.5 m.
ARTICLE_OSCILLATOR = Oscillator(mass=1.0, stiffness=40.0, damping=1.0)
ARTICLE_X0_M = 0.5


def _validate(osc: Oscillator) -> None:
    for name, unit, value in (("mass", "kg", osc.mass), ("stiffness", "N/m", osc.stiffness),
                              ("damping", "N·s/m", osc.damping)):
        if not math.isfinite(value):
            raise SteadystepError(Status.NOT_FINITE, f"{name} = {value} {unit}: must be finite")
    if osc.mass <= 0:
        raise SteadystepError(Status.OUT_OF_RANGE, f"mass = {osc.mass} kg: must be positive")
    if osc.stiffness <= 0:
        raise SteadystepError(Status.OUT_OF_RANGE, f"stiffness = {osc.stiffness} N/m: must be positive")
    if osc.damping < 0:
        raise SteadystepError(Status.OUT_OF_RANGE, f"damping = {osc.damping} N·s/m: must not be negative")


def article_step(osc: Oscillator, x: float, v: float, step_s: float) -> tuple[float, float]:
    """One step of equations 4 and 5: the state (m, m/s) after step_s seconds."""
    m, k, c, h = osc.mass, osc.stiffness, osc.damping, step_s
    x_next = x * (1.0 - k / (2.0 * m) * h * h) + v * (1.0 - c / (2.0 * m) * h) * h
    v_next = v * (1.0 - c / m * h) - k / m * x * h
    return x_next, v_next


def implicit_euler_step(osc: Oscillator, x: float, v: float, step_s: float) -> tuple[float, float]:
    """One implicit-Euler step of the spring (what ODE solves with erp = hk/(hk+c), cfm = 1/(hk+c))."""
    m, k, c, h = osc.mass, osc.stiffness, osc.damping, step_s
    v_next = (m * v - h * k * x) / (m + h * c + h * h * k)
    return x + h * v_next, v_next


def integrate(osc: Oscillator, x0: float, v0: float, steps_s, method: str = "article"):
    """Steps the model through the given step lengths (s). Returns (t, x, v) arrays of len(steps_s) + 1, starting
    with the initial state at t = 0. method: "article" (equations 4 and 5) or "implicit" (implicit Euler)."""
    _validate(osc)
    step = {"article": article_step, "implicit": implicit_euler_step}.get(method)
    if step is None:
        raise SteadystepError(Status.UNSUPPORTED, f"method = {method!r}: must be 'article' or 'implicit'")
    x0, v0 = number("x0", x0, "m"), number("v0", v0, "m/s")
    try:
        steps = np.asarray(steps_s, dtype=float)
    except (TypeError, ValueError):
        raise SteadystepError(Status.OUT_OF_RANGE, f"steps_s = {shown(steps_s)}: must be step lengths in s") from None
    if steps.ndim != 1 or not np.all(np.isfinite(steps)) or np.any(steps <= 0):
        raise SteadystepError(Status.OUT_OF_RANGE, "steps_s: every step length must be finite and positive (s)")
    t = np.concatenate(([0.0], np.cumsum(steps)))
    x = np.empty(len(steps) + 1)
    v = np.empty(len(steps) + 1)
    x[0], v[0] = x0, v0
    for i, h in enumerate(steps):
        x[i + 1], v[i + 1] = step(osc, x[i], v[i], h)
    return t, x, v


def exact_parameters(osc: Oscillator, x0: float, v0: float) -> tuple[float, float]:
    """C (m) and α (rad) of the exact solution through x(0) = x0, ẋ(0) = v0."""
    _validate(osc)
    x0, v0 = number("x0", x0, "m"), number("v0", v0, "m/s")
    if osc.damping_ratio >= 1.0:
        raise SteadystepError(Status.OUT_OF_RANGE, f"damping ratio = {osc.damping_ratio:g}: the exact solution here "
                                              "is for weak damping (< 1)")
    w = osc.angular_frequency
    # x0 = C sin α and (v0 + γ x0)/ω = C cos α, γ = c/2m.
    cos_part = (v0 + osc.decay_rate * x0) / w
    return math.hypot(x0, cos_part), math.atan2(x0, cos_part)


def exact(osc: Oscillator, x0: float, v0: float, t) -> tuple[np.ndarray, np.ndarray]:
    """The exact extension (m) and velocity (m/s) at times t (s)."""
    amplitude, alpha = exact_parameters(osc, x0, v0)
    try:
        t = np.asarray(t, dtype=float)
    except (TypeError, ValueError):
        raise SteadystepError(Status.OUT_OF_RANGE, f"t = {shown(t)}: must be times in s") from None
    w, gamma = osc.angular_frequency, osc.decay_rate
    envelope = amplitude * np.exp(-gamma * t)
    phase = w * t + alpha
    return envelope * np.sin(phase), envelope * (w * np.cos(phase) - gamma * np.sin(phase))

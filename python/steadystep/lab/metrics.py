"""What every comparison prints: deviations, spread across profiles, step counts, blow-ups, fitted decay.

All trajectories are (t, y) pairs of 1-D arrays: times (s) and one followed quantity in its unit.
"""

from __future__ import annotations

import math

import numpy as np

from steadystep.core._native import SteadystepError, number, shown
from steadystep.core.enums import Status


def _samples(name: str, values) -> np.ndarray:
    """values as a 1-D float array; SteadystepError naming it when it is not one."""
    try:
        array = np.asarray(values, float)
    except (TypeError, ValueError):
        raise SteadystepError(Status.OUT_OF_RANGE, f"{name} = {shown(values)}: must be an array of numbers") from None
    if array.ndim != 1:
        raise SteadystepError(Status.OUT_OF_RANGE, f"{name}: must be one-dimensional, not of shape {array.shape}")
    return array


def rms_deviation(t, y, reference_t, reference_y) -> float:
    """RMS of y minus the reference interpolated at t, relative to the reference's amplitude (max - min).

    Only times inside the reference's span count. A trajectory with a NaN or an infinity (a blow-up) gives inf.
    """
    t, y = _samples("t", t), _samples("y", y)
    reference_t, reference_y = _samples("reference_t", reference_t), _samples("reference_y", reference_y)
    if len(t) != len(y) or len(reference_t) != len(reference_y):
        raise SteadystepError(Status.OUT_OF_RANGE, "rms_deviation: t and y, and the reference's t and y, must match")
    if len(t) == 0 or len(reference_t) < 2:
        raise SteadystepError(Status.OUT_OF_RANGE, "rms_deviation: needs samples and a reference of two or more")
    if not np.all(np.isfinite(y)):
        return math.inf
    inside = (t >= reference_t[0]) & (t <= reference_t[-1])
    if not np.any(inside):
        raise SteadystepError(Status.OUT_OF_RANGE, "rms_deviation: no sample lies within the reference's time span")
    difference = y[inside] - np.interp(t[inside], reference_t, reference_y)
    amplitude = float(np.max(reference_y) - np.min(reference_y))
    rms = float(np.sqrt(np.mean(difference**2)))
    if amplitude == 0.0:
        return 0.0 if rms == 0.0 else math.inf
    return rms / amplitude


def rms_vs_exact(x, exact_x, x0: float) -> float:
    """RMS of x minus the exact solution at the same times, relative to |x0| (m/m). inf after a blow-up."""
    x, exact_x, x0 = _samples("x", x), _samples("exact_x", exact_x), number("x0", x0, "m")
    if len(x) != len(exact_x):
        raise SteadystepError(Status.OUT_OF_RANGE, f"rms_vs_exact: {len(x)} samples against {len(exact_x)} exact ones")
    if x0 == 0 or not math.isfinite(x0):
        raise SteadystepError(Status.OUT_OF_RANGE, f"x0 = {x0} m: must be finite and non-zero")
    if not np.all(np.isfinite(x)):
        return math.inf
    return float(np.sqrt(np.mean((x - exact_x) ** 2)) / abs(x0))


def spread(deviations) -> float:
    """The spread of a policy across profiles: the RMS over profiles of each profile's deviation."""
    values = _samples("deviations", list(deviations))
    if len(values) == 0:
        raise SteadystepError(Status.OUT_OF_RANGE, "spread: needs at least one profile's deviation")
    return float(np.sqrt(np.mean(values**2)))


def steps_per_frame(step_count: int, frame_count: int) -> float:
    """Physics steps per rendered frame."""
    return step_count / frame_count if frame_count > 0 else math.nan


def steps_per_second(step_count: int, simulated_s: float) -> float:
    """Physics steps per simulated second (1/s)."""
    return step_count / simulated_s if simulated_s > 0 else math.nan


def _least_squares(a: np.ndarray, b: np.ndarray) -> np.ndarray | None:
    """The least-squares solution of a·z = b, or None when a or b holds an infinity or a NaN: LAPACK's solver
    (gelsd) can loop for ever on such input instead of failing."""
    if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
        return None
    return np.linalg.lstsq(a, b, rcond=None)[0]


def _prony(t: np.ndarray, x: np.ndarray) -> tuple[float, float]:
    """A first estimate of (decay rate 1/s, angular frequency rad/s) from the samples on a uniform grid.

    A damped sinusoid about an offset obeys x[n+1] = a1 x[n] + a2 x[n-1] + a0 exactly on a uniform grid of
    spacing d, with a2 = -r², a1 = 2 r cos(ω d), r = e^{-γ d}: a linear least-squares fit gives γ and ω."""
    spacing = float(np.median(np.diff(t)))
    grid = np.arange(t[0], t[-1] + 0.5 * spacing, spacing)
    grid = grid[grid <= t[-1]]
    u = np.interp(grid, t, x)
    if len(u) < 8:
        raise SteadystepError(Status.OUT_OF_RANGE, "fit_oscillation: needs at least 8 samples")
    design = np.column_stack((u[1:-1], u[:-2], np.ones(len(u) - 2)))
    solution = _least_squares(design, u[2:])
    if solution is None or not np.all(np.isfinite(solution)) or not math.isfinite(spacing) or spacing <= 0:
        raise SteadystepError(Status.OUT_OF_RANGE, "fit_oscillation: the samples do not fit in double precision")
    a1, a2, _ = solution
    if a2 >= 0:
        raise SteadystepError(Status.OUT_OF_RANGE, "fit_oscillation: the trajectory does not oscillate")
    r = math.sqrt(-a2)
    cosine = a1 / (2.0 * r)
    if not -1.0 < cosine < 1.0:
        raise SteadystepError(Status.OUT_OF_RANGE, "fit_oscillation: the trajectory does not oscillate")
    return -math.log(r) / spacing, math.acos(cosine) / spacing


def _residual(params: np.ndarray, t: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Residual of the best e^{-γt}(A cos ωt + B sin ωt) + D for given (γ, ω): A, B, D are linear."""
    gamma, omega = params
    envelope = np.exp(-gamma * t)
    basis = np.column_stack((envelope * np.cos(omega * t), envelope * np.sin(omega * t), np.ones_like(t)))
    coefficients = _least_squares(basis, x)
    if coefficients is None:  # the envelope overflowed at these (γ, ω): as bad a trial as can be
        return np.full_like(x, np.inf)
    return basis @ coefficients - x


def fit_oscillation(t, x) -> tuple[float, float]:
    """Fits x(t) ≈ e^{-γt}(A cos ωt + B sin ωt) + D and returns (γ in 1/s, ω in rad/s).

    Starts from a Prony estimate and refines (γ, ω) by Levenberg-Marquardt on the samples as they are (steps of
    any length), with A, B, D solved linearly at each trial. Raises SteadystepError when nothing oscillates.
    """
    t, x = _samples("t", t), _samples("x", x)
    if (t.shape != x.shape or len(t) < 8 or not np.all(np.isfinite(x)) or not np.all(np.isfinite(t))
            or np.any(np.diff(t) <= 0)):
        raise SteadystepError(Status.OUT_OF_RANGE, "fit_oscillation: needs 8 or more finite samples at rising times")
    # γ and ω do not depend on the amplitude: fitting x / max|x| keeps every product far from overflow.
    scale = float(np.max(np.abs(x)))
    if scale == 0:
        raise SteadystepError(Status.OUT_OF_RANGE, "fit_oscillation: the trajectory does not oscillate")
    t, x = t - t[0], x / scale
    params = np.array(_prony(t, x))
    damping = 1e-3
    cost = float(np.sum(_residual(params, t, x) ** 2))
    for _ in range(100):
        residual = _residual(params, t, x)
        jacobian = np.empty((len(t), 2))
        for j in range(2):
            delta = np.zeros(2)
            delta[j] = 1e-7 * max(abs(params[j]), 1e-3)
            jacobian[:, j] = (_residual(params + delta, t, x) - residual) / delta[j]
        normal = jacobian.T @ jacobian
        gradient = jacobian.T @ residual
        improved = False
        while damping < 1e12:
            try:
                trial = params - np.linalg.solve(normal + damping * np.diag(np.diag(normal)), gradient)
            except np.linalg.LinAlgError:  # a flat direction: more damping makes the system regular
                damping *= 10.0
                continue
            trial_cost = float(np.sum(_residual(trial, t, x) ** 2))
            if trial_cost < cost:
                change = np.max(np.abs(trial - params) / np.maximum(np.abs(params), 1e-12))
                params, cost, damping, improved = trial, trial_cost, damping * 0.3, True
                break
            damping *= 10.0
        if not improved or change < 1e-13:
            break
    if not np.all(np.isfinite(params)):
        raise SteadystepError(Status.OUT_OF_RANGE, "fit_oscillation: the fit does not converge to finite values")
    return float(params[0]), float(params[1])

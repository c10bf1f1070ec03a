"""The largest stable step: how long a physics step a scene survives under a policy.

The article asks for "a largest time step the simulation can handle"; this finds it on real ODE. A trial runs the
scene with every frame one step of length h (max_step_s = fixed_step_s = h). It is stable when the run ends without
a blow-up (NaN or a speed above the scene's limit) and every followed quantity stays within the reference run's
range widened by that range on both sides. The step is found by bisection in log(h), which assumes that a scene
stable at some h is stable at every shorter one; a scene that is not (a resonance) gets the border nearest to the
start of the search.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from steadystep.lab import runs
from steadystep.core._native import SteadystepError, lib, number
from steadystep.core.enums import Status
from steadystep.lab.limits import MAX_RUN_STEPS, MIN_MEASURED_DURATION_S

DEFAULT_LOW_S = 1.0 / 1000.0
DEFAULT_HIGH_S = 0.25


def default_policies() -> list[str]:
    """The library's policies that do not cut frames at a fixed step of their own (naive, implicit-euler, matched,
    exact): with every frame one step of h, a fixed policy steps as its mapping's substep policy does."""
    return [policy for policy in runs.policy_names() if runs.make_stepping(policy)["cut"] != lib.SS_CUT_FIXED]


# Below this the bisection's midpoint would no longer move between its ends in double precision.
MIN_TOLERANCE = 1e-9


@dataclass
class ProbeResult:
    scene: str
    policy: str
    stable_s: float      # the longest step found stable (s); 0 when even low_s is not
    unstable_s: float    # the shortest step found unstable (s); inf when high_s is stable
    trials: int
    reason: str          # why unstable_s failed ("blow-up: ...", "x left its range", ""), for the report
    grid: dict = field(default_factory=dict)  # a study's swept values for this bisection (the report's), {} if none


def _trial(scene: str, policy: str, step_s: float, duration_s: float, bounds: dict, params,
           name: str = "step_s") -> str:
    """'' when the scene is stable at step_s, else why not. A step the library refuses is refused naming it as
    name (low_s, high_s: what the caller gave)."""
    try:
        result = runs.run(scene, f"fixed:{1.0 / step_s!r}", policy, duration_s, params=params,
                          stepping={"max_step_s": step_s, "fixed_step_s": step_s})
    except SteadystepError as error:
        if error.status != "no finite mapping":  # a mapping with nothing to offer at this step is a failure of it
            raise SteadystepError(error.code, f"{name} = {step_s:g} s: {error.message}") from None
        return f"{error.status}: {error.message}"
    if result.step_count == 0:  # a fixed cut steps whole steps only: a trial shorter than its step takes none
        raise SteadystepError(Status.OUT_OF_RANGE, f"{name} = {step_s:g} s: policy {policy} takes no step of "
                              f"{step_s:g} s within duration_s = {duration_s:g} s (a fixed cut steps whole steps "
                              f"only), so nothing is probed: give a duration of at least {step_s:g} s or a shorter "
                              f"{name}")
    if result.failed:  # blew up or broke
        return f"{result.status}: {result.message}"
    for name, (low, high) in bounds.items():
        values = result.quantities[name]
        if not np.all(np.isfinite(values)) or values.min() < low or values.max() > high:
            return f"{name} left [{low:.3g}, {high:.3g}]"
    return ""


def largest_stable_step(scene: str, policy: str, duration_s: float = 3.0, low_s: float = DEFAULT_LOW_S,
                        high_s: float = DEFAULT_HIGH_S, tolerance: float = 0.02, params: dict | None = None
                        ) -> ProbeResult:
    """Bisects for the longest step in [low_s, high_s] at which scene stays stable under policy, to a relative
    tolerance (at least 1e-9). duration_s (s) is at least MIN_MEASURED_DURATION_S (0.1 s), and a trial at low_s may
    take at most MAX_RUN_STEPS steps (lab/limits.py): duration_s / low_s <= 1e7. Raises SteadystepError naming the value
    for bad input (the scene, policy and parameters are checked by the library)."""
    values = {}
    for name, value in (("duration_s", duration_s), ("low_s", low_s), ("high_s", high_s), ("tolerance", tolerance)):
        value = values[name] = number(name, value)
        if not math.isfinite(value) or value <= 0:
            raise SteadystepError(Status.OUT_OF_RANGE, f"{name} = {value}: must be a positive finite number")
    duration_s, low_s, high_s, tolerance = values.values()
    if duration_s < MIN_MEASURED_DURATION_S:
        raise SteadystepError(Status.OUT_OF_RANGE, f"duration_s = {duration_s:g} s: a trial needs at least "
                              f"{MIN_MEASURED_DURATION_S:g} s to be measured")
    if tolerance < MIN_TOLERANCE:
        raise SteadystepError(Status.OUT_OF_RANGE, f"tolerance = {tolerance:g}: must be at least {MIN_TOLERANCE:g}")
    if low_s >= high_s:
        raise SteadystepError(Status.OUT_OF_RANGE, f"low_s = {low_s} s: must be shorter than high_s = {high_s} s")
    if duration_s / low_s > MAX_RUN_STEPS:
        raise SteadystepError(Status.OUT_OF_RANGE, f"low_s = {low_s:g} s: a trial of duration_s = {duration_s:g} s "
                              f"would take more than the bound of {MAX_RUN_STEPS} steps per run")
    reference = runs.reference_run(scene, duration_s, params)
    bounds = {}
    for name in runs.motion_quantities(scene):
        values = reference.quantities[name]
        width = max(float(values.max() - values.min()), 1e-3)
        bounds[name] = (float(values.min()) - width, float(values.max()) + width)

    trials = 1
    reason = _trial(scene, policy, high_s, duration_s, bounds, params, "high_s")
    if not reason:
        return ProbeResult(scene, policy, high_s, math.inf, trials, "")
    trials += 1
    low_reason = _trial(scene, policy, low_s, duration_s, bounds, params, "low_s")
    if low_reason:
        return ProbeResult(scene, policy, 0.0, low_s, trials, low_reason)
    stable, unstable = low_s, high_s
    while unstable / stable > 1.0 + tolerance:
        middle = math.exp(0.5 * (math.log(stable) + math.log(unstable)))  # sqrt(stable·unstable), never inf
        trials += 1
        why = _trial(scene, policy, middle, duration_s, bounds, params)
        if why:
            unstable, reason = middle, why
        else:
            stable = middle
    return ProbeResult(scene, policy, stable, unstable, trials, reason)


def largest_stable_steps(scene: str, policies, duration_s: float = 3.0, low_s: float = DEFAULT_LOW_S,
                         high_s: float = DEFAULT_HIGH_S, tolerance: float = 0.02, params: dict | None = None,
                         executor=None, progress: bool | None = None) -> list[ProbeResult]:
    """largest_stable_step for each policy, one bisection per policy through executor (any
    concurrent.futures.Executor, or a name for study.make_executor: "local", "dask", ...; None: in this process),
    in the policies' order. progress: a tqdm bar on stderr (None: only on a terminal) counting finished policies.
    The results do not depend on the executor."""
    from steadystep.lab import study

    tasks = [dict(scene=scene, policy=policy, duration_s=duration_s, low_s=low_s, high_s=high_s,
                  tolerance=tolerance, params=params) for policy in policies]
    return study.sweep(largest_stable_step, tasks, executor, progress, f"steadystep probe {scene}", "policy",
                       lambda task: task["policy"])

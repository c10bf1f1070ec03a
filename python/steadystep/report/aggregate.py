"""The comparison's numbers from its finished runs: each run's row, each scene's deviation and consistency per
policy, how much those move when the random profiles are repeated with the next seed (the measured spread of
repeats, which decides whether the page names a winner or says they tie), who served each accurate mapping's rows
and contacts, and the oscillator's side-by-side table against the exact solution."""

from __future__ import annotations

import math

import numpy as np

from steadystep.lab import article, metrics, runs
from steadystep.core._native import SteadystepError
from steadystep.lab.consistency import consistency
from steadystep.report.model import Report, Row

SERVED_KINDS = ("by_mapping", "handed_to_matched", "handed_to_implicit_euler")


def deviation(result: runs.RunResult, reference: runs.RunResult, quantity: str) -> float:
    """The run's RMS deviation from the reference in quantity, over the reference's amplitude; inf when it failed."""
    if result.failed or result.step_count == 0:
        return math.inf
    return metrics.rms_deviation(result.times, result.quantities[quantity], reference.times,
                                 reference.quantities[quantity])


def _row(scene: str, result: runs.RunResult, reference: runs.RunResult, grid: dict) -> Row:
    quantities = runs.motion_quantities(scene)
    return Row(scene, result.profile, result.policy, {q: deviation(result, reference, q) for q in quantities},
               metrics.steps_per_frame(result.step_count, result.frame_count),
               metrics.steps_per_second(result.step_count, result.simulated_s),
               1e6 * result.wall_s / result.step_count if result.step_count else math.nan,
               result.status, rms_vs_exact(result) if scene == "oscillator" else None,
               dict(result.counters["rows"]), dict(result.counters["contacts"]), grid=dict(grid))


def compare_scene(report: Report, scene: str, done: dict, springs: list[dict], steps: list[dict],
                  probed: bool) -> None:
    """The scene's rows, deviations, consistency, repeat spreads, served counts and probes from its finished runs
    (done: by task key, tasks.tasks)."""
    report.params[scene] = done["reference", scene, 0].params
    quantities = runs.motion_quantities(scene)
    policies = report.policies[scene]
    spreads = {policy: {q: [] for q in quantities} for policy in policies}
    consistencies = {policy: {q: [] for q in quantities} for policy in policies}
    for i, point in enumerate(springs):
        reference = done["reference", scene, i]
        for j, step in enumerate(steps):
            rows = [_row(scene, done["run", scene, i, j, profile, policy], reference, {**point, **step})
                    for profile in report.profiles for policy in policies]
            for policy in policies:
                by_profile = {profile: done["run", scene, i, j, profile, policy] for profile in report.profiles}
                for q in quantities:
                    spreads[policy][q].append(metrics.spread(r.deviations[q] for r in rows if r.policy == policy))
                    consistencies[policy][q].append(consistency(by_profile, reference, q))
            report.rows += rows
    # One grid point: its numbers; several: the largest, how much the frame rate matters at worst over the grid.
    report.spreads[scene] = {policy: {q: max(values) for q, values in by_quantity.items()}
                             for policy, by_quantity in spreads.items()}
    report.consistency[scene] = {policy: {q: largest(values) for q, values in by_quantity.items()}
                                 for policy, by_quantity in consistencies.items()}
    _repeat_spreads(report, scene, done)
    report.served[scene] = {policy: served(done["run", scene, 0, 0, profile, policy] for profile in report.profiles)
                            for policy in policies}
    if probed:
        report.probes[scene] = []
        for i, point in enumerate(springs):
            for policy in policies:
                result = done["probe", scene, i, policy]
                result.grid = dict(point)
                report.probes[scene].append(result)


def served(results) -> dict[str, dict[str, int]]:
    """ssServedCounts of rows and contacts summed over runs: {"rows": {kind: n}, "contacts": {kind: n}}."""
    total = {"rows": dict.fromkeys(SERVED_KINDS, 0), "contacts": dict.fromkeys(SERVED_KINDS, 0)}
    for result in results:
        for what in total:
            for kind in SERVED_KINDS:
                total[what][kind] += int(result.counters[what][kind])
    return total


def _repeat_spreads(report: Report, scene: str, done: dict) -> None:
    """How much each policy's deviation and consistency move when the profiles a seed changes are run again with
    the next seed, at the grid's first point: the spread of repeats below which two policies tie."""
    if not report.repeat_profiles:
        return
    reference = done["reference", scene, 0]
    quantities = runs.motion_quantities(scene)
    report.repeat_deviation[scene], report.repeat_consistency[scene] = {}, {}
    for policy in report.policies[scene]:
        first = {p: done["run", scene, 0, 0, p, policy] for p in report.profiles}
        again = {**first, **{p: done["repeat", scene, p, policy] for p in report.repeat_profiles}}
        report.repeat_deviation[scene][policy], report.repeat_consistency[scene][policy] = {}, {}
        for q in quantities:
            devs = [metrics.spread(deviation(r, reference, q) for r in runs_.values()) for runs_ in (first, again)]
            cons = [consistency(runs_, reference, q) for runs_ in (first, again)]
            report.repeat_deviation[scene][policy][q] = _moved(*devs)
            report.repeat_consistency[scene][policy][q] = _moved(*cons)


def _moved(a: float, b: float) -> float:
    """|a - b|; nan when either is nan, inf when one failed (a failure's spread is not measured)."""
    if math.isnan(a) or math.isnan(b):
        return math.nan
    if math.isinf(a) or math.isinf(b):
        return 0.0 if a == b else math.inf
    return abs(a - b)


def largest(values: list[float]) -> float:
    """The largest value, nan when every one is (a consistency of one profile)."""
    finite_or_inf = [v for v in values if not math.isnan(v)]
    return max(finite_or_inf) if finite_or_inf else math.nan


def oscillator(params: dict) -> article.Oscillator:
    return article.Oscillator(params["mass"], params["spring"]["stiffness"], params["spring"]["damping"])


def exact_curve(params: dict, duration_s: float):
    t = np.linspace(0.0, duration_s, 1501)
    return t, article.exact(oscillator(params), params["x0"], 0.0, t)[0]


def rms_vs_exact(result: runs.RunResult) -> float:
    """The oscillator's RMS error against the exact solution over the run, relative to x0 (no gravity only)."""
    if result.failed or result.params["gravity"] != 0.0:
        return math.inf if result.failed else math.nan
    exact_x, _ = article.exact(oscillator(result.params), result.params["x0"], 0.0, result.times)
    return metrics.rms_vs_exact(result.quantities["x"], exact_x, result.params["x0"])


def side_by_side(report: Report, results: list[runs.RunResult], point: dict) -> None:
    """Issue 4's table: the oscillator at 30 fps and 15-45 fps under every policy, against the exact solution."""
    for result in results:
        osc = oscillator(result.params)
        try:
            true_omega = osc.angular_frequency
        except SteadystepError:
            true_omega = math.nan  # damped too strongly to oscillate: the table shows "-"
        entry = {"profile": result.profile, "policy": result.policy, "rms_vs_exact": rms_vs_exact(result),
                 "decay_rate_per_s": math.nan, "angular_frequency_rad_s": math.nan,
                 "true_decay_rate_per_s": osc.decay_rate, "true_angular_frequency_rad_s": true_omega,
                 "status": result.status}
        if point:
            entry["grid"] = dict(point)
        try:
            entry["decay_rate_per_s"], entry["angular_frequency_rad_s"] = metrics.fit_oscillation(
                result.times, result.quantities["x"])
        except SteadystepError:
            pass  # nothing oscillates (over-damped or blown up): the table shows "-"
        report.side_by_side.append(entry)

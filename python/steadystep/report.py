"""The comparison: scenes x frame-time profiles x policies on real ODE, measured against a reference run, written
as an HTML report (report.html, figures embedded and also beside it), metrics.json and metrics.csv (their
schema: docs/metrics.md)."""

from __future__ import annotations

import base64
import csv
import dataclasses
import html
import io
import json
import math
import platform
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from steadystep import animation, article, cost, figures, metrics, page, probe, runs, study
from steadystep.consistency import consistency
from steadystep._native import SteadystepError, number, printable
from steadystep.enums import Status
from steadystep.files import atomic_write_text
from steadystep.limits import MIN_MEASURED_DURATION_S
from steadystep.profiles import DEFAULT_PROFILES, Profile, seed_value

# Every scene runs every policy the library names (runs.policy_names()) unless told otherwise.
SIDE_BY_SIDE_PROFILES = ("fixed:30", "uniform:15:45")
# Quantities that are settings, not motion: they are plotted by `run`, never measured against a reference.
# The pile is there for timing; the report keeps it small so that the whole report takes a few minutes.
REPORT_PARAMS = {"pile": {"body_count": 150}}
# The pile is for timing: each probe trial at 1 ms steps would cost seconds of it.
NOT_PROBED = frozenset({"pile"})


@dataclass
class Row:
    """One run's line in the table."""

    scene: str
    profile: str
    policy: str
    deviations: dict[str, float]     # per motion quantity: RMS deviation from the reference / its amplitude
    steps_per_frame: float
    steps_per_second: float
    wall_us_per_step: float
    status: str
    rms_vs_exact: float | None = None
    rows_handed_to_implicit_euler: int = 0      # matched/exact row-steps implicit Euler served (ssRun_Counters)
    contacts_handed_to_implicit_euler: int = 0  # matched/exact contacts implicit Euler served
    grid: dict[str, float] = field(default_factory=dict)  # the swept values of this row (GRID_AXES), {} if none


@dataclass
class Report:
    scenes: list[str]
    profiles: list[str]
    policies: dict[str, list[str]]
    duration_s: float
    seed: int
    rows: list[Row] = field(default_factory=list)
    spreads: dict[str, dict[str, dict[str, float]]] = field(default_factory=dict)  # scene -> policy -> quantity
    side_by_side: list[dict] = field(default_factory=list)
    probes: dict[str, list[probe.ProbeResult]] = field(default_factory=dict)  # scene -> one per policy (grid point)
    params: dict[str, dict] = field(default_factory=dict)
    figures: dict[str, list[Path]] = field(default_factory=dict)
    elapsed_s: float = 0.0
    consistency: dict[str, dict[str, dict[str, float]]] = field(default_factory=dict)  # scene -> policy -> quantity
    costs: list[cost.Cost] = field(default_factory=list)   # one per scene and policy, from one benchmark run
    cost_wall_s: float = 0.0                                # the benchmark's wall time (s)
    animation: dict | None = None                           # animation.record(): the chain to watch


def policies_for(scene: str, policies) -> list[str]:
    """The policies a scene runs: the given ones, or every policy the library names (runs.policy_names())."""
    if policies:
        return list(policies)
    return runs.policy_names()


GRID_AXES = {"stiffness": "N/m", "damping": "N·s/m", "max_step_s": "s"}  # what a study may sweep, with units
GRID_CSV_COLUMNS = {"stiffness": "stiffness_N_per_m", "damping": "damping_N_s_per_m", "max_step_s": "max_step_s"}


def _grid_points(grid: dict | None) -> tuple[list[dict], list[dict]]:
    """The spring points (stiffness x damping) and step points (max_step_s) of a grid, each [{}] when not swept."""
    grid = grid or {}
    unknown = set(grid) - set(GRID_AXES)
    if unknown:
        raise SteadystepError(Status.OUT_OF_RANGE,
                              f"grid: no axis {sorted(unknown)[0]!r} (axes: {', '.join(GRID_AXES)})")
    springs = study.grid(**{axis: grid[axis] for axis in ("stiffness", "damping") if axis in grid})
    steps = study.grid(**{axis: grid[axis] for axis in ("max_step_s",) if axis in grid})
    return springs, steps


def _with_spring(scene_params: dict | None, point: dict) -> dict | None:
    """A scene's parameters with a spring point's stiffness and damping (None: the scene's defaults)."""
    if not point:
        return scene_params
    merged = dict(scene_params or {})
    merged["spring"] = {**merged.get("spring", {}), **point}
    return merged


def validate(scenes, profiles, policies, duration_s: float = 5.0, seed: int = 1, grid: dict | None = None,
             params: dict | None = None) -> list[str]:
    """Checks every name, spec and number before anything runs or is written; returns the scenes (default: all).

    duration_s (s) is at least MIN_MEASURED_DURATION_S (0.1 s), and every run within the bound of limits.py (the
    reference's 1 ms steps: at most 1000 s). grid: a list of values per axis of GRID_AXES (stiffness N/m, damping
    N·s/m, max_step_s s), each non-empty; every spring is checked on each scene by the library. Raises
    SteadystepError naming the value."""
    scenes = list(scenes) if scenes else [info.name for info in runs.scenes()]
    for scene in scenes:
        runs.scene_info(scene)
    profiles = list(profiles)
    if not profiles:
        raise SteadystepError(Status.OUT_OF_RANGE, "profiles = []: name at least one frame-time profile")
    for profile in profiles:
        Profile(profile, seed)
    for policy in policies or ():
        runs.make_stepping(policy)
    duration_s = number("duration_s", duration_s, "s")
    if not duration_s >= MIN_MEASURED_DURATION_S or not math.isfinite(duration_s):
        raise SteadystepError(Status.OUT_OF_RANGE, f"duration_s = {duration_s:g} s: must be finite and at least "
                              f"{MIN_MEASURED_DURATION_S:g} s to be measured")
    for axis, values in (grid or {}).items():
        if axis in GRID_AXES and not isinstance(values, (list, tuple)):
            raise SteadystepError(Status.OUT_OF_RANGE, f"grid.{axis} = {values!r}: must be a list of values")
        if axis in GRID_AXES and not values:
            raise SteadystepError(Status.OUT_OF_RANGE, f"grid.{axis} = []: give at least one value or leave it out")
        for value in values if axis in GRID_AXES else ():
            number(f"grid.{axis}", value, GRID_AXES[axis])
    springs, steps = _grid_points(grid)
    params = REPORT_PARAMS if params is None else params
    for scene in scenes:
        for point in springs if springs != [{}] else ():
            runs.Scene(scene, params=_with_spring(params.get(scene), point)).close()  # the library checks it
    runs.check_run_size(runs.REFERENCE_PROFILE, duration_s, 1, runs.reference_stepping())
    for policy in sorted({p for scene in scenes for p in policies_for(scene, policies)}):
        for step in steps:
            stepping = runs.make_stepping(policy, **step)
            for profile in profiles:
                runs.check_run_size(profile, duration_s, seed, stepping)
    return scenes


def _unit(kind: str, **arguments):
    """One independent piece of the comparison, run wherever the executor puts it: a reference run, a run, one
    largest-stable-step bisection (sequential inside) or the animation's recording."""
    return {"reference": runs.reference_run, "run": runs.run, "probe": probe.largest_stable_step,
            "animation": animation.record}[kind](**arguments)


def _label(task: dict) -> str:
    if task["kind"] == "animation":
        return "animation"
    words = [task["scene"], task.get("profile", "reference" if task["kind"] == "reference" else ""),
             task.get("policy", "")]
    if task["kind"] == "probe":
        words[1] = "largest stable step,"
    return " ".join(w for w in words if w)


def compare(scenes=None, profiles=DEFAULT_PROFILES, policies=None, duration_s: float = 5.0, seed: int = 1,
            params: dict | None = None, progress: bool | None = None, figure_dir: Path | None = None,
            executor=None, grid: dict | None = None) -> Report:
    """Runs every scene under every profile and policy, plus each scene's reference, and measures them.

    params: per scene changes to its parameters (default REPORT_PARAMS). progress: tqdm bars on stderr (None: only
    on a terminal). figure_dir: where to draw the figures (None: none drawn). executor: where the independent runs,
    probes and the animation go, any concurrent.futures.Executor or a name for study.make_executor ("local",
    "dask", ...); None: in this process. The numbers do not depend on it, only the wall times do; the cost
    benchmark always runs here, alone, after them. grid: values per axis of GRID_AXES (e.g. {"stiffness": [20, 40],
    "max_step_s": [1/60, 1/30]}): every combination is run, and each row carries its values in Row.grid; a scene's
    spread and consistency are then the largest over the grid's points, its figures, parameters and the animation
    those of the first point."""
    started = time.perf_counter()
    scenes = validate(scenes, profiles, policies, duration_s, seed, grid, params)
    seed, duration_s, profiles = seed_value(seed), float(duration_s), list(profiles)
    params = REPORT_PARAMS if params is None else params
    report = Report(scenes, list(profiles), {s: policies_for(s, policies) for s in scenes}, duration_s, seed)
    springs, steps = _grid_points(grid)
    tasks: dict[tuple, dict] = {}
    # Submitted longest first (references at 1 ms steps, then bisections), so that no core idles at the end.
    for scene in scenes:
        for i, point in enumerate(springs):
            tasks["reference", scene, i] = dict(kind="reference", scene=scene, duration_s=duration_s,
                                                params=_with_spring(params.get(scene), point))
    for scene in (s for s in scenes if s not in NOT_PROBED):
        for i, point in enumerate(springs):
            for policy in report.policies[scene]:
                tasks["probe", scene, i, policy] = dict(kind="probe", scene=scene, policy=policy,
                                                        params=_with_spring(params.get(scene), point))
    for scene in scenes:
        for i, point in enumerate(springs):
            for j, step in enumerate(steps):
                for profile in profiles:
                    for policy in report.policies[scene]:
                        tasks["run", scene, i, j, profile, policy] = dict(
                            kind="run", scene=scene, profile=profile, policy=policy, duration_s=duration_s,
                            seed=seed, params=_with_spring(params.get(scene), point), stepping=step or None)
    if "oscillator" in scenes:
        for i, point in enumerate(springs):
            for profile in SIDE_BY_SIDE_PROFILES:
                for policy in runs.policy_names():
                    tasks["side", i, profile, policy] = dict(
                        kind="run", scene="oscillator", profile=profile, policy=policy, duration_s=duration_s,
                        seed=seed, params=_with_spring(params.get("oscillator"), point))
    if animation.SCENE in scenes:
        tasks["animation", None] = dict(kind="animation", duration_s=duration_s, seed=seed,
                                        params=_with_spring(params.get(animation.SCENE), springs[0]))
    done = dict(zip(tasks, study.sweep(_unit, tasks.values(), executor, progress, "steadystep compare", "run",
                                       _label)))
    for scene in scenes:
        _compare_scene(report, scene, done, springs, steps)
        if figure_dir is not None:
            # Drawn here, from the finished runs: the files belong on this machine, not on a worker's.
            report.figures[scene] = _scene_figures(report, scene, done, figure_dir)
    if "oscillator" in scenes:
        for i, point in enumerate(springs):
            _side_by_side(report, [done["side", i, profile, policy] for profile in SIDE_BY_SIDE_PROFILES
                                   for policy in runs.policy_names()], point)
    report.animation = done.get(("animation", None))
    report.costs, report.cost_wall_s = _costs(report, params, progress)
    report.elapsed_s = time.perf_counter() - started
    return report


def _costs(report: Report, params: dict, progress: bool | None) -> tuple[list[cost.Cost], float]:
    """cost.measure for every scene and policy, with a bar: the benchmark runs in this process, once the workers are done, so that its
    timings are taken on a machine that does nothing else of ours."""
    pairs = [(scene, policy) for scene in report.scenes for policy in report.policies[scene]]
    started = time.perf_counter()
    costs = []
    with study.progress_bar(len(pairs), progress, "steadystep compare: cost against plain ODE", "run") as bar:
        for scene, policy in pairs:
            costs.append(cost.measure(scene, policy, seed=report.seed, params=params.get(scene)))
            bar.set_postfix_str(f"{scene} {policy}", refresh=False)
            bar.update()
    return costs, time.perf_counter() - started


def _compare_scene(report: Report, scene: str, done: dict, springs: list[dict], steps: list[dict]) -> None:
    """The scene's rows, spreads, consistency and probes from its finished runs (done: by task key)."""
    report.params[scene] = done["reference", scene, 0].params
    quantities = runs.motion_quantities(scene)
    spreads = {policy: {q: [] for q in quantities} for policy in report.policies[scene]}
    consistencies = {policy: {q: [] for q in quantities} for policy in report.policies[scene]}
    for i, point in enumerate(springs):
        reference = done["reference", scene, i]
        for j, step in enumerate(steps):
            rows = []
            for profile in report.profiles:
                for policy in report.policies[scene]:
                    result = done["run", scene, i, j, profile, policy]
                    deviations = {q: _deviation(result, reference, q) for q in quantities}
                    rows.append(Row(
                        scene, profile, policy, deviations,
                        metrics.steps_per_frame(result.step_count, result.frame_count),
                        metrics.steps_per_second(result.step_count, result.simulated_s),
                        1e6 * result.wall_s / result.step_count if result.step_count else math.nan,
                        result.status, _rms_vs_exact(result) if scene == "oscillator" else None,
                        result.counters["rows"]["handed_to_implicit_euler"],
                        result.counters["contacts"]["handed_to_implicit_euler"],
                        grid={**point, **step}))
            for policy in report.policies[scene]:
                by_profile = {profile: done["run", scene, i, j, profile, policy] for profile in report.profiles}
                for q in quantities:
                    spreads[policy][q].append(metrics.spread(r.deviations[q] for r in rows if r.policy == policy))
                    consistencies[policy][q].append(consistency(by_profile, reference, q))
            report.rows += rows
    # One grid point: its numbers; several: the largest, how much the frame rate matters at worst over the grid.
    report.spreads[scene] = {policy: {q: max(values) for q, values in by_quantity.items()}
                             for policy, by_quantity in spreads.items()}
    report.consistency[scene] = {policy: {q: _largest(values) for q, values in by_quantity.items()}
                                 for policy, by_quantity in consistencies.items()}
    if scene not in NOT_PROBED:
        report.probes[scene] = []
        for i, point in enumerate(springs):
            for policy in report.policies[scene]:
                result = done["probe", scene, i, policy]
                result.grid = dict(point)
                report.probes[scene].append(result)


def _largest(values: list[float]) -> float:
    """The largest value, nan when every one is (a consistency of one profile)."""
    finite_or_inf = [v for v in values if not math.isnan(v)]
    return max(finite_or_inf) if finite_or_inf else math.nan


def _scene_figures(report: Report, scene: str, done: dict, figure_dir: Path) -> list[Path]:
    """The scene's figures, at the grid's first point, from its finished runs (done: by task key)."""
    quantities = runs.motion_quantities(scene)
    reference = done["reference", scene, 0]
    results = {(profile, policy): done["run", scene, 0, 0, profile, policy]
               for profile in report.profiles for policy in report.policies[scene]}
    exact_curve = _exact_curve(reference.params, report.duration_s) if scene == "oscillator" else None
    paths = []
    for q in quantities[:2]:
        paths += figures.scene_figure(scene, q, reference.units[q], reference, results, figure_dir,
                                      exact_curve if q == "x" else None)
    deviations = {key: _deviation(result, reference, quantities[0]) for key, result in results.items()}
    paths += figures.deviation_figure(scene, quantities[0], deviations, figure_dir,
                                      {key: result.status for key, result in results.items()})
    return paths


def _deviation(result: runs.RunResult, reference: runs.RunResult, quantity: str) -> float:
    if result.failed or result.step_count == 0:
        return math.inf
    return metrics.rms_deviation(result.times, result.quantities[quantity], reference.times,
                                 reference.quantities[quantity])


def _oscillator(params: dict) -> article.Oscillator:
    return article.Oscillator(params["mass"], params["spring"]["stiffness"], params["spring"]["damping"])


def _exact_curve(params: dict, duration_s: float):
    t = np.linspace(0.0, duration_s, 1501)
    return t, article.exact(_oscillator(params), params["x0"], 0.0, t)[0]


def _rms_vs_exact(result: runs.RunResult) -> float:
    """The oscillator's RMS error against the exact solution over the run, relative to x0 (no gravity only)."""
    if result.failed or result.params["gravity"] != 0.0:
        return math.inf if result.failed else math.nan
    exact_x, _ = article.exact(_oscillator(result.params), result.params["x0"], 0.0, result.times)
    return metrics.rms_vs_exact(result.quantities["x"], exact_x, result.params["x0"])


def _side_by_side(report: Report, results: list[runs.RunResult], point: dict) -> None:
    """Issue 4's table: the oscillator at 30 fps and 15-45 fps under every policy, against the exact solution."""
    for result in results:
        osc = _oscillator(result.params)
        try:
            true_omega = osc.angular_frequency
        except SteadystepError:
            true_omega = math.nan  # damped too strongly to oscillate: the table shows "-"
        entry = {"profile": result.profile, "policy": result.policy, "rms_vs_exact": _rms_vs_exact(result),
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


# ---- writing ------------------------------------------------------------------------------------------------

def write(report: Report, out_dir: Path, command: str, article_paths: list[Path] | None = None) -> Path:
    """Writes report.html (figures embedded), index.html (a link to it), metrics.json and metrics.csv."""
    out_dir, command = Path(out_dir), printable(command)
    metrics_json = json.dumps(_finite_json(_as_json(report, command)), indent=1, default=_json_default, allow_nan=False)
    atomic_write_text(out_dir / "metrics.json", metrics_json)
    atomic_write_text(out_dir / "metrics.csv", _as_csv(report))
    path = atomic_write_text(out_dir / "report.html", _as_html(report, command, article_paths or []))
    atomic_write_text(out_dir / "index.html", '<!doctype html><meta charset="utf-8"><title>steadystep report</title>'
                      '<meta http-equiv="refresh" content="0; url=report.html"><a href="report.html">report</a>\n')
    return path


def _json_default(value):
    if isinstance(value, Path):
        return value.name
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(type(value))


def _finite_json(value):
    """value with every float that is not finite (a blow-up's inf, a rate with no frames) as None: metrics.json is
    strict JSON, which has no NaN or Infinity."""
    if isinstance(value, dict):
        return {key: _finite_json(item) for key, item in value.items()}
    if isinstance(value, (list, tuple)):
        return [_finite_json(item) for item in value]
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else None
    return value


def _as_json(report: Report, command: str) -> dict:
    """metrics.json; its schema is docs/metrics.md."""
    return {
        "command": command, "duration_s": report.duration_s, "seed": report.seed, "profiles": report.profiles,
        "policies": report.policies, "params": report.params, "elapsed_s": report.elapsed_s,
        "rows": [{"scene": r.scene, "profile": r.profile, "policy": r.policy, "status": r.status,
                  "deviation": dict(r.deviations),
                  "steps_per_frame": r.steps_per_frame, "steps_per_second": r.steps_per_second,
                  "rms_vs_exact": r.rms_vs_exact, "rows_handed_to_implicit_euler": r.rows_handed_to_implicit_euler,
                  "contacts_handed_to_implicit_euler": r.contacts_handed_to_implicit_euler,
                  **({"grid": r.grid} if r.grid else {})}
                 for r in report.rows],
        "spread": report.spreads,
        "consistency": report.consistency,
        "oscillator_side_by_side": report.side_by_side,
        "largest_stable_step": {s: [{"policy": r.policy, "stable_s": r.stable_s,
                                     "unstable_s": r.unstable_s, "reason": r.reason,
                                     **({"grid": r.grid} if r.grid else {})}
                                    for r in results] for s, results in report.probes.items()},
        "cost": {"wall_s": report.cost_wall_s,
                 "runs": [dataclasses.asdict(c) for c in report.costs]},
    }


CSV_COLUMNS = ("scene", "profile", "policy", "quantity", "deviation_per_amplitude", "quantity_unit",
               "rms_vs_exact_per_x0", "steps_per_frame", "steps_per_s", "rows_handed_to_implicit_euler",
               "contacts_handed_to_implicit_euler", "status")


def _as_csv(report: Report) -> str:
    """metrics.csv: one line per run and motion quantity; columns CSV_COLUMNS, documented in docs/metrics.md."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    swept = _swept_axes(report)  # a study's grid columns (after policy), none without a grid
    writer.writerow([*CSV_COLUMNS[:3], *(GRID_CSV_COLUMNS[a] for a in swept), *CSV_COLUMNS[3:]])
    for r in report.rows:
        units = dict(zip(runs.scene_info(r.scene).quantities, runs.scene_info(r.scene).units))
        for q, v in r.deviations.items():
            exact = "" if r.rms_vs_exact is None else f"{r.rms_vs_exact:.6g}"
            writer.writerow([r.scene, r.profile, r.policy, *(f"{r.grid[a]!r}" for a in swept), q, f"{v:.6g}",
                             units.get(q, ""), exact,
                             f"{r.steps_per_frame:.6g}", f"{r.steps_per_second:.6g}", r.rows_handed_to_implicit_euler,
                             r.contacts_handed_to_implicit_euler, r.status])
    return buffer.getvalue()


def _swept_axes(report: Report) -> list[str]:
    """The grid axes the report's rows carry, in GRID_AXES's order."""
    return [axis for axis in GRID_AXES if any(axis in r.grid for r in report.rows)]


def _number(value, digits: int = 3) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "-"
    if isinstance(value, float) and math.isinf(value):
        return "failed"
    return f"{value:.{digits}g}"


def _cell(value, status: str = "ok", digits: int = 3) -> str:
    """A number, or the run's status when the run failed (blew up, ran away, broke)."""
    if status != "ok":
        return f"<span class=bad>{html.escape(status)}</span>"
    return _number(value, digits)


def _status(status: str) -> str:
    """A run's status: ok, or what went wrong (blow-up, speed limit, broken) in red: a failure either way."""
    return "ok" if status == "ok" else f"<span class=bad>{html.escape(status)}</span>"


def _table(header: list[str], rows: list[list[str]], anchor: str | None = None) -> str:
    head = "".join(f"<th>{h}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{cell}</td>" for cell in row) + "</tr>" for row in rows)
    where = f" id='{html.escape(anchor)}'" if anchor else ""
    return f"<table{where}><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def _policy_cell(policy: str) -> str:
    color = figures.policy_color(policy)
    return f'<span class="dot" style="background:{color}"></span>{html.escape(policy)}'


def _embed(path: Path, anchor: str | None = None) -> str:
    data = base64.b64encode(Path(path).read_bytes()).decode()
    where = f" id='{html.escape(anchor)}'" if anchor else ""
    return f'<img{where} src="data:image/png;base64,{data}" alt="{html.escape(Path(path).name)}">'


def _all_policies(report: Report) -> list[str]:
    return list(dict.fromkeys(p for s in report.scenes for p in report.policies[s]))


def _by_scene(report: Report, values: dict, anchor: str, what: str, zero: float = 0.0) -> str:
    """A scene x policy table of values[scene][policy][first motion quantity], the smallest of a row in bold."""
    policies = _all_policies(report)
    rows = []
    for scene in report.scenes:
        if scene not in values:
            continue
        quantity = runs.motion_quantities(scene)[0]
        cells = {p: values[scene][p][quantity] for p in report.policies[scene] if p in values[scene]}
        # At or below zero the numbers are rounding: shown as 0, all of them the best.
        cells = {p: 0.0 if v is not None and math.isfinite(v) and v <= zero else v for p, v in cells.items()}
        finite = [v for v in cells.values() if math.isfinite(v)]
        best = min(finite) if finite else None
        row = [f"<a href='#{html.escape(scene)}'>{html.escape(scene)}</a>", html.escape(quantity)]
        for p in policies:
            text = _number(cells.get(p))
            row.append(f"<b>{text}</b>" if best is not None and cells.get(p) == best else text)
        rows.append(row)
    return _table(["scene", "quantity"] + [_policy_cell(p) for p in policies], rows, anchor) + (
        f"<p class=small>{what} Bold: the smallest of the row; failed: a run of that policy blew up or broke.</p>")


def _cost_table(report: Report) -> str:
    rows = []
    for c in report.costs:
        ok = c.status == "ok"
        rows.append([html.escape(c.scene), _policy_cell(c.policy), _number(c.steps_per_frame),
                     _number(c.us_per_frame) if ok else f"<span class=bad>{html.escape(c.status)}</span>",
                     f"×{_number(c.ratio_median)}" if ok else "-",
                     f"{_number(c.ratio_low)} – {_number(c.ratio_high)}" if ok else "-",
                     f"×{_number(c.overhead_median, 4)}" if ok else "-",
                     f"{_number(c.overhead_low, 4)} – {_number(c.overhead_high, 4)}" if ok else "-"])
    profile = report.costs[0].profile if report.costs else "-"
    repeats = report.costs[0].repeats if report.costs else 0
    return (_table(["scene", "policy", "steps / frame", "µs / frame", "per frame / program's own (median)",
                    "range over blocks", "library: / plain ODE at the same steps (median)", "range over blocks"],
                   rows, "cost")
            + f"<p class=small>One benchmark run of {report.cost_wall_s:.1f} s: each policy and two plain ODE copies "
            f"of the same scene take the same {html.escape(profile)} frames in {repeats} blocks, the order of the "
            "three rotating; each ratio is taken per block, its median and range shown. The program's own: collide, "
            "one dWorldQuickStep of each whole frame, softness as tuned once for 30 fps (a program without the "
            "library). Plain ODE at the same steps: one dWorldQuickStep per step the stepper takes, no library call "
            "in between; its ratio is what the library itself costs. The timing loop runs in C "
            "(ssScene_TimeFrames).</p>")


def _stable_table(report: Report) -> str:
    policies = _all_policies(report)
    rows = []
    for scene, results in report.probes.items():
        by_policy = {}
        for r in results:
            by_policy.setdefault(r.policy, r)  # a study's grid: its first point
        cells = [html.escape(scene)]
        for p in policies:
            r = by_policy.get(p)
            if r is None:
                cells.append("-")
            elif not math.isfinite(r.unstable_s):
                cells.append(f"≥ {_number(1000 * r.stable_s, 4)}")
            else:
                cells.append(f"<span title='{html.escape(r.reason or '')}'>{_number(1000 * r.stable_s, 4)}</span>")
        rows.append(cells)
    return (_table(["scene"] + [_policy_cell(p) for p in policies], rows, "stable")
            + "<p class=small>The longest step (ms) at which each scene stays stable: every frame one step of h "
            "(max_step_s = fixed_step_s = h), 3 s; stable: no blow-up and every motion quantity within the "
            "reference's range widened by that range on both sides. Bisection in log h between 1 and 250 ms "
            "(≥ 250: stable at the top). Hover a number for the first failure above it.</p>")


def _as_html(report: Report, command: str, article_paths: list[Path]) -> str:
    parts = ["<h1>steadystep: which constraint-softness policy, under variable frame times</h1>",
             "<p>Every run is real ODE 0.16 (libode from Debian) stepped by libsteadystep: each scene under each "
             f"frame-time profile ({html.escape(', '.join(report.profiles))}) and each policy, for "
             f"{report.duration_s:g} s, against a reference run (the same scene at a fixed 1/1000 s step, the "
             "article's mapping).</p>",
             page.recommendation(report)]
    if report.animation:
        parts += ["<h2 id='animation'>Watch: the chain at 15-45 fps</h2>", animation.section(report.animation)]
    parts += ["<h2>Frame-rate consistency</h2>",
              _by_scene(report, report.consistency, "consistency",
                        "Consistency: each run's followed quantity minus the mean over the profiles of the same "
                        "policy, RMS over profiles and time, divided by the reference's amplitude (max − min): 0 "
                        "when the motion is the same at every frame rate (shown 0 at or below "
                        f"{page.IDENTICAL:g}: rounding).", zero=page.IDENTICAL),
              "<h2>Deviation from the fine-step reference</h2>",
              _by_scene(report, report.spreads, "deviation",
                        "RMS over the profiles of each run's deviation: RMS of the followed quantity minus the "
                        "reference run, divided by the reference's amplitude (max − min).")]
    if report.side_by_side:
        parts += ["<h2>Oscillator against the exact solution</h2>", _side_by_side_table(report)]
    if report.costs:
        parts += ["<h2>Cost against plain ODE</h2>", _cost_table(report)]
    if report.probes:
        parts += ["<h2>Largest stable step</h2>", _stable_table(report)]
    pngs = [p for p in article_paths if p.suffix == ".png"]
    if pngs:
        parts += ["<h2>The article's figure</h2>",
                  "<p>Top: the article's equations 4 and 5. Bottom: real ODE with the article's mapping, one step per "
                  "frame (policy implicit-euler, max_step_s = 1/15 s).</p>", _embed(pngs[0])]
    parts.append("<section id='runs'><h2>Every scene, every run</h2>")
    for scene in report.scenes:
        parts += _scene_section(report, scene)
    parts.append("</section>")
    parts += ["<h2>Parameters</h2>", _parameters(report),
              "<h2>Regenerate</h2>", f"<pre>{html.escape(command)}</pre>",
              f"<p class=small>Made in {report.elapsed_s:.1f} s on {html.escape(platform.node())} "
              f"({html.escape(platform.machine())}), {time.strftime('%Y-%m-%d %H:%M:%S %Z')}.</p>"]
    return _PAGE.format(body="\n".join(parts))


def _side_by_side_table(report: Report) -> str:
    rows = []
    for e in report.side_by_side:
        decay, omega, status = e["decay_rate_per_s"], e["angular_frequency_rad_s"], e["status"]
        rows.append([html.escape(e["profile"]), _policy_cell(e["policy"]), _cell(e["rms_vs_exact"], status),
                     _number(decay, 4), _number(e["true_decay_rate_per_s"], 4),
                     _number(omega, 5), _number(e["true_angular_frequency_rad_s"], 5), _status(status)])
    return _table(["profile", "policy", "RMS vs exact / x0", "fitted decay (1/s)", "true decay (1/s)",
                   "fitted ω (rad/s)", "true ω (rad/s)", "status"], rows, "exact")


def _scene_section(report: Report, scene: str) -> list[str]:
    quantities = runs.motion_quantities(scene)
    info = runs.scene_info(scene)
    units = dict(zip(info.quantities, info.units))
    parts = [f"<h3 id='{html.escape(scene)}'>{html.escape(scene)}</h3>", f"<p>{html.escape(info.description)}</p>"]
    swept = _swept_axes(report)
    header = (["profile", "policy"] + [html.escape(f"{a} ({GRID_AXES[a]})") for a in swept]
              + [f"deviation of {html.escape(q)}" for q in quantities]
              + (["RMS vs exact / x0"] if scene == "oscillator" else [])
              + ["steps / frame", "rows served by implicit Euler", "contacts served by implicit Euler", "status"])
    rows = []
    for r in (r for r in report.rows if r.scene == scene):
        fallback = r.policy in _ACCURATE
        rows.append([html.escape(r.profile), _policy_cell(r.policy)] + [_number(r.grid[a], 6) for a in swept]
                    + [_cell(r.deviations[q], r.status) for q in quantities]
                    + ([_cell(r.rms_vs_exact, r.status)] if scene == "oscillator" else [])
                    + [_number(r.steps_per_frame), str(r.rows_handed_to_implicit_euler) if fallback else "-",
                       str(r.contacts_handed_to_implicit_euler) if fallback else "-",
                       _status(r.status)])
    parts += [_table(header, rows, f"runs-{scene}"),
              "<p class=small>Rows (contacts) served by implicit Euler: of a matched or exact policy, the joint rows "
              "(contacts) that the accurate mapping could not serve at that step (near-rigid rows above the step's "
              "Nyquist frequency, undamped rows...), summed over the run's steps; - for policies that use implicit "
              f"Euler throughout. Units: {html.escape(', '.join(f'{q} in {units[q]}' for q in quantities))}.</p>"]
    parts += [_embed(p) for p in report.figures.get(scene, []) if p.suffix == ".png"]
    return parts


def _parameters(report: Report) -> str:
    rows = [[html.escape(s), f"<code>{html.escape(json.dumps(p))}</code>"] for s, p in report.params.items()]
    general = (f"<p>duration {report.duration_s:g} s simulated per run, profile seed {report.seed}, profiles "
               f"{html.escape(', '.join(report.profiles))}; stepping defaults "
               f"<code>{html.escape(json.dumps(runs.default_stepping()))}</code> (policy set per run); reference "
               f"<code>{html.escape(json.dumps(runs.reference_stepping()))}</code> under "
               f"{runs.REFERENCE_PROFILE}.</p>")
    return general + _table(["scene", "parameters"], rows)


# Policies whose mapping is matched or exact: their rows can fall back to implicit Euler.
_ACCURATE = frozenset({"matched", "exact", "fixed-matched", "fixed-exact"})

_PAGE = """<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>steadystep report</title>
<style>
body {{ font-family: system-ui, sans-serif; max-width: 1400px; margin: 2em auto; padding: 0 1em; color: #222; }}
table {{ border-collapse: collapse; margin: 0.5em 0 0.5em; font-size: 0.9em; }}
th, td {{ border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: right; }}
th {{ background: #f3f3f3; }} td:first-child, td:nth-child(2) {{ text-align: left; }}
#policies td {{ text-align: left; }}
img {{ max-width: 100%; display: block; margin: 0.5em 0 1.5em; }}
.dot {{ display: inline-block; width: 0.7em; height: 0.7em; border-radius: 50%; margin-right: 0.4em; }}
.bad {{ color: #b00; font-weight: bold; }}
#recommendation {{ background: #f4f8ff; border: 1px solid #c9d8f0; padding: 0.3em 1em 1em; }}
.answers li {{ margin: 0.35em 0; }}
pre {{ background: #f6f6f6; padding: 0.6em; }} .small {{ color: #666; font-size: 0.85em; margin-bottom: 1.5em; }}
figure {{ margin: 0.5em 0 1.5em; }}
</style></head><body>
{body}
</body></html>
"""

"""The comparison: scenes x frame-time profiles x policies on real ODE, measured against a reference run, written
as an HTML report (report.html, figures embedded and also beside it), metrics.json and metrics.csv (their
schema: docs/metrics.md).

Five concepts, each in its own module of this package: the inputs checked (validate), the task graph and its
phases run through any executor (tasks), the numbers aggregated from the finished runs (aggregate), the data
exported as JSON and CSV (export) and the page (html, templates in templates, the recommendation in
recommendation). This module ties them together: compare() and write().
"""

from __future__ import annotations

import time
from pathlib import Path

from steadystep.report import aggregate as report_aggregate, tasks as report_tasks
from steadystep.lab import runs
from steadystep.core._native import printable
from steadystep.files import write_output_text
from steadystep.lab.profiles import DEFAULT_PROFILES, seed_value
from steadystep.report.export import CSV_COLUMNS, as_csv, as_json_text
from steadystep.report.model import Report, Row
from steadystep.report.tasks import NOT_PROBED, SIDE_BY_SIDE_PROFILES
from steadystep.report.validate import GRID_AXES, REPORT_PARAMS, grid_points, policies_for, validate

__all__ = ["CSV_COLUMNS", "GRID_AXES", "NOT_PROBED", "REPORT_PARAMS", "Report", "Row", "compare", "validate",
           "write"]


def compare(scenes=None, profiles=DEFAULT_PROFILES, policies=None, duration_s: float = 5.0, seed: int = 1,
            params: dict | None = None, progress: bool | str | None = None, figure_dir: Path | None = None,
            executor=None, grid: dict | None = None) -> Report:
    """Runs every scene under every profile and policy, plus each scene's reference, and measures them.

    params: per scene changes to its parameters (default REPORT_PARAMS). progress: on stderr, naming the phase:
    None, tqdm bars on a terminal and lines off one (a line at least every 10 s with an estimate: progress.py);
    "lines", lines anyway; True, tqdm bars; False, nothing. figure_dir: where to write the figures (None: none drawn). executor: where
    the independent runs, probes, the animation and the figures go, any concurrent.futures.Executor or a name for
    study.make_executor ("local", "dask", ...); None: in this process. The numbers do not depend on it, only the
    wall times do; the cost benchmark always runs here, alone, after them (tasks.py). grid: values per axis of
    GRID_AXES (e.g. {"stiffness": [20, 40], "max_step_s": [1/60, 1/30]}): every combination is run, and each row
    carries its values in Row.grid; a scene's spread and consistency are then the largest over the grid's points,
    its figures, parameters, repeats and the animation those of the first point."""
    started = time.perf_counter()
    scenes = validate(scenes, profiles, policies, duration_s, seed, grid, params)
    seed, duration_s, profiles = seed_value(seed), float(duration_s), list(profiles)
    params = REPORT_PARAMS if params is None else params
    report = Report(scenes, profiles, {s: policies_for(s, policies) for s in scenes}, duration_s, seed)
    report.machine["load_at_start"] = report_tasks.machine_state()["load"]
    report.repeat_profiles = report_tasks.repeat_profiles(profiles, seed)
    report.not_probed = [s for s in scenes if s in NOT_PROBED]
    springs, steps = grid_points(grid)
    probed = [s for s in scenes if s not in NOT_PROBED]
    units = report_tasks.tasks(report, params, springs, steps, probed)
    if isinstance(executor, str):
        from steadystep.lab import study

        with study.make_executor(executor) as made:
            done = report_tasks.run_phases(report, units, made, progress, figure_dir)
    else:
        done = report_tasks.run_phases(report, units, executor, progress, figure_dir)
    for scene in scenes:
        report_aggregate.compare_scene(report, scene, done, springs, steps, scene in probed)
    if "oscillator" in scenes:
        for i, point in enumerate(springs):
            report_aggregate.side_by_side(report, [done["side", i, profile, policy]
                                                   for profile in SIDE_BY_SIDE_PROFILES
                                                   for policy in runs.policy_names()], point)
    report.animation = done.get(("animation", None))
    report_tasks.costs(report, done, progress)
    report.elapsed_s = time.perf_counter() - started
    return report


def write(report: Report, out_dir: Path, command: str, article_paths: list[Path] | None = None) -> Path:
    """Writes report.html (figures embedded), index.html (a link to it), metrics.json and metrics.csv."""
    from steadystep.report.html import as_html  # Jinja2: only where a page is written

    out_dir, command = Path(out_dir), printable(command)
    write_output_text(out_dir / "metrics.json", as_json_text(report, command))
    write_output_text(out_dir / "metrics.csv", as_csv(report))
    path = write_output_text(out_dir / "report.html", as_html(report, command, article_paths or []))
    write_output_text(out_dir / "index.html", '<!doctype html><meta charset="utf-8"><title>steadystep report</title>'
                      '<meta http-equiv="refresh" content="0; url=report.html"><a href="report.html">report</a>\n')
    return path

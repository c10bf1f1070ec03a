"""The comparison's task graph and its phases.

Every piece of the comparison that does not depend on another is a unit (a reference run, a run, a repeat of a
run under the next seed, one largest-stable-step bisection, the animation's recording, the plan of a cost
benchmark, a scene's figures), run wherever the executor puts it. The phases, each named on the progress bar:

1. runs: references first (the longest, at 1 ms steps), then each scene's runs, then the bisections, then the cost
   benchmark's plans (its frames and the stepper's steps over them, counted untimed: cost.plan);
2. figures: a scene's figures (one unit each) are drawn in a worker as soon as that scene's reference and runs
   are back, ahead of the units still waiting, so that they fill the sweep instead of following it (the unit
   returns the files' bytes; they are written here, on this machine, whatever executor drew them);
3. cost: the benchmark times its plans in this process once every unit is done, so that its timings are taken
   while nothing else of the study runs; the aggregation and the page do not wait for anything else.

Off a terminal every phase writes its progress as lines (progress.py): at least one every 10 s, with an estimate.
"""

from __future__ import annotations

import concurrent.futures
import tempfile
import time
from pathlib import Path

import numpy as np

from steadystep.report import animation, progress as report_progress
from steadystep.lab import cost, probe, runs, study
from steadystep.files import write_output_bytes
from steadystep.lab.profiles import frame_times
from steadystep.report.aggregate import deviation, exact_curve
from steadystep.report.validate import with_spring

SIDE_BY_SIDE_PROFILES = ("fixed:30", "uniform:15:45")
# Scenes the largest-stable-step probe leaves out, and why (the page says so).
NOT_PROBED = {
    "pile": "it is there for timing: each probe trial at 1 ms steps would cost seconds of it",
    "wall": "its probe alone costs about 18 s of one core (hundreds of contacts a step at the probe's short steps), "
            "a tenth of the whole report",
}
PHASES = ("runs", "figures", "cost")


def scene_figures(scene: str, figure: str, profiles: list[str], policies: list[str], duration_s: float, reference,
                  results: dict) -> list[tuple[str, bytes]]:
    """One of a scene's figures, drawn where the unit runs: figure is a quantity (its runs against the reference)
    or "deviation" (the first quantity's deviation per run). Returns (file name, bytes) of its png and svg."""
    from steadystep.report import figures  # matplotlib: only where figures are drawn

    quantities = runs.motion_quantities(scene)
    with tempfile.TemporaryDirectory() as directory:
        out = Path(directory)
        if figure == "deviation":
            deviations = {key: deviation(result, reference, quantities[0]) for key, result in results.items()}
            paths = figures.deviation_figure(scene, quantities[0], deviations, out,
                                             {key: result.status for key, result in results.items()})
        else:
            curve = exact_curve(reference.params, duration_s) if scene == "oscillator" and figure == "x" else None
            paths = figures.scene_figure(scene, figure, reference.units[figure], reference, results, out, curve)
        return [(path.name, path.read_bytes()) for path in paths]


def unit(kind: str, **arguments):
    """One independent piece of the comparison, run wherever the executor puts it."""
    return {"reference": runs.reference_run, "run": runs.run, "probe": probe.largest_stable_step,
            "animation": animation.record, "figures": scene_figures, "cost plan": cost.plan}[kind](**arguments)


def label(task: dict) -> str:
    """What the progress bar says of a finished unit."""
    if task["kind"] in ("animation", "figures"):
        return f"{task.get('scene', '')} {task['kind']}".strip()
    if task["kind"] == "cost plan":
        return f"{task['scene']} {task['policy']} cost plan"
    words = [task["scene"], task.get("profile", "reference" if task["kind"] == "reference" else ""),
             task.get("policy", ""), "(seed + 1)" if task.get("repeat") else ""]
    if task["kind"] == "probe":
        words[1] = "largest stable step,"
    return " ".join(w for w in words if w)


def repeat_profiles(profiles: list[str], seed: int) -> list[str]:
    """The profiles whose frames the seed changes (random ones): run again under seed + 1 for the spread of
    repeats."""
    return [p for p in profiles if not np.array_equal(frame_times(p, 64, seed), frame_times(p, 64, seed + 1))]


def tasks(report, params: dict, springs: list[dict], steps: list[dict], probed: list[str]) -> dict[tuple, dict]:
    """Every unit of phase 1 by key, in the order they are started: the references (the longest, at 1 ms steps),
    each scene's runs (so that its figures can start while the rest runs), the side-by-side runs, the bisections,
    the animation and the cost benchmark's plans (short: they fill the sweep's end)."""
    duration_s, seed, out = report.duration_s, report.seed, {}
    for scene in report.scenes:
        for i, point in enumerate(springs):
            out["reference", scene, i] = dict(kind="reference", scene=scene, duration_s=duration_s,
                                              params=with_spring(params.get(scene), point))
    for scene in report.scenes:
        for i, point in enumerate(springs):
            for j, step in enumerate(steps):
                for profile in report.profiles:
                    for policy in report.policies[scene]:
                        out["run", scene, i, j, profile, policy] = dict(
                            kind="run", scene=scene, profile=profile, policy=policy, duration_s=duration_s,
                            seed=seed, params=with_spring(params.get(scene), point), stepping=step or None)
        for profile in report.repeat_profiles:
            for policy in report.policies[scene]:
                out["repeat", scene, profile, policy] = dict(
                    kind="run", scene=scene, profile=profile, policy=policy, duration_s=duration_s, seed=seed + 1,
                    params=with_spring(params.get(scene), springs[0]), stepping=steps[0] or None)
    if "oscillator" in report.scenes:
        for i, point in enumerate(springs):
            for profile in SIDE_BY_SIDE_PROFILES:
                for policy in runs.policy_names():
                    out["side", i, profile, policy] = dict(
                        kind="run", scene="oscillator", profile=profile, policy=policy, duration_s=duration_s,
                        seed=seed, params=with_spring(params.get("oscillator"), point))
    for scene in probed:
        for i, point in enumerate(springs):
            for policy in report.policies[scene]:
                out["probe", scene, i, policy] = dict(kind="probe", scene=scene, policy=policy,
                                                      params=with_spring(params.get(scene), point))
    if animation.SCENE in report.scenes:
        out["animation", None] = dict(kind="animation", duration_s=duration_s, seed=seed,
                                      params=with_spring(params.get(animation.SCENE), springs[0]))
    for scene in report.scenes:
        for policy in report.policies[scene]:
            out["cost", scene, policy] = dict(kind="cost plan", scene=scene, policy=policy, seed=seed,
                                              params=params.get(scene))
    return out


def _figure_tasks(report, scene: str, done: dict) -> list[dict]:
    """The figure units of a scene (its first two quantities, then its deviation), from its finished reference
    and runs at the grid's first point."""
    results = {(profile, policy): done["run", scene, 0, 0, profile, policy]
               for profile in report.profiles for policy in report.policies[scene]}
    return [dict(kind="figures", scene=scene, figure=figure, profiles=report.profiles,
                 policies=report.policies[scene], duration_s=report.duration_s,
                 reference=done["reference", scene, 0], results=results)
            for figure in [*runs.motion_quantities(scene)[:2], "deviation"]]


def _figure_count(scene: str) -> int:
    return len(runs.motion_quantities(scene)[:2]) + 1


def _figures_needed(report, scene: str) -> set[tuple]:
    return {("reference", scene, 0)} | {("run", scene, 0, 0, profile, policy) for profile in report.profiles
                                        for policy in report.policies[scene]}


def run_phases(report, units: dict[tuple, dict], executor, progress: bool | None,
               figure_dir: Path | None) -> dict[tuple, object]:
    """Phases 1 and 2 through executor (None: in this process): every unit's result by key; the figures written
    into figure_dir (report.figures). The phases' wall times go into report.phases_s."""
    started = time.perf_counter()
    waiting = {scene: _figures_needed(report, scene) for scene in report.scenes} if figure_dir is not None else {}
    total = len(units) + sum(_figure_count(scene) for scene in waiting)
    done: dict[tuple, object] = {}
    with report_progress.bar(total, progress, "steadystep compare [runs]", "unit") as bar:
        def finished(key, task, result):
            done[key] = result
            bar.set_postfix_str(label(task), refresh=False)
            bar.update()

        def figures_done(scene: str, files: list[tuple[str, bytes]]):
            paths = report.figures.setdefault(scene, [])
            paths += [write_output_bytes(figure_dir / name, data) for name, data in files]
            paths.sort(key=lambda path: (path.name.startswith("deviation_"), path.name))  # as drawn in order
            bar.set_postfix_str(f"{scene} figures", refresh=False)
            bar.update()

        if executor is None or isinstance(executor, study.SerialExecutor):
            for key, task in units.items():
                finished(key, task, unit(**task))
            bar.set_description_str("steadystep compare [figures]", refresh=False)
            runs_s = time.perf_counter() - started
            for scene in waiting:
                for task in _figure_tasks(report, scene, done):
                    figures_done(scene, unit(**task))
        else:
            # A bounded number in flight, so that a scene's figures, ready once its runs are back, go to the next
            # free worker ahead of the units still waiting (a pool's queue is first in, first out).
            waiting_units = list(units.items())
            ready_figures: list[dict] = []
            in_flight: dict = {}  # future -> ("unit", key) or ("figures", scene)
            limit = study.capacity(executor) + 1
            runs_s = 0.0
            try:
                while waiting_units or ready_figures or in_flight:
                    while len(in_flight) < limit and (ready_figures or waiting_units):
                        if ready_figures:
                            task = ready_figures.pop(0)
                            in_flight[study.submit(executor, unit, task)] = ("figures", task["scene"])
                        else:
                            key, task = waiting_units.pop(0)
                            in_flight[study.submit(executor, unit, task)] = ("unit", key)
                    finished_now, _ = concurrent.futures.wait(in_flight,
                                                              return_when=concurrent.futures.FIRST_COMPLETED)
                    for future in finished_now:
                        what, key = in_flight.pop(future)
                        if what == "figures":
                            figures_done(key, future.result())
                            continue
                        finished(key, units[key], future.result())
                        for scene, needed in waiting.items():
                            if key in needed:
                                needed.discard(key)
                                if not needed:
                                    ready_figures += _figure_tasks(report, scene, done)
                    if not runs_s and len(done) == len(units):
                        runs_s = time.perf_counter() - started
                    running = {"runs" if what == "unit" else "figures" for what, _ in in_flight.values()}
                    if running:  # (none once the last unit is back: the bar keeps the phase it ended in)
                        bar.set_description_str(f"steadystep compare [{', '.join(sorted(running, reverse=True))}]",
                                                refresh=False)
            finally:  # a failure or Ctrl-C: nothing more is started
                for future in in_flight:
                    future.cancel()
    report.phases_s["runs"] = runs_s
    report.phases_s["figures"] = time.perf_counter() - started - runs_s
    return done


def machine_state() -> dict[str, float | None]:
    """What a timing ran on: cores (os.cpu_count), usable_cores (this process' affinity), load (the 1-minute load
    average now; None where the system has none). Recorded beside every timing: a ratio timed under a load of 15 on
    2 cores is not one timed alone."""
    import os

    try:
        usable = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        usable = os.cpu_count() or 0
    try:
        load = os.getloadavg()[0]
    except (AttributeError, OSError):
        load = None
    return {"cores": os.cpu_count() or 0, "usable_cores": usable, "load": load}


def costs(report, done: dict, progress: bool | None) -> None:
    """Phase 3: the cost benchmark of every scene and policy timed in this process (cost.time_plan of its plan,
    made in phase 1), once every unit is done, so that its timings are taken while nothing else of the study
    runs."""
    pairs = [(scene, policy) for scene in report.scenes for policy in report.policies[scene]]
    state = machine_state()
    report.machine.update(cores=state["cores"], usable_cores=state["usable_cores"], load_before_cost=state["load"])
    started = time.perf_counter()
    with report_progress.bar(len(pairs), progress, "steadystep compare [cost against plain ODE]", "run") as bar:
        for scene, policy in pairs:
            report.costs.append(cost.time_plan(done["cost", scene, policy]))
            bar.set_postfix_str(f"{scene} {policy}", refresh=False)
            bar.update()
    report.cost_wall_s = report.phases_s["cost"] = time.perf_counter() - started
    report.machine["load_after_cost"] = machine_state()["load"]

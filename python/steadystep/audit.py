"""`steadystep audit`: how much a user's own program depends on the frame rate, under each policy, against a
fine-step reference that the audit checks itself (docs/audit.md).

    from steadystep import audit
    result = audit.audit(audit.Executable(("build/my_game_steadystep",), own=("build/my_game",)))
    audit.write(result, Path("audit"), "steadystep audit build/my_game_steadystep --own build/my_game")

Variants: every policy (the program run with --policy NAME) and, given a second program that steps the same world
without the library, its own stepping ("own"). Each variant runs under every profile; random profiles (all but
fixed: and trace:) once per seed. The reference is the program under implicit-euler at REFERENCE_FPS frames a
second (1 ms frames, one step each); the check of the reference is the same at CHECK_FPS.

For each followed quantity q, with A_q = max - min of q over the reference:
- spread (across profiles) = sqrt(mean over the variant's runs after its first, of the mean over the first run's
  times of (q_run - q_first)^2) / A_q, every run interpolated linearly onto those times;
- deviation (from the reference) = sqrt(mean over all the variant's runs of the mean over the reference's times of
  (q_run - q_reference)^2) / A_q.
Both are given over the whole run and over the times where the reference holds (check_reference); every claim of
the recommendation uses those. A variant with a failed run has spread and deviation inf.
"""

from __future__ import annotations

import json
import math
import platform
import statistics
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from steadystep import study
from steadystep._native import SteadystepError, number, printable
from steadystep.enums import Status
from steadystep.audit_run import (OWN, SERVED_COLUMNS, STEP_COLUMN, TIME_COLUMN, BadProgram,
                                  Executable, PythonProgram, PythonWorld, Run)
from steadystep.audit_run import run as run_program
from steadystep.profiles import Profile, frame_count, seed_value

__all__ = ["Audit", "BadProgram", "Executable", "PythonProgram", "PythonWorld", "audit", "write",
           "DEFAULT_PROFILES", "DEFAULT_SEEDS"]

DEFAULT_PROFILES = ("fixed:60", "fixed:30", "uniform:15:45")
DEFAULT_SEEDS = (1, 2, 3)
DEFAULT_DURATION_S = 10.0
REFERENCE_POLICY = "implicit-euler"
REFERENCE_FPS = 1000   # the reference's frames: 1 ms, one physics step each (max_step_s 1/60 s or less)
CHECK_FPS = 4000       # the check of the reference: four times finer
# The reference holds while the two references' RMS difference over a centred window of REFERENCE_WINDOW_S (or a
# fifth of the run, if shorter) stays within REFERENCE_TOLERANCE of the quantity's range, for every quantity.
REFERENCE_TOLERANCE = 0.05
REFERENCE_WINDOW_S = 1.0
# A reference that holds for less than this fraction of the run leaves too little to claim anything.
MIN_WINDOW_FRACTION = 0.2
# Costs within this fraction of the cheapest are not told apart by one set of runs.
COST_TIE = 0.1
DETERMINISTIC_KINDS = ("fixed:", "trace:")


def profile_runs(profiles, seeds) -> list[tuple[str, int]]:
    """(profile, seed) of every run of a variant: a deterministic profile once (with the first seed), a random one
    once per seed."""
    seeds = list(seeds)
    out = []
    for profile in profiles:
        for seed in seeds[:1] if profile.startswith(DETERMINISTIC_KINDS) else seeds:
            out.append((profile, seed))
    return out


@dataclass
class Audit:
    """Everything the page, metrics.json and metrics.csv show."""

    program: str
    own: str | None
    variants: list[str]
    runs_per_variant: list[tuple[str, int]]
    duration_s: float
    quantities: list[str]
    amplitudes: dict[str, float]
    reference: dict                     # check_reference(): where the reference holds
    spread: dict = field(default_factory=dict)      # "whole" / "window" -> variant -> quantity -> value
    deviation: dict = field(default_factory=dict)   # likewise
    runs: list[dict] = field(default_factory=list)  # one per run: variant, profile, seed, status, steps, cost...
    cost: dict = field(default_factory=dict)        # variant -> cpu_ms_per_simulated_s (median over its runs)
    served: dict = field(default_factory=dict)      # variant -> column -> sum over its runs (columns present)
    claims: list[dict] = field(default_factory=list)
    trajectories: dict = field(default_factory=dict)  # for the figures: reference, check, each variant's first run
    elapsed_s: float = 0.0
    language: str = "C"  # the program's: "C" (an executable) or "Python"; its snippet comes first (code_to_write)


def validate(program, profiles, seeds, policies, duration_s: float) -> None:
    """Checks the program, profiles, seeds, policies and duration before anything runs (SteadystepError naming the
    value; BadProgram for the program)."""
    from steadystep.stepping import policy_names

    program.check()
    if not profiles:
        raise SteadystepError(Status.OUT_OF_RANGE, "profiles = []: name at least one frame-time profile")
    if not seeds:
        raise SteadystepError(Status.OUT_OF_RANGE, "seeds = []: name at least one seed")
    for seed in seeds:
        seed_value(seed)
    for profile in profiles:
        Profile(profile, seeds[0])
    known = policy_names()
    for policy in policies:
        if policy not in known:
            raise SteadystepError(Status.PARSE, f"policy = {policy!r}: unknown; use one of {', '.join(known)}")
    duration_s = number("duration_s", duration_s, "s")
    if not (math.isfinite(duration_s) and duration_s > 0):
        raise SteadystepError(Status.OUT_OF_RANGE, f"duration_s = {duration_s!r} s: must be finite and above 0")


def _unit(program, variant: str, profile: str, seed: int, duration_s: float) -> Run:
    return run_program(program, variant, profile, seed, duration_s)


def audit(program, profiles=DEFAULT_PROFILES, seeds=DEFAULT_SEEDS, policies=None,
          duration_s: float = DEFAULT_DURATION_S, executor=None, progress: bool | None = None,
          reference_fps: int = REFERENCE_FPS, check_fps: int = CHECK_FPS) -> Audit:
    """Runs program (Executable or PythonProgram) as every variant under every profile run, plus the reference and
    its check, through executor (any concurrent.futures.Executor, a name for study.make_executor, or None: here),
    and measures them. policies: default every policy the library names."""
    from steadystep.stepping import policy_names

    started = time.perf_counter()
    policies = list(policies) if policies else policy_names()
    profiles, seeds = list(profiles), [seed_value(s) for s in seeds]
    validate(program, profiles, seeds, policies, duration_s)
    variants = ([OWN] if program.own is not None else []) + policies
    runs_per_variant = profile_runs(profiles, seeds)
    tasks = {("reference",): dict(variant=REFERENCE_POLICY, profile=f"fixed:{reference_fps}", seed=1),
             ("check",): dict(variant=REFERENCE_POLICY, profile=f"fixed:{check_fps}", seed=1)}
    for variant in variants:
        for profile, seed in runs_per_variant:
            tasks[variant, profile, seed] = dict(variant=variant, profile=profile, seed=seed)
    units = [dict(program=program, duration_s=float(duration_s), **task) for task in tasks.values()]
    done = dict(zip(tasks, study.sweep(_unit, units, executor, progress, f"steadystep audit {program.name}", "run",
                                       lambda task: f"{task['variant']} {task['profile']} seed {task['seed']}")))
    result = measure(program, variants, runs_per_variant, float(duration_s), done)
    result.elapsed_s = time.perf_counter() - started
    return result


def _on(t: np.ndarray, run: Run, quantity: str) -> np.ndarray:
    return np.interp(t, run.columns[TIME_COLUMN], run.columns[quantity])


def _rms_against(runs: list[Run], against: Run, quantity: str, holds=None) -> float:
    """sqrt(mean over runs of the mean over against's times where the reference holds (holds(t); None: every time)
    of (q_run - q_against)^2)."""
    t = against.columns[TIME_COLUMN]
    inside = np.ones(len(t), bool) if holds is None else holds(t)
    if not np.any(inside):
        return math.nan
    truth = against.columns[quantity][inside]
    return float(np.sqrt(np.mean([np.mean((_on(t[inside], run, quantity) - truth) ** 2) for run in runs])))


def _relative(rms: float, amplitude: float) -> float:
    """rms over the reference's range; a quantity the reference holds still: 0 when the run does too, else inf (as
    metrics.rms_deviation)."""
    if amplitude > 0 or math.isnan(rms):
        return rms / amplitude if amplitude > 0 else rms
    return 0.0 if rms == 0 else math.inf


def check_reference(reference: Run, check: Run, quantities: list[str], amplitudes: dict, duration_s: float,
                    reference_fps: int, check_fps: int) -> dict:
    """Where the reference holds: on the reference's times, the two references' difference per quantity over its
    range, as an RMS over a centred moving window of REFERENCE_WINDOW_S (a fifth of the run if shorter); the
    reference holds where that stays within REFERENCE_TOLERANCE for every quantity. A stretch where it holds that is
    shorter than the moving window, between two where it does not, counts as not held (two chaotic runs that cross
    by chance). Returns the stretches not held ([start, end] s), the time held, and the differences."""
    t = reference.columns[TIME_COLUMN]
    width_s = min(REFERENCE_WINDOW_S, duration_s / 5)
    half = max(1, int(round(width_s / 2 * reference_fps)))
    holds = np.ones(len(t), bool)
    moving, largest, parted_by = {}, {}, []
    index = np.arange(len(t))
    lo, hi = np.clip(index - half, 0, len(t)), np.clip(index + half + 1, 0, len(t))
    for q in quantities:
        d = (_on(t, check, q) - reference.columns[q]) / amplitudes[q] if amplitudes[q] > 0 else np.zeros_like(t)
        squares = np.concatenate(([0.0], np.cumsum(d ** 2)))
        moving[q] = np.sqrt((squares[hi] - squares[lo]) / (hi - lo))
        largest[q] = float(np.max(moving[q]))
        if largest[q] > REFERENCE_TOLERANCE:
            parted_by.append(q)
            holds &= moving[q] <= REFERENCE_TOLERANCE
    stretches = _stretches(t, ~holds)
    for (_, end_a), (start_b, _) in zip(stretches, stretches[1:]):
        if start_b - end_a < 2 * half / reference_fps:
            holds[(t >= end_a) & (t <= start_b)] = False
    not_held = _stretches(t, ~holds)
    step = np.diff(t, append=t[-1])
    held_s = float(np.sum(step[holds]))
    floor = {q: float(np.sqrt(np.mean((_on(t[holds], check, q) - reference.columns[q][holds]) ** 2)) / amplitudes[q])
             if amplitudes[q] > 0 and np.any(holds) else 0.0 for q in quantities}
    return {"reference_fps": reference_fps, "check_fps": check_fps, "tolerance": REFERENCE_TOLERANCE,
            "window_s": 2 * half / reference_fps, "holds_whole_run": not parted_by, "not_held": not_held,
            "held_s": held_s, "parted_by": parted_by, "usable": held_s >= MIN_WINDOW_FRACTION * duration_s,
            "largest_moving_difference": largest, "difference_in_window": floor,
            "_moving": moving, "_t": t, "_holds": holds}


def _stretches(t: np.ndarray, mask: np.ndarray) -> list[list[float]]:
    """The [first, last] times of each run of True in mask."""
    edges = np.flatnonzero(np.diff(np.concatenate(([0], mask.astype(int), [0]))))
    return [[float(t[a]), float(t[b - 1])] for a, b in zip(edges[::2], edges[1::2])]


def holds_at(checked: dict):
    """A function of times (s) that is True where the reference holds (both neighbours on its times hold)."""
    t, holds = checked["_t"], checked["_holds"].astype(float)
    return lambda times: np.interp(times, t, holds) >= 1.0


def measure(program, variants: list[str], runs_per_variant, duration_s: float, done: dict) -> Audit:
    """The audit's numbers from its finished runs (done: by task key)."""
    reference, check = done["reference",], done["check",]
    for name, run in (("reference", reference), ("check of the reference", check)):
        if not run.ok:
            raise BadProgram(f"{program.name}: the {name} ({REFERENCE_POLICY}, {run.profile}) "
                             f"failed, so nothing can be measured: {run.status}")
    for run in (reference, check):  # a program that ignores --profile would measure the same run everywhere
        expected = frame_count(run.profile, duration_s, run.seed)
        if run.frames and abs(run.frames - expected) > 1:
            raise BadProgram(f"{program.name}: under --profile {run.profile} --duration "
                             f"{duration_s:g} it printed {run.frames} frames, not the profile's {expected}: it does "
                             "not follow --profile (one CSV row per frame of the profile, after a t = 0 row)")
    quantities = reference.quantities()
    for key, run in done.items():
        if run.quantities() != quantities:
            raise BadProgram(f"{program.name}: the {run.variant} run under {run.profile} prints the "
                             f"columns {', '.join(run.quantities())}, the reference {', '.join(quantities)}: every "
                             "run must follow the same quantities")
    amplitudes = {q: float(np.ptp(reference.columns[q])) for q in quantities}
    reference_fps = int(round(1 / np.median(np.diff(reference.columns[TIME_COLUMN]))))
    check_fps = int(round(1 / np.median(np.diff(check.columns[TIME_COLUMN]))))
    checked = check_reference(reference, check, quantities, amplitudes, duration_s, reference_fps, check_fps)
    result = Audit(program.name, None if program.own is None else Path(program.own[0]).name, variants,
                   list(runs_per_variant), duration_s, quantities, amplitudes, checked,
                   language="Python" if isinstance(program, PythonProgram) else "C")
    for window, holds in (("whole", None), ("window", holds_at(checked))):
        result.spread[window], result.deviation[window] = {}, {}
        for variant in variants:
            runs = [done[variant, profile, seed] for profile, seed in runs_per_variant]
            failed = not all(run.ok for run in runs)
            result.spread[window][variant] = {
                q: math.inf if failed else (_relative(_rms_against(runs[1:], runs[0], q, holds), amplitudes[q])
                                            if len(runs) > 1 else math.nan) for q in quantities}
            result.deviation[window][variant] = {
                q: math.inf if failed else _relative(_rms_against(runs, reference, q, holds), amplitudes[q])
                for q in quantities}
    for variant in variants:
        costs = []
        for profile, seed in runs_per_variant:
            run = done[variant, profile, seed]
            simulated_s = float(run.columns[TIME_COLUMN][-1]) if len(run.columns[TIME_COLUMN]) else 0.0
            steps = run.columns.get(STEP_COLUMN)
            result.runs.append({
                "variant": variant, "profile": profile, "seed": seed, "status": run.status, "frames": run.frames,
                "simulated_s": simulated_s,
                "steps_per_frame": float(np.sum(steps)) / run.frames if steps is not None and run.frames else None,
                "cpu_s": run.cpu_s, "wall_s": run.wall_s,
                "cpu_ms_per_simulated_s": 1000 * run.cpu_s / simulated_s if simulated_s > 0 else None,
                "served": {name: int(np.sum(run.columns[name])) for name in SERVED_COLUMNS if name in run.columns}})
            if run.ok and simulated_s > 0:
                costs.append(1000 * run.cpu_s / simulated_s)
        result.cost[variant] = statistics.median(costs) if costs else None
        served = [r["served"] for r in result.runs if r["variant"] == variant]
        if served and served[0]:
            result.served[variant] = {name: sum(s.get(name, 0) for s in served) for name in served[0]}
    first = runs_per_variant[0]
    result.trajectories = {"reference": reference.columns, "check": check.columns,
                           **{variant: done[(variant, *first)].columns for variant in variants}}
    from steadystep.audit_claims import claims

    result.claims = claims(result)
    return result


def recommended(result: Audit) -> str | None:
    """The policy the recommendation names (its "recommend" claim), or None when it names none."""
    return next((c["variant"] for c in result.claims if c["kind"] == "recommend"), None)


def code_to_write(result: Audit) -> str:
    """The end of the recommendation as text: the lines of code to write for the recommended policy, the program's
    language first (snippets.as_text); "" when no policy is recommended."""
    from steadystep import snippets

    policy = recommended(result)
    return snippets.as_text(policy, result.language) if policy else ""


# ---- writing ------------------------------------------------------------------------------------------------------

OUTPUT_FILES = ("audit.html", "metrics.json", "metrics.csv")


def existing_outputs(out_dir: Path) -> list[Path]:
    """The files of an earlier audit in out_dir, which write() replaces only when forced."""
    return [Path(out_dir) / name for name in OUTPUT_FILES if (Path(out_dir) / name).exists()]


def as_json(result: Audit, command: str) -> dict:
    """metrics.json (docs/audit.md): every table of the page and every claim, strict JSON (inf and nan as null)."""
    reference = {k: v for k, v in result.reference.items() if not k.startswith("_")}
    data = {"command": printable(command), "program": result.program, "own": result.own,
            "duration_s": result.duration_s, "variants": result.variants,
            "profile_runs": [{"profile": p, "seed": s} for p, s in result.runs_per_variant],
            "reference_policy": REFERENCE_POLICY, "quantities": result.quantities, "amplitudes": result.amplitudes,
            "reference_check": reference, "spread": result.spread, "deviation": result.deviation,
            "runs": result.runs, "cost_cpu_ms_per_simulated_s": result.cost, "served": result.served,
            "claims": result.claims, "elapsed_s": result.elapsed_s, "machine": platform.node()}
    return _strict(data)


def _strict(value):
    """value with every non-finite float as None (JSON has no inf or nan; docs/audit.md: null = failed or none)."""
    if isinstance(value, dict):
        return {k: _strict(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_strict(v) for v in value]
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else None
    if isinstance(value, np.integer):
        return int(value)
    return value


CSV_COLUMNS = ("variant", "quantity", "spread", "deviation", "spread_in_window", "deviation_in_window",
               "cpu_ms_per_simulated_s", "runs_failed")


def as_csv(result: Audit) -> str:
    """metrics.csv: one line per variant and quantity (CSV_COLUMNS; empty = failed or not measured)."""
    lines = [",".join(CSV_COLUMNS)]
    for variant in result.variants:
        failed = sum(1 for r in result.runs if r["variant"] == variant and r["status"] != "ok")
        for q in result.quantities:
            values = [result.spread["whole"][variant][q], result.deviation["whole"][variant][q],
                      result.spread["window"][variant][q], result.deviation["window"][variant][q],
                      result.cost[variant]]
            cells = ["" if v is None or not math.isfinite(v) else f"{v:.9g}" for v in values]
            lines.append(",".join([variant, q, *cells, str(failed)]))
    return "\n".join(lines) + "\n"


def write(result: Audit, out_dir: Path, command: str, force: bool = False) -> Path:
    """Writes audit.html (figures embedded, also beside it as PNG), metrics.json and metrics.csv to out_dir, each
    whole. Refuses (SteadystepError naming the file) to replace an earlier audit's files unless force."""
    from steadystep import audit_page
    from steadystep.files import atomic_write_text

    out_dir = Path(out_dir)
    found = existing_outputs(out_dir)
    if found and not force:
        raise SteadystepError(Status.OUT_OF_RANGE, f"{found[0]}: an earlier audit is there; pass --force to replace it, or "
                              "--out another directory")
    out_dir.mkdir(parents=True, exist_ok=True)
    atomic_write_text(out_dir / "metrics.json", json.dumps(as_json(result, command), indent=1, allow_nan=False))
    atomic_write_text(out_dir / "metrics.csv", as_csv(result))
    return atomic_write_text(out_dir / "audit.html", audit_page.page(result, out_dir, command))

"""`steadystep audit`: how much a user's own program depends on the frame rate, under each policy, against a
fine-step reference that the audit checks itself (docs/audit.md).

    from steadystep import audit
    result = audit.audit(audit.Executable(("build/my_game_steadystep",), own=("build/my_game",)),
                         out_dir=Path("audit"))
    audit.write(result, Path("audit"), "steadystep audit build/my_game_steadystep --own build/my_game")

Variants: the program's own stepping ("own": a second program, or a Python program's own_frame), every policy, and
the diagnosis variants (implicit-euler with the largest step halved, and with four times QuickStep's iterations).
Each runs under every profile, random profiles once per seed, each run a process of its own (audit/run.py). The
reference is the program under implicit-euler at REFERENCE_FPS frames a second (1 ms frames, one step each), its
check the same at CHECK_FPS. The numbers are audit/measure.py's, the claims audit/claims.py's, the page
audit/page.py's. Finished runs are kept in OUT/runs, so that an audit interrupted and run again resumes.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import math
import os
import platform
import shutil
import stat
import statistics
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from steadystep.audit import measure as measure_
from steadystep.core._native import SteadystepError, printable
from steadystep.audit.run import (DIAGNOSIS_FLAGS, HALF_STEP, MORE_ITERATIONS, OWN, SERVED_COLUMNS, STEP_COLUMN,
                                  TIME_COLUMN, UNSOFTENED_COLUMN, BadProgram, Executable, PythonProgram, PythonWorld,
                                  Run)
from steadystep.audit.claims import claims, recommended
from steadystep.audit.run import run as run_program
from steadystep.audit.run import supports
from steadystep.core.enums import Status
from steadystep.lab.profiles import Profile, seed_value
from steadystep.report.export import strict_json

__all__ = ["Audit", "BadProgram", "Executable", "PythonProgram", "PythonWorld", "audit", "write",
           "DEFAULT_PROFILES", "DEFAULT_SEEDS"]

DEFAULT_PROFILES = ("fixed:60", "fixed:30", "uniform:15:45")
DEFAULT_SEEDS = (1, 2, 3)
DEFAULT_DURATION_S = 10.0
REFERENCE_POLICY = "implicit-euler"
REFERENCE_FPS = 1000   # the reference's frames: 1 ms, one physics step each (max_step_s 1/60 s or less)
CHECK_FPS = 4000       # the check of the reference: four times finer
DETERMINISTIC_KINDS = ("fixed:", "trace:")
CONTROL = "substeps-frozen"  # shown, never recommended: what the cut alone gives
DIAGNOSIS = (HALF_STEP, MORE_ITERATIONS)
COST_METHODS = ("auto", "instructions", "time", "none")
TIME_REPEATS = 3  # CPU-time samples of each variant's cost run when instructions are not counted
OUTPUT_FILES = ("audit.html", "metrics.json", "metrics.csv")
RUNS_DIRECTORY = "runs"


def profile_runs(profiles, seeds) -> list[tuple[str, int]]:
    """(profile, seed) of every run of a variant: a deterministic profile once (with the first seed), a random one
    once per seed."""
    seeds = list(seeds)
    out = []
    for profile in profiles:
        for seed in seeds[:1] if profile.startswith(DETERMINISTIC_KINDS) else seeds:
            out.append((profile, seed))
    return out


def roles(variants: list[str]) -> dict[str, str]:
    """Each variant's role: own (the program's own stepping), control (shown, never advice), diagnosis (a variant
    that changes one thing of implicit-euler) or advice (a policy the recommendation may name)."""
    return {v: OWN if v == OWN else "control" if v == CONTROL else "diagnosis" if v in DIAGNOSIS else "advice"
            for v in variants}


@dataclass
class Audit:
    """Everything the page, metrics.json and metrics.csv show (docs/audit.md, "Files")."""

    program: str
    own: str | None
    variants: list[str]
    runs_per_variant: list[tuple[str, int]]
    duration_s: float
    quantities: list[str]
    language: str = "C"  # the program's: "C" (an executable) or "Python"; its snippet comes first
    roles: dict = field(default_factory=dict)
    units: dict = field(default_factory=dict)
    scales: dict = field(default_factory=dict)       # quantity -> the scale every number is divided by
    scale_source: str = "reference"
    deciding: list = field(default_factory=list)      # the quantities that may decide a claim
    reference: dict = field(default_factory=dict)     # measure.check_reference, sanity and usability
    spread: dict = field(default_factory=dict)        # variant -> quantity -> value (whole run)
    spread_runs: dict = field(default_factory=dict)   # variant -> quantity -> per-run values
    spread_error: dict = field(default_factory=dict)  # variant -> quantity -> standard error over its runs
    deviation: dict = field(default_factory=dict)     # "window" / "whole" -> variant -> quantity -> value
    deviation_runs: dict = field(default_factory=dict)   # variant -> quantity -> per-run values (window)
    deviation_error: dict = field(default_factory=dict)  # variant -> quantity -> standard error (window)
    repeat: dict = field(default_factory=dict)        # the repeated run and its difference per quantity
    runs: list = field(default_factory=list)          # one per run: variant, profile, seed, status, steps, cost...
    cost: dict = field(default_factory=dict)          # method, per_simulated_s, noise, samples, unit
    served: dict = field(default_factory=dict)        # variant -> column -> sum over its runs (columns present)
    not_measured: dict = field(default_factory=dict)  # diagnosis variant -> why it was not run
    claims: list = field(default_factory=list)
    trajectories: dict = field(default_factory=dict)  # reference, check, and (variant, profile, seed) -> columns
    elapsed_s: float = 0.0
    reused_runs: int = 0
    figures: dict = field(default_factory=dict)       # the page's figures drawn with the runs: file stem -> PNG


def validate(program, profiles, seeds, policies, duration_s: float) -> None:
    """Checks the profiles, seeds, policies and duration before anything runs (SteadystepError naming the value)."""
    from steadystep.core.stepping import policy_names

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
            raise SteadystepError(Status.OUT_OF_RANGE, f"policy {policy!r}: not a policy of the library "
                                  f"({', '.join(known)})")
    if not (isinstance(duration_s, (int, float)) and math.isfinite(duration_s) and duration_s > 0):
        raise SteadystepError(Status.OUT_OF_RANGE, f"duration = {duration_s!r} s: must be finite and above 0")


# ---- kept runs ----------------------------------------------------------------------------------------------------

class RunStore:
    """Finished runs kept in OUT/runs, one JSON file each, named by what the run depends on (the program's files
    and commands, the variant, profile, seed, duration and kind): a run found there is not run again. Files are
    written whole and never through a link; a link or anything but a directory at OUT/runs is refused."""

    def __init__(self, out_dir: Path | None, identity: dict, duration_s: float):
        self.directory = None if out_dir is None else Path(out_dir) / RUNS_DIRECTORY
        self.identity = {"program": identity, "duration_s": float(duration_s)}
        self.made = False  # whether this audit made the directory (removed when the program is refused)
        self.out_existed = out_dir is not None and os.path.lexists(out_dir)
        if self.directory is not None and os.path.lexists(self.directory):
            mode = os.lstat(self.directory).st_mode
            if not stat.S_ISDIR(mode):
                raise SteadystepError(Status.OUT_OF_RANGE, f"{self.directory}: is "
                                      f"{'a symbolic link' if stat.S_ISLNK(mode) else 'not a directory'}: the audit "
                                      "keeps its runs there and writes through no link; remove it")

    def _path(self, key: tuple) -> Path:
        digest = hashlib.sha256(json.dumps([self.identity, list(key)], sort_keys=True).encode()).hexdigest()[:20]
        return self.directory / (".".join(measure_.sanitize_name(str(part)) for part in key) + f".{digest}.json")

    def get(self, key: tuple) -> Run | None:
        if self.directory is None:
            return None
        path = self._path(key)
        try:
            if not stat.S_ISREG(os.lstat(path).st_mode):
                return None
            with open(path, "rb") as file:
                return Run.from_json(json.loads(file.read()))
        except (OSError, ValueError, TypeError, KeyError):
            return None

    def put(self, key: tuple, run: Run) -> None:
        from steadystep.files import write_output_text

        if self.directory is None:
            return
        if not os.path.lexists(self.directory):
            self.directory.mkdir(parents=True)
            self.made = True
        write_output_text(self._path(key), json.dumps(run.as_json()))

    def forget(self) -> None:
        """Removes the kept runs (the directory, when this audit made it)."""
        if self.directory is not None and self.made:
            shutil.rmtree(self.directory, ignore_errors=True)
            if not self.out_existed:
                with contextlib.suppress(OSError):
                    self.directory.parent.rmdir()  # only when empty


def clear_kept_runs(out_dir: Path) -> None:
    """Removes OUT/runs's files (an audit replaced with --force runs everything again)."""
    directory = Path(out_dir) / RUNS_DIRECTORY
    if os.path.lexists(directory) and stat.S_ISDIR(os.lstat(directory).st_mode):
        for entry in os.scandir(directory):
            if entry.is_file(follow_symlinks=False) or entry.is_symlink():
                os.unlink(entry.path)


# ---- the audit ----------------------------------------------------------------------------------------------------

def _unit(program, variant: str, profile: str, seed: int, duration_s: float, count: bool = False) -> Run:
    return run_program(program, variant, profile, seed, duration_s, count)


def _cost_method(program, cost: str) -> str:
    if cost not in COST_METHODS:
        raise SteadystepError(Status.OUT_OF_RANGE, f"cost = {cost!r}: one of {', '.join(COST_METHODS)}")
    if cost == "auto":
        return "instructions" if isinstance(program, Executable) and shutil.which("valgrind") else "time"
    if cost == "instructions" and not (isinstance(program, Executable) and shutil.which("valgrind")):
        raise SteadystepError(Status.OUT_OF_RANGE, "cost = 'instructions': needs valgrind on the PATH and an "
                              "executable (a Python program's cost is its stepping loop's CPU time)")
    return cost


def cost_run(runs_per_variant: list[tuple[str, int]]) -> tuple[str, int]:
    """The (profile, seed) whose run measures each variant's cost: the first of a random profile, else the first."""
    return next(((p, s) for p, s in runs_per_variant if not p.startswith(DETERMINISTIC_KINDS)), runs_per_variant[0])


def pool_workers() -> int:
    """The local pool's processes for an audit: one more than the usable cores. A unit is mostly its worker waiting
    for the program's process; between two runs the worker writes the frames, forks the next one and parses the
    last one's CSV, and the spare worker's program keeps that core busy meanwhile. The figures likewise: the
    default three drawn at once on two cores, rather than two and then one."""
    from steadystep.lab import study

    return study.usable_cores() + 1


def _longest_first(key: tuple) -> int:
    """The order units are handed to a pool: it is done when its last unit is, so those that take longest go first
    (counts under valgrind, then the check of the reference and the reference: 4000 and 1000 frames a second), and
    the short runs fill in around them."""
    return {"count": 0, "count-repeat": 0, "check": 1, "reference": 2}.get(key[0], 3)


def audit(program, profiles=DEFAULT_PROFILES, seeds=DEFAULT_SEEDS, policies=None,
          duration_s: float = DEFAULT_DURATION_S, executor=None, progress: bool | None = None,
          reference_fps: int = REFERENCE_FPS, check_fps: int = CHECK_FPS, out_dir: Path | None = None,
          cost: str = "auto", diagnosis: bool = True, draw: bool = False) -> Audit:
    """Runs program (Executable or PythonProgram) as every variant under every profile run, plus the reference, its
    check, a repeat and the cost runs, through executor (any concurrent.futures.Executor, a name for
    study.make_executor, or None: here), and measures them. policies: default every policy the library names.
    out_dir: where finished runs are kept (OUT/runs) and found again; None keeps none. cost: "auto"
    (instructions under valgrind for an executable when valgrind is there, else CPU time over repeats),
    "instructions", "time" or "none". diagnosis: run the diagnosis variants (when the program takes their flags).
    draw: draw the page's figures too, after the runs, through the same executor (Audit.figures; write() draws
    those it does not find there, in this process)."""
    from steadystep.lab import study
    from steadystep.core.stepping import policy_names

    if isinstance(executor, str):  # one pool for the runs and the figures
        with study.make_executor(executor, pool_workers()) as made:
            return audit(program, profiles, seeds, policies, duration_s, made, progress, reference_fps, check_fps,
                         out_dir, cost, diagnosis, draw)
    started = time.perf_counter()
    policies = list(policies) if policies else policy_names()
    profiles, seeds = list(profiles), [seed_value(s) for s in seeds]
    validate(program, profiles, seeds, policies, duration_s)
    method = _cost_method(program, cost)
    has_own = program.check()
    not_measured = {}
    extra = []
    if diagnosis and REFERENCE_POLICY in policies:
        for variant in DIAGNOSIS:
            if supports(program, variant):
                extra.append(variant)
            else:
                flag = DIAGNOSIS_FLAGS[variant][0]
                not_measured[variant] = (f"the program does not take {flag} (steadystep/audit/protocol.h does): "
                                         "not measured")
    variants = ([OWN] if has_own else []) + policies + extra
    runs_per_variant = profile_runs(profiles, seeds)
    tasks = {("reference",): dict(variant=REFERENCE_POLICY, profile=f"fixed:{reference_fps}", seed=1),
             ("check",): dict(variant=REFERENCE_POLICY, profile=f"fixed:{check_fps}", seed=1)}
    for variant in variants:
        for profile, seed in runs_per_variant:
            tasks[variant, profile, seed] = dict(variant=variant, profile=profile, seed=seed)
    first_profile, first_seed = runs_per_variant[0]
    tasks["repeat",] = dict(variant=variants[0], profile=first_profile, seed=first_seed)
    cost_profile, cost_seed = cost_run(runs_per_variant)
    costed = [v for v in variants if v not in DIAGNOSIS]
    if method == "instructions":
        for variant in costed:
            tasks["count", variant] = dict(variant=variant, profile=cost_profile, seed=cost_seed, count=True)
        tasks["count-repeat",] = dict(variant=costed[0], profile=cost_profile, seed=cost_seed, count=True)
    elif method == "time":
        for variant in costed:
            for i in range(1, TIME_REPEATS):
                tasks["time", variant, i] = dict(variant=variant, profile=cost_profile, seed=cost_seed)
    store = RunStore(out_dir, program.identity(), duration_s)
    done = {key: store.get(key) for key in tasks}
    reused = sum(run is not None for run in done.values())
    missing = [key for key in tasks if done[key] is None]
    if executor is not None and not isinstance(executor, study.SerialExecutor):
        missing.sort(key=_longest_first)  # in this process they run in the tasks' order, the reference first
    units = [dict(program=program, duration_s=float(duration_s), **tasks[key]) for key in missing]
    try:
        for index, made in study.as_completed(_unit, units, executor, progress, f"steadystep audit {program.name}",
                                              "run", lambda t: f"{t['variant']} {t['profile']} seed {t['seed']}"):
            done[missing[index]] = made
            store.put(missing[index], made)
    except BadProgram:
        store.forget()  # a refused program: its runs are of no use (its files change before it is audited again)
        raise
    result = measure(program, variants, runs_per_variant, float(duration_s), done, method, (cost_profile, cost_seed),
                     has_own, not_measured)
    result.reused_runs = reused
    if draw:
        result.figures = _draw_figures(result, executor, progress)
    result.elapsed_s = time.perf_counter() - started
    return result


def _draw_figures(result: Audit, executor, progress: bool | None) -> dict:
    """The page's figures (page.figure_units), drawn through executor: file stem -> PNG bytes."""
    from steadystep.audit import page as audit_page
    from steadystep.lab import study

    units = audit_page.figure_units(result)
    drawn = dict(study.as_completed(audit_page.draw_png, units, executor, progress,
                                    f"steadystep audit {result.program}", "figure", lambda unit: unit["stem"]))
    return {unit["stem"]: drawn[i] for i, unit in enumerate(units)}


# ---- the numbers ----------------------------------------------------------------------------------------------

def _name(variant: str) -> str:
    return "own stepping" if variant == OWN else variant


def _simulated_s(run: Run) -> float:
    t = run.columns[TIME_COLUMN]
    return float(t[-1]) if len(t) else 0.0


def measure(program, variants: list[str], runs_per_variant, duration_s: float, done: dict, method: str = "none",
            cost_profile: tuple[str, int] | None = None, has_own: bool = False,
            not_measured: dict | None = None) -> Audit:
    """The audit's numbers from its finished runs (done: by task key; docs/audit.md, "What it measures")."""
    reference, check = done["reference",], done["check",]
    for name, run in (("reference", reference), ("check of the reference", check)):
        if not run.ok:
            raise BadProgram(f"{program.name}: the {name} ({REFERENCE_POLICY}, {run.profile}) "
                             f"failed, so nothing can be measured: {run.status}")
    quantities = reference.quantities()
    for key, run in done.items():
        if run.quantities() != quantities:
            raise BadProgram(f"{program.name}: the {run.variant} run under {run.profile} prints the "
                             f"columns {', '.join(run.quantities())}, the reference {', '.join(quantities)}: every "
                             "run must follow the same quantities")
    by_variant = {v: [done[(v, p, s)] for p, s in runs_per_variant] for v in variants}
    ok_runs = [run.columns for runs in by_variant.values() for run in runs if run.ok]
    sanity = measure_.reference_sanity(reference.columns, ok_runs, quantities)
    base = OWN if OWN in variants else ("naive" if "naive" in variants else variants[0])
    spanned = [r.columns for r in by_variant[base] if r.ok]
    scale_source = f"the {_name(base)} runs"
    if sanity["sane"]:
        spanned.append(reference.columns)
        scale_source += " and the reference"
    scales = measure_.scales_of(spanned or [reference.columns], quantities)
    decide = measure_.deciding(quantities, scales)
    checked = measure_.check_reference(reference.columns, check.columns, quantities, scales, duration_s, decide)
    checked.update(sanity)
    checked["reference_fps"] = int(float(reference.profile.split(":")[1]))
    checked["check_fps"] = int(float(check.profile.split(":")[1]))
    reasons = []
    if not sanity["sane"]:
        reasons.append("unphysical")
    if not checked["check_finer"]:
        reasons.append("unchecked")
    if checked["held_s"] < measure_.MIN_WINDOW_FRACTION * duration_s:
        reasons.append("parted early")
    checked["usable"] = not reasons
    checked["not_usable_because"] = reasons
    holds = measure_.holds_at(checked)

    result = Audit(program.name, None if not has_own else (Path(program.own[0]).name if program.own else
                                                           f"{program.name}: own_frame()"),
                   variants, list(runs_per_variant), duration_s, quantities,
                   language=program.language, roles=roles(variants),
                   units={q: measure_.unit_of(q) for q in quantities}, scales=scales, scale_source=scale_source,
                   deciding=decide, reference=checked)
    result.deviation = {"window": {}, "whole": {}}
    for variant in variants:
        runs = by_variant[variant]
        failed = not all(run.ok for run in runs)
        result.spread[variant], result.spread_runs[variant], result.spread_error[variant] = {}, {}, {}
        result.deviation_runs[variant], result.deviation_error[variant] = {}, {}
        result.deviation["window"][variant], result.deviation["whole"][variant] = {}, {}
        for q in quantities:
            if failed:
                per_run = [math.inf] * (len(runs) - 1)
            else:
                per_run = [measure_.compared(r.columns, runs[0].columns, q)[0] / scales[q] for r in runs[1:]]
            result.spread_runs[variant][q] = per_run
            result.spread[variant][q], result.spread_error[variant][q] = (
                measure_.rms_and_error(per_run) if per_run else (math.nan, 0.0))
            for window, inside in (("window", holds), ("whole", None)):
                per_run = ([math.inf] * len(runs) if failed else
                           [measure_.against_reference(r.columns, reference.columns, q, inside)[0] / scales[q]
                            for r in runs])
                value, error = measure_.rms_and_error(per_run)
                result.deviation[window][variant][q] = value
                if window == "window":
                    result.deviation_runs[variant][q], result.deviation_error[variant][q] = per_run, error
    repeated = done["repeat",]
    original = done[(variants[0], *runs_per_variant[0])]
    result.repeat = {"variant": variants[0], "profile": runs_per_variant[0][0], "seed": runs_per_variant[0][1],
                     "difference": {q: (measure_.compared(repeated.columns, original.columns, q)[0] / scales[q]
                                        if repeated.ok and original.ok else 0.0) for q in quantities},
                     "status": repeated.status}
    for variant in variants:
        for profile, seed in runs_per_variant:
            run = done[variant, profile, seed]
            result.runs.append(_run_row(run, reference, runs_per_variant, by_variant[variant][0]))
        served = [r["served"] for r in result.runs if r["variant"] == variant]
        if served and served[0]:
            result.served[variant] = {name: sum(s.get(name, 0) for s in served) for name in served[0]}
    result.cost = _cost(done, variants, method, cost_profile)
    result.not_measured = dict(not_measured or {})
    result.trajectories = {"reference": reference.columns, "check": check.columns,
                           **{(v, p, s): done[v, p, s].columns for v in variants for p, s in runs_per_variant}}

    result.claims = claims(result)
    return result


def _run_row(run: Run, reference: Run, runs_per_variant, first: Run) -> dict:
    simulated_s = _simulated_s(run)
    steps = run.columns.get(STEP_COLUMN)
    compared = ("baseline" if run is first else
                measure_.compared(run.columns, first.columns, run.quantities()[0])[1] if run.ok and first.ok else "-")
    return {"variant": run.variant, "profile": run.profile, "seed": run.seed, "status": run.status,
            "frames": run.frames, "simulated_s": simulated_s,
            "steps_per_frame": float(np.sum(steps)) / run.frames if steps is not None and run.frames else None,
            "cpu_s": run.cpu_s, "wall_s": run.wall_s, "compared_at": compared,
            "cpu_ms_per_simulated_s": 1000 * run.cpu_s / simulated_s if simulated_s > 0 else None,
            "served": {name: int(np.sum(run.columns[name])) for name in SERVED_COLUMNS if name in run.columns},
            # steps that made contacts but softened none (None: the program does not count them)
            "unsoftened_contact_steps": (int(np.sum(run.columns[UNSOFTENED_COLUMN]))
                                         if UNSOFTENED_COLUMN in run.columns else None)}


def _cost(done: dict, variants: list[str], method: str, cost_profile) -> dict:
    """The cost table: per variant (not the diagnosis ones) its cost per simulated second and the noise of that
    value. instructions: valgrind's count of the cost run (one count, repeated once for the first variant), noise
    the larger of the repeat's difference and COUNT_RESOLUTION of the value; time: the median of TIME_REPEATS CPU
    times of the cost run, noise their range."""
    out = {"method": method, "profile": cost_profile[0] if cost_profile else None,
           "seed": cost_profile[1] if cost_profile else None, "per_simulated_s": {}, "noise": {}, "samples": {},
           "unit": {"instructions": "instructions per simulated s", "time": "CPU ms per simulated s"}.get(method)}
    if method == "none":
        return out
    costed = [v for v in variants if v not in DIAGNOSIS]
    if method == "instructions":
        repeat = done["count-repeat",]
        first = done["count", costed[0]]
        repeat_difference = abs(repeat.instructions - first.instructions) / max(first.instructions, 1)
        out["repeat_difference"] = repeat_difference
        for v in costed:
            run = done["count", v]
            simulated_s = _simulated_s(run)
            if not run.ok or simulated_s <= 0:
                continue
            value = run.instructions / simulated_s
            out["per_simulated_s"][v] = value
            out["samples"][v] = [value]
            out["noise"][v] = max(repeat_difference, measure_.COUNT_RESOLUTION) * value
        return out
    for v in costed:
        runs = [done[(v, *cost_profile)]] + [done["time", v, i] for i in range(1, TIME_REPEATS)]
        samples = [1000 * r.cpu_s / _simulated_s(r) for r in runs if r.ok and _simulated_s(r) > 0]
        if len(samples) == len(runs):
            out["per_simulated_s"][v] = statistics.median(samples)
            out["samples"][v] = samples
            out["noise"][v] = max(samples) - min(samples)
    return out


def code_to_write(result: Audit) -> str:
    """The end of the recommendation as text: the lines of code to write for the recommended policy, the program's
    language first (snippets.as_text); "" when no policy is recommended."""
    from steadystep.report import snippets

    policy = recommended(result)
    return snippets.as_text(policy, result.language) if policy else ""


# ---- writing ------------------------------------------------------------------------------------------------------

def existing_outputs(out_dir: Path) -> list[Path]:
    """The files of an earlier audit in out_dir (a link there counts, dangling or not), which write() replaces only
    when forced."""
    return [Path(out_dir) / name for name in OUTPUT_FILES if os.path.lexists(Path(out_dir) / name)]


def refuse_earlier(out_dir: Path, force: bool) -> None:
    """SteadystepError naming an earlier audit's file in out_dir unless force."""
    found = existing_outputs(out_dir)
    if found and not force:
        link = " (a symbolic link: it is replaced, never written through)" if found[0].is_symlink() else ""
        raise SteadystepError(Status.OUT_OF_RANGE, f"{found[0]}: an earlier audit is there{link}; pass --force to "
                              "replace it, or --out another directory")


def as_json(result: Audit, command: str) -> dict:
    """metrics.json (docs/audit.md): every table of the page and every claim, strict JSON (inf and nan as null)."""
    reference = {k: v for k, v in result.reference.items() if not k.startswith("_")}
    data = {"command": printable(command), "program": result.program, "own": result.own,
            "language": result.language, "duration_s": result.duration_s, "variants": result.variants,
            "roles": result.roles, "profile_runs": [{"profile": p, "seed": s} for p, s in result.runs_per_variant],
            "reference_policy": REFERENCE_POLICY, "quantities": result.quantities, "units": result.units,
            "scales": result.scales, "scale_source": result.scale_source, "deciding": result.deciding,
            "noise_rule": {"sigmas": measure_.NOISE_SIGMAS, "tiny_range": measure_.TINY_RANGE,
                           "count_resolution": measure_.COUNT_RESOLUTION},
            "reference_check": reference, "spread": result.spread, "spread_runs": result.spread_runs,
            "spread_error": result.spread_error, "deviation": result.deviation,
            "deviation_runs": result.deviation_runs, "deviation_error": result.deviation_error,
            "repeat": result.repeat, "runs": result.runs, "cost": result.cost, "served": result.served,
            "not_measured": result.not_measured, "claims": result.claims, "elapsed_s": result.elapsed_s,
            "reused_runs": result.reused_runs, "machine": platform.node()}
    return strict_json(data)


CSV_COLUMNS = ("variant", "role", "quantity", "scale", "spread", "spread_error", "deviation_in_window",
               "deviation_error", "deviation_whole", "cost_per_simulated_s", "cost_unit", "runs_failed")


def as_csv(result: Audit) -> str:
    """metrics.csv: one line per variant and quantity (CSV_COLUMNS; empty = failed or not measured)."""
    lines = [",".join(CSV_COLUMNS)]
    for variant in result.variants:
        failed = sum(1 for r in result.runs if r["variant"] == variant and r["status"] != "ok")
        cost = result.cost.get("per_simulated_s", {}).get(variant)
        for q in result.quantities:
            values = [result.scales[q], result.spread[variant][q], result.spread_error[variant][q],
                      result.deviation["window"][variant][q], result.deviation_error[variant][q],
                      result.deviation["whole"][variant][q], cost]
            cells = ["" if v is None or not math.isfinite(v) else f"{v:.9g}" for v in values]
            lines.append(",".join([variant, result.roles[variant], q, *cells[:6], cells[6],
                                   (result.cost.get("unit") or "") if cost is not None else "", str(failed)]))
    return "\n".join(lines) + "\n"


def write(result: Audit, out_dir: Path, command: str, force: bool = False) -> Path:
    """Writes audit.html (figures embedded, also beside it as PNG), metrics.json and metrics.csv to out_dir, each
    whole, never through a link (files.write_output_text). Refuses (SteadystepError naming the file) to replace an
    earlier audit's files unless force."""
    from steadystep.audit import page as audit_page
    from steadystep.files import write_output_text

    out_dir = Path(out_dir)
    refuse_earlier(out_dir, force)
    out_dir.mkdir(parents=True, exist_ok=True)
    write_output_text(out_dir / "metrics.json", json.dumps(as_json(result, command), indent=1, allow_nan=False))
    write_output_text(out_dir / "metrics.csv", as_csv(result))
    return write_output_text(out_dir / "audit.html", audit_page.page(result, out_dir, command))

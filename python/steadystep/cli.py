"""The `steadystep` command: figure, compare, run, probe, convert, audit. A thin layer over the package.

Whatever the arguments' bytes, the command never shows a traceback. Exit codes: 0 done; 1 a run blew up or broke
(its records are still written); 2 a refusal: bad arguments, every SteadystepError, a file that cannot be read or
written, an executor that cannot be had, standard output closed or full, a --json result that is not finite, with
one line on stderr naming the value; 3 an internal error (a bug), with one line naming it; 130 interrupted; 141
stdout closed early (a pipe to `head`). Output files are written whole (temporary name, then rename) where PATH is a
regular file, through a symlink to its target, and in place to a device or a FIFO (steadystep.files).
--json output is strict JSON (no NaN or Infinity).
"""

from __future__ import annotations

import argparse
import contextlib
import csv
import io
import json
import math
import os
import shlex
import sys
import warnings
from pathlib import Path

import numpy as np

from steadystep.core._native import SteadystepError, one_line, printable
from steadystep.lab.limits import MAX_RUN_STEPS, MIN_MEASURED_DURATION_S

EXIT_FAILED_RUN = 1  # the run blew up or broke (its records are still written)
EXIT_BAD_INPUT = 2
EXIT_INTERNAL = 3
EXIT_INTERRUPTED = 130
EXIT_BROKEN_PIPE = 141

RUN_BOUND_HELP = (f"A run may take at most {MAX_RUN_STEPS:.0e} steps of the longest step allowed (--max-step, "
                  f"default 1/60 s: {MAX_RUN_STEPS / 60:.0f} s) and at most {MAX_RUN_STEPS:.0e} frames of its "
                  "profile; a run above that is refused before it starts.")


class _UsageError(Exception):
    pass


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors: the usage text is for --help, not for every mistake."""

    def error(self, message: str):
        raise _UsageError(f"{self.prog}: {message} (see {self.prog} --help)")


def _positive(text: str, value: float) -> float:
    if not math.isfinite(value) or value <= 0:
        raise argparse.ArgumentTypeError(f"{text!r} must be a finite number above 0")
    return value


def _positive_float(text: str) -> float:
    return _positive(text, _float(text))


def _measured_duration(text: str) -> float:
    value = _positive_float(text)
    if value < MIN_MEASURED_DURATION_S:
        raise argparse.ArgumentTypeError(f"{text!r} s is too short to measure: at least {MIN_MEASURED_DURATION_S:g} s")
    return value


def _float(text: str) -> float:
    try:
        return float(text)
    except (ValueError, OverflowError):
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None


def _seed(text: str) -> int:
    try:
        value = int(text, 0)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
    if not 0 <= value < 2**64:
        raise argparse.ArgumentTypeError(f"{text!r} must be in [0, 2^64)")
    return value


def _out_dir(text: str) -> Path:
    path = Path(text)
    if path.exists() and not path.is_dir():
        raise argparse.ArgumentTypeError(f"{text!r} exists and is not a directory")
    return path


def _fraction(text: str) -> float:
    """A number or a fraction such as 1/60."""
    numerator, slash, denominator = text.partition("/")
    if not slash:
        return _float(text)
    value = _float(numerator) / _nonzero(_float(denominator), text)
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"{text!r} is not a finite number")
    return value


def _nonzero(value: float, text: str) -> float:
    if value == 0:
        raise argparse.ArgumentTypeError(f"{text!r} divides by zero")
    return value


def _positive_fraction(text: str) -> float:
    return _positive(text, _fraction(text))


def _grid_value(text: str) -> float:
    """A spring's stiffness or damping for a grid: any finite number; the library judges its range."""
    value = _fraction(text)
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"{text!r} must be a finite number")
    return value


def _executor_argument(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--executor", default="local", metavar="WHERE",
                        help="where the independent runs go: local (a process pool over every core, the default), "
                        "serial (this process), dask (a Dask cluster on this machine) or dask:ADDRESS (an existing "
                        "Dask scheduler, e.g. dask:tcp://host:8786; needs pip install 'steadystep[dask]'). The "
                        "results do not depend on it")


def build_parser() -> argparse.ArgumentParser:
    # Every list below is the library's (scenes, policies, profiles): no second list here.
    from steadystep.lab.probe import default_policies
    from steadystep.lab.profiles import DEFAULT_PROFILES
    from steadystep.lab.runs import policy_names, scene_names

    parser = _Parser(prog="steadystep", description="Frame-rate independent constraint softness for ODE: the "
                     "article's figure, comparisons on real ODE scenes, single runs and conversions.",
                     epilog="Exit codes: 0 done, 1 a run blew up or broke, 2 refused (one line on stderr naming the "
                     "value), 3 internal error. " + RUN_BOUND_HELP)
    from steadystep import __version__

    parser.add_argument("--version", action="version", version=f"steadystep {__version__}")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    figure = commands.add_parser("figure", help="reproduce the article's figure (PNG and SVG)",
                                 description="The article's figure from its equations 4 and 5 (exact blue, fixed "
                                 "30 fps red, variable 15-45 fps green) and the same three curves from real ODE.")
    figure.add_argument("--out", type=_out_dir, default=Path("."), metavar="DIR",
                        help="directory for article_figure.png and .svg (default: the current one)")
    figure.add_argument("--duration", type=_measured_duration, default=5.0, metavar="S",
                        help=f"seconds, at least {MIN_MEASURED_DURATION_S:g} (default 5); bounded as every run")
    figure.add_argument("--seed", type=_seed, default=1, metavar="N", help="seed of the 15-45 fps frames")

    compare = commands.add_parser("compare", help="run scenes x profiles x policies and write the report",
                                  description="Runs every scene under every profile and policy, measures each run "
                                  "against a reference at 1/1000 s, and writes report.html, metrics.json, "
                                  "metrics.csv and the figures to --out. " + RUN_BOUND_HELP)
    compare.add_argument("--out", type=_out_dir, default=Path("report"), metavar="DIR",
                         help="output directory (default: ./report)")
    compare.add_argument("--force", action="store_true", help="replace an earlier report's files in --out")
    compare.add_argument("--scenes", nargs="+", metavar="SCENE", help="default: every scene")
    compare.add_argument("--profiles", nargs="+", metavar="SPEC", default=list(DEFAULT_PROFILES),
                         help=f"frame-time profiles (default: {' '.join(DEFAULT_PROFILES)})")
    from steadystep.lab.runs import policy_names  # the library's names: no second list here
    compare.add_argument("--policies", nargs="+", metavar="POLICY",
                         help=f"default: every policy the library names ({' '.join(policy_names())})")
    compare.add_argument("--duration", type=_measured_duration, default=5.0, metavar="S",
                         help=f"simulated seconds per run, at least {MIN_MEASURED_DURATION_S:g} (default 5); the "
                         f"reference's 1 ms steps bound it to {MAX_RUN_STEPS / 1000:.0f} s")
    compare.add_argument("--seed", type=_seed, default=1, metavar="N", help="profile seed (default 1)")
    compare.add_argument("--stiffness", type=_grid_value, nargs="+", metavar="K",
                         help="a study's grid: the scenes' spring stiffness (N/m), one set of runs per value")
    compare.add_argument("--damping", type=_grid_value, nargs="+", metavar="C",
                         help="a study's grid: the scenes' spring damping (N·s/m), one set of runs per value")
    compare.add_argument("--max-step", type=_positive_fraction, nargs="+", metavar="S",
                         help="a study's grid: the longest physics step (s, fractions such as 1/60 allowed; the "
                         "fixed policies step at their own fixed step). Every combination of the grid's values runs, "
                         "and each row of the report carries its values")
    _executor_argument(compare)

    run = commands.add_parser("run", help="one run of a scene; the trajectory as CSV or JSON",
                              description="Runs SCENE under a frame-time profile and a policy and prints a row for "
                              "t = 0, then one record per physics step: t and the scene's quantities, each column named "
                              "with its unit (oscillator: t_s,x_m,v_m_per_s,erp,cfm_m_per_N_s). A run ends early, exit "
                              "1, when it blows up or breaks: leaves one of the scene's sanity bounds (a torn joint, a "
                              "box through the floor, energy made; the status and message say which). "
                              + RUN_BOUND_HELP)
    run.add_argument("scene", metavar="SCENE", help=", ".join(scene_names()))
    run.add_argument("--profile", required=True, metavar="SPEC",
                     help="fixed:FPS, uniform:MIN:MAX, jitter:FPS:MS, hitch:FPS:EVERY:S, vsync:A:B or trace:FILE")
    run.add_argument("--policy", required=True, metavar="P", help=", ".join(policy_names()))
    run.add_argument("--duration", type=_positive_float, default=5.0, metavar="S",
                     help=f"seconds (default 5), at most {MAX_RUN_STEPS:.0e} steps of --max-step")
    run.add_argument("--seed", type=_seed, default=1, metavar="N", help="profile seed (default 1)")
    run.add_argument("--max-step", type=_positive_float, metavar="S", help="longest physics step (default 1/60 s)")
    output = run.add_mutually_exclusive_group()
    output.add_argument("--csv", type=Path, metavar="FILE", help="write CSV to FILE (default: CSV on stdout)")
    output.add_argument("--json", action="store_true", help="strict JSON on stdout: columns and a summary")

    probe = commands.add_parser("probe", help="the largest step a scene survives under each policy",
                                description="Bisects for the longest physics step (every frame one step of h) at "
                                "which SCENE stays stable: no blow-up, and its motion within the reference run's "
                                "range widened by that range on both sides. A trial at --low may take at most "
                                f"{MAX_RUN_STEPS:.0e} steps.")
    probe.add_argument("scene", metavar="SCENE", help=", ".join(scene_names()))
    probe.add_argument("--policies", nargs="+", metavar="POLICY", default=default_policies(),
                       help=f"default: {' '.join(default_policies())} (the policies without a fixed step of their "
                       "own)")
    probe.add_argument("--duration", type=_measured_duration, default=3.0, metavar="S",
                       help=f"seconds per trial, at least {MIN_MEASURED_DURATION_S:g} (default 3)")
    probe.add_argument("--low", type=_positive_float, default=0.001, metavar="S",
                       help="shortest step tried (default 0.001 s)")
    probe.add_argument("--high", type=_positive_float, default=0.25, metavar="S",
                       help="longest step tried (default 0.25 s)")
    probe.add_argument("--json", action="store_true", help="strict JSON on stdout")
    _executor_argument(probe)

    from steadystep.audit import cli as audit_cli  # the audit's arguments live with it
    audit_cli.add_parser(commands, _seed, _executor_argument)

    convert = commands.add_parser("convert", help="springs <-> ERP/CFM <-> frequency and damping ratio",
                                  description="One of: --k K --c C --dt H (spring to ERP/CFM), --erp E --cfm F "
                                  "--dt H (tuned ERP/CFM to a spring), --frequency HZ --damping-ratio Z --mass M "
                                  "(to a spring; add --dt H for its ERP/CFM). With --mass, k/c also give the "
                                  "matched mapping and the frequency. A result that is not finite is refused.")
    convert.add_argument("--k", type=_float, metavar="K", help="stiffness (N/m)")
    convert.add_argument("--c", type=_float, metavar="C", help="damping (N·s/m)")
    convert.add_argument("--erp", type=_float, metavar="E", help="error reduction parameter")
    convert.add_argument("--cfm", type=_float, metavar="F", help="constraint force mixing (m/(N·s))")
    convert.add_argument("--dt", type=_float, metavar="H", help="step length (s)")
    convert.add_argument("--frequency", type=_float, metavar="HZ", help="undamped natural frequency (Hz)")
    convert.add_argument("--damping-ratio", type=_float, metavar="Z", help="damping ratio (1 = critical)")
    convert.add_argument("--mass", type=_float, metavar="M", help="effective mass (kg)")
    convert.add_argument("--json", action="store_true", help="strict JSON on stdout")
    return parser


def _command_line(argv: list[str]) -> str:
    return printable(shlex.join(["steadystep", *argv]))


def _say(line: str) -> None:
    """One line on stdout, whatever bytes the arguments it quotes were made of."""
    print(one_line(printable(line)))


def _strict_json(command: str, data, columns: dict[str, np.ndarray] | None = None) -> str:
    """data as strict JSON, with columns (arrays by name), if given, as data["columns"]. Raises _UsageError naming
    the first value that is not finite: JSON has no NaN or Infinity, and writing one anyway would hand the reader
    something it cannot parse."""
    for name, values in (columns or {}).items():
        bad = np.flatnonzero(~np.isfinite(values))
        if len(bad):
            raise _UsageError(f"steadystep {command}: columns.{name}[{bad[0]}] = {values[bad[0]]}: not a finite "
                              "number, which strict JSON cannot hold")
    found = _first_non_finite(data)
    if found is not None:
        name, value = found
        raise _UsageError(f"steadystep {command}: {name} = {value}: not a finite number, which strict JSON cannot hold")
    if columns is not None:
        data = {**data, "columns": {name: values.tolist() for name, values in columns.items()}}
    return json.dumps(data, allow_nan=False)


def _first_non_finite(data, name: str = ""):
    if isinstance(data, dict):
        items = ((f"{name}.{key}" if name else str(key), value) for key, value in data.items())
    elif isinstance(data, (list, tuple)):
        items = ((f"{name}[{index}]", value) for index, value in enumerate(data))
    elif isinstance(data, float) and not math.isfinite(data):
        return name, data
    else:
        return None
    for item_name, value in items:
        found = _first_non_finite(value, item_name)
        if found is not None:
            return found
    return None


# What figure, compare and audit need beyond the core: pyproject's report extra (jinja2 writes the page).
REPORT_EXTRA = ("matplotlib", "tqdm", "jinja2")


def _require_report_extra(command: str, modules: tuple[str, ...] = REPORT_EXTRA,
                          looked_up: tuple[str, ...] = ()) -> None:
    """Refuses the command in one line (exit 2) when a module of the report extra it needs cannot be imported,
    naming it and the pip extra that provides it. A module also in looked_up is only looked for (installed or not),
    not imported: one that other processes use and this one need not import."""
    import importlib
    import importlib.util

    missing = []
    for name in modules:
        try:
            if name not in looked_up:
                importlib.import_module(name)
            elif importlib.util.find_spec(name) is None:
                raise ImportError(name)
        except (ImportError, ValueError):  # absent, or present and broken: either way the extra is what to install
            missing.append(name)
    if missing:
        raise _UsageError(f"steadystep {command}: needs the report extra, {' and '.join(missing)} not installed: "
                          "pip install 'steadystep[report]'")


@contextlib.contextmanager
def _executor(command: str, spec: str):
    """study.make_executor(spec), refused in one line (exit 2) when it cannot be had."""
    from steadystep.lab import study

    try:
        with study.make_executor(spec) as executor:
            yield executor
    except study.ExecutorUnavailable as error:
        raise _UsageError(f"steadystep {command}: {error}") from None


def _figure(args, argv) -> int:
    _require_report_extra("figure", ("matplotlib",))
    from steadystep.report.figures import article_figure

    args.out.mkdir(parents=True, exist_ok=True)
    for path in article_figure(args.out, args.duration, args.seed):
        _say(str(path))
    return 0


def _audit(args, argv) -> int:
    # jinja2 writes the page in this process; matplotlib draws the figures, in the pool's workers when there is one,
    # so it is looked up, not imported: importing it here would cost the pool's audit 0.2 s for nothing.
    _require_report_extra("audit", ("matplotlib", "jinja2"), looked_up=("matplotlib",))
    from steadystep.audit import cli as audit_cli

    return audit_cli.command(args, argv)


# The files of a report in --out (report.write), which compare replaces only with --force.
REPORT_FILES = ("report.html", "index.html", "metrics.json", "metrics.csv")


def _compare(args, argv) -> int:
    _require_report_extra("compare")
    from steadystep import report
    from steadystep.report.validate import validate as report_validate
    from steadystep.report import progress as report_progress
    from steadystep.report.figures import article_figure

    grid = {axis: values for axis, values in (("stiffness", args.stiffness), ("damping", args.damping),
                                              ("max_step_s", args.max_step)) if values}
    # Everything checked before any directory is made or any worker started.
    report_validate(args.scenes, args.profiles, args.policies, args.duration, args.seed, grid)
    found = [args.out / name for name in REPORT_FILES if os.path.lexists(args.out / name)]
    if found and not args.force:  # a link planted there counts as a file: replaced only when forced, never followed
        raise _UsageError(f"steadystep compare: {found[0]}: an earlier report is there; pass --force to replace it, "
                          "or --out another directory")
    with _executor("compare", args.executor) as executor:
        args.out.mkdir(parents=True, exist_ok=True)
        result = report.compare(args.scenes, args.profiles, args.policies, args.duration, args.seed,
                                figure_dir=args.out, executor=executor, grid=grid)
    with report_progress.step("steadystep compare [article's figure]"):
        article_paths = article_figure(args.out, args.duration, args.seed)
    with report_progress.step("steadystep compare [page]"):
        path = report.write(result, args.out, _command_line(argv), article_paths)
    _say(str(path))
    return 0


def _run(args, argv) -> int:
    from steadystep.lab import runs
    from steadystep.files import atomic_write_text

    stepping = {"max_step_s": args.max_step} if args.max_step else None
    result = runs.run(args.scene, args.profile, args.policy, args.duration, args.seed, stepping=stepping)
    columns = result.trajectory()
    if args.json:
        units = {"t": "s", **result.units}
        summary = {"scene": result.scene, "profile": printable(result.profile), "policy": result.policy,
                   "seed": result.seed, "duration_s": result.duration_s, "status": result.status,
                   "message": result.message, "steps": result.step_count, "frames": result.frame_count,
                   "bound_use": result.bound_use,
                   "units": {runs.column_name(name, unit): unit for name, unit in units.items()}}
        print(_strict_json("run", summary, columns))
    else:
        # To a file whole (written aside, then renamed); to stdout row by row, so that a reader that stops early
        # (`| head`) stops the command at once.
        buffer = io.StringIO() if args.csv else sys.stdout
        writer = csv.writer(buffer, lineterminator="\n")
        writer.writerow(columns)
        for row in zip(*columns.values()):
            writer.writerow(f"{value:.17g}" for value in row)
        if args.csv:
            atomic_write_text(args.csv, buffer.getvalue())
    if result.failed:
        _complain(f"steadystep run: {result.status}: {result.message}")
        return EXIT_FAILED_RUN
    return 0


def _probe(args, argv) -> int:
    from steadystep.lab import probe, runs

    runs.scene_info(args.scene)
    for policy in args.policies:
        runs.make_stepping(policy)
    with _executor("probe", args.executor) as executor:
        results = probe.largest_stable_steps(args.scene, args.policies, args.duration, args.low, args.high,
                                             executor=executor)
    if args.json:
        print(_strict_json("probe", [{"scene": r.scene, "policy": r.policy, "stable_s": r.stable_s,
                                      "unstable_s": r.unstable_s if math.isfinite(r.unstable_s) else None,
                                      "reason": r.reason} for r in results]))
    else:
        for r in results:
            unstable = f"unstable at {1000 * r.unstable_s:.4g} ms: {r.reason}" if math.isfinite(r.unstable_s) \
                else "stable up to the longest step tried"
            _say(f"{r.scene} {r.policy}: stable up to {1000 * r.stable_s:.4g} ms; {unstable}")
    return 0


def _conversions(args, given: set[str]) -> dict[str, float]:
    from steadystep.core import convert

    out: dict[str, float] = {}
    if {"k", "c"} <= given and not given & {"erp", "cfm", "frequency", "damping_ratio"}:
        if "dt" not in given and "mass" not in given:
            raise _UsageError("steadystep convert: --k and --c need --dt H (or --mass M)")
        spring = (args.k, args.c)
        if args.dt is not None:
            out.update(convert.implicit_euler_softness(spring, args.dt)._asdict())
        if args.mass is not None:
            out["frequency_hz"], out["damping_ratio"] = convert.frequency_from_spring(spring, args.mass)
            if args.dt is not None:
                matched = convert.matched_softness(spring, args.mass, args.dt)
                out["matched_erp"], out["matched_cfm"] = matched
    elif given == {"erp", "cfm", "dt"}:
        out.update(convert.spring_from_softness((args.erp, args.cfm), args.dt)._asdict())
    elif {"frequency", "damping_ratio", "mass"} <= given and given <= {"frequency", "damping_ratio", "mass", "dt"}:
        spring = convert.spring_from_frequency(args.frequency, args.damping_ratio, args.mass)
        out.update(spring._asdict())
        if args.dt is not None:
            out.update(convert.implicit_euler_softness(spring, args.dt)._asdict())
    else:
        raise _UsageError("steadystep convert: give --k K --c C --dt H, or --erp E --cfm F --dt H, or "
                          "--frequency HZ --damping-ratio Z --mass M (see steadystep convert --help)")
    return out


def _convert(args, argv) -> int:
    given = {name for name in ("k", "c", "erp", "cfm", "dt", "frequency", "damping_ratio", "mass")
             if getattr(args, name) is not None}
    try:
        out = _conversions(args, given)
    except SteadystepError as error:
        # A chain of conversions can fail in a later link (a spring from a frequency, then its erp): name what the
        # user typed, then the library's message.
        typed = " ".join(f"--{name.replace('_', '-')} {getattr(args, name):g}" for name in sorted(given))
        raise _UsageError(f"steadystep convert {typed}: {error}") from None
    if args.json:
        print(_strict_json("convert", out))
    else:
        units = {"stiffness": "N/m", "damping": "N·s/m", "cfm": "m/(N·s)", "matched_cfm": "m/(N·s)",
                 "frequency_hz": "Hz"}
        for name, value in out.items():
            print(f"{name} = {value:.17g} {units.get(name, '')}".rstrip())
    return 0


def _complain(line: str) -> None:
    """One line on stderr: bytes that were not UTF-8 shown as U+FFFD, control characters escaped."""
    print(one_line(printable(str(line))), file=sys.stderr)


def _one_line_warning(message, category, filename, lineno, file=None, line=None) -> None:
    _complain(f"steadystep: warning: {category.__name__}: {message}")


def _dispatch(argv: list[str]) -> int:
    try:
        args = build_parser().parse_args(argv)
    except SystemExit as done:  # --help: argparse has printed it
        return done.code if isinstance(done.code, int) else 0
    handler = {"figure": _figure, "compare": _compare, "run": _run, "probe": _probe,
               "convert": _convert, "audit": _audit}[args.command]
    if sys.stdout is None and not (args.command == "run" and args.csv):
        # Started with its standard output closed (>&-): Python then has no sys.stdout at all.
        raise _UsageError(f"steadystep {args.command}: standard output is closed, so the results have nowhere to go "
                          "(redirect it: >FILE or >/dev/null)")
    code = handler(args, argv)
    if sys.stdout is not None:
        try:
            sys.stdout.flush()  # here, so that a full disk or device (>/dev/full) is a refusal, not a lost write
        except BrokenPipeError:
            raise
        except OSError as error:
            _silence_stdout()
            raise _UsageError(f"steadystep {args.command}: cannot write standard output: "
                              f"{error.strerror or error}") from None
    return code


def _silence_stdout() -> None:
    """Points standard output at /dev/null, so that nothing is flushed (and fails again) at exit."""
    try:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    except (OSError, ValueError, AttributeError, io.UnsupportedOperation):
        pass


def main(argv: list[str] | None = None) -> int:
    """Runs the command on argv (default: sys.argv[1:]) and returns its exit code (see the module's docstring)."""
    argv = sys.argv[1:] if argv is None else list(argv)
    try:
        with warnings.catch_warnings():
            warnings.showwarning = _one_line_warning
            return _dispatch(argv)
    except _UsageError as error:
        _complain(str(error))
        return EXIT_BAD_INPUT
    except SteadystepError as error:
        _complain(f"steadystep: {error}")
        return EXIT_BAD_INPUT
    except BrokenPipeError:
        # The reader went away (`steadystep run ... | head`): nothing more to say, and nothing to flush at exit.
        _silence_stdout()
        return EXIT_BROKEN_PIPE
    except OSError as error:
        filename = error.filename if isinstance(error.filename, str) else ""
        _complain(f"steadystep: {error.strerror or error}: {filename}".rstrip(": "))
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        _complain("steadystep: interrupted")
        return EXIT_INTERRUPTED
    except Exception as error:  # a bug: one line that names it, not a traceback
        _complain(f"steadystep: internal error: {type(error).__name__}: {error} (please report this with the "
                  "command that caused it)")
        return EXIT_INTERNAL


if __name__ == "__main__":
    sys.exit(main())

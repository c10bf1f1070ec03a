"""The `steadystep` command: figure, compare, run, probe, convert. A thin layer over the package.

Bad arguments and every SteadystepError end with one line on stderr and exit code 2, never a traceback. Output
files are written whole (temporary name, then rename).
"""

from __future__ import annotations

import argparse
import csv
import io
import json
import math
import shlex
import sys
from pathlib import Path

from steadystep._native import SteadystepError

EXIT_BAD_INPUT = 2
EXIT_BLOWUP = 1


class _UsageError(Exception):
    pass


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors: the usage text is for --help, not for every mistake."""

    def error(self, message: str):
        raise _UsageError(f"{self.prog}: {message} (see {self.prog} --help)")


def _positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not math.isfinite(value) or value <= 0:
        raise argparse.ArgumentTypeError(f"{text!r} must be a finite number above 0")
    return value


def _float(text: str) -> float:
    try:
        return float(text)
    except ValueError:
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


def build_parser() -> argparse.ArgumentParser:
    from steadystep.profiles import DEFAULT_PROFILES

    parser = _Parser(prog="steadystep", description="Frame-rate independent constraint softness for ODE: the "
                     "article's figure, comparisons on real ODE scenes, single runs and conversions.")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    figure = commands.add_parser("figure", help="reproduce the article's figure (PNG and SVG)",
                                 description="The article's figure from its equations 4 and 5 (exact blue, fixed "
                                 "30 fps red, variable 15-45 fps green) and the same three curves from real ODE.")
    figure.add_argument("--out", type=_out_dir, default=Path("."), metavar="DIR",
                        help="directory for article_figure.png and .svg (default: the current one)")
    figure.add_argument("--duration", type=_positive_float, default=5.0, metavar="S", help="seconds (default 5)")
    figure.add_argument("--seed", type=_seed, default=1, metavar="N", help="seed of the 15-45 fps frames")

    compare = commands.add_parser("compare", help="run scenes x profiles x policies and write the report",
                                  description="Runs every scene under every profile and policy, measures each run "
                                  "against a reference at 1/1000 s, and writes report.html, metrics.json, "
                                  "metrics.csv and the figures to --out.")
    compare.add_argument("--out", type=_out_dir, default=Path("report"), metavar="DIR",
                         help="output directory (default: ./report)")
    compare.add_argument("--scenes", nargs="+", metavar="SCENE", help="default: every scene")
    compare.add_argument("--profiles", nargs="+", metavar="SPEC", default=list(DEFAULT_PROFILES),
                         help=f"frame-time profiles (default: {' '.join(DEFAULT_PROFILES)})")
    compare.add_argument("--policies", nargs="+", metavar="POLICY",
                         help="default: naive spring fixed, and also matched exact for the oscillator")
    compare.add_argument("--duration", type=_positive_float, default=5.0, metavar="S",
                         help="simulated seconds per run (default 5)")
    compare.add_argument("--seed", type=_seed, default=1, metavar="N", help="profile seed (default 1)")

    run = commands.add_parser("run", help="one run of a scene; the trajectory as CSV or JSON",
                              description="Runs SCENE under a frame-time profile and a policy and prints one record "
                              "per physics step: t and the scene's quantities (oscillator: t,x,v,erp,cfm).")
    run.add_argument("scene", metavar="SCENE", help="oscillator, buggy, drop, chain or pile")
    run.add_argument("--profile", required=True, metavar="SPEC",
                     help="fixed:FPS, uniform:MIN:MAX, jitter:FPS:MS, hitch:FPS:EVERY:S, vsync:A:B or trace:FILE")
    run.add_argument("--policy", required=True, metavar="P", help="naive, spring, matched, exact or fixed")
    run.add_argument("--duration", type=_positive_float, default=5.0, metavar="S", help="seconds (default 5)")
    run.add_argument("--seed", type=_seed, default=1, metavar="N", help="profile seed (default 1)")
    run.add_argument("--max-step", type=_positive_float, metavar="S", help="longest physics step (default 1/60 s)")
    output = run.add_mutually_exclusive_group()
    output.add_argument("--csv", type=Path, metavar="FILE", help="write CSV to FILE (default: CSV on stdout)")
    output.add_argument("--json", action="store_true", help="JSON on stdout: columns and a summary")

    probe = commands.add_parser("probe", help="the largest step a scene survives under each policy",
                                description="Bisects for the longest physics step (every frame one step of h) at "
                                "which SCENE stays stable: no blow-up, and its motion within the reference run's "
                                "range widened by that range on both sides.")
    probe.add_argument("scene", metavar="SCENE", help="oscillator, buggy, drop, chain or pile")
    probe.add_argument("--policies", nargs="+", metavar="POLICY", default=["naive", "spring", "matched", "exact"],
                       help="default: naive spring matched exact")
    probe.add_argument("--duration", type=_positive_float, default=3.0, metavar="S",
                       help="seconds per trial (default 3)")
    probe.add_argument("--low", type=_positive_float, default=0.001, metavar="S",
                       help="shortest step tried (default 0.001 s)")
    probe.add_argument("--high", type=_positive_float, default=0.25, metavar="S",
                       help="longest step tried (default 0.25 s)")
    probe.add_argument("--json", action="store_true", help="JSON on stdout")

    convert = commands.add_parser("convert", help="springs <-> ERP/CFM <-> frequency and damping ratio",
                                  description="One of: --k K --c C --dt H (spring to ERP/CFM), --erp E --cfm F "
                                  "--dt H (tuned ERP/CFM to a spring), --frequency HZ --damping-ratio Z --mass M "
                                  "(to a spring; add --dt H for its ERP/CFM). With --mass, k/c also give the "
                                  "matched mapping and the frequency.")
    convert.add_argument("--k", type=_float, metavar="K", help="stiffness (N/m)")
    convert.add_argument("--c", type=_float, metavar="C", help="damping (N·s/m)")
    convert.add_argument("--erp", type=_float, metavar="E", help="error reduction parameter")
    convert.add_argument("--cfm", type=_float, metavar="F", help="constraint force mixing (m/(N·s))")
    convert.add_argument("--dt", type=_float, metavar="H", help="step length (s)")
    convert.add_argument("--frequency", type=_float, metavar="HZ", help="undamped natural frequency (Hz)")
    convert.add_argument("--damping-ratio", type=_float, metavar="Z", help="damping ratio (1 = critical)")
    convert.add_argument("--mass", type=_float, metavar="M", help="effective mass (kg)")
    convert.add_argument("--json", action="store_true", help="JSON on stdout")
    return parser


def _command_line(argv: list[str]) -> str:
    return shlex.join(["steadystep", *argv])


def _figure(args, argv) -> int:
    from steadystep.figures import article_figure

    args.out.mkdir(parents=True, exist_ok=True)
    for path in article_figure(args.out, args.duration, args.seed):
        print(path)
    return 0


def _compare(args, argv) -> int:
    from steadystep import report
    from steadystep.figures import article_figure

    report.validate(args.scenes, args.profiles, args.policies)  # before the directory is made
    args.out.mkdir(parents=True, exist_ok=True)
    result = report.compare(args.scenes, args.profiles, args.policies, args.duration, args.seed,
                            figure_dir=args.out)
    article_paths = article_figure(args.out, args.duration, args.seed)
    path = report.write(result, args.out, _command_line(argv), article_paths)
    print(path)
    return 0


def _run(args, argv) -> int:
    from steadystep import runs
    from steadystep.files import atomic_write_text

    stepping = {"max_step_s": args.max_step} if args.max_step else None
    result = runs.run(args.scene, args.profile, args.policy, args.duration, args.seed, stepping=stepping)
    columns = {"t": result.times, **result.quantities}
    if args.json:
        print(json.dumps({"scene": result.scene, "profile": result.profile, "policy": result.policy,
                          "seed": result.seed, "duration_s": result.duration_s, "status": result.status,
                          "message": result.message, "steps": result.step_count, "frames": result.frame_count,
                          "units": {"t": "s", **result.units},
                          "columns": {name: values.tolist() for name, values in columns.items()}}))
    else:
        buffer = io.StringIO()
        writer = csv.writer(buffer, lineterminator="\n")
        writer.writerow(columns)
        for row in zip(*columns.values()):
            writer.writerow(f"{value:.17g}" for value in row)
        if args.csv:
            atomic_write_text(args.csv, buffer.getvalue())
        else:
            sys.stdout.write(buffer.getvalue())
    if result.blew_up:
        print(f"steadystep run: {result.status}: {result.message}", file=sys.stderr)
        return EXIT_BLOWUP
    return 0


def _probe(args, argv) -> int:
    from steadystep import probe, runs

    runs.scene_info(args.scene)
    for policy in args.policies:
        runs.policy_value(policy)
    results = [probe.largest_stable_step(args.scene, policy, args.duration, args.low, args.high)
               for policy in args.policies]
    if args.json:
        print(json.dumps([{"scene": r.scene, "policy": r.policy, "stable_s": r.stable_s,
                           "unstable_s": r.unstable_s if math.isfinite(r.unstable_s) else None, "reason": r.reason}
                          for r in results]))
    else:
        for r in results:
            unstable = f"unstable at {1000 * r.unstable_s:.4g} ms: {r.reason}" if math.isfinite(r.unstable_s) \
                else "stable up to the longest step tried"
            print(f"{r.scene} {r.policy}: stable up to {1000 * r.stable_s:.4g} ms; {unstable}")
    return 0


def _convert(args, argv) -> int:
    from steadystep import convert

    given = {name for name in ("k", "c", "erp", "cfm", "dt", "frequency", "damping_ratio", "mass")
             if getattr(args, name) is not None}
    out: dict[str, float] = {}
    if {"k", "c"} <= given and not given & {"erp", "cfm", "frequency", "damping_ratio"}:
        if "dt" not in given and "mass" not in given:
            raise _UsageError("steadystep convert: --k and --c need --dt H (or --mass M)")
        spring = (args.k, args.c)
        if args.dt is not None:
            out.update(convert.softness_from_spring(spring, args.dt)._asdict())
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
            out.update(convert.softness_from_spring(spring, args.dt)._asdict())
    else:
        raise _UsageError("steadystep convert: give --k K --c C --dt H, or --erp E --cfm F --dt H, or "
                          "--frequency HZ --damping-ratio Z --mass M (see steadystep convert --help)")
    if args.json:
        print(json.dumps(out))
    else:
        units = {"stiffness": "N/m", "damping": "N·s/m", "cfm": "m/(N·s)", "matched_cfm": "m/(N·s)",
                 "frequency_hz": "Hz"}
        for name, value in out.items():
            print(f"{name} = {value:.17g} {units.get(name, '')}".rstrip())
    return 0


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    try:
        args = build_parser().parse_args(argv)
        handler = {"figure": _figure, "compare": _compare, "run": _run, "probe": _probe,
                   "convert": _convert}[args.command]
        return handler(args, argv)
    except _UsageError as error:
        print(error, file=sys.stderr)
        return EXIT_BAD_INPUT
    except SteadystepError as error:
        print(f"steadystep: {error}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except OSError as error:
        print(f"steadystep: {error.strerror or error}: {error.filename or ''}".rstrip(": "), file=sys.stderr)
        return EXIT_BAD_INPUT


if __name__ == "__main__":
    sys.exit(main())

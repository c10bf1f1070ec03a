"""The `steadystep audit` subcommand: its arguments and its run (cli.py hooks it in)."""

from __future__ import annotations

import math
import os
import shlex
from pathlib import Path

from steadystep.core._native import SteadystepError
from steadystep.core.enums import Status

HELP = ("audit your own program: its frame-rate dependence under every policy, against a checked reference")
DESCRIPTION = (
    "Runs PROGRAM (an executable taking --profile SPEC --seed N --duration S --policy NAME and printing CSV "
    "t_s,<quantity>_<unit>,... on stdout, one row per frame; exit 0 done, 1 a frame failed) or a Python file "
    "(--python FILE defining build_world() and read_quantities(world), and own_frame(world, time_s, frame_s) for "
    "its own stepping) under every frame-time profile and policy, and the program's own stepping (--own: the same "
    "flags but --policy), each run a process of its own, against a fine-step reference (implicit-euler at 1000 "
    "frames a second) that it checks at 4000. Writes audit.html, metrics.json and metrics.csv to --out "
    "(docs/audit.md), and keeps every finished run in --out/runs: an audit interrupted and run again resumes. A "
    "program that does not exist, is not executable, prints no or malformed CSV, hangs past --time-limit, exits or "
    "crashes is refused with exit 2, naming it.")


def _positive(text: str) -> float:
    import argparse

    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"{text!r} must be a finite number above 0")
    return value


def add_parser(commands, seed_type, executor_argument) -> None:
    """The audit subparser, on cli.py's subcommands (seed_type and executor_argument: cli.py's own)."""
    from steadystep.audit import comparison

    parser = commands.add_parser("audit", help=HELP, description=DESCRIPTION)
    program = parser.add_mutually_exclusive_group(required=True)
    program.add_argument("program", nargs="?", metavar="PROGRAM", help="the program run with --policy NAME; "
                         "quote it with its own fixed arguments: 'build/game --level 2'")
    program.add_argument("--python", metavar="FILE", help="a Python file defining build_world() and "
                         "read_quantities(world) (docs/audit.md)")
    parser.add_argument("--own", metavar="PROGRAM", help="the same program stepping on its own, without the "
                        "library (the same flags but --policy)")
    parser.add_argument("--out", type=Path, default=Path("audit"), metavar="DIR", help="output directory "
                        "(default ./audit)")
    parser.add_argument("--force", action="store_true", help="replace an earlier audit's files in --out")
    parser.add_argument("--profiles", nargs="+", default=list(comparison.DEFAULT_PROFILES), metavar="SPEC",
                        help=f"frame-time profiles, the first the baseline of the spread (default: "
                        f"{' '.join(comparison.DEFAULT_PROFILES)})")
    parser.add_argument("--seeds", nargs="+", type=seed_type, default=list(comparison.DEFAULT_SEEDS), metavar="N",
                        help="seeds of the random profiles, each run once per seed (default 1 2 3)")
    parser.add_argument("--policies", nargs="+", metavar="POLICY", help="default: every policy")
    parser.add_argument("--duration", type=_positive, default=comparison.DEFAULT_DURATION_S, metavar="S",
                        help=f"simulated seconds per run (default {comparison.DEFAULT_DURATION_S:g})")
    parser.add_argument("--time-limit", type=_positive, default=60.0, metavar="S",
                        help="CPU seconds a run may use before it is killed and the program refused (default 60); "
                        "a run that sleeps is killed after this much wall time once it has used no CPU for 1 s")
    parser.add_argument("--cost", choices=comparison.COST_METHODS, default="auto",
                        help="how cost is measured: instructions (valgrind, an executable), time (CPU time of "
                        "repeated runs), none; auto (default): instructions when valgrind is there")
    parser.add_argument("--no-diagnosis", action="store_true", help="skip the diagnosis variants (half-step, "
                        "more-iterations)")
    executor_argument(parser)


def command(args, argv) -> int:
    from steadystep.audit import comparison
    from steadystep.audit.run import Executable, PythonProgram

    if os.path.lexists(args.out) and not args.out.is_dir():
        raise SteadystepError(Status.OUT_OF_RANGE, f"--out {args.out}: exists and is not a directory")
    comparison.refuse_earlier(args.out, args.force)  # refused before anything runs
    if args.python:
        if args.own:
            raise SteadystepError(Status.OUT_OF_RANGE, f"--own {args.own}: a --python program's own stepping is its "
                                  "own_frame(world, time_s, frame_s), not a second program")
        program = PythonProgram(args.python, args.time_limit)
    else:
        words = shlex.split(args.program)
        if not words:
            raise SteadystepError(Status.OUT_OF_RANGE, "PROGRAM = '': name the program to audit")
        own = tuple(shlex.split(args.own)) if args.own else None
        program = Executable(tuple(words), own, args.time_limit)
    comparison.validate(program, args.profiles, args.seeds, args.policies or [], args.duration)
    from steadystep.lab import study

    if args.force:
        comparison.clear_kept_runs(args.out)  # a replaced audit runs everything again
    try:
        with study.make_executor(args.executor, comparison.pool_workers()) as executor:
            result = comparison.audit(program, args.profiles, args.seeds, args.policies, args.duration, executor,
                                 out_dir=args.out, cost=args.cost, diagnosis=not args.no_diagnosis,
                                 draw=True)  # the figures drawn in the executor's workers, after the runs
    except study.ExecutorUnavailable as error:
        raise SteadystepError(Status.OUT_OF_RANGE, f"steadystep audit: {error}") from None
    path = comparison.write(result, args.out, shlex.join(["steadystep", *argv]), force=args.force)
    print(path)
    if result.reused_runs:
        print(f"({result.reused_runs} finished runs kept in {args.out / comparison.RUNS_DIRECTORY} were not run again)")
    for claim in result.claims:
        print(f"- {claim['text']}")
    code = comparison.code_to_write(result)
    if code:
        print()
        print(code)
    return 0

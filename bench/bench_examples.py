"""The example programs (examples/*_ode.c and their steadystep adoptions), measured: how much their followed
quantities depend on the frame rate, how far they are from a fine-step reference, and what adopted stepping costs.

Usage: .venv/bin/python bench/bench_examples.py [BUILD_DIR] [--repeats N] [--boxes N] [--cost-seconds S]
       [--vehicle-seconds S] [--skip-cost | --cost-only] [--instructions] [--executor WHERE]

1-2. Frame-rate spread and accuracy: `steadystep audit` (python/steadystep/audit/comparison.py, docs/audit.md) of each
   adopted program with its *_ode twin as its own stepping, under the profiles fixed:60, fixed:30 and uniform:15:45
   (seeds 1, 2, 3), 10 s, the policies implicit-euler, matched, exact and fixed (max step 1/60 s), so that the bench's
   numbers
   are the audit's (docs/audit.md, "What it measures"): each quantity over its scale (its range over the own stepping
   runs and the fine-step reference, the adopted program under implicit-euler with 1 ms frames); spread = each run
   against the variant's fixed:60 run, at the simulated times they share when they share most of them, else
   interpolated onto the fixed:60 run's times, RMS over time then over runs; error = each run against the reference
   interpolated at the run's own times, RMS over time then over runs, over the whole run. The audit's own claims use
   the deviation while its reference holds (checked at 0.25 ms), printed below each table.
3. Cost. The stack with --boxes N (default 200) under fixed:60: its own stepping (one dWorldQuickStep a frame)
   against the adopted program under implicit-euler with --max-step 1 (also one step a frame: the same step
   sequence); the vehicle likewise under implicit-euler, matched and exact (issue 15: the accurate mappings where
   they serve, its suspension). Each program times its stepping loop alone (--quiet): wall clock and process CPU
   time. Each repeat runs the own stepping and every policy once, in an order rotated from repeat to repeat, and the
   ratio policy / own is taken per repeat; printed: the median ratio over the repeats and its range, for both clocks
   (CPU time is the one a shared, busy machine disturbs least).
   With --instructions (needs valgrind: apt-get install valgrind), the same variants' instructions are counted as
   well, by callgrind: each variant runs once for the cost run's simulated time and once for twice that, and the
   difference is the instructions of that much more stepping loop, start-up and world building taken off. A count
   does not vary from run to run as times do on a shared machine (the vehicle's CPU-time ratios range over about
   15 % here); it does not see cache misses, which the times do.
Prints Markdown tables. Exit 1 when a run fails (a program the audit refuses: its one line, exit 1).
"""

from __future__ import annotations

import argparse
import os
import pathlib
import shutil
import statistics
import subprocess
import sys

PROGRAMS = ["vehicle", "chain", "stack"]
POLICIES = ["implicit-euler", "matched", "exact", "fixed"]
PROFILES = ["fixed:60", "fixed:30", "uniform:15:45"]
SEEDS = [1, 2, 3]
SECONDS = 10.0


def machine() -> str:
    """The load average (1, 5 and 15 minutes) and the cores this process may use: what the times were measured on."""
    one, five, fifteen = os.getloadavg()
    return (f"load average {one:.2f} {five:.2f} {fifteen:.2f}, {len(os.sched_getaffinity(0))} of {os.cpu_count()} "
            "cores usable")


def frame_rate_tables(build: pathlib.Path, executor: str) -> None:
    from steadystep import audit

    for program in PROGRAMS:
        result = audit.audit(audit.Executable((str(build / f"steadystep_example_{program}_steadystep"),),
                                              own=(str(build / f"steadystep_example_{program}_ode"),)),
                             PROFILES, SEEDS, POLICIES, SECONDS, executor, cost="none", diagnosis=False)
        quantities = result.quantities
        print(f"\n{program}: A = " + ", ".join(f"{q} {result.scales[q]:.4g}" for q in quantities))
        print()
        print("| variant | " + " | ".join(f"spread {q}" for q in quantities) + " | "
              + " | ".join(f"error {q}" for q in quantities) + " |")
        print("|---" * (1 + 2 * len(quantities)) + "|")
        for variant in result.variants:
            spreads = [result.spread[variant][q] for q in quantities]
            errors = [result.deviation["whole"][variant][q] for q in quantities]
            name = f"{program}_ode (own stepping)" if variant == "own" else f"adopted, {variant}"
            print(f"| {name} | " + " | ".join(f"{x:.4f}" for x in spreads + errors) + " |")
        check = result.reference
        held = "the whole run" if check["holds_whole_run"] else \
            f"{check['held_s']:.3g} s (it parts from its check at {check['parted_at']:.3g} s)"
        print(f"\nThe reference holds for {held}; the audit's recommendation: "
              + next(c["variant"] for c in result.claims if c["kind"] == "recommend") + ".")
        failed = [r for r in result.runs if r["status"] != "ok"]
        if failed:
            sys.exit(f"bench_examples: {program}: {len(failed)} runs failed: {failed[0]['status']}")


def loop_command(build: pathlib.Path, program: str, variant: str, seconds: float, extra: list[str]) -> list[str]:
    """The command of one cost run of the program at fixed:60: its own stepping ("own") or adopted under the policy
    `variant` with one step a frame."""
    if variant == "own":
        command = [str(build / f"steadystep_example_{program}_ode")]
    else:
        command = [str(build / f"steadystep_example_{program}_steadystep"), "--policy", variant, "--max-step", "1"]
    return command + ["--profile", "fixed:60", "--duration", str(seconds), "--quiet"] + extra


def loop_seconds(build: pathlib.Path, program: str, variant: str, seconds: float,
                 extra: list[str]) -> tuple[float, float]:
    """The stepping loop's (wall, CPU) seconds of one cost run (loop_command)."""
    command = loop_command(build, program, variant, seconds, extra)
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"bench_examples: {' '.join(command)} exited {done.returncode}: {done.stderr.strip()}")
    wall_s, cpu_s = (float(x) for x in done.stderr.strip().splitlines()[-1].split())
    return wall_s, cpu_s


def loop_instructions(build: pathlib.Path, program: str, variant: str, seconds: float, extra: list[str]) -> int:
    """Instructions, counted by callgrind, of `seconds` of the program's stepping loop at fixed:60: a run twice as
    long less a run as long."""
    counts = []
    for duration in (seconds, 2 * seconds):
        command = ["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null"] + \
            loop_command(build, program, variant, duration, extra)
        done = subprocess.run(command, capture_output=True, text=True)
        collected = [line for line in done.stderr.splitlines() if "Collected :" in line]
        if done.returncode != 0 or not collected:
            sys.exit(f"bench_examples: {' '.join(command)} exited {done.returncode}: {done.stderr.strip()[-400:]}")
        counts.append(int(collected[-1].split(":")[-1]))
    return counts[1] - counts[0]


def instruction_table(build: pathlib.Path, program: str, policies: list[str], seconds: float, extra: list[str],
                      title: str) -> None:
    own = loop_instructions(build, program, "own", seconds, extra)
    print()
    print(f"| {title}, {seconds:g} s of the loop at fixed:60 | instructions (M) | ratio to own |")
    print("|---|---|---|")
    print(f"| own stepping loop | {own / 1e6:.1f} | 1 |")
    for variant in policies:
        count = loop_instructions(build, program, variant, seconds, extra)
        print(f"| adopted, {variant} (one step a frame) | {count / 1e6:.1f} | {count / own:.4f} |")


def cost_table(build: pathlib.Path, program: str, policies: list[str], repeats: int, seconds: float,
               extra: list[str], title: str) -> None:
    """Each repeat runs the program's own stepping and every policy once, in an order rotated from repeat to repeat;
    each policy's ratio to the own run of the same repeat, median and range over the repeats."""
    variants = ["own"] + policies
    times: dict[str, list[tuple[float, float]]] = {v: [] for v in variants}
    for repeat in range(repeats):
        shift = repeat % len(variants)
        for variant in variants[shift:] + variants[:shift]:
            times[variant].append(loop_seconds(build, program, variant, seconds, extra))
    print()
    print(f"| {title}, {seconds:g} s at fixed:60, {repeats} interleaved repeats | wall clock | CPU time |")
    print("|---|---|---|")
    for variant in variants:
        label = "own stepping loop, median (s)" if variant == "own" else \
            f"adopted, {variant} (one step a frame), median (s)"
        print(f"| {label} | " + " | ".join(f"{statistics.median(t[k] for t in times[variant]):.4f}" for k in (0, 1))
              + " |")
    for variant in policies:
        ratios = [[a[k] / o[k] for a, o in zip(times[variant], times["own"])] for k in (0, 1)]
        print(f"| ratio {variant} / own, median (min - max) | "
              + " | ".join(f"{statistics.median(r):.4f} ({min(r):.4f} - {max(r):.4f})" for r in ratios) + " |")


def diff_sizes(root: pathlib.Path) -> None:
    print()
    print("| program | `diff -u` lines | lines removed | lines added |")
    print("|---|---|---|---|")
    for program in PROGRAMS:
        files = [str(root / "examples" / f"{program}_ode.c"), str(root / "examples" / f"{program}_steadystep.c")]
        unified = subprocess.run(["diff", "-u"] + files, capture_output=True, text=True).stdout.splitlines()
        removed = sum(1 for line in unified if line.startswith("-") and not line.startswith("---"))
        added = sum(1 for line in unified if line.startswith("+") and not line.startswith("+++"))
        print(f"| {program} | {len(unified)} | {removed} | {added} |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("build", nargs="?", default="build", help="the CMake build directory (default build)")
    parser.add_argument("--repeats", type=int, default=9, help="interleaved cost repeats (default 9)")
    parser.add_argument("--boxes", type=int, default=200, help="boxes of the cost run (default 200)")
    parser.add_argument("--cost-seconds", type=float, default=10.0, help="simulated time of a cost run (s)")
    parser.add_argument("--vehicle-seconds", type=float, default=300.0,
                        help="simulated time of a vehicle cost run (s; default 300: its loop takes about 0.3 s)")
    parser.add_argument("--skip-cost", action="store_true", help="the frame-rate tables only")
    parser.add_argument("--cost-only", action="store_true", help="the cost tables only")
    parser.add_argument("--instructions", action="store_true",
                        help="also count the cost runs' instructions with callgrind (needs valgrind)")
    parser.add_argument("--executor", default="local", help="where the audit's runs go (lab/study.py; default local)")
    args = parser.parse_args()
    build = pathlib.Path(args.build).resolve()
    print(f"bench_examples: {machine()}")
    if not args.cost_only:
        from steadystep.core._native import SteadystepError

        try:
            frame_rate_tables(build, args.executor)
        except SteadystepError as error:  # a program the audit refuses (BadProgram): its one line
            sys.exit(f"bench_examples: {error}")
    if not args.skip_cost:
        cost_table(build, "stack", ["implicit-euler"], args.repeats, args.cost_seconds, ["--boxes", str(args.boxes)],
                   f"stack, {args.boxes} boxes")
        cost_table(build, "vehicle", ["implicit-euler", "matched", "exact"], args.repeats, args.vehicle_seconds, [],
                   "vehicle")
    if args.instructions and not args.skip_cost:
        if shutil.which("valgrind") is None:
            sys.exit("bench_examples: --instructions needs valgrind (apt-get install valgrind)")
        instruction_table(build, "stack", ["implicit-euler"], 1.0, ["--boxes", str(args.boxes)],
                          f"stack, {args.boxes} boxes")
        instruction_table(build, "vehicle", ["implicit-euler", "matched", "exact"], 60.0, [], "vehicle")
    diff_sizes(pathlib.Path(__file__).resolve().parent.parent)
    print(f"\nafter: {machine()}")


if __name__ == "__main__":
    main()

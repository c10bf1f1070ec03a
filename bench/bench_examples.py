"""The example programs (examples/*_ode.c and their steadystep adoptions), measured: how much their followed
quantities depend on the frame rate, how far they are from a fine-step reference, and what adopted stepping costs.

Usage: .venv/bin/python bench/bench_examples.py [BUILD_DIR] [--repeats N] [--boxes N] [--cost-seconds S]

1. Frame-rate spread. Every variant (the program's own stepping, and the adopted program under the policies implicit-euler,
   matched, exact and fixed, max step 1/60 s) runs 10 s under the profiles fixed:60, fixed:30 and uniform:15:45
   (seeds 1, 2, 3). For each followed quantity q, every run is interpolated linearly onto the time grid of the
   variant's own fixed:60 run, and

       spread = sqrt(mean over the fixed:30 and the three uniform:15:45 runs, and over the grid, of
                     (q_run(t) - q_fixed60(t))^2) / A

   where A = max(q) - min(q) over the fine-step reference run (below), one scale per quantity shared by all variants.
2. Accuracy. The fine-step reference is the adopted program under implicit-euler, fixed:1000, --max-step 0.001. For each
   variant, over all five runs (fixed:60 included), error = RMS of (q_run(t) - q_reference(t)) on the reference's
   grid, divided by the same A.
3. Cost. The stack with --boxes N (default 200) under fixed:60: its own stepping (one dWorldQuickStep a frame)
   against the adopted program under implicit-euler with --max-step 1 (also one step a frame: the same step sequence). Each
   program times its stepping loop alone (--quiet): wall clock and process CPU time. Runs alternate (own, adopted,
   adopted, own, ...) and the ratio adopted / own is taken per pair; printed: the median ratio over the pairs and its
   range, for both clocks (CPU time is the one a shared, busy machine disturbs least).
Prints Markdown tables. Exit 1 when a run fails.
"""

from __future__ import annotations

import argparse
import pathlib
import statistics
import subprocess
import sys

import numpy as np

PROGRAMS = {  # program: followed quantities as the CSV names them
    "vehicle": ["height_m", "pitch_rad"],
    "chain": ["end_x_m", "end_z_m"],
    "stack": ["top_z_m", "ground_force_N"],
}
POLICIES = ["implicit-euler", "matched", "exact", "fixed"]
REFERENCE_PROFILE = "fixed:60"
OTHER_RUNS = [("fixed:30", 1), ("uniform:15:45", 1), ("uniform:15:45", 2), ("uniform:15:45", 3)]
SECONDS = 10.0


def run_csv(build: pathlib.Path, program: str, variant: str, profile: str, seed: int,
            extra: list[str] | None = None) -> dict[str, np.ndarray]:
    """Runs one example and returns its CSV columns. variant: "own" or a policy name."""
    if variant == "own":
        command = [str(build / f"steadystep_example_{program}_ode")]
    else:
        command = [str(build / f"steadystep_example_{program}_steadystep"), "--policy", variant]
    command += ["--profile", profile, "--seed", str(seed), "--duration", str(SECONDS)] + (extra or [])
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"bench_examples: {' '.join(command)} exited {done.returncode}: {done.stderr.strip()}")
    lines = done.stdout.strip().splitlines()
    names = lines[0].split(",")
    table = np.array([[float(x) for x in line.split(",")] for line in lines[1:]])
    return {name: table[:, i] for i, name in enumerate(names)}


def on_grid(run: dict[str, np.ndarray], grid_s: np.ndarray, quantity: str) -> np.ndarray:
    return np.interp(grid_s, run["t_s"], run[quantity])


def mean_square(runs: list[dict[str, np.ndarray]], against: dict[str, np.ndarray], quantity: str) -> float:
    grid_s = against["t_s"]
    truth = against[quantity]
    return float(np.mean([np.mean((on_grid(run, grid_s, quantity) - truth) ** 2) for run in runs]))


def frame_rate_tables(build: pathlib.Path) -> None:
    for program, quantities in PROGRAMS.items():
        reference = run_csv(build, program, "implicit-euler", "fixed:1000", 1, ["--max-step", "0.001"])
        scales = {quantity: float(np.ptp(reference[quantity])) for quantity in quantities}
        print(f"\n{program}: A = " + ", ".join(f"{q} {scales[q]:.4g}" for q in quantities))
        print()
        print("| variant | " + " | ".join(f"spread {q}" for q in quantities) + " | "
              + " | ".join(f"error {q}" for q in quantities) + " |")
        print("|---" * (1 + 2 * len(quantities)) + "|")
        for variant in ["own"] + POLICIES:
            at_60 = run_csv(build, program, variant, REFERENCE_PROFILE, 1)
            others = [run_csv(build, program, variant, profile, seed) for profile, seed in OTHER_RUNS]
            spreads = [np.sqrt(mean_square(others, at_60, q)) / scales[q] for q in quantities]
            errors = [np.sqrt(mean_square([at_60] + others, reference, q)) / scales[q] for q in quantities]
            name = f"{program}_ode (own stepping)" if variant == "own" else f"adopted, {variant}"
            print(f"| {name} | " + " | ".join(f"{x:.4f}" for x in spreads + errors) + " |")


def loop_seconds(build: pathlib.Path, variant: str, boxes: int, seconds: float) -> tuple[float, float]:
    """The stepping loop's (wall, CPU) seconds of one stack run at fixed:60."""
    if variant == "own":
        command = [str(build / "steadystep_example_stack_ode")]
    else:
        command = [str(build / "steadystep_example_stack_steadystep"), "--policy", "implicit-euler", "--max-step", "1"]
    command += ["--profile", "fixed:60", "--duration", str(seconds), "--boxes", str(boxes), "--quiet"]
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"bench_examples: {' '.join(command)} exited {done.returncode}: {done.stderr.strip()}")
    wall_s, cpu_s = (float(x) for x in done.stderr.strip().splitlines()[-1].split())
    return wall_s, cpu_s


def cost_table(build: pathlib.Path, repeats: int, boxes: int, seconds: float) -> None:
    times: dict[str, list[tuple[float, float]]] = {"own": [], "adopted": []}
    for repeat in range(repeats):
        for variant in ["own", "adopted"] if repeat % 2 == 0 else ["adopted", "own"]:
            times[variant].append(loop_seconds(build, variant, boxes, seconds))
    print()
    print(f"| stack, {boxes} boxes, {seconds:g} s at fixed:60, {repeats} interleaved pairs | wall clock | CPU time |")
    print("|---|---|---|")
    for label, variant in [("own stepping loop, median (s)", "own"),
                           ("adopted stepping loop (implicit-euler, one step a frame), median (s)", "adopted")]:
        print(f"| {label} | " + " | ".join(f"{statistics.median(t[k] for t in times[variant]):.4f}" for k in (0, 1))
              + " |")
    ratios = [[a[k] / o[k] for a, o in zip(times["adopted"], times["own"])] for k in (0, 1)]
    print("| ratio adopted / own, median over pairs | "
          + " | ".join(f"{statistics.median(r):.4f}" for r in ratios) + " |")
    print("| ratio, min - max over pairs | " + " | ".join(f"{min(r):.4f} - {max(r):.4f}" for r in ratios) + " |")


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
    parser.add_argument("--repeats", type=int, default=9, help="interleaved cost pairs (default 9)")
    parser.add_argument("--boxes", type=int, default=200, help="boxes of the cost run (default 200)")
    parser.add_argument("--cost-seconds", type=float, default=10.0, help="simulated time of a cost run (s)")
    parser.add_argument("--skip-cost", action="store_true", help="the frame-rate tables only")
    args = parser.parse_args()
    build = pathlib.Path(args.build).resolve()
    frame_rate_tables(build)
    if not args.skip_cost:
        cost_table(build, args.repeats, args.boxes, args.cost_seconds)
    diff_sizes(pathlib.Path(__file__).resolve().parent.parent)


if __name__ == "__main__":
    main()

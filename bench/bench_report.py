"""The report's wall time on this machine: the whole comparison (every scene, profile and policy, the references,
the largest-stable-step probes, the side-by-side table, the animation, the cost benchmark and the figures) in one
process against a local process pool over every core.

Prints each timing, with the part of it that is the cost benchmark (which runs in this process alone either way),
and the ratio one process / local pool, measured in this one run in the order serial, local, local, serial (ABBA)
so that a drift in the machine's load falls on both sides alike, and the load average before and after (the
machine may be shared). Usage: python bench/bench_report.py [DURATION_S] (default 5, the report's)
"""

from __future__ import annotations

import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

from steadystep import report, study


def wall_s(executor: str, duration_s: float) -> tuple[float, float]:
    """The report's wall time (s) and, within it, the cost benchmark's (which always runs in this process alone)."""
    with tempfile.TemporaryDirectory() as figures:
        started = time.perf_counter()
        with study.make_executor(executor) as made:  # a pool's start-up is part of the report's time
            result = report.compare(duration_s=duration_s, progress=False, figure_dir=Path(figures), executor=made)
        return time.perf_counter() - started, result.cost_wall_s


def main() -> None:
    duration_s = float(sys.argv[1]) if len(sys.argv) > 1 else 5.0
    print(f"report wall time, duration {duration_s:g} s per run, {study.usable_cores()} usable cores, "
          f"load average {os.getloadavg()[0]:.2f}")
    times: dict[str, list[float]] = {"serial": [], "local": []}
    for executor in ("serial", "local", "local", "serial"):
        total_s, cost_s = wall_s(executor, duration_s)
        times[executor].append(total_s)
        print(f"  {executor:6s} {total_s:8.2f} s (of which the cost benchmark, one process either way: {cost_s:.2f} s)",
              flush=True)
    serial, local = statistics.mean(times["serial"]), statistics.mean(times["local"])
    print(f"one process / local pool: {serial / local:.2f} (mean {serial:.2f} s / {local:.2f} s); "
          f"load average after {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()

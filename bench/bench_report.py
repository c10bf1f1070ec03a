"""The report's wall time on this machine: the whole comparison (every scene, profile and policy, the references,
the repeats under the next seed, the largest-stable-step probes, the side-by-side table, the animation, the figures
and the cost benchmark) in one process against a local process pool over every core.

Prints each timing with its phases (report_tasks: runs, figures still drawing after the runs, the cost benchmark's
timing, which runs in this process alone either way, with how many of its scene-policy pairs stopped before the
most blocks because their ranges were tight (cost.TIGHT_RANGE: a quiet machine); "other": the rest, in this process:
the pool's start-up, the aggregation, the page and the data written), the ratio one process / local pool, and the
load average before and after (the machine may be shared). The order is serial, local, local, serial (ABBA), so
that a drift in the load falls on both sides alike; --once measures serial, local once each (half the time). First
it prints the parallelism the machine gives two processes at that moment (two CPU-bound loops in one process, then
in two): a shared machine whose cores others take gives about 1, and then no pool can be faster.
Usage: python bench/bench_report.py [DURATION_S] [--once] (default 5, the report's)
"""

from __future__ import annotations

import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

from steadystep import cost, report, study


def wall_s(executor: str, duration_s: float) -> tuple[float, report.Report]:
    """The report's wall time (s), figures and page written, and the report (its phases_s, its costs)."""
    with tempfile.TemporaryDirectory() as out:
        started = time.perf_counter()
        with study.make_executor(executor) as made:  # a pool's start-up is part of the report's time
            result = report.compare(duration_s=duration_s, progress=False, figure_dir=Path(out), executor=made)
        report.write(result, Path(out), "bench/bench_report.py")
        return time.perf_counter() - started, result


def phases(total_s: float, result: report.Report) -> str:
    """The phases' seconds in words, the cost's blocks, and the rest of the wall time."""
    said = [f"{name} {seconds:.1f} s" for name, seconds in result.phases_s.items()]
    early = sum(c.status == "ok" and c.repeats < cost.DEFAULT_REPEATS for c in result.costs)
    said.append(f"cost pairs stopped before {cost.DEFAULT_REPEATS} blocks {early} of {len(result.costs)}")
    said.append(f"other {total_s - sum(result.phases_s.values()):.1f} s")
    return ", ".join(said)


def _spin(count: int) -> int:
    total = 0
    for i in range(count):
        total += i
    return total


def parallelism(count: int = 3_000_000) -> float:
    """What the machine gives two processes at this moment: the time of two CPU-bound loops one after the other
    over their time in two processes at once (2 on two idle cores; about 1 when others take the cores)."""
    import concurrent.futures

    started = time.perf_counter()
    _spin(count), _spin(count)
    serial = time.perf_counter() - started
    with study.make_executor("local") as pool:
        pool.submit(_spin, 1).result()  # the workers started
        started = time.perf_counter()
        concurrent.futures.wait([pool.submit(_spin, count) for _ in range(2)])
        return serial / (time.perf_counter() - started)


def main() -> None:
    arguments = [a for a in sys.argv[1:] if a != "--once"]
    duration_s = float(arguments[0]) if arguments else 5.0
    order = ("serial", "local") if "--once" in sys.argv[1:] else ("serial", "local", "local", "serial")
    print(f"report wall time, duration {duration_s:g} s per run, {study.usable_cores()} usable cores, "
          f"load average {' '.join(f'{x:.2f}' for x in os.getloadavg())}", flush=True)
    print(f"two CPU-bound loops: {parallelism():.2f} times faster in two processes than in one (the machine's "
          "parallelism now; 2 on two idle cores)", flush=True)
    times: dict[str, list[float]] = {"serial": [], "local": []}
    for executor in order:
        total_s, result = wall_s(executor, duration_s)
        times[executor].append(total_s)
        print(f"  {executor:6s} {total_s:8.2f} s ({phases(total_s, result)}); load average "
              f"{os.getloadavg()[0]:.2f}", flush=True)
    serial, local = statistics.mean(times["serial"]), statistics.mean(times["local"])
    print(f"one process / local pool: {serial / local:.2f} (mean {serial:.2f} s / {local:.2f} s); "
          f"load average after {' '.join(f'{x:.2f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()

"""The report's time on this machine: the whole comparison (every scene, profile and policy, the references, the
repeats under the next seed, the largest-stable-step probes, the side-by-side table, the animation, the figures and
the cost benchmark) in one process against a local process pool over every usable core.

For each run it prints the wall time with its phases (report/tasks.py: runs, figures still drawing after the runs, the
cost benchmark's timing, which runs in this process alone either way, with how many of its scene-policy pairs
stopped before the most blocks because their ranges were tight (cost.TIGHT_RANGE: a quiet machine); "other": the
rest, in this process: the pool's start-up, the aggregation, the page and the data written), and the CPU time of
the work: this process's, its children's and the pool's workers' (the forkserver's reaped children), so that the
CPU time a unit of work costs, which another process on the machine changes little, stands beside the wall time,
which it changes a lot. Then the ratio one process / local pool of the wall times, stated against the usable cores
(a pool of N processes cannot be more than N times faster: a ratio above that says the one-process run waited for a
core) and of the CPU times (what running in a pool costs in work), with the load average before and after.

The order is serial, local, local, serial (ABBA), so that a drift in the load falls on both sides alike; --once
measures serial, local once each (half the time). First it prints how many cores the machine gives two processes
at that moment: two CPU-bound loops run at once in two processes, their CPU time over the wall time they took
(about 2 on two idle cores, about 1 when others take a core: then no pool can be much faster).
Usage: python bench/bench_report.py [DURATION_S] [--once] (default 5, the report's)
"""

from __future__ import annotations

import os
import resource
import statistics
import sys
import tempfile
import time
from pathlib import Path

from steadystep import report
from steadystep.lab import cost, study


def machine() -> str:
    """The load average (1, 5 and 15 minutes) and the cores this process may use, of all the machine's."""
    return (f"load average {' '.join(f'{x:.2f}' for x in os.getloadavg())}, {study.usable_cores()} of "
            f"{os.cpu_count()} cores usable")


def _stat_fields(pid: int) -> list[str] | None:
    """The fields of /proc/PID/stat after the process's name (state, ppid, ...), or None when it is gone."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except (OSError, IndexError):
        return None


def _forkservers() -> list[int]:
    """This process's children that are multiprocessing's forkserver (the local pool's workers are its children)."""
    me, found = os.getpid(), []
    for entry in os.scandir("/proc"):
        if not entry.name.isdigit():
            continue
        fields = _stat_fields(int(entry.name))
        if fields is None or int(fields[1]) != me:
            continue
        try:
            command = Path(entry.path, "cmdline").read_bytes()
        except OSError:
            continue
        if b"forkserver" in command:
            found.append(int(entry.name))
    return found


def work_cpu_s() -> float:
    """CPU time (s) of the work so far: this process, its reaped children, and the forkserver with its reaped
    children (the local pool's workers, once the pool is shut down, and the processes they ran)."""
    own = resource.getrusage(resource.RUSAGE_SELF)
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    total = own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime
    ticks = os.sysconf("SC_CLK_TCK")
    for pid in _forkservers():
        fields = _stat_fields(pid)
        if fields is not None:  # utime, stime, cutime, cstime
            total += sum(int(f) for f in fields[11:15]) / ticks
    return total


def _workers_reaped(timeout_s: float = 5.0) -> None:
    """Waits until the forkserver has reaped the pool's workers (it does so on SIGCHLD, after the pool's shutdown
    returned), so that their CPU time is counted."""
    servers = {str(pid) for pid in _forkservers()}
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        stats = (_stat_fields(int(e.name)) for e in os.scandir("/proc") if e.name.isdigit())
        if not any(fields is not None and fields[1] in servers for fields in stats):
            return
        time.sleep(0.05)


def timed(executor: str, duration_s: float) -> tuple[float, float, report.Report]:
    """The report's wall time and its work's CPU time (s), figures and page written, and the report (its phases_s,
    its costs)."""
    with tempfile.TemporaryDirectory() as out:
        cpu_before = work_cpu_s()
        started = time.perf_counter()
        with study.make_executor(executor) as made:  # a pool's start-up is part of the report's time
            result = report.compare(duration_s=duration_s, progress=False, figure_dir=Path(out), executor=made)
        report.write(result, Path(out), "bench/bench_report.py")
        wall_s = time.perf_counter() - started
        _workers_reaped()
        return wall_s, work_cpu_s() - cpu_before, result


def phases(total_s: float, result: report.Report) -> str:
    """The phases' seconds in words, the cost's blocks, and the rest of the wall time."""
    said = [f"{name} {seconds:.1f} s" for name, seconds in result.phases_s.items()]
    early = sum(c.status == "ok" and c.repeats < cost.DEFAULT_REPEATS for c in result.costs)
    said.append(f"cost pairs stopped before {cost.DEFAULT_REPEATS} blocks {early} of {len(result.costs)}")
    said.append(f"other {total_s - sum(result.phases_s.values()):.1f} s")
    return ", ".join(said)


def _spin(count: int) -> float:
    """A CPU-bound loop; returns the CPU time (s) this process spent in it."""
    started = time.thread_time()
    total = 0
    for i in range(count):
        total += i
    return time.thread_time() - started


def cores_obtained(count: int = 3_000_000) -> float:
    """How many cores two processes get at this moment: two CPU-bound loops run at once in two processes, their CPU
    time over the wall time they took (about 2 on two idle cores, about 1 when others take a core)."""
    import concurrent.futures

    with study.make_executor("local") as pool:
        concurrent.futures.wait([pool.submit(_spin, 1) for _ in range(2)])  # the workers started
        started = time.perf_counter()
        futures = [pool.submit(_spin, count) for _ in range(2)]
        concurrent.futures.wait(futures)
        wall_s = time.perf_counter() - started
    return sum(f.result() for f in futures) / wall_s


def main() -> None:
    arguments = [a for a in sys.argv[1:] if a != "--once"]
    duration_s = float(arguments[0]) if arguments else 5.0
    order = ("serial", "local") if "--once" in sys.argv[1:] else ("serial", "local", "local", "serial")
    cores = study.usable_cores()
    print(f"report time, duration {duration_s:g} s per run, {machine()}", flush=True)
    print(f"two CPU-bound loops at once in two processes: {cores_obtained():.2f} cores obtained (their CPU time "
          f"over their wall time; at most {min(2, cores)})", flush=True)
    walls: dict[str, list[float]] = {"serial": [], "local": []}
    cpus: dict[str, list[float]] = {"serial": [], "local": []}
    for executor in order:
        wall_s, cpu_s, result = timed(executor, duration_s)
        walls[executor].append(wall_s)
        cpus[executor].append(cpu_s)
        print(f"  {executor:6s} wall {wall_s:8.2f} s ({phases(wall_s, result)}); CPU {cpu_s:8.2f} s, "
              f"{cpu_s / wall_s:.2f} cores busy on average; load average {os.getloadavg()[0]:.2f}", flush=True)
    serial, local = statistics.mean(walls["serial"]), statistics.mean(walls["local"])
    serial_cpu, local_cpu = statistics.mean(cpus["serial"]), statistics.mean(cpus["local"])
    ratio = serial / local
    bound = ("" if ratio <= cores * 1.02 else
             f": above the {cores} usable cores, so the one-process runs waited for a core (the load), and the ratio "
             "says more about the machine than about the report")
    print(f"wall, one process / local pool: {ratio:.2f} (mean {serial:.2f} s / {local:.2f} s; at most {cores}, the "
          f"usable cores){bound}")
    print(f"CPU, local pool / one process: {local_cpu / serial_cpu:.2f} (mean {local_cpu:.2f} s / {serial_cpu:.2f} s:"
          " the work a pool adds)")
    print(f"after: {machine()}")


if __name__ == "__main__":
    main()

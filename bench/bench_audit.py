"""`steadystep audit` of an example program, run as a user runs it (a process of its own, every run, the page and
its figures written), once in one process (--executor serial) and once with the local pool (--executor local), in
one run of this benchmark: the wall time of each and its CPU time (the audit's process and every process it waited
for), the ratio serial / local of the wall times, and the load average and cores beside.

The audits alternate serial, local, local, serial (ABBA) for each repeat, so that a drift in the load falls on both
alike; the ratio printed is of the mean wall times, with each pair's ratio beside it. A pool of N processes makes
the audit at most about N times faster, less what stays in one process (the pool's start-up, the measurement, the
page); a load average above the cores means others took cores from both sides. First it prints how many cores two
processes get at that moment (two CPU-bound loops at once, their CPU time over their wall time: about 2 on two idle
cores, about 1 when others take a core, and then no pool can be much faster). The pages of the two sides are checked
to hold the same tables and figures (everything but the times and the command).

Usage: .venv/bin/python bench/bench_audit.py [BUILD_DIR] [--program vehicle|chain|stack] [--python FILE]
       [--repeats N]        (default: build, the vehicle (examples/vehicle_steadystep.c, its own stepping
                             examples/vehicle_ode.c), 1 repeat: 4 audits)
"""

from __future__ import annotations

import argparse
import concurrent.futures
import ctypes
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

CLI = "import sys; from steadystep.cli import main; sys.exit(main())"


def machine() -> str:
    one, five, fifteen = os.getloadavg()
    return (f"load average {one:.2f} {five:.2f} {fifteen:.2f}, {len(os.sched_getaffinity(0))} of {os.cpu_count()} "
            "cores usable")


def _spin(count: int) -> float:
    started = time.thread_time()
    total = 0
    for i in range(count):
        total += i
    return time.thread_time() - started


def cores_obtained(count: int = 3_000_000) -> float:
    """Two CPU-bound loops at once in two processes: their CPU time over the wall time they took."""
    with concurrent.futures.ProcessPoolExecutor(2) as pool:
        concurrent.futures.wait([pool.submit(_spin, 1) for _ in range(2)])  # the workers started
        started = time.perf_counter()
        futures = [pool.submit(_spin, count) for _ in range(2)]
        concurrent.futures.wait(futures)
        wall_s = time.perf_counter() - started
    return sum(f.result() for f in futures) / wall_s


def _children_cpu_s() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def audit_s(program: list[str], executor: str, out: Path) -> tuple[float, float]:
    """(wall time, CPU time) (s) of one audit, as a user runs it; exits naming the audit when it fails. The CPU
    time is of the audit's process and every process it waited for (its workers, the programs' runs): the work
    done, which a pool spreads over the cores and does not reduce."""
    command = [sys.executable, "-c", CLI, "audit", *program, "--out", str(out), "--force", "--executor", executor]
    cpu_before_s = _children_cpu_s()
    started = time.perf_counter()
    done = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    wall_s = time.perf_counter() - started
    if done.returncode != 0:
        sys.exit(f"bench_audit: the {executor} audit failed (exit {done.returncode}): {done.stderr.strip()[-400:]}")
    while True:  # the pool's fork server outlives the audit by a moment: reaped here (a subreaper), its CPU counted
        try:
            os.wait()
        except ChildProcessError:
            break
    return wall_s, _children_cpu_s() - cpu_before_s


def _page_content(out: Path) -> str:
    """The page without what differs from one audit to the next: its times and the command."""
    text = (out / "audit.html").read_text()
    text = re.sub(r"<h2>Regenerate</h2>.*", "", text, flags=re.S)
    return re.sub(r"<td>[0-9.e+-]+</td><td>(ok|<span class=bad>[^<]*</span>)</td></tr>", r"<td>\1</td></tr>",
                  text)  # the runs table's CPU column


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("build", nargs="?", default="build", type=Path)
    parser.add_argument("--program", default="vehicle", choices=("vehicle", "chain", "stack"))
    parser.add_argument("--python", metavar="FILE", help="audit this Python program instead")
    parser.add_argument("--repeats", type=int, default=1)
    args = parser.parse_args()
    if args.python:
        program, name = ["--python", args.python], args.python
    else:
        adopted = args.build / f"steadystep_example_{args.program}_steadystep"
        own = args.build / f"steadystep_example_{args.program}_ode"
        program, name = [str(adopted), "--own", str(own)], f"{adopted.name} --own {own.name}"
    print(f"bench_audit: steadystep audit {name}, default profiles, seeds and policies; {machine()}", flush=True)
    print(f"two CPU-bound loops at once in two processes: {cores_obtained():.2f} cores obtained (their CPU time over "
          "their wall time)", flush=True)
    # Orphans of the audits (the local pool's fork server, which reaps the workers) become this process's children,
    # so that their CPU time reaches RUSAGE_CHILDREN (PR_SET_CHILD_SUBREAPER, Linux).
    ctypes.CDLL(None, use_errno=True).prctl(36, 1, 0, 0, 0)
    times: dict[str, list[float]] = {"serial": [], "local": []}
    with tempfile.TemporaryDirectory(prefix="bench-audit-") as scratch:
        for repeat in range(args.repeats):
            pair = {}
            for executor in ("serial", "local", "local", "serial"):
                wall_s, cpu_s = audit_s(program, executor, Path(scratch) / executor)
                times[executor].append(wall_s)
                pair.setdefault(executor, []).append(wall_s)
                print(f"  {executor:6s} {wall_s:7.2f} s wall, {cpu_s:6.2f} s CPU (the audit and its processes)   "
                      f"load average {os.getloadavg()[0]:.2f}", flush=True)
            ratio = statistics.mean(pair["serial"]) / statistics.mean(pair["local"])
            print(f"  repeat {repeat + 1}: serial / local {ratio:.2f}", flush=True)
        if _page_content(Path(scratch) / "serial") != _page_content(Path(scratch) / "local"):
            print("bench_audit: the serial and local audits' pages differ beyond their times", file=sys.stderr)
            return 1
        for png in sorted((Path(scratch) / "serial").glob("*.png")):
            if png.read_bytes() != (Path(scratch) / "local" / png.name).read_bytes():
                print(f"bench_audit: the figure {png.name} differs between the serial and local audits",
                      file=sys.stderr)
                return 1
    serial, local = statistics.mean(times["serial"]), statistics.mean(times["local"])
    print(f"serial / local pool: {serial / local:.2f} (mean wall {serial:.2f} s / {local:.2f} s over "
          f"{len(times['serial'])} audits each; the same tables and figures)")
    print(f"after: {machine()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

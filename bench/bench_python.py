"""The Python binding's overhead: the pile scene driven frame by frame from Python (ssScene_Frame through cffi,
one sample per frame) against the same run driven from C in one call (ssRun_Execute, one record per step).

Prints the ratio Python / C of the stepping wall time, measured in this one run (target: at most 1.05 for 500
bodies or more). Scene building is excluded on both sides. Usage: python bench/bench_python.py [BODIES] [SECONDS]
"""

from __future__ import annotations

import statistics
import sys
import time

from steadystep import runs
from steadystep.profiles import Profile

PROFILE = "uniform:15:45"
SEED = 1
REPEATS = 3


def python_loop(bodies: int, duration_s: float) -> tuple[float, int]:
    scene = runs.Scene("pile", "implicit-euler", params={"body_count": bodies})
    profile = Profile(PROFILE, SEED)
    steps = 0
    elapsed_s = 0.0
    started = time.perf_counter()
    while elapsed_s < duration_s:
        frame_s = min(profile.next(), duration_s - elapsed_s)  # as ssRun_Execute cuts its last frame
        steps += scene.frame(frame_s)
        scene.sample()
        elapsed_s += frame_s
    wall_s = time.perf_counter() - started
    scene.close()
    return wall_s, steps


def c_run(bodies: int, duration_s: float) -> tuple[float, int]:
    result = runs.run("pile", PROFILE, "implicit-euler", duration_s, SEED, params={"body_count": bodies})
    return result.wall_s, result.step_count


def main() -> int:
    bodies = int(sys.argv[1]) if len(sys.argv) > 1 else 500
    duration_s = float(sys.argv[2]) if len(sys.argv) > 2 else 3.0
    python_times, c_times = [], []
    for _ in range(REPEATS):  # interleaved, so that a slow moment of the machine hits both sides
        c_wall, c_steps = c_run(bodies, duration_s)
        py_wall, py_steps = python_loop(bodies, duration_s)
        if py_steps != c_steps:
            print(f"bench_python: the runs differ: {py_steps} steps from Python, {c_steps} from C", file=sys.stderr)
            return 1
        c_times.append(c_wall)
        python_times.append(py_wall)
    ratio = min(python_times) / min(c_times)
    print(f"pile, {bodies} bodies, {PROFILE}, {duration_s:g} s simulated, {c_steps} steps, best of {REPEATS}:")
    print(f"  C      (ssRun_Execute)         {min(c_times) * 1e3:9.1f} ms  (median {statistics.median(c_times) * 1e3:.1f})")
    print(f"  Python (ssScene_Frame loop)    {min(python_times) * 1e3:9.1f} ms  "
          f"(median {statistics.median(python_times) * 1e3:.1f})")
    print(f"  ratio Python / C               {ratio:9.3f}  (target <= 1.05)")
    return 0


if __name__ == "__main__":
    sys.exit(main())

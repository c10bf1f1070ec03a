"""What a policy costs: its stepping against plain ODE on the same scene, measured in one benchmark run.

For each scene and policy three copies of the scene step the same frame times (a profile's frames, by default
15-45 fps):
- through the library's stepper under the policy;
- as plain ODE at the stepper's own steps: one dWorldQuickStep per step the stepper takes, no library call in
  between (every softness as the stepper last wrote it). The ratio of the two is what the library itself costs;
- as a program without the library: one dWorldQuickStep of each whole frame, every softness as the naive policy
  wrote it at its first frame (tuned once for 30 fps). The ratio to it is what a frame costs the program,
  substeps included.
The copies take the frames in blocks, the order of the three rotating from block to block so that all see the same
machine at the same moments; each ratio is taken per block, and the median and range over the blocks are reported
(as bench/bench_stepper.c does in C). The stepper's steps are counted on a fourth, untimed copy stepped ahead over
the same frames. The timing loop runs in C (ssScene_TimeFrames), so that Python's call overhead is not measured.
"""

from __future__ import annotations

import math
import statistics
from dataclasses import dataclass

import numpy as np

from steadystep import runs
from steadystep._native import SteadystepError, lib
from steadystep.profiles import frame_times

DEFAULT_PROFILE = "uniform:15:45"
DEFAULT_REPEATS = 7
# A block lasts about this long when stepped plain: long against the clock's resolution, short against the drift
# of a shared machine.
BLOCK_TARGET_S = 0.005
MAX_BLOCK_FRAMES = 2000


@dataclass
class Cost:
    """One policy's cost on one scene, against plain ODE in the same benchmark run."""

    scene: str
    policy: str
    profile: str
    frames_per_block: int
    repeats: int
    ratio_median: float       # policy wall time / the program's plain frames, median over the blocks
    ratio_low: float          # the smallest and largest of that ratio over the blocks
    ratio_high: float
    us_per_frame: float       # the policy's median wall time per frame (µs)
    plain_us_per_frame: float # the program's plain ODE, one step a frame: median wall time per frame (µs)
    steps_per_frame: float    # the policy's physics steps per frame in the benchmark
    overhead_median: float = math.nan  # policy wall time / plain ODE at the stepper's own steps, median
    overhead_low: float = math.nan     # the smallest and largest of that ratio over the blocks
    overhead_high: float = math.nan
    status: str = "ok"        # "ok", or why the measurement stopped (a blow-up of a copy)


def _steps_of(counter: runs.Scene, stepping: dict, frames: np.ndarray) -> np.ndarray:
    """The steps (s each) the stepper takes over frames, counted on counter (stepped ahead, untimed): a whole
    frame, n equal substeps, or n fixed steps, n as the stepper chose."""
    steps = []
    for frame_s in frames:
        count = counter.frame(float(frame_s))
        if stepping["cut"] == lib.SS_CUT_FIXED:
            steps += [stepping["fixed_step_s"]] * count
        elif count:
            steps += [frame_s / count] * count
    return np.asarray(steps, dtype=np.float64)


def measure(scene: str, policy: str, profile: str = DEFAULT_PROFILE, repeats: int = DEFAULT_REPEATS,
            seed: int = 1, params: dict | None = None) -> Cost:
    """policy against plain ODE on scene under profile's frames: repeats rounds of interleaved blocks."""
    stepping = runs.make_stepping(policy)
    stepped = runs.Scene(scene, policy, params=params)
    same_steps = runs.Scene(scene, policy, params=params)
    counter = runs.Scene(scene, policy, params=params)
    program = runs.Scene(scene, "naive", params=params)
    copies = (stepped, same_steps, counter, program)
    try:
        first = float(frame_times(profile, 1, seed)[0])
        for copy in copies:
            copy.frame(first)  # writes every softness once, as a program tunes it once
        # Calibrate: how many frames make a plain block of about BLOCK_TARGET_S.
        probe_frames = frame_times(profile, 20, seed + 1)
        wall = program.time_frames(probe_frames, plain=True)
        same_steps.time_frames(_steps_of(counter, stepping, probe_frames), plain=True)
        stepped.time_frames(probe_frames)
        per_frame = max(wall / len(probe_frames), 1e-7)
        block = int(min(MAX_BLOCK_FRAMES, max(5, BLOCK_TARGET_S / per_frame)))
        frames = frame_times(profile, block * repeats, seed + 2)
        steps_before = stepped.counters()["steps"]
        walls = {"policy": [], "same": [], "program": []}
        for r in range(repeats):
            chunk = frames[r * block:(r + 1) * block]
            steps = _steps_of(counter, stepping, chunk)
            timed = {"policy": lambda: stepped.time_frames(chunk),
                     "same": lambda: same_steps.time_frames(steps, plain=True),
                     "program": lambda: program.time_frames(chunk, plain=True)}
            order = list(timed)[r % 3:] + list(timed)[:r % 3]
            for name in order:
                walls[name].append(timed[name]())
        steps = stepped.counters()["steps"] - steps_before
        ratios = [a / b if b > 0 else math.inf for a, b in zip(walls["policy"], walls["program"])]
        overheads = [a / b if b > 0 else math.inf for a, b in zip(walls["policy"], walls["same"])]
        return Cost(scene, policy, profile, block, repeats, statistics.median(ratios), min(ratios), max(ratios),
                    1e6 * statistics.median(walls["policy"]) / block,
                    1e6 * statistics.median(walls["program"]) / block, steps / (block * repeats),
                    statistics.median(overheads), min(overheads), max(overheads))
    except SteadystepError as error:
        return Cost(scene, policy, profile, 0, repeats, math.nan, math.nan, math.nan, math.nan, math.nan, math.nan,
                    status=f"{error.status}: {error.message}")
    finally:
        for copy in copies:
            copy.close()


"""What a policy costs: its stepping against plain ODE on the same scene, measured in one benchmark run.

For each scene and policy two copies of the scene are built: one stepped through the library's stepper under the
policy, one stepped plain, as a program without the library steps (collide, one dWorldQuickStep of the whole
frame, contacts emptied; every softness as the naive policy wrote it at its first frame: tuned once for 30 fps).
Both take the same frame times (a profile's frames, by default 15-45 fps) in alternating blocks, the order of the
two rotating from block to block, so that both see the same machine at the same moments; the ratio
policy / plain is taken per repeat, and the median and range over the repeats are reported (as
bench/bench_stepper.c does in C). The cost per frame is the policy's median wall time per frame (µs).

The timing loop runs in C (ssScene_TimeFrames), so that Python's call overhead is not measured.
"""

from __future__ import annotations

import math
import statistics
import time
from dataclasses import dataclass

import numpy as np

from steadystep import runs
from steadystep._native import SteadystepError
from steadystep.profiles import frame_times

DEFAULT_PROFILE = "uniform:15:45"
DEFAULT_REPEATS = 7
# A block lasts about this long when stepped plain: long against the clock's resolution, short against the drift
# of a shared machine.
BLOCK_TARGET_S = 0.01
MAX_BLOCK_FRAMES = 2000


@dataclass
class Cost:
    """One policy's cost on one scene, against plain ODE in the same benchmark run."""

    scene: str
    policy: str
    profile: str
    frames_per_block: int
    repeats: int
    ratio_median: float       # policy wall time / plain wall time, median over the repeats
    ratio_low: float          # the smallest and largest ratio over the repeats
    ratio_high: float
    us_per_frame: float       # the policy's median wall time per frame (µs)
    plain_us_per_frame: float # plain ODE's median wall time per frame (µs)
    steps_per_frame: float    # the policy's physics steps per frame in the benchmark
    status: str = "ok"        # "ok", or why the measurement stopped (a blow-up of either copy)


def _frames(profile: str, count: int, seed: int) -> np.ndarray:
    frames = np.asarray(frame_times(profile, count, seed), dtype=np.float64)
    return frames[:count]


def measure(scene: str, policy: str, profile: str = DEFAULT_PROFILE, repeats: int = DEFAULT_REPEATS,
            seed: int = 1, params: dict | None = None) -> Cost:
    """policy against plain ODE on scene under profile's frames: repeats pairs of interleaved blocks."""
    stepped = runs.Scene(scene, policy, params=params)
    plain = runs.Scene(scene, "naive", params=params)
    try:
        first = _frames(profile, 1, seed)
        stepped.frame(float(first[0]))
        plain.frame(float(first[0]))  # writes every softness once, as a program tunes it once
        # Calibrate: how many frames make a plain block of about BLOCK_TARGET_S.
        probe_frames = _frames(profile, 20, seed + 1)
        wall = plain.time_frames(probe_frames, plain=True)
        stepped.time_frames(probe_frames)
        per_frame = max(wall / len(probe_frames), 1e-7)
        block = int(min(MAX_BLOCK_FRAMES, max(5, BLOCK_TARGET_S / per_frame)))
        frames = _frames(profile, block * repeats, seed + 2)
        steps_before = stepped.counters()["steps"]
        ratios, policy_walls, plain_walls = [], [], []
        for r in range(repeats):
            chunk = frames[r * block:(r + 1) * block]
            if r % 2 == 0:
                a = stepped.time_frames(chunk)
                b = plain.time_frames(chunk, plain=True)
            else:
                b = plain.time_frames(chunk, plain=True)
                a = stepped.time_frames(chunk)
            ratios.append(a / b if b > 0 else math.inf)
            policy_walls.append(a / block)
            plain_walls.append(b / block)
        steps = stepped.counters()["steps"] - steps_before
        return Cost(scene, policy, profile, block, repeats, statistics.median(ratios), min(ratios), max(ratios),
                    1e6 * statistics.median(policy_walls), 1e6 * statistics.median(plain_walls),
                    steps / (block * repeats))
    except SteadystepError as error:
        return Cost(scene, policy, profile, 0, repeats, math.nan, math.nan, math.nan, math.nan, math.nan, math.nan,
                    f"{error.status}: {error.message}")
    finally:
        stepped.close()
        plain.close()


def measure_all(scenes, policies: dict, profile: str = DEFAULT_PROFILE, repeats: int = DEFAULT_REPEATS,
                params: dict | None = None, seed: int = 1) -> tuple[list[Cost], float]:
    """Every scene's policies (policies: scene -> names) against plain ODE; returns the costs and the benchmark's
    wall time (s). params: scene -> parameter changes."""
    started = time.perf_counter()
    costs = [measure(scene, policy, profile, repeats, seed, (params or {}).get(scene))
             for scene in scenes for policy in policies[scene]]
    return costs, time.perf_counter() - started

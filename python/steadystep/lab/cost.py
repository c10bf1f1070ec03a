"""What a policy costs: its stepping against plain ODE on the same scene, measured in one benchmark run.

For each scene and policy three copies of the scene step the same frame times (a profile's frames, by default
15-45 fps):
- through the library's stepper under the policy;
- as plain ODE at the stepper's own steps: one dWorldQuickStep per step the stepper takes, no library call in
  between (every softness as the stepper last wrote it). The ratio of the two is what the library itself costs;
- as a program without the library: one dWorldQuickStep of each whole frame, every softness as the naive policy
  wrote it at its first frame (tuned once for 30 fps), its per-step input given before each step as the stepper
  gives it (the stack's push, the piston's motor: ssScene_TimeFrames), so that it moves, and falls asleep, as the
  program does. The ratio to it is what a frame costs the program, substeps included.
The copies take the frames in blocks, the order of the three rotating from block to block so that all see the same
machine at the same moments; each ratio is taken per block, and the median and range over the blocks are reported
(as bench/bench_stepper.c does in C). A ratio counts only blocks that compare like with like: before and after the
block both of its copies had as many bodies awake (ssScene_AwakeBodies). In a scene with auto-disable (stack, wall)
a copy that fell asleep steps for almost nothing; against one that did not, its ratio would measure the sleep, not
the stepping. A ratio with no such block is not given (nan, ratio_blocks 0). The timing loop runs in C (ssScene_TimeFrames), so that Python's call overhead
is not measured, and times the thread's CPU (CLOCK_THREAD_CPUTIME_ID), so that other work on a shared machine does
not count; the page records the cores and the load beside it (report/html.py: machine_line).

What the copies step is fixed before any of them is timed, by plan(): the block's length (frames that take about
BLOCK_TARGET_S plain), the frames, and the stepper's steps over them, counted on a fourth, untimed copy that steps
the same frames (a third of the benchmark's stepping). Nothing in a plan is timed but the calibration, so a study
makes the plans in its sweep, wherever its executor runs them, and only the timing runs alone (report/tasks.py).
"""

from __future__ import annotations

import math
import statistics
from dataclasses import dataclass

import numpy as np

from steadystep.lab import runs
from steadystep.core._native import SteadystepError, lib
from steadystep.lab.profiles import frame_times

DEFAULT_PROFILE = "uniform:15:45"
DEFAULT_REPEATS = 7
# A block lasts about this long when stepped plain: long against the clock's resolution, short against the drift
# of a shared machine.
BLOCK_TARGET_S = 0.005
MAX_BLOCK_FRAMES = 2000
# The benchmark stops after one whole rotation of the three copies' order (MIN_REPEATS blocks) when both ratios'
# ranges over them lie within TIGHT_RANGE of their medians: a quiet machine, whose blocks agree to within that. The
# page calls two policies tied where their ranges overlap; a busy machine widens the ranges, and then every block of
# `repeats` is measured.
MIN_REPEATS = 3
TIGHT_RANGE = 0.02


@dataclass
class Cost:
    """One policy's cost on one scene, against plain ODE in the same benchmark run."""

    scene: str
    policy: str
    profile: str
    frames_per_block: int
    repeats: int              # the blocks measured (fewer than asked for when the ranges were tight: TIGHT_RANGE)
    ratio_median: float       # policy CPU time / the program's plain frames, median over the blocks
    ratio_low: float          # the smallest and largest of that ratio over the blocks
    ratio_high: float
    us_per_frame: float       # the policy's median CPU time per frame (µs, this thread's)
    plain_us_per_frame: float # the program's plain ODE, one step a frame: median CPU time per frame (µs)
    steps_per_frame: float    # the policy's physics steps per frame in the benchmark
    overhead_median: float = math.nan  # policy CPU time / plain ODE at the stepper's own steps, median
    overhead_low: float = math.nan     # the smallest and largest of that ratio over the blocks
    overhead_high: float = math.nan
    status: str = "ok"        # "ok", or why the measurement stopped (a blow-up of a copy)
    ratio_blocks: int = 0     # the blocks in ratio_*: those after which the policy's copy and the program's had as
                              # many bodies awake as before them (like with like: neither alone fell asleep)
    overhead_blocks: int = 0  # the blocks in overhead_*, by the same rule for the copy at the stepper's own steps


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


@dataclass
class Plan:
    """What a cost benchmark steps (plan()): its frames in blocks and the stepper's steps over them, or why there
    are none (status)."""

    scene: str
    policy: str
    profile: str
    seed: int
    params: dict | None
    frames_per_block: int
    repeats: int
    warmup_frames: np.ndarray  # stepped by every copy before the blocks (s each): one block's worth at most
    warmup_steps: np.ndarray   # the stepper's steps (s each) over them
    frames: np.ndarray        # frames_per_block * repeats frames (s each), block after block
    block_steps: list[np.ndarray]  # the stepper's steps (s each) over each block's frames
    status: str = "ok"        # "ok", or why the counting stopped (a blow-up)


def _first_frame(profile: str, seed: int) -> float:
    """The frame every copy steps first: it writes every softness, as a program tunes it once."""
    return float(frame_times(profile, 1, seed)[0])


def plan(scene: str, policy: str, profile: str = DEFAULT_PROFILE, repeats: int = DEFAULT_REPEATS, seed: int = 1,
         params: dict | None = None) -> Plan:
    """The benchmark's frames and the stepper's steps over them: a block is as many frames as take about
    BLOCK_TARGET_S when the program steps them plain (timed here, once, on a copy of its own), the steps are counted
    on an untimed copy that steps every frame the timed stepper will."""
    stepping = runs.make_stepping(policy)
    counter = runs.Scene(scene, policy, params=params)
    program = runs.Scene(scene, "naive", params=params)
    try:
        first = _first_frame(profile, seed)
        counter.frame(first)
        program.frame(first)
        calibration = frame_times(profile, 20, seed + 1)
        per_frame = max(program.time_frames(calibration, plain=True) / len(calibration), 1e-7)
        block = int(min(MAX_BLOCK_FRAMES, max(5, BLOCK_TARGET_S / per_frame)))
        warmup = calibration[:block]
        warmup_steps = _steps_of(counter, stepping, warmup)
        frames = frame_times(profile, block * repeats, seed + 2)
        block_steps = [_steps_of(counter, stepping, frames[r * block:(r + 1) * block]) for r in range(repeats)]
        return Plan(scene, policy, profile, seed, params, block, repeats, warmup, warmup_steps, frames, block_steps)
    except SteadystepError as error:
        nothing = np.empty(0)
        return Plan(scene, policy, profile, seed, params, 0, repeats, nothing, nothing, nothing, [],
                    status=f"{error.status}: {error.message}")
    finally:
        counter.close()
        program.close()


def measure(scene: str, policy: str, profile: str = DEFAULT_PROFILE, repeats: int = DEFAULT_REPEATS,
            seed: int = 1, params: dict | None = None) -> Cost:
    """policy against plain ODE on scene under profile's frames: up to repeats rounds of interleaved blocks
    (time_plan)."""
    return time_plan(plan(scene, policy, profile, repeats, seed, params))


def _tight(ratios: list[float], within: float) -> bool:
    middle = statistics.median(ratios)
    return math.isfinite(middle) and max(ratios) - min(ratios) <= within * middle


def _summary(ratios: list[float]) -> tuple[float, float, float]:
    """(median, smallest, largest) of the blocks' ratios; nan for none."""
    if not ratios:
        return math.nan, math.nan, math.nan
    return statistics.median(ratios), min(ratios), max(ratios)


def time_plan(planned: Plan, tight_range: float = TIGHT_RANGE) -> Cost:
    """The benchmark of a plan (made here or elsewhere): the policy and two plain copies of its scene step its
    blocks, each timed, the order of the three rotating; it stops after the first MIN_REPEATS blocks (a rotation)
    when both ratios' ranges over them lie within tight_range of their medians (0: every block of the plan)."""
    scene, policy, profile, repeats, seed, params = (planned.scene, planned.policy, planned.profile, planned.repeats,
                                                     planned.seed, planned.params)
    failed = Cost(scene, policy, profile, 0, repeats, math.nan, math.nan, math.nan, math.nan, math.nan, math.nan,
                  status=planned.status)
    if planned.status != "ok":
        return failed
    block = planned.frames_per_block
    stepped = runs.Scene(scene, policy, params=params)
    same_steps = runs.Scene(scene, policy, params=params)
    program = runs.Scene(scene, "naive", params=params)
    copies = (stepped, same_steps, program)
    try:
        first = _first_frame(profile, seed)
        for copy in copies:
            copy.frame(first)
        # A warm-up (caches, branch predictors), untimed; the plan's counter stepped it too: the same history.
        program.time_frames(planned.warmup_frames, plain=True)
        same_steps.time_frames(planned.warmup_steps, plain=True)
        stepped.time_frames(planned.warmup_frames)
        steps_before = stepped.counters()["steps"]
        cpu = {"policy": [], "same": [], "program": []}
        ratios, overheads = [], []
        awake = [copy.awake_bodies() for copy in copies]
        for r in range(repeats):
            chunk = planned.frames[r * block:(r + 1) * block]
            steps = planned.block_steps[r]
            timed = {"policy": lambda: stepped.time_frames(chunk),
                     "same": lambda: same_steps.time_frames(steps, plain=True),
                     "program": lambda: program.time_frames(chunk, plain=True)}
            order = list(timed)[r % 3:] + list(timed)[:r % 3]
            for name in order:
                cpu[name].append(timed[name]())
            before, awake = awake, [copy.awake_bodies() for copy in copies]
            if before[0] == before[2] and awake[0] == awake[2]:  # the policy's copy and the program's alike
                ratios.append(cpu["policy"][-1] / cpu["program"][-1] if cpu["program"][-1] > 0 else math.inf)
            if before[0] == before[1] and awake[0] == awake[1]:  # and the copy at the stepper's own steps
                overheads.append(cpu["policy"][-1] / cpu["same"][-1] if cpu["same"][-1] > 0 else math.inf)
            measured = r + 1
            if (measured == MIN_REPEATS and len(ratios) == len(overheads) == measured
                    and _tight(ratios, tight_range) and _tight(overheads, tight_range)):
                break  # checked once: more blocks only widen a range
        steps = stepped.counters()["steps"] - steps_before
        ratio, overhead = _summary(ratios), _summary(overheads)
        return Cost(scene, policy, profile, block, measured, *ratio, 1e6 * statistics.median(cpu["policy"]) / block,
                    1e6 * statistics.median(cpu["program"]) / block, steps / (block * measured), *overhead,
                    ratio_blocks=len(ratios), overhead_blocks=len(overheads))
    except SteadystepError as error:
        failed.status = f"{error.status}: {error.message}"
        return failed
    finally:
        for copy in copies:
            copy.close()

"""The report's cost benchmark in two parts, on real ODE: its plan (frames, the stepper's steps, counted untimed)
made anywhere, in a process pool's worker as in the report's sweep, and its timing here; the timed stepper takes
exactly the steps the plan counted, and the timing stops early only at the end of a rotation of the copies."""

import math

import pytest

from steadystep.lab import cost, study


@pytest.mark.parametrize("scene, policy", [("chain", "implicit-euler"), ("drop", "fixed")])
def test_a_plan_made_in_a_worker_is_what_the_timed_stepper_steps(scene, policy):
    with study.make_executor("local") as pool:
        planned = pool.submit(cost.plan, scene, policy, repeats=3).result()
    assert planned.status == "ok" and len(planned.block_steps) == 3
    assert len(planned.frames) == 3 * planned.frames_per_block
    for r, steps in enumerate(planned.block_steps):  # every step within its block's frames, none longer than the cap
        frames = planned.frames[r * planned.frames_per_block:(r + 1) * planned.frames_per_block]
        assert 0 < steps.max() <= 1 / 60 * (1 + 1e-12)
        assert abs(steps.sum() - frames.sum()) < 1 / 60
    measured = cost.time_plan(planned, tight_range=0.0)
    assert measured.status == "ok" and measured.repeats == 3
    # The timed stepper counted its own steps (ssScene_Counters): as many as the plan's untimed copy.
    counted = sum(len(steps) for steps in planned.block_steps)
    assert measured.steps_per_frame * 3 * planned.frames_per_block == pytest.approx(counted, rel=1e-12)
    assert measured.ratio_low <= measured.ratio_median <= measured.ratio_high


@pytest.mark.parametrize("repeats, tight_range, blocks", [(7, math.inf, 3), (4, math.inf, 3), (7, 0.0, 7),
                                                          (2, math.inf, 2)])
def test_the_timing_stops_early_only_after_a_whole_rotation_whose_ranges_are_tight(repeats, tight_range, blocks):
    """A range always within inf of its median stops after the first rotation (3 blocks, one per position of each
    copy); within 0 (blocks that never time alike) never; a plan shorter than a rotation is measured whole."""
    planned = cost.plan("oscillator", "matched", repeats=repeats)
    measured = cost.time_plan(planned, tight_range=tight_range)
    assert measured.status == "ok" and measured.repeats == blocks
    # steps_per_frame is over the blocks measured: the substeps of a 15-45 fps frame at 1/60 s, 2 to 4.
    assert 2 <= measured.steps_per_frame <= 4


def test_measure_is_its_plan_timed():
    measured = cost.measure("buggy", "naive", repeats=3)
    assert measured.status == "ok" and measured.repeats == 3 and measured.steps_per_frame == 1.0


def test_a_ratio_counts_only_the_blocks_whose_copies_sleep_alike():
    """Issue 28: the stack's plain copy, not pushed, fell asleep while the library's did not ("library ×77"). Now the
    plain copies are pushed as the stepper pushes, and a block counts only when both copies of a ratio have as many
    bodies awake before and after it: under fixed 1/60 s steps the stack falls asleep after its push (3 s), the
    program's whole 15-45 fps frames keep four of its boxes awake, so the later blocks of that ratio are left out;
    the copy at the stepper's own steps sleeps with it, so every block of that ratio counts. The chain has nothing
    to fall asleep: every block counts."""
    stack = cost.time_plan(cost.plan("stack", "fixed", repeats=7), tight_range=0.0)
    assert stack.status == "ok" and stack.repeats == 7
    assert stack.ratio_blocks < 7 and stack.overhead_blocks == 7
    if stack.ratio_blocks:  # how many of the first blocks the program's copy kept all six awake: the machine's speed
        assert stack.ratio_low <= stack.ratio_median <= stack.ratio_high
    else:
        assert math.isnan(stack.ratio_median)  # no block like with like: no ratio, rather than a wrong one
    chain = cost.time_plan(cost.plan("chain", "fixed", repeats=3), tight_range=0.0)
    assert chain.ratio_blocks == chain.overhead_blocks == 3

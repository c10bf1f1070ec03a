"""What the report reads from the lab besides the followed quantities: the stepper's counters, the chain's drawing,
and frames timed plain or through the stepper (ssScene_Counters, ssScene_Points, ssScene_TimeFrames)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from steadystep.lab import cost, runs
from steadystep.core._native import SteadystepError
from steadystep.lab.profiles import frame_times


def test_run_counters_count_the_recorded_steps_and_frames():
    for policy in runs.policy_names():
        result = runs.run("chain", "uniform:15:45", policy, 1.0, seed=4)
        assert result.counters["steps"] == result.step_count, policy
        assert result.counters["frames"] == result.frame_count, policy
        if policy in ("naive", "implicit-euler", "fixed"):
            assert result.counters["rows"]["handed_to_implicit_euler"] == 0, policy
        # every bound row is counted once a step, by whoever served it: the same number of rows every step
        row_steps = sum(result.counters["rows"].values())
        assert row_steps > 0 and row_steps % result.step_count == 0, policy


def test_the_chain_is_drawn_as_links_of_its_length_hanging_from_the_pivot():
    scene = runs.Scene("chain", "implicit-euler", params={"body_count": 5})
    try:
        start = scene.points()
        assert start.shape == (6, 3)
        assert np.allclose(start[0], [0.0, 0.0, 2.5], atol=1e-9)  # the pivot, at the chain's start
        lowest_tip_z = start[-1, 2]
        for _ in range(60):
            scene.frame(1 / 30)
            lowest_tip_z = min(lowest_tip_z, scene.points()[-1, 2])
        moved = scene.points()
        links = np.linalg.norm(np.diff(moved, axis=0), axis=1)
        assert np.allclose(links, 0.25, rtol=1e-2), links  # rigid links of 0.25 m, the joints' error small
        assert np.allclose(moved[0], [0.0, 0.0, 2.5], atol=1e-3)  # still pinned
        assert lowest_tip_z < start[-1, 2] - 0.5  # it swung down
    finally:
        scene.close()
    oscillator = runs.Scene("oscillator")
    assert oscillator.points().shape == (0, 3)
    oscillator.close()


@pytest.mark.parametrize("scene", ["oscillator", "stack", "piston"])
def test_plain_frames_are_naive_frames_without_the_stepper(scene):
    # naive writes the same softness (frozen at its tuned step) before each whole-frame step: stepping the world plain
    # after its first frame must give the same motion, the per-step input included (issue 28: the stack's plain copy
    # was not pushed, nor the piston's motor reversed, so the cost benchmark compared a pushed tower with one asleep).
    frames = frame_times("uniform:15:45", 200, 7)  # 6 s: the stack's push (3 s), the piston's reversals
    stepped, plain = runs.Scene(scene, "naive"), runs.Scene(scene, "naive")
    try:
        stepped.frame(frames[0])
        plain.frame(frames[0])
        stepped.time_frames(frames[1:])
        plain.time_frames(frames[1:], plain=True)
        assert stepped.time_s == pytest.approx(plain.time_s, rel=1e-12)
        for name, value in stepped.sample().items():
            assert plain.sample()[name] == pytest.approx(value, rel=1e-9, abs=1e-12), name
        assert plain.counters()["frames"] == 1 and stepped.counters()["frames"] == len(frames)
        assert plain.awake_bodies() == stepped.awake_bodies()
    finally:
        stepped.close()
        plain.close()


def test_awake_bodies_counts_what_auto_disable_put_to_sleep():
    """The stack (auto-disable tuned at 1/60 s) falls asleep under fixed 1/60 s steps once its push stops at 3 s;
    the buggy (no auto-disable: a chassis, four wheels, each with geoms) never does; every body counted once, those
    without a geom not at all (the chain's links are reached by no geom)."""
    frames = frame_times("fixed:30", 300, 1)  # 10 s
    stack, chain = runs.Scene("stack", "fixed"), runs.Scene("buggy", "fixed")
    try:
        assert stack.awake_bodies() == 6 and chain.awake_bodies() == 5
        unseen = runs.Scene("chain", "fixed")
        assert unseen.awake_bodies() == 0
        unseen.close()
        for frame_s in frames[:60]:  # 2 s: pushed, awake
            stack.frame(frame_s)
        assert stack.awake_bodies() == 6
        stack.time_frames(frames[60:])
        chain.time_frames(frames)
        assert stack.awake_bodies() == 0 and chain.awake_bodies() == 5
    finally:
        stack.close()
        chain.close()


def test_timed_frames_are_the_threads_cpu_time():
    """ssScene_TimeFrames times the thread's CPU (issue 28: timings on a shared machine are CPU time): never more
    than this thread's CPU time around the call, and most of it."""
    import time

    scene = runs.Scene("chain", "implicit-euler")
    try:
        scene.frame(1 / 30)
        frames = frame_times("uniform:15:45", 400, 3)
        before = time.thread_time()
        measured = scene.time_frames(frames)
        around = time.thread_time() - before
        assert 0.5 * around <= measured <= around + 1e-4, (measured, around)
    finally:
        scene.close()


def test_plain_frames_are_refused_before_the_first_frame_and_out_of_range():
    scene = runs.Scene("oscillator", "naive")
    try:
        with pytest.raises(SteadystepError, match="plain = 1"):
            scene.time_frames([1 / 60], plain=True)
        scene.frame(1 / 60)
        with pytest.raises(SteadystepError, match=r"frames_s\[1\] = -1"):
            scene.time_frames([1 / 60, -1.0], plain=True)
        assert scene.counters()["frames"] == 1 and scene.time_s == pytest.approx(1 / 60)  # nothing stepped
    finally:
        scene.close()


@pytest.mark.parametrize("scene, policy", [("chain", "implicit-euler"), ("buggy", "matched")])
def test_a_cost_is_two_ratios_in_their_ranges(scene, policy):
    """Per frame against the program's own loop, and the library against plain ODE at the same steps."""
    measured = cost.measure(scene, policy, repeats=3)
    assert measured.status == "ok"
    assert measured.ratio_low <= measured.ratio_median <= measured.ratio_high
    assert measured.overhead_low <= measured.overhead_median <= measured.overhead_high
    assert 0 < measured.overhead_median < math.inf
    assert measured.steps_per_frame > 1.5  # 15-45 fps frames in substeps of at most 1/60 s


@pytest.mark.parametrize("policy", ["naive", "implicit-euler", "exact", "fixed"])
def test_plain_ode_at_the_same_steps_takes_the_steppers_own_steps(policy):
    """The cost's plain copy steps what the stepper stepped: as many steps, as long in all, none above the cap."""
    stepping = runs.make_stepping(policy)
    counter = runs.Scene("chain", policy)
    try:
        frames = frame_times("uniform:15:45", 60, 3)
        steps = cost._steps_of(counter, stepping, frames)
        assert len(steps) == counter.counters()["steps"]
        assert steps.sum() == pytest.approx(counter.time_s, rel=1e-12)
        if policy != "naive":
            assert steps.max() <= stepping["max_step_s"] * (1 + 1e-12)
    finally:
        counter.close()



def test_timed_frames_leave_the_labs_bounds_unchecked_and_frames_check_them_again():
    """A program pays for the stepper, not for the lab's sanity bounds: ssScene_TimeFrames skips them."""
    scene = runs.Scene("chain", "naive")
    try:
        scene.time_frames([2.0])  # tears the chain, as one 2 s frame does (test_cli's broken run)
        assert scene.broken is None and scene.bound_use == 0
        scene.frame(2.0)
        assert scene.broken is not None and "hinge" in scene.broken and scene.bound_use > 1
    finally:
        scene.close()


# The scenes written as ODE programs (scene.h) soften their contacts through the stepper, tuned at 1/60 s: the
# counters count every contact, and implicit Euler never hands one on. Their columns carry their units.
@pytest.mark.parametrize("scene, columns", [
    ("stack", ["top_x_m", "top_z_m", "kinetic_energy_J"]),
    ("wall", ["wall_mean_displacement_m", "ball_x_m", "ball_z_m"]),
    ("piston", ["ram_x_m", "ram_v_m_per_s", "arm_angle_rad"]),
])
def test_program_scenes_are_listed_with_their_units_and_count_their_contacts(scene, columns):
    info = runs.scene_info(scene)
    assert [runs.column_name(q, u) for q, u in zip(info.quantities, info.units)] == columns
    assert runs.motion_quantities(scene) == list(info.quantities)
    result = runs.run(scene, "uniform:15:45", "implicit-euler", 1.0, seed=2)
    assert result.status == "ok"
    contacts = result.counters["contacts"]
    assert contacts["handed_to_implicit_euler"] == contacts["handed_to_matched"] == 0
    if scene == "piston":
        assert contacts["by_mapping"] == 0  # a mechanism in the air: nothing touches
    else:
        # every step makes contacts: the tower's boxes on each other, the wall's bricks (276 standing)
        assert contacts["by_mapping"] >= (4 if scene == "stack" else 200) * result.step_count


def test_the_drawn_points_are_the_interpolated_poses():
    """Under fixed, frames of exactly one step end with interpolation 0: the pose drawn is the one before the frame's
    step, so the drawing after frame n is ODE's after frame n - 1. Under the other cuts it is ODE's own."""
    step_s = runs.make_stepping("fixed")["fixed_step_s"]
    scene = runs.Scene("chain", "fixed")
    try:
        before = scene.points()
        for _ in range(5):
            scene.frame(step_s)
            np.testing.assert_allclose(scene.points(interpolated=True), before, rtol=0, atol=1e-9)
            before = scene.points()
        assert not np.allclose(scene.points(interpolated=True), scene.points())  # it moved: the test can fail
    finally:
        scene.close()
    scene = runs.Scene("chain", "implicit-euler")
    try:
        scene.frame(0.025)
        np.testing.assert_array_equal(scene.points(interpolated=True), scene.points())
    finally:
        scene.close()

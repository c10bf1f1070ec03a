"""Runs on real ODE through scene.h: records copied out whole, the reference run, the Python frame loop equal to
the C one, and the report's claim that the article's method cuts the spread across frame-time profiles."""

import math

import numpy as np
import pytest

from steadystep import SteadystepError, report, runs
from steadystep.profiles import Profile


def test_scenes_and_policies_come_from_the_library():
    names = [info.name for info in runs.scenes()]
    assert {"oscillator", "buggy", "drop", "chain", "pile"} <= set(names)
    assert runs.scene_info("oscillator").quantities == ("x", "v", "erp", "cfm")
    assert runs.policy_names() == ["naive", "implicit-euler", "matched", "exact", "fixed", "fixed-matched",
                                   "fixed-exact"]
    assert runs.default_params("oscillator")["spring"] == {"stiffness": 40.0, "damping": 1.0}


def test_run_records_every_step_as_numpy_arrays():
    result = runs.run("oscillator", "uniform:15:45", "implicit-euler", duration_s=2.0, seed=5)
    assert result.status == "ok" and not result.blew_up
    assert result.step_count == len(result.step_lengths) == len(result.quantities["x"])
    assert np.all(result.step_lengths > 0) and np.all(result.step_lengths <= 1 / 60 + 1e-12)
    assert np.allclose(np.cumsum(result.step_lengths), result.times, rtol=0, atol=1e-12)
    assert result.simulated_s >= 2.0 - 1e-9
    assert 1.0 < result.step_count / result.frame_count <= 4.0
    # The article's mapping at each step's h, read back from ODE's joint: erp = hk/(hk+c).
    h = result.step_lengths
    assert np.allclose(result.quantities["erp"], h * 40.0 / (h * 40.0 + 1.0), rtol=1e-12)


def test_same_seed_same_run_other_seed_another():
    a = runs.run("oscillator", "uniform:15:45", "implicit-euler", 1.0, seed=3)
    b = runs.run("oscillator", "uniform:15:45", "implicit-euler", 1.0, seed=3)
    c = runs.run("oscillator", "uniform:15:45", "implicit-euler", 1.0, seed=4)
    assert np.array_equal(a.quantities["x"], b.quantities["x"])
    assert not np.array_equal(a.times, c.times)


def test_reference_run_steps_at_a_millisecond():
    reference = runs.reference_run("oscillator", duration_s=0.5)
    assert np.allclose(reference.step_lengths, 1e-3, rtol=1e-12)
    assert reference.step_count == pytest.approx(500, abs=1)


def test_python_frame_loop_matches_the_c_run():
    c_run = runs.run("oscillator", "uniform:15:45", "implicit-euler", 1.0, seed=11, stepping={"max_step_s": 1 / 15})
    scene = runs.Scene("oscillator", "implicit-euler", stepping={"max_step_s": 1 / 15})
    profile = Profile("uniform:15:45", seed=11)
    xs = []
    elapsed_s = 0.0
    while elapsed_s < 1.0:
        frame_s = min(profile.next(), 1.0 - elapsed_s)  # the run cuts its last frame at the duration
        assert scene.frame(frame_s) == 1
        elapsed_s += frame_s
        xs.append(scene.sample()["x"])
    scene.close()
    assert np.array_equal(np.array(xs), c_run.quantities["x"][: len(xs)])
    assert len(xs) == c_run.step_count


def test_bad_run_input_is_refused():
    with pytest.raises(SteadystepError, match="nosuch"):
        runs.run("nosuch", "fixed:30", "implicit-euler", 1.0)
    with pytest.raises(SteadystepError, match="mass"):
        runs.run("oscillator", "fixed:30", "implicit-euler", 1.0, params={"mass": -1.0})
    with pytest.raises(SteadystepError, match="colour"):
        runs.run("oscillator", "fixed:30", "implicit-euler", 1.0, params={"colour": 1})
    with pytest.raises(SteadystepError) as error:
        runs.run("oscillator", "fixed:30", "implicit-euler", 0.0)
    assert error.value.status == "out of range"
    with pytest.raises(SteadystepError, match="bogus"):
        runs.run("oscillator", "fixed:30", "bogus", 1.0)


def test_spring_halves_the_spread_of_naive_in_every_soft_scene():
    soft_scenes = ["oscillator", "buggy", "drop", "chain"]
    result = report.compare(soft_scenes, ["fixed:30", "uniform:15:45", "hitch:60:30:0.1", "vsync:60:30"],
                            ["naive", "implicit-euler"], duration_s=2.0, seed=1, progress=False)
    for scene in soft_scenes:
        for quantity in runs.motion_quantities(scene):
            naive = result.spreads[scene]["naive"][quantity]
            spring = result.spreads[scene]["implicit-euler"][quantity]
            assert math.isfinite(spring), (scene, quantity)
            assert spring <= 0.5 * naive, (scene, quantity, spring, naive)

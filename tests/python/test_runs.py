"""Runs on real ODE through scene.h: records copied out whole, the reference run, the Python frame loop equal to
the C one, and the report's claim that the article's method cuts the spread across frame-time profiles."""

import math

import numpy as np
import pytest

from steadystep import SteadystepError, report
from steadystep.lab import runs
from steadystep.lab.profiles import Profile
from steadystep.report.aggregate import deviation


def test_scenes_and_policies_come_from_the_library():
    names = [info.name for info in runs.scenes()]
    assert {"oscillator", "buggy", "drop", "chain", "pile"} <= set(names)
    assert runs.scene_info("oscillator").quantities == ("x", "v", "erp", "cfm")
    assert runs.policy_names() == ["naive", "substeps-frozen", "implicit-euler", "matched", "exact", "fixed", "fixed-matched",
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


def test_implicit_euler_halves_the_spread_of_naive_in_every_soft_scene():
    soft_scenes = ["oscillator", "buggy", "drop", "chain"]
    result = report.compare(soft_scenes, ["fixed:30", "uniform:15:45", "hitch:60:30:0.1", "vsync:60:30"],
                            ["naive", "implicit-euler"], duration_s=2.0, seed=1, progress=False)
    for scene in soft_scenes:
        for quantity in runs.motion_quantities(scene):
            naive = result.spreads[scene]["naive"][quantity]
            spring = result.spreads[scene]["implicit-euler"][quantity]
            assert math.isfinite(spring), (scene, quantity)
            assert spring <= 0.5 * naive, (scene, quantity, spring, naive)
    # An infinite naive spread is a naive run that broke (the report counts it as failed), never one that blew up;
    # the article's method runs every one of them to the end within the scenes' sanity bounds.
    statuses = {(row.scene, row.profile, row.policy): row.status for row in result.rows}
    assert all(status == "ok" for (_, _, policy), status in statuses.items() if policy == "implicit-euler"), statuses
    assert all(status in ("ok", "broken") for status in statuses.values()), statuses
    for scene in soft_scenes:
        naive_failed = any(statuses[scene, profile, "naive"] != "ok" for profile in result.profiles)
        for quantity in runs.motion_quantities(scene):
            assert math.isinf(result.spreads[scene]["naive"][quantity]) == naive_failed, (scene, statuses)
    assert statuses["chain", "fixed:30", "naive"] == "broken"  # a hinge torn 0.065 m open (test_bounds.cpp)


def test_statuses_say_how_a_run_ended():
    # Broken: 2 s frames tear the naive chain apart in its first step; finite, physically wrong, failed.
    broken = runs.run("chain", "fixed:0.5", "naive", 5.0)
    assert broken.status == "broken" and broken.broken and broken.failed and not broken.blew_up
    assert broken.message.startswith("t = 2 s: chain hinge ") and "apart, bound 0.05 m" in broken.message
    assert broken.step_count == 1 and broken.bound_use > 1
    assert all(np.all(np.isfinite(values)) for values in broken.quantities.values())
    # Blown up: gravity of 1e3 m/s^2 along the slider swings the body past the 100 m/s limit (test_scenes.cpp).
    blown = runs.run("oscillator", "fixed:60", "implicit-euler", 5.0, params={"gravity": 1e3})
    assert blown.status == "speed limit" and blown.blew_up and blown.failed and not blown.broken
    ok = runs.run("chain", "fixed:30", "implicit-euler", 1.0)
    assert ok.status == "ok" and not (ok.failed or ok.blew_up or ok.broken) and ok.message == ""
    assert 0 < ok.bound_use < 1
    # The report measures neither: a failed run's deviation is infinite, however close its records were.
    reference = runs.reference_run("chain", 1.0)
    assert math.isinf(deviation(broken, reference, "end x"))
    assert math.isfinite(deviation(ok, reference, "end x"))


def test_trajectory_starts_at_t0_with_unit_columns():
    result = runs.run("oscillator", "fixed:30", "implicit-euler", 0.2, params={"x0": 0.25})
    table = result.trajectory()
    assert list(table) == ["t_s", "x_m", "v_m_per_s", "erp", "cfm_m_per_N_s"]
    assert all(len(column) == result.step_count + 1 for column in table.values())
    assert table["t_s"][0] == 0.0 and table["x_m"][0] == 0.25 and table["v_m_per_s"][0] == 0.0
    assert result.initial["x"] == 0.25
    assert np.array_equal(table["t_s"][1:], result.times) and np.array_equal(table["x_m"][1:], result.quantities["x"])
    # The records stay one per step: the report's metrics and the probe read them as before.
    assert np.all(result.step_lengths > 0) and result.step_count == len(result.times)
    assert runs.column_name("chassis pitch", "rad") == "chassis_pitch_rad"
    assert runs.column_name("erp", "") == "erp"


def test_scene_reports_its_first_violation_and_steps_on():
    scene = runs.Scene("chain", "naive")
    scene.frame(1 / 60)
    assert scene.broken is None and 0 < scene.bound_use < 1
    scene.frame(2.0)  # leaving a bound is no error
    first = scene.broken
    assert first is not None and first.startswith("t = 2.01666667 s: chain hinge ")
    # The next step pulls the torn hinge together at over 100 m/s: a blow-up, reported as one; the violation that
    # came first stays the scene's.
    with pytest.raises(SteadystepError, match="speed"):
        scene.frame(1 / 60)
    assert scene.broken == first and scene.bound_use > 1
    scene.close()

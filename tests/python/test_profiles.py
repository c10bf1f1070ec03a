"""Frame-time profiles through the C library: seeded, with the promised means and bounds, traces good and bad."""

import numpy as np
import pytest

from steadystep import SteadystepError
from steadystep.lab.profiles import Profile, frame_times


def test_same_seed_same_frames_other_seed_others():
    for spec in ("uniform:15:45", "jitter:30:3", "vsync:60:30"):
        assert np.array_equal(frame_times(spec, 500, seed=3), frame_times(spec, 500, seed=3))
        assert not np.array_equal(frame_times(spec, 500, seed=3), frame_times(spec, 500, seed=4))


def test_reset_restarts_the_sequence():
    profile = Profile("uniform:15:45", seed=9)
    first = profile.frames(50)
    profile.reset()
    assert np.array_equal(profile.frames(50), first)


def test_means_and_bounds():
    assert np.all(frame_times("fixed:30", 100) == 1 / 30)
    uniform = frame_times("uniform:15:45", 20000)
    assert uniform.min() >= 1 / 45 and uniform.max() <= 1 / 15
    assert uniform.mean() == pytest.approx((1 / 15 + 1 / 45) / 2, rel=0.01)
    jitter = frame_times("jitter:30:3", 20000)
    assert jitter.mean() == pytest.approx(1 / 30, rel=0.01)
    assert np.all(np.abs(jitter - 1 / 30) <= 0.009 + 1e-12)
    hitch = frame_times("hitch:60:30:0.1", 90)
    assert np.count_nonzero(hitch == 0.1) == 3 and np.count_nonzero(hitch == 1 / 60) == 87
    vsync = frame_times("vsync:60:30", 2000)
    assert set(np.unique(vsync)) == {1 / 60, 1 / 30}


def test_trace_file_repeats(tmp_path):
    trace = tmp_path / "frames.txt"
    trace.write_text("# recorded\n0.016\n\n0.033\n0.05\n")
    assert frame_times(f"trace:{trace}", 7) == pytest.approx([0.016, 0.033, 0.05, 0.016, 0.033, 0.05, 0.016])


def test_malformed_trace_names_the_line(tmp_path):
    trace = tmp_path / "bad.txt"
    trace.write_text("0.016\n0.033\nfast\n")
    with pytest.raises(SteadystepError) as error:
        Profile(f"trace:{trace}")
    assert error.value.status == "parse error"
    assert "line 3" in error.value.message and "fast" in error.value.message


@pytest.mark.parametrize("spec, status", [
    ("warp:30", "parse error"), ("fixed:", "parse error"), ("fixed:-30", "out of range"),
    ("uniform:45:15", "out of range"), ("fixed:nan", "not finite"), ("trace:/no/such/file", "i/o error"),
])
def test_bad_specs_are_refused(spec, status):
    with pytest.raises(SteadystepError) as error:
        Profile(spec)
    assert error.value.status == status
    assert error.value.message

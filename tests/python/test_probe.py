"""The largest-stable-step probe on real ODE: its bracket is tight and honest, and bad input is refused."""

import math

import pytest

from steadystep import SteadystepError
from steadystep.lab import probe, runs


def test_the_bracket_is_tight_and_the_stable_side_is_stable():
    found = probe.largest_stable_step("buggy", "naive", duration_s=2.0)
    assert 0.001 < found.stable_s < found.unstable_s <= found.stable_s * 1.02
    assert found.reason  # why the unstable side failed
    at_stable = runs.run("buggy", f"fixed:{1 / found.stable_s!r}", "naive", 2.0,
                         stepping={"max_step_s": found.stable_s, "fixed_step_s": found.stable_s})
    assert not at_stable.blew_up


def test_implicit_euler_keeps_the_lone_spring_stable_at_every_step():
    found = probe.largest_stable_step("oscillator", "implicit-euler", duration_s=2.0)
    assert found.stable_s == probe.DEFAULT_HIGH_S and math.isinf(found.unstable_s) and found.trials == 1


@pytest.mark.parametrize("scene, policy, kwargs", [
    ("nosuch", "implicit-euler", {}),
    ("chain", "sideways", {}),
    ("chain", "implicit-euler", {"low_s": 0.2, "high_s": 0.1}),
    ("chain", "implicit-euler", {"duration_s": float("nan")}),
    ("chain", "implicit-euler", {"tolerance": 0}),
])
def test_bad_input_is_refused(scene, policy, kwargs):
    with pytest.raises(SteadystepError):
        probe.largest_stable_step(scene, policy, **kwargs)

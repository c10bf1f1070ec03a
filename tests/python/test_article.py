"""The article's model (equations 4 and 5) against steps worked by hand, and the exact solution against its own
differential equation m x'' + c x' + k x = 0."""

import math

import numpy as np
import pytest

from steadystep import SteadystepError
from steadystep.lab.article import Oscillator, exact, exact_parameters, integrate

OSC = Oscillator(mass=1.0, stiffness=40.0, damping=1.0)


def test_equations_4_and_5_fixed_step_by_hand():
    # h = 0.1: x1 = 0.5 (1 - 40/2 · 0.01) = 0.4, v1 = -40 · 0.5 · 0.1 = -2;
    # x2 = 0.4 · 0.8 + (-2)(1 - 0.05) · 0.1 = 0.13, v2 = -2 (1 - 0.1) - 40 · 0.4 · 0.1 = -3.4.
    t, x, v = integrate(OSC, 0.5, 0.0, [0.1, 0.1])
    assert t == pytest.approx([0.0, 0.1, 0.2], abs=1e-15)
    assert x == pytest.approx([0.5, 0.4, 0.13], abs=1e-14)
    assert v == pytest.approx([0.0, -2.0, -3.4], abs=1e-14)


def test_equations_4_and_5_variable_step_by_hand():
    # h1 = 0.1 as above, then h2 = 0.05: x2 = 0.4 (1 - 20 · 0.0025) + (-2)(1 - 0.025) · 0.05 = 0.2825,
    # v2 = -2 (1 - 0.05) - 40 · 0.4 · 0.05 = -2.7.
    t, x, v = integrate(OSC, 0.5, 0.0, [0.1, 0.05])
    assert t[-1] == pytest.approx(0.15, abs=1e-15)
    assert x[-1] == pytest.approx(0.2825, abs=1e-14)
    assert v[-1] == pytest.approx(-2.7, abs=1e-14)


def test_implicit_euler_step_by_hand():
    # v1 = (m v0 - h k x0) / (m + h c + h² k) = (0 - 2) / 1.5, x1 = x0 + h v1.
    _, x, v = integrate(OSC, 0.5, 0.0, [0.1], method="implicit")
    assert v[1] == pytest.approx(-4.0 / 3.0, abs=1e-14)
    assert x[1] == pytest.approx(0.5 - 0.4 / 3.0, abs=1e-14)


def test_exact_solution_meets_initial_state():
    for x0, v0 in ((0.5, 0.0), (-0.2, 1.5), (0.0, -0.7)):
        x, v = exact(OSC, x0, v0, [0.0])
        assert x[0] == pytest.approx(x0, abs=1e-15)
        assert v[0] == pytest.approx(v0, abs=1e-14)


def test_exact_solution_solves_its_differential_equation():
    dt = 1e-4
    t = np.linspace(0.0, 5.0, 401)
    x, v = exact(OSC, 0.5, 0.3, t)
    x_before, _ = exact(OSC, 0.5, 0.3, t - dt)
    x_after, _ = exact(OSC, 0.5, 0.3, t + dt)
    velocity = (x_after - x_before) / (2 * dt)
    acceleration = (x_after - 2 * x + x_before) / dt**2
    residual = OSC.mass * acceleration + OSC.damping * velocity + OSC.stiffness * x
    # Central differences: O(dt²) truncation (~1e-6 here) plus rounding of about 1e-16/dt² · |x|.
    assert np.max(np.abs(residual)) < 1e-4
    assert np.max(np.abs(velocity - v)) < 1e-6


def test_exact_parameters_are_the_articles_c_and_alpha():
    amplitude, alpha = exact_parameters(OSC, 0.5, 0.0)
    w, gamma = OSC.angular_frequency, OSC.decay_rate
    assert amplitude * math.sin(alpha) == pytest.approx(0.5, abs=1e-15)
    assert amplitude * (w * math.cos(alpha) - gamma * math.sin(alpha)) == pytest.approx(0.0, abs=1e-14)


def test_bad_inputs_are_refused_naming_the_value():
    with pytest.raises(SteadystepError, match="mass"):
        integrate(Oscillator(0.0, 40.0, 1.0), 0.5, 0.0, [0.1])
    with pytest.raises(SteadystepError, match="steps_s"):
        integrate(OSC, 0.5, 0.0, [0.1, -0.1])
    with pytest.raises(SteadystepError, match="damping ratio"):
        exact(Oscillator(1.0, 1.0, 3.0), 0.5, 0.0, [0.0])
    with pytest.raises(SteadystepError, match="method"):
        integrate(OSC, 0.5, 0.0, [0.1], method="rk4")

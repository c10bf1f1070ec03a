"""Metrics: the oscillation fit recovers decay and frequency from clean data, deviations behave as defined."""

import math

import numpy as np
import pytest

from steadystep import SteadystepError
from steadystep.lab.article import Oscillator, exact, integrate
from steadystep.lab.metrics import fit_oscillation, rms_deviation, rms_vs_exact, spread, steps_per_frame

OSC = Oscillator(mass=1.0, stiffness=40.0, damping=1.0)


def test_fit_recovers_exact_decay_and_frequency_on_uniform_and_irregular_times():
    rng = np.random.default_rng(2)
    for t in (np.linspace(0, 5, 151), np.cumsum(rng.uniform(1 / 45, 1 / 15, 110))):
        x, _ = exact(OSC, 0.5, 0.2, t)
        decay, omega = fit_oscillation(t, x)
        assert decay == pytest.approx(OSC.decay_rate, rel=1e-4)
        assert omega == pytest.approx(OSC.angular_frequency, rel=1e-4)


def test_fit_recovers_the_poles_of_implicit_euler():
    # At a fixed h, implicit Euler's samples are exactly z^n of its discrete poles: decay -ln|z|/h, arg(z)/h.
    h, m, k, c = 1 / 30, OSC.mass, OSC.stiffness, OSC.damping
    d = m + h * c + h * h * k
    step = np.array([[1 - h * h * k / d, h * m / d], [-h * k / d, m / d]])
    z = np.linalg.eigvals(step)[0]
    t, x, _ = integrate(OSC, 0.5, 0.0, np.full(150, h), method="implicit")
    decay, omega = fit_oscillation(t, x)
    assert decay == pytest.approx(-math.log(abs(z)) / h, rel=1e-6)
    assert omega == pytest.approx(abs(np.angle(z)) / h, rel=1e-6)
    assert decay > 2 * OSC.decay_rate  # implicit Euler's numerical damping, as issue 4 measured on ODE


def test_fit_refuses_what_does_not_oscillate():
    t = np.linspace(0, 5, 100)
    with pytest.raises(SteadystepError):
        fit_oscillation(t, np.exp(-t))
    with pytest.raises(SteadystepError):
        fit_oscillation(t[:5], t[:5])


def test_rms_deviation_is_relative_to_the_reference_amplitude():
    reference_t = np.linspace(0, 1, 1001)
    reference_y = np.sin(2 * np.pi * reference_t)  # amplitude max - min = 2
    t = np.linspace(0, 1, 31)
    assert rms_deviation(t, np.sin(2 * np.pi * t), reference_t, reference_y) < 1e-5
    assert rms_deviation(t, np.sin(2 * np.pi * t) + 0.1, reference_t, reference_y) == pytest.approx(0.05, rel=1e-3)
    assert rms_deviation(t, np.full(31, math.nan), reference_t, reference_y) == math.inf


def test_rms_vs_exact_spread_and_step_counts():
    assert rms_vs_exact([0.5, 0.1], [0.4, 0.2], 0.5) == pytest.approx(0.2)
    assert rms_vs_exact([math.inf], [0.0], 0.5) == math.inf
    assert spread([0.3, 0.4]) == pytest.approx(math.sqrt(0.125))
    assert steps_per_frame(300, 150) == 2.0
    with pytest.raises(SteadystepError):
        spread([])

"""The Python conversions are the C ones: compared with direct calls into libsteadystep, with the article's
formulas written out here, and round-tripped."""

import math

import numpy as np
import pytest

from steadystep import SteadystepError
from steadystep.core._native import ffi, lib
from steadystep.core.convert import (exact_softness, frequency_from_spring, implicit_euler_softness, matched_softness,
                                     softness_for, spring_from_frequency, spring_from_softness)


def test_softness_equals_c_and_the_articles_formula():
    for k, c, h in ((40.0, 1.0, 1 / 30), (1e4, 50.0, 1 / 144), (0.0, 2.0, 0.1), (3.0, 0.0, 0.02)):
        erp, cfm = implicit_euler_softness((k, c), h)
        direct = ffi.new("ssSoftness*")
        assert lib.ssImplicitEulerSoftness({"stiffness": k, "damping": c}, h, direct) == lib.SS_OK
        assert (erp, cfm) == (direct.erp, direct.cfm)
        assert erp == pytest.approx(h * k / (h * k + c), rel=1e-15)
        assert cfm == pytest.approx(1.0 / (h * k + c), rel=1e-15)


def test_round_trips():
    rng = np.random.default_rng(7)
    for _ in range(200):
        k, c, h = 10 ** rng.uniform(-2, 5), 10 ** rng.uniform(-3, 3), 10 ** rng.uniform(-4, -0.5)
        back = spring_from_softness(implicit_euler_softness((k, c), h), h)
        assert back.stiffness == pytest.approx(k, rel=1e-9)
        assert back.damping == pytest.approx(c, rel=1e-9)
        f, zeta = frequency_from_spring((k, c), 2.0)
        again = spring_from_frequency(f, zeta, 2.0)
        assert again.stiffness == pytest.approx(k, rel=1e-12)
        assert again.damping == pytest.approx(c, rel=1e-12)


def test_frequency_form_is_jolts():
    k, c = spring_from_frequency(2.0, 0.5, 3.0)
    w = 2 * math.pi * 2.0
    assert k == pytest.approx(3.0 * w * w, rel=1e-15)
    assert c == pytest.approx(2 * 0.5 * 3.0 * w, rel=1e-15)


def test_matched_and_exact_equal_c_and_agree_without_history():
    spring, mass, h = (40.0, 1.0), 1.0, 1 / 30
    matched = matched_softness(spring, mass, h)
    direct = ffi.new("ssSoftness*")
    assert lib.ssMatchedSoftness({"stiffness": 40.0, "damping": 1.0}, mass, h, direct) == lib.SS_OK
    assert matched == (direct.erp, direct.cfm)
    # Independent truth: r² = P = exp(-c h/m), cfm = h P / (m (1 - P)).
    p = math.exp(-1.0 * h / mass)
    assert matched.cfm == pytest.approx(h * p / (mass * (1 - p)), rel=1e-12)
    assert softness_for("matched", spring, mass, h) == matched
    assert softness_for("implicit-euler", spring, mass, h) == implicit_euler_softness(spring, h)
    assert softness_for("exact", spring, mass, h, 1 / 20) == exact_softness(spring, mass, h, 1 / 20)


@pytest.mark.parametrize("call, named, status", [
    (lambda: implicit_euler_softness((-1.0, 1.0), 0.1), "k", "out of range"),
    (lambda: implicit_euler_softness((1.0, 1.0), 0.0), "step_s", "out of range"),
    (lambda: implicit_euler_softness((0.0, 0.0), 0.1), "", "no spring"),
    (lambda: implicit_euler_softness((math.nan, 1.0), 0.1), "k", "not finite"),
    (lambda: spring_from_softness((1.5, 0.1), 0.1), "erp", "out of range"),
    (lambda: matched_softness((40.0, 0.0), 1.0, 0.1), "", "no finite mapping"),
    (lambda: matched_softness((40.0, 1.0), -1.0, 0.1), "mass", "out of range"),
    (lambda: softness_for("magic", (40.0, 1.0), 1.0, 0.1), "mapping", "unsupported"),
])
def test_bad_inputs_raise_with_the_status_and_a_message(call, named, status):
    with pytest.raises(SteadystepError) as error:
        call()
    assert error.value.status == status
    assert named in error.value.message
    assert isinstance(error.value, ValueError)

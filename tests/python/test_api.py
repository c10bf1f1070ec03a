"""The package's public surface: everything in __all__ exists, py.typed ships, the enums and report dataclasses
hold exactly what the C headers declare, importing changes no global state, the conversions work elementwise on
numpy arrays, and the commands that draw say in one line when the report extra is missing."""

import dataclasses
import importlib.util
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import steadystep as ss
from steadystep import cli
from steadystep.core._native import ffi, lib


def test_everything_in_all_exists_and_the_package_is_typed():
    assert len(set(ss.__all__)) == len(ss.__all__)
    for name in ss.__all__:
        assert getattr(ss, name) is not None, name
    assert (Path(ss.__file__).parent / "py.typed").is_file()


@pytest.mark.parametrize("enum, ctype, prefix", [
    (ss.FrameCut, "ssFrameCut", "SS_CUT_"), (ss.Mapping, "ssMapping", "SS_MAPPING_"),
    (ss.Solver, "ssSolver", "SS_SOLVER_"), (ss.JointParam, "ssJointParam", "SS_PARAM_"),
    (ss.Status, "ssStatus", "SS_")])
def test_each_enum_has_exactly_the_c_enumerators(enum, ctype, prefix):
    declared = {name.removeprefix(prefix).removeprefix("ERROR_"): value
                for name, value in ffi.typeof(ctype).relements.items()}
    assert {member.name: member.value for member in enum} == declared


@pytest.mark.parametrize("cls, ctype", [(ss.Stepping, "ssStepping")])
def test_each_dataclass_has_exactly_the_c_fields_in_order(cls, ctype):
    assert [field.name for field in dataclasses.fields(cls)] == [name for name, _ in ffi.typeof(ctype).fields]


@pytest.mark.parametrize("cls, ctype", [
    (ss.ServedCounts, "ssServedCounts"), (ss.ApplyReport, "ssApplyReport"), (ss.AdoptReport, "ssAdoptReport"),
    (ss.FrameReport, "ssFrameReport"), (ss.StepInfo, "ssStepInfo")])
def test_each_report_reads_exactly_the_c_fields_in_order(cls, ctype):
    c_fields = [name for name, _ in ffi.typeof(ctype).fields]
    assert list(cls.FIELDS) == c_fields
    report = cls.of(ffi.new(f"{ctype}*"))
    assert list(report.as_dict()) == c_fields
    with pytest.raises(AttributeError):
        setattr(report, c_fields[0], 1)
    # Made by hand, as the dataclasses were: positional in the C order, or by name.
    assert cls(**report.as_dict()) == report == cls(*report.as_dict().values())
    with pytest.raises(TypeError, match="no field"):
        cls(no_such_field=1)


def test_the_stepping_defaults_and_presets_are_the_librarys():
    default = lib.ssDefaultStepping()
    assert ss.Stepping() == ss.Stepping.from_c(default) and ss.Stepping().policy == "implicit-euler"
    for name in ss.policy_names():
        stepping = ss.Stepping.for_policy(name, 1 / 30, solver=ss.Solver.QUICK)
        assert stepping.policy == name
        stepping.validate()
    assert ss.Stepping.for_policy("naive", 1 / 30).frozen_step_s == 1 / 30
    with pytest.raises(ss.SteadystepError, match="fastest"):
        ss.Stepping.for_policy("fastest")
    with pytest.raises(ss.SteadystepError, match="max_step_s"):
        ss.Stepping(solver=ss.Solver.QUICK, max_step_s=-1.0).validate()
    with pytest.raises(ss.SteadystepError, match="stepping.solver = unset"):
        ss.Stepping(max_step_s=1 / 60).validate()
    assert ss.Stepping().max_step_s == 0.0 and ss.Stepping().solver == ss.Solver.UNSET  # the tuned step; say which
    with pytest.raises(ss.SteadystepError, match="stepping.cut = 'x'"):
        ss.Stepping(cut="x").validate()


def test_every_stepping_field_round_trips_through_c():
    """Each field set to a value unlike its default comes back from the C struct as it went in, with its type."""
    chosen = ss.Stepping(cut=ss.FrameCut.FIXED, mapping=ss.Mapping.MATCHED, frozen_step_s=1 / 50,
                         solver=ss.Solver.STEP, quick_iterations=7, max_step_s=1 / 90, fixed_step_s=1 / 120,
                         max_step_slack=0.5, step_seed=12345, max_steps_per_frame=9, max_speed=50.0,
                         max_angular_speed=60.0)
    default = ss.Stepping()
    assert all(getattr(chosen, f.name) != getattr(default, f.name) for f in dataclasses.fields(ss.Stepping))
    back = ss.Stepping.from_c(ffi.new("ssStepping*", chosen.as_c_fields())[0])
    assert back == chosen
    assert type(back.max_step_slack) is float and type(back.step_seed) is int
    # The library's defaults: a quarter of slack, seed 0; naive leaves ODE's generator alone, the others seed it.
    assert (default.max_step_slack, default.step_seed) == (0.25, 0)
    assert ss.Stepping.for_policy("naive").step_seed == -1
    for name in ("implicit-euler", "fixed"):
        assert ss.Stepping.for_policy(name, step_seed=-1).step_seed == 0
        assert ss.Stepping.for_policy(name, step_seed=7).step_seed == 7
    quick = ss.Stepping(solver=ss.Solver.QUICK, max_step_s=1 / 60)
    with pytest.raises(ss.SteadystepError, match="stepping.max_step_slack = 1.5"):
        dataclasses.replace(quick, max_step_slack=1.5).validate()
    with pytest.raises(ss.SteadystepError, match="stepping.step_seed = -2"):
        dataclasses.replace(quick, step_seed=-2).validate()
    with pytest.raises(ss.SteadystepError, match="stepping.step_seed"):
        dataclasses.replace(quick, step_seed=2**31).as_c_fields()  # beyond C's int, named before C sees it


def test_the_run_bound_is_the_c_librarys():
    from steadystep.lab.limits import MAX_RUN_FRAMES, MAX_RUN_STEPS
    header = (Path(ss.__file__).parent / "core" / "_native" / "include" / "steadystep" / "lab" / "scene.h").read_text()
    assert f"#define SS_MAX_RUN_STEPS {MAX_RUN_STEPS}\n" in header
    assert f"#define SS_MAX_RUN_FRAMES {MAX_RUN_FRAMES}\n" in header


IMPORT_LEAVES_MATPLOTLIB_ALONE = """
import sys
import steadystep
assert "matplotlib" not in sys.modules and "tqdm" not in sys.modules, "the core imported the report's dependencies"
import matplotlib
matplotlib.use("svg")
import steadystep.report.figures, steadystep.report
assert matplotlib.get_backend() == "svg", matplotlib.get_backend()
assert matplotlib.rcParams["font.size"] == matplotlib.rcParamsDefault["font.size"]
print("ok")
"""


@pytest.mark.skipif(importlib.util.find_spec("matplotlib") is None, reason="the report extra is not installed")
def test_importing_the_package_changes_no_global_state():
    done = subprocess.run([sys.executable, "-c", IMPORT_LEAVES_MATPLOTLIB_ALONE], capture_output=True, text=True)
    assert done.returncode == 0 and done.stdout == "ok\n", done.stderr


def test_conversions_work_elementwise_on_numpy_arrays():
    k = np.array([10.0, 40.0, 1e3])
    h = np.array([[1 / 30], [1 / 60]])
    erp, cfm = ss.implicit_euler_softness((k, 1.0), h)
    assert erp.shape == cfm.shape == (2, 3)
    assert np.allclose(erp, h * k / (h * k + 1.0), rtol=1e-14) and np.allclose(cfm, 1 / (h * k + 1.0), rtol=1e-14)
    back = ss.spring_from_softness((erp, cfm), h)
    assert np.allclose(back.stiffness, np.broadcast_to(k, (2, 3)), rtol=1e-12)
    assert np.allclose(back.damping, 1.0, rtol=1e-12)
    frequency, ratio = ss.frequency_from_spring((k, 2.0), 1.5)
    assert np.allclose(frequency, np.sqrt(k / 1.5) / (2 * np.pi)) and np.allclose(ratio, 2.0 / (2 * np.sqrt(k * 1.5)))
    for mapping in ("implicit-euler", "matched", "exact"):
        many = ss.softness_for(mapping, (k, 1.0), 1.0, 1 / 60)
        one = [ss.softness_for(mapping, (value, 1.0), 1.0, 1 / 60) for value in k]
        assert list(many.erp) == [s.erp for s in one] and list(many.cfm) == [s.cfm for s in one]
    scalar = ss.implicit_euler_softness((40.0, 1.0), 1 / 30)
    assert isinstance(scalar.erp, float)
    with pytest.raises(ss.SteadystepError, match=r"at index \(1,\): .*k = -1"):
        ss.implicit_euler_softness((np.array([1.0, -1.0]), 1.0), 0.1)
    with pytest.raises(ss.SteadystepError, match="cannot be broadcast"):
        ss.implicit_euler_softness((np.ones(2), np.ones(3)), 0.1)


@pytest.mark.parametrize("command, missing", [(["figure", "--out", "unused"], "matplotlib"),
                                              (["compare", "--out", "unused"], "tqdm"),
                                              (["compare", "--out", "unused"], "jinja2"),
                                              (["audit", "program", "--out", "unused"], "matplotlib"),
                                              (["audit", "program", "--out", "unused"], "jinja2")])
def test_drawing_commands_say_the_extra_is_missing_in_one_line(command, missing, monkeypatch, capsys, tmp_path):
    monkeypatch.setitem(sys.modules, missing, None)  # its import fails, as when it is not installed
    monkeypatch.chdir(tmp_path)
    assert cli.main(command) == cli.EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"{missing} not installed" in err and "steadystep[report]" in err
    assert not (tmp_path / "unused").exists()

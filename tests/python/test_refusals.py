"""One test per class of hostile input the Python package and the command must survive (issue 8, point 5):
text that is not UTF-8 in either direction, strict --json, the bound on runs, and library calls with values of
the wrong kind. Each asserts the refusal names the value, and that nothing but SteadystepError escapes."""

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

from steadystep import SteadystepError, report
from steadystep.core import convert
from steadystep.lab import probe, runs
from steadystep.core._native import ffi, text
from steadystep.cli import EXIT_BAD_INPUT, EXIT_INTERNAL, build_parser, main
from steadystep.lab.limits import MAX_RUN_STEPS
from steadystep.lab.profiles import Profile, frame_times

SCRIPT = Path(sys.executable).parent / "steadystep"
COMMAND = [str(SCRIPT)] if SCRIPT.exists() else [sys.executable, "-m", "steadystep.cli"]


def _refuse_constant(name):
    raise ValueError(f"{name} is not strict JSON")


def run_cli(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


# ---- text that is not UTF-8 -----------------------------------------------------------------------------------

def test_c_text_cut_inside_a_character_is_decoded():
    # The library cuts its messages at 255 bytes; were one cut inside a UTF-8 character, or quote bytes that are not
    # UTF-8, Python reads U+FFFD there instead of raising. A C buffer holding such bytes stands for that message.
    for raw, expected in ((b"spec \"\xc3\xa9\xc3", 'spec "\u00e9\ufffd'), (b"\xff\xfe x", "\ufffd\ufffd x")):
        assert text(ffi.new("char[]", raw)) == expected
    # Today's library escapes what is not ASCII: the message quotes the spec whole, on one line.
    spec = "x" + "\u00e9" * 300
    with pytest.raises(SteadystepError) as error:
        Profile(spec)
    assert "x\\xc3\\xa9" in error.value.message and "\n" not in error.value.message


def test_a_binary_trace_is_refused_in_one_printable_line(tmp_path, capsys):
    trace = tmp_path / "binary.trace"
    trace.write_bytes(b"\x1b[2J\xff\xfe\x00\x85\r" + bytes(range(1, 256)))
    with pytest.raises(SteadystepError) as error:
        Profile(f"trace:{trace}")
    message = error.value.message
    assert str(trace) in message
    assert not any(ord(ch) < 32 or 127 <= ord(ch) < 160 for ch in message), message
    code, out, err = run_cli(capsys, "run", "oscillator", "--profile", f"trace:{trace}", "--policy", "implicit-euler")
    assert code == EXIT_BAD_INPUT and len(err.splitlines()) == 1 and "\x1b" not in err


def test_names_and_specs_of_the_wrong_kind_raise_steadystep_error():
    bad_calls = [
        (lambda: runs.run(None, "fixed:30", "implicit-euler", 0.1), "scene = None"),
        (lambda: runs.run("oscillator\0", "fixed:30", "implicit-euler", 0.1), "NUL"),
        (lambda: runs.run("oscillator", b"fixed:30\0x", "implicit-euler", 0.1), "NUL"),
        (lambda: runs.run("oscillator", "fixed:30", "spring\ud800", 0.1), "surrogate"),
        (lambda: runs.run("oscillator", "fixed:30", 3, 0.1), "policy = 3"),
        (lambda: runs.scene_info(["oscillator"]), "scene = ['oscillator']"),
        (lambda: Profile(5), "profile = 5"),
        (lambda: Profile("fixed:30", seed=-1), "seed = -1"),
        (lambda: Profile("fixed:30", seed=2**64), "seed = 18446744073709551616"),
        (lambda: Profile("fixed:30", seed="1"), "seed = '1'"),
        (lambda: Profile("fixed:30", seed=10**5000), "seed = <an integer of"),
        (lambda: frame_times("fixed:30", 10**9), "count = 1000000000"),
        (lambda: frame_times("fixed:30", 2.5), "count = 2.5"),
        (lambda: runs.run("oscillator", "fixed:30", "implicit-euler", "5"), "duration_s = '5'"),
        (lambda: runs.run("oscillator", "fixed:30", "implicit-euler", 0.1, stepping={"max_steps_per_frame": 2**40}),
         "stepping.max_steps_per_frame"),
        (lambda: runs.run("oscillator", "fixed:30", "implicit-euler", 0.1, stepping={"max_step_s": "fast"}),
         "stepping.max_step_s = 'fast'"),
        (lambda: runs.run("oscillator", "fixed:30", "implicit-euler", 0.1, params={"spring": 5}), "params.spring = 5"),
        (lambda: runs.run("oscillator", "fixed:30", "implicit-euler", 0.1, params=[1]), "params = [1]"),
        (lambda: runs.Scene("oscillator").frame("long"), "frame_s = 'long'"),
        (lambda: convert.implicit_euler_softness("ab", 0.1), "k = 'a'"),
        (lambda: convert.implicit_euler_softness((1, 2, 3), 0.1), "spring = (1, 2, 3)"),
        (lambda: convert.spring_from_softness(None, 0.1), "softness = None"),
        (lambda: convert.softness_for(5, (40, 1), 1, 0.1), "mapping = 5"),
        (lambda: convert.matched_softness((40, 1), [], 0.1), "mass = []"),
        (lambda: probe.largest_stable_step("oscillator", "implicit-euler", tolerance=1e-300), "tolerance = 1e-300"),
    ]
    for call, named in bad_calls:
        with pytest.raises(SteadystepError) as error:
            call()
        assert named in error.value.message, (named, error.value.message)


def test_a_closed_scene_refuses_by_name():
    scene = runs.Scene("oscillator")
    scene.close()
    for use in (lambda: scene.frame(0.01), scene.sample, lambda: scene.time_s):
        with pytest.raises(SteadystepError, match="after close"):
            use()


def test_an_internal_error_is_one_line_with_its_own_exit_code(capsys, monkeypatch):
    # A bug stands in for every unexpected exception: the command names it in one line, never a traceback.
    def broken(*args):
        raise ZeroDivisionError("float division by zero")

    monkeypatch.setattr(convert, "implicit_euler_softness", broken)
    code, out, err = run_cli(capsys, "convert", "--k", "40", "--c", "1", "--dt", "0.02")
    assert code == EXIT_INTERNAL and code not in (0, 1, 2)
    assert err.splitlines() == ["steadystep: internal error: ZeroDivisionError: float division by zero (please "
                                "report this with the command that caused it)"]


def test_a_reader_that_goes_away_ends_the_command_quietly():
    command = [*COMMAND, "run", "oscillator", "--profile", "fixed:1000", "--policy", "implicit-euler", "--duration", "60",
               "--max-step", "0.001"]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    process.stdout.read(100)
    process.stdout.close()
    stderr = process.stderr.read()
    assert process.wait(timeout=120) == 141
    assert stderr == b""


# ---- strict JSON ----------------------------------------------------------------------------------------------

def test_convert_json_is_strict_and_equals_the_package(capsys):
    code, out, err = run_cli(capsys, "convert", "--erp", "0.2", "--cfm", "1e-5", "--dt", "0.016667", "--json")
    assert code == 0, err
    assert json.loads(out, parse_constant=_refuse_constant) == convert.spring_from_softness((0.2, 1e-5),
                                                                                           0.016667)._asdict()


def test_a_conversion_without_a_finite_result_is_refused_by_name(capsys):
    # k = 1e308, h = 10: h·k overflows and erp = hk/(hk + c) is NaN. Refused, whether by the library or by Python.
    with pytest.raises(SteadystepError) as error:
        convert.implicit_euler_softness((1e308, 1.0), 10.0)
    assert "k = 1e+308" in error.value.message
    for json_flag in ([], ["--json"]):
        code, out, err = run_cli(capsys, "convert", "--k", "1e308", "--c", "1", "--dt", "10", *json_flag)
        assert code == EXIT_BAD_INPUT and out == "" and "--k 1e+308" in err and len(err.splitlines()) == 1


def test_strict_json_refuses_a_number_that_is_not_finite_by_its_path():
    from steadystep.cli import _strict_json, _UsageError

    for data, path in (({"erp": math.nan}, "erp = nan"), ({"a": [1.0, {"b": -math.inf}]}, "a[1].b = -inf")):
        with pytest.raises(_UsageError, match=path.replace("[", r"\[").replace("]", r"\]")):
            _strict_json("convert", data)
    import numpy as np

    with pytest.raises(_UsageError, match=r"columns.x\[2\] = inf"):
        _strict_json("run", {}, {"t": np.arange(4.0), "x": np.array([0.0, 1.0, math.inf, math.nan])})


def test_metrics_json_is_strict_with_null_for_a_blow_up(tmp_path):
    row = report.Row("oscillator", "fixed:30", "naive", {"x": math.inf, "v": math.inf}, math.nan, math.nan,
                     math.nan, "blowup", math.inf)
    made = report.Report(["oscillator"], ["fixed:30"], {"oscillator": ["naive"]}, 1.0, 1, rows=[row],
                         spreads={"oscillator": {"naive": {"x": math.inf, "v": math.inf}}})
    report.write(made, tmp_path, "steadystep compare \udcff")
    data = json.loads((tmp_path / "metrics.json").read_text(), parse_constant=_refuse_constant)
    assert data["rows"][0]["deviation"] == {"x": None, "v": None} and data["rows"][0]["steps_per_frame"] is None
    assert "\ufffd" in data["command"]


# ---- the bound on runs ----------------------------------------------------------------------------------------

def test_the_bound_is_in_the_help_and_the_docstrings():
    shown = f"{MAX_RUN_STEPS:.0e}"
    commands = build_parser()._subparsers._group_actions[0].choices
    for name in ("run", "compare", "probe"):
        assert shown in commands[name].format_help(), name
    assert "MAX_RUN_STEPS" in runs.run.__doc__ and "MAX_RUN_STEPS" in probe.largest_stable_step.__doc__


def test_runs_above_the_bound_are_refused_by_name_before_they_start(capsys):
    code, out, err = run_cli(capsys, "run", "oscillator", "--profile", "fixed:30", "--policy", "implicit-euler",
                             "--duration", "1e9")
    assert code == EXIT_BAD_INPUT and "duration_s = 1e+09" in err and str(MAX_RUN_STEPS) in err
    code, out, err = run_cli(capsys, "run", "oscillator", "--profile", "fixed:1e12", "--policy", "implicit-euler")
    assert code == EXIT_BAD_INPUT and "'fixed:1e12'" in err and str(MAX_RUN_STEPS) in err
    code, out, err = run_cli(capsys, "compare", "--duration", "1e9", "--scenes", "oscillator")
    assert code == EXIT_BAD_INPUT and "duration_s = 1e+09" in err
    code, out, err = run_cli(capsys, "probe", "oscillator", "--low", "1e-300")
    assert code == EXIT_BAD_INPUT and "low_s = 1e-300" in err
    with pytest.raises(SteadystepError, match="duration_s = 1e\\+09"):
        runs.run("oscillator", "fixed:30", "naive", 1e9)
    with pytest.raises(SteadystepError, match="'fixed:1e12'"):
        runs.run("oscillator", "fixed:1e12", "implicit-euler", 5.0)


def test_the_bound_sits_where_limits_says():
    # Steps: duration_s / max_step_s against MAX_RUN_STEPS, on either side of it.
    step_s = 1.0 / 1000
    stepping = runs.make_stepping("implicit-euler", max_step_s=step_s)
    with pytest.raises(SteadystepError, match="duration_s"):
        runs.check_run_size("fixed:1", MAX_RUN_STEPS * step_s * 1.001, 1, stepping)
    runs.check_run_size("fixed:1", MAX_RUN_STEPS * step_s * 0.999, 1, stepping)
    # Frames: a profile of 2000 fps against MAX_RUN_STEPS frames, with steps far below the bound.
    rate = 2000
    coarse = runs.make_stepping("implicit-euler", max_step_s=1.0)
    runs.check_run_size(f"fixed:{rate}", MAX_RUN_STEPS / rate * 0.999, 1, coarse)
    with pytest.raises(SteadystepError, match=f"'fixed:{rate}'"):
        runs.check_run_size(f"fixed:{rate}", MAX_RUN_STEPS / rate * 1.001, 1, coarse)


def test_a_profile_that_hands_out_a_frame_that_is_not_finite_is_refused():
    # 1/1e-320 overflows: the library's profile hands out infinite frames today; the run refuses them by name.
    with pytest.raises(SteadystepError, match="fixed:1e-320"):
        runs.run("oscillator", "fixed:1e-320", "implicit-euler", 1.0)


# ---- the pure-Python model and metrics ------------------------------------------------------------------------

def test_the_model_and_the_metrics_raise_only_steadystep_error_whatever_the_numbers():
    import itertools
    import warnings

    import numpy as np

    from steadystep.lab import article, metrics

    values = [math.nan, math.inf, -math.inf, 1e308, 0.0, 1e-320, -1.0, 40.0, 1e300]
    t = np.linspace(0.0, 1.0, 50)
    calls = []
    for m, k, c in itertools.product(values, repeat=3):
        osc = article.Oscillator(m, k, c)
        calls += [lambda osc=osc: (osc.decay_rate, osc.angular_frequency, osc.damping_ratio),
                  lambda osc=osc: article.integrate(osc, 0.5, 0.0, [0.01, 0.02], method="implicit"),
                  lambda osc=osc: article.exact(osc, 0.5, 1e308, [0.0, 1e308])]
    for a, b in itertools.product(values, repeat=2):
        calls += [lambda a=a, b=b: metrics.fit_oscillation(t, a * np.sin(b * t)),  # 1e308·sin(1e300 t) hung LAPACK
                  lambda a=a, b=b: metrics.fit_oscillation(t * a, np.sin(20 * t) * np.exp(-b * t)),
                  lambda a=a, b=b: metrics.rms_deviation([0.0, 1.0], [a, b], [0.0, 1.0], [b, a]),
                  lambda a=a, b=b: metrics.rms_vs_exact([1.0, 2.0], [a, b], a)]
    calls += [lambda: metrics.fit_oscillation("abc", "def"), lambda: metrics.spread("ab"),
              lambda: article.integrate(article.ARTICLE_OSCILLATOR, "a", 0.0, [0.1]),
              lambda: article.integrate(article.ARTICLE_OSCILLATOR, 0.5, 0.0, "x")]
    refused = 0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # overflow in numpy is what the values are for
        for call in calls:
            try:
                call()
            except SteadystepError:
                refused += 1
    assert refused > len(calls) // 2

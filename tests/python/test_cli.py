"""The steadystep command end to end, as a user runs it: every command on short runs, and every bad-argument path
ending with exit code 2, one line on stderr and no file written."""

import csv
import io
import json
import math
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from steadystep.core.convert import implicit_euler_softness, spring_from_frequency, spring_from_softness

SCRIPT = Path(sys.executable).parent / "steadystep"
COMMAND = [str(SCRIPT)] if SCRIPT.exists() else [sys.executable, "-m", "steadystep.cli"]


def steadystep(*args, cwd=None):
    return subprocess.run([*COMMAND, *map(str, args)], capture_output=True, text=True, cwd=cwd, timeout=120)


def no_temporaries(directory: Path) -> bool:
    return not any(p.name.startswith(".") and p.name.endswith(p.suffix) and ".tmp" in p.name
                   for p in directory.iterdir())


def test_every_command_has_help():
    for command in ([], ["figure"], ["compare"], ["run"], ["probe"], ["convert"]):
        result = steadystep(*command, "--help")
        assert result.returncode == 0 and "usage: steadystep" in result.stdout


def test_help_names_policies_the_library_knows():
    # "spring" was the implicit-Euler policy's name in 0.1.0: help texts must name the policies that exist
    from steadystep.lab.runs import policy_names
    known = set(policy_names())
    for command in ("compare", "probe"):
        text = " ".join(steadystep(command, "--help").stdout.split())
        default = text.rsplit("--policies POLICY [POLICY ...]", 1)[1].split("default:", 1)[1].split("--", 1)[0]
        # the list stands in parentheses ("every policy the library names (...)") or before them ("naive ... (why)")
        inner = default.split("(", 1)[1].split(")", 1)[0] if "(" in default else ""
        listed = inner if inner.split() and set(inner.split()) <= known else default.split("(", 1)[0]
        named = listed.split()
        assert named and set(named) <= known, (command, named)
        assert "spring" not in default, command


def test_figure_writes_png_and_svg(tmp_path):
    result = steadystep("figure", "--out", tmp_path / "figs", "--duration", "2")
    assert result.returncode == 0, result.stderr
    png, svg = tmp_path / "figs" / "article_figure.png", tmp_path / "figs" / "article_figure.svg"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "<svg" in svg.read_text()[:1000]
    assert no_temporaries(tmp_path / "figs")


def test_compare_writes_the_report(tmp_path):
    result = steadystep("compare", "--out", tmp_path, "--scenes", "oscillator", "chain", "--profiles", "fixed:30",
                        "uniform:15:45", "--duration", "1", "--seed", "3")
    assert result.returncode == 0, result.stderr
    page = (tmp_path / "report.html").read_text()
    assert "Oscillator against the exact solution" in page and "steadystep compare --out" in page
    metrics = json.loads((tmp_path / "metrics.json").read_text())
    assert {(r["scene"], r["profile"], r["policy"]) for r in metrics["rows"]} >= {
        ("oscillator", "uniform:15:45", "exact"), ("chain", "fixed:30", "naive"), ("chain", "uniform:15:45", "fixed")}
    assert metrics["seed"] == 3
    assert (tmp_path / "metrics.csv").read_text().startswith("scene,profile,policy,quantity,deviation")
    assert (tmp_path / "deviation_chain.png").exists() and (tmp_path / "index.html").exists()
    assert no_temporaries(tmp_path)


def test_run_csv_on_stdout_and_to_a_file(tmp_path):
    result = steadystep("run", "oscillator", "--profile", "fixed:30", "--policy", "implicit-euler", "--duration", "0.5")
    assert result.returncode == 0, result.stderr
    rows = list(csv.reader(io.StringIO(result.stdout)))
    assert rows[0] == ["t_s", "x_m", "v_m_per_s", "erp", "cfm_m_per_N_s"]
    assert len(rows) == 1 + 1 + 30  # header, t = 0, then 15 frames of 1/30 s, two 1/60 s steps each
    assert [float(v) for v in rows[1][:3]] == [0.0, 0.5, 0.0]  # released at rest from x0 = 0.5 m
    assert float(rows[2][0]) == pytest.approx(1 / 60)
    # Full precision: every step length recomputed from t is 1/60 s to the last bits of the sum.
    t = np.array([float(row[0]) for row in rows[1:]])
    assert np.allclose(np.diff(t), 1 / 60, rtol=0, atol=1e-15)
    out = tmp_path / "run.csv"
    result = steadystep("run", "chain", "--profile", "uniform:15:45", "--policy", "implicit-euler", "--duration", "0.5",
                        "--csv", out)
    assert result.returncode == 0, result.stderr
    lines = out.read_text().splitlines()
    assert lines[0] == "t_s,end_x_m,end_z_m"
    assert lines[1] == "0,2,2.5"  # the chain's end at the start: 8 links of 0.25 m, horizontal at 2.5 m
    assert no_temporaries(tmp_path)


def test_run_json():
    result = steadystep("run", "oscillator", "--profile", "uniform:15:45", "--policy", "exact", "--duration", "0.5",
                        "--json", "--max-step", "0.1")
    assert result.returncode == 0, result.stderr
    data = json.loads(result.stdout)
    assert data["status"] == "ok" and data["message"] == "" and data["frames"] == data["steps"]
    assert list(data["columns"]) == ["t_s", "x_m", "v_m_per_s", "erp", "cfm_m_per_N_s"]
    assert data["units"] == {"t_s": "s", "x_m": "m", "v_m_per_s": "m/s", "erp": "", "cfm_m_per_N_s": "m/(N*s)"}
    columns = data["columns"]
    assert all(len(values) == data["steps"] + 1 for values in columns.values())  # the t = 0 sample, then each step
    assert columns["t_s"][0] == 0.0 and columns["x_m"][0] == 0.5 and columns["v_m_per_s"][0] == 0.0
    assert 0 < data["bound_use"] < 1


def test_run_broken_chain_reports_and_exits_1():
    # Issue 10: 2 s frames tear the naive chain apart. Its end, 2 m of chain from a pivot 2.5 m up, is recorded far
    # beyond what the chain can reach: the JSON says broken, names the bound, and the records stop at that step.
    result = steadystep("run", "chain", "--policy", "naive", "--profile", "fixed:0.5", "--json")
    assert result.returncode == 1, result.stderr
    data = json.loads(result.stdout)
    assert data["status"] == "broken" and data["bound_use"] > 1
    assert data["message"].startswith("t = 2 s: chain hinge ") and "bound 0.05 m" in data["message"]
    assert data["steps"] == 1 and data["columns"]["t_s"] == [0.0, 2.0]
    end_x, end_z = data["columns"]["end_x_m"][-1], data["columns"]["end_z_m"][-1]
    assert math.hypot(end_x, end_z - 2.5) > 2.0
    assert result.stderr.count("\n") == 1 and "broken: t = 2 s" in result.stderr
    csv_result = steadystep("run", "chain", "--policy", "naive", "--profile", "fixed:0.5")
    assert csv_result.returncode == 1 and len(csv_result.stdout.splitlines()) == 3  # header, t = 0, the step


EXAMPLE = Path(__file__).resolve().parents[2] / "build" / "steadystep_example_oscillator"


@pytest.mark.parametrize("args", [
    [],  # the defaults: implicit-euler, uniform:15:45, seed 1, 5 s
    ["--policy", "naive", "--profile", "fixed:30", "--duration", "1"],
    ["--policy", "exact", "--profile", "jitter:30:3", "--seed", "7", "--duration", "1.3", "--max-step", "0.01"],
    ["--policy", "matched", "--profile", "hitch:60:30:0.1", "--seed", "3", "--duration", "2"],
    ["--policy", "fixed", "--profile", "vsync:60:30", "--duration", "0.7"],
])
def test_c_example_prints_what_steadystep_run_prints(args):
    # examples/oscillator.c is a plain ODE program, built by scripts/test (cmake) before pytest runs; with the same
    # flags it must print the same CSV, byte for byte: header, t = 0 row, every step at full precision.
    assert EXAMPLE.exists(), f"{EXAMPLE}: build the C side first (scripts/test, or cmake --build build)"
    if not args:
        cli_args = ["--policy", "implicit-euler", "--profile", "uniform:15:45"]
    else:
        cli_args = args
    example = subprocess.run([str(EXAMPLE), *args], capture_output=True, text=True, timeout=60)
    assert example.returncode == 0, example.stderr
    cli = steadystep("run", "oscillator", *cli_args)
    assert cli.returncode == 0, cli.stderr
    assert len(example.stdout.splitlines()) > 20
    assert example.stdout == cli.stdout


def test_probe_prints_each_policy():
    result = steadystep("probe", "chain", "--policies", "naive", "implicit-euler", "--duration", "1", "--json")
    assert result.returncode == 0, result.stderr
    found = json.loads(result.stdout)
    assert [r["policy"] for r in found] == ["naive", "implicit-euler"]
    for r in found:
        assert 0.001 < r["stable_s"] < r["unstable_s"] <= 0.25 and r["reason"]


def test_convert_all_three_ways_equal_the_package():
    result = steadystep("convert", "--k", "40", "--c", "1", "--dt", "0.02", "--json")
    assert json.loads(result.stdout) == implicit_euler_softness((40, 1), 0.02)._asdict()
    result = steadystep("convert", "--erp", "0.2", "--cfm", "1e-5", "--dt", "0.01", "--json")
    assert json.loads(result.stdout) == spring_from_softness((0.2, 1e-5), 0.01)._asdict()
    result = steadystep("convert", "--frequency", "2", "--damping-ratio", "0.3", "--mass", "1.5")
    k, c = spring_from_frequency(2, 0.3, 1.5)
    assert result.stdout.splitlines() == [f"stiffness = {k:.17g} N/m", f"damping = {c:.17g} N·s/m"]


@pytest.mark.parametrize("args", [
    ["frobnicate"],
    [],
    ["run", "oscillator", "--policy", "implicit-euler"],
    ["run", "oscillator", "--profile", "fixed:30", "--policy", "sideways"],
    ["run", "nosuch", "--profile", "fixed:30", "--policy", "implicit-euler"],
    ["run", "oscillator", "--profile", "fixed:-30", "--policy", "implicit-euler"],
    ["run", "oscillator", "--profile", "warp:9", "--policy", "implicit-euler"],
    ["run", "oscillator", "--profile", "trace:/no/such/file", "--policy", "implicit-euler"],
    ["run", "oscillator", "--profile", "fixed:30", "--policy", "implicit-euler", "--duration", "-1"],
    ["run", "oscillator", "--profile", "fixed:30", "--policy", "implicit-euler", "--duration", "inf"],
    ["run", "oscillator", "--profile", "fixed:30", "--policy", "implicit-euler", "--seed", "-4"],
    ["run", "oscillator", "--profile", "fixed:30", "--policy", "implicit-euler", "--max-step", "0"],
    ["run", "oscillator", "--profile", "fixed:30", "--policy", "implicit-euler", "--json", "--csv", "x.csv"],
    ["run", "oscillator", "--profile", "fixed:30", "--policy", "implicit-euler", "--csv", "no/such/dir/x.csv"],
    ["convert", "--k", "40"],
    ["convert", "--k", "40", "--c", "1", "--erp", "0.2", "--dt", "0.1"],
    ["convert", "--k", "-40", "--c", "1", "--dt", "0.1"],
    ["convert", "--k", "forty", "--c", "1", "--dt", "0.1"],
    ["convert", "--erp", "1.5", "--cfm", "0.1", "--dt", "0.1"],
    ["convert", "--frequency", "2", "--damping-ratio", "0.3", "--mass", "0"],
    ["compare", "--scenes", "nosuch", "--duration", "1"],
    ["compare", "--policies", "sideways", "--duration", "1"],
    ["compare", "--profiles", "fixed:0", "--scenes", "oscillator", "--duration", "1"],
    ["probe", "nosuch"],
    ["probe", "chain", "--policies", "sideways"],
    ["probe", "chain", "--low", "0.5", "--high", "0.25"],
    ["probe", "chain", "--duration", "0"],
    ["figure", "--duration", "0"],
    ["figure", "--out", "a_file"],
])
def test_bad_arguments_exit_2_with_one_line(tmp_path, args):
    (tmp_path / "a_file").write_text("not a directory")
    before = sorted(p.name for p in tmp_path.rglob("*"))
    result = steadystep(*args, cwd=tmp_path)
    assert result.returncode == 2, (args, result.stdout, result.stderr)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, (args, result.stderr)
    assert "Traceback" not in result.stderr and lines[0].startswith("steadystep")
    assert sorted(p.name for p in tmp_path.rglob("*")) == before  # nothing written, not even half


def test_version_is_the_one_in_cmakelists():
    import re

    cmake = (Path(__file__).resolve().parents[2] / "CMakeLists.txt").read_text()
    version = re.search(r"project\(steadystep VERSION ([0-9.]+)", cmake).group(1)
    result = steadystep("--version")
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == f"steadystep {version}"


def test_an_unknown_policy_is_refused_naming_the_known_ones():
    from steadystep.lab.runs import policy_names
    result = steadystep("run", "oscillator", "--policy", "smooth", "--profile", "fixed:30", "--duration", "1")
    assert result.returncode == 2 and result.stdout == ""
    assert f'policy "smooth": unknown ({", ".join(policy_names())})' in result.stderr
    assert "Traceback" not in result.stderr


def test_the_help_lists_are_the_librarys():
    from steadystep.lab import probe, runs

    scenes = ", ".join(runs.scene_names())
    for command in ("compare", "probe", "run"):
        text = " ".join(steadystep(command, "--help").stdout.split())  # argparse wraps lines anywhere
        # The policy once called "spring" is implicit-euler: "spring" is left only as the scenes' spring itself.
        assert re.findall(r"\bspring\b(?! (?:stiffness|damping))", text) == [], command
        if command != "compare":
            assert scenes in text, command
    compare = " ".join(steadystep("compare", "--help").stdout.split())
    assert " ".join(runs.policy_names()) in compare
    probe_help = " ".join(steadystep("probe", "--help").stdout.split())
    assert f"default: {' '.join(probe.default_policies())}" in probe_help
    assert probe.default_policies() == [p for p in runs.policy_names() if not p.startswith("fixed")]

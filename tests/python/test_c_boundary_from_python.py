"""Issue 8's examples that reach ODE, from Python and from the command, each in its own process: ODE aborts the
whole process (SIGABRT) on some of them, and a test must see that as a failure rather than die with it.

Every case must end with exit code 0, 1 or 2 and no traceback. Python cannot make ODE take a frame it aborts on:
that boundary is the library's (limits.h); these cases check it from the outside, where a user meets it.
"""

import subprocess
import sys
from pathlib import Path

import pytest

SCRIPT = Path(sys.executable).parent / "steadystep"
COMMAND = [str(SCRIPT)] if SCRIPT.exists() else [sys.executable, "-m", "steadystep.cli"]


def finishes_cleanly(args, timeout_s=20.0):
    try:
        result = subprocess.run(args, capture_output=True, text=True, errors="replace", timeout=timeout_s)
    except subprocess.TimeoutExpired:
        pytest.fail(f"{args!r} did not finish within {timeout_s} s")
    assert result.returncode in (0, 1, 2), (args, result.returncode, result.stderr[-500:])
    assert "Traceback" not in result.stderr, result.stderr
    return result


def python_call(code: str):
    return finishes_cleanly([sys.executable, "-c", "from steadystep.lab import runs\n" + code])


@pytest.mark.parametrize("profile", [
    "fixed:1e200",          # frames of 1e-200 s
    "fixed:1e-320",         # 1/FPS overflows: infinite frames
    "uniform:1e-320:30",
    "hitch:60:1e19:1",      # EVERY beyond a long
    "hitch:60:2:1e-320",    # every other frame a denormal
    "vsync:1e308:1e-308",
    "hitch:60:2:1e308",
])
@pytest.mark.parametrize("policy", ["naive", "implicit-euler"])
def test_profiles_with_absurd_frames(profile, policy):
    finishes_cleanly([*COMMAND, "run", "oscillator", "--profile", profile, "--policy", policy, "--duration", "0.5",
                      "--json"])


@pytest.mark.parametrize("lines", [
    b"0.02\n1e-310\n",
    b"0.02\n1.8e308\n",
])
def test_trace_lines_with_absurd_frames(tmp_path, lines):
    trace = tmp_path / "frames.trace"
    trace.write_bytes(lines)
    finishes_cleanly([*COMMAND, "run", "oscillator", "--profile", f"trace:{trace}", "--policy", "naive",
                      "--duration", "0.5"])


def test_a_trace_that_never_ends():
    finishes_cleanly([*COMMAND, "run", "oscillator", "--profile", "trace:/dev/zero", "--policy", "implicit-euler"],
                     timeout_s=5.0)


@pytest.mark.parametrize("code", [
    "runs.Scene('oscillator').frame(1e-310)",
    "runs.run('oscillator', 'fixed:30', 'implicit-euler', 0.5, params={'mass': 1e300})",
    "runs.run('oscillator', 'fixed:30', 'implicit-euler', 0.5, params={'mass': 1e-320})",
])
def test_python_calls_that_reach_ode(code):
    python_call(f"""
try:
    {code}
except runs.SteadystepError as error:
    print(error)
""")

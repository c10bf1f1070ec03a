"""Robust runs and safe files (docs/audit.md, "Bad programs", "Files"): every hostile Python program is refused with
exit 2 and one line naming it; a program's children do not outlive its run; its output is bounded; an audit
interrupted and run again resumes without running again what it finished; `audit` and `compare` write no file
through a link planted in --out, and `compare` replaces an earlier report only with --force; `probe` refuses by name
a policy that takes no step."""

import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

SCRIPT = Path(sys.executable).parent / "steadystep"
COMMAND = [str(SCRIPT)] if SCRIPT.exists() else [sys.executable, "-m", "steadystep.cli"]
ROOT = Path(__file__).resolve().parents[2]
QUICK = ["--duration", "0.5", "--profiles", "fixed:30", "--seeds", "1", "--policies", "implicit-euler", "--executor",
         "serial", "--cost", "none", "--no-diagnosis"]


def steadystep(*args, timeout=120):
    return subprocess.run([*COMMAND, *map(str, args)], capture_output=True, text=True, timeout=timeout)


def refused(done, *words) -> str:
    assert done.returncode == 2, (done.returncode, done.stderr)
    lines = done.stderr.splitlines()
    assert len(lines) == 1 and "Traceback" not in done.stderr, done.stderr
    for word in words:
        assert word in lines[0], (word, lines[0])
    return lines[0]


# A Python program that takes part (the slider of examples/audit_slider.py, imported as a sibling module: the
# program's directory is on the path), with one hook made hostile.
SIBLING = (ROOT / "examples" / "audit_slider.py").read_text()
HOSTILE = {
    "busy_hang": ("def build_world():\n    while True:\n        pass\n", ["time limit", "CPU time", "killed"]),
    "sleeping_hang": ("import time\ndef build_world():\n    time.sleep(300)\n", ["time limit", "no CPU", "killed"]),
    "exits": ("import os\ndef read_quantities(world):\n    os._exit(0)\n", ["ended it itself"]),
    "system_exit": ("def read_quantities(world):\n    raise SystemExit(0)\n",
                    ["read_quantities() raised SystemExit"]),
    "exit_at_import": ("import sys\nsys.exit(4)\n", ["importing it failed: SystemExit: 4"]),
    "keyboard_interrupt": ("def before_step(time_s, step_s):\n    raise KeyboardInterrupt\n"
                           "def build_world():\n    world = slider.build_world()\n"
                           "    world.before_step = before_step\n    return world\n",
                           ["before_step() raised KeyboardInterrupt"]),
    "not_a_number": ("def read_quantities(world):\n    return {'x_m': 'far'}\n", ["returned 'far' for x_m",
                                                                               "not a number"]),
    "none": ("def read_quantities(world):\n    return None\n", ["returned None", "not a dict"]),
    "bool": ("def read_quantities(world):\n    return {'x_m': True}\n", ["returned True for x_m"]),
    "renamed": ("n = [0]\ndef read_quantities(world):\n    n[0] += 1\n"
                "    return {'x_m' if n[0] < 3 else 'y_m': 1.0}\n", ["the same names every time"]),
    "not_a_world": ("def build_world():\n    return 42\n", ["returned int, not a steadystep.audit.PythonWorld"]),
    "spam": ("def read_quantities(world):\n    print('x' * 100000)\n    return slider.read_quantities(world)\n",
             ["up to the bound of a run's output", "stopped"]),
}


@pytest.mark.parametrize("name", HOSTILE)
def test_a_hostile_python_program_is_refused_in_one_line(tmp_path, name):
    body, words = HOSTILE[name]
    (tmp_path / "slider.py").write_text(SIBLING)
    program = tmp_path / f"{name}.py"
    program.write_text("import slider\nbuild_world = slider.build_world\nread_quantities = slider.read_quantities\n"
                       + body)
    started = time.monotonic()
    line = refused(steadystep("audit", "--python", program, "--out", tmp_path / "out", "--time-limit", "1", *QUICK),
                   f"{name}.py", *words)
    assert time.monotonic() - started < 60, line
    assert not (tmp_path / "out").exists()


def test_a_pyode_world_audits_in_processes_of_its_own(tmp_path):
    """A world built with Debian's PyODE, whose objects free themselves in any order when collected: each run is a
    process of its own that ends without a collection, so none crashes, and imports no other binding than the
    program's (needs the package to take PyODE worlds)."""
    ode = pytest.importorskip("ode")
    steadystep_pyode = pytest.importorskip("steadystep.core.pyode")  # noqa: F841 - the binding's support, issue 29
    del ode
    program = tmp_path / "pyode_ball.py"
    program.write_text(textwrap.dedent('''
        import sys

        import ode
        from steadystep.audit import PythonWorld

        def build_world():
            assert "odepy" not in sys.modules, "the audit imported another binding"
            world = ode.World()
            world.setGravity((0, 0, -9.81))
            body = ode.Body(world)
            mass = ode.Mass()
            mass.setSphereTotal(1.0, 0.1)
            body.setMass(mass)
            body.setPosition((0, 0, 1))
            return PythonWorld(world=world, extra={"body": body})

        def read_quantities(world):
            return {"z_m": world.extra["body"].getPosition()[2]}

        def own_frame(world, time_s, frame_s):
            world.world.step(frame_s)
    '''))
    done = steadystep("audit", "--python", program, "--out", tmp_path / "out", "--duration", "0.5", "--profiles",
                      "fixed:60", "fixed:30", "--policies", "implicit-euler", "fixed", "--cost", "none",
                      "--no-diagnosis", timeout=300)
    assert done.returncode == 0, done.stderr
    metrics = json.loads((tmp_path / "out" / "metrics.json").read_text())
    assert metrics["variants"][0] == "own" and all(r["status"] == "ok" for r in metrics["runs"])


GOOD = ('fps=30; d=1\n'
        'while [ $# -gt 0 ]; do case "$1" in --profile) fps=${2#fixed:}; shift;; --duration) d=$2; shift;; esac; '
        'shift; done\n'
        'awk -v f="$fps" -v d="$d" \'BEGIN { print "t_s,x_m"; n = int(f * d + 0.5); '
        'for (i = 0; i <= n; i++) printf "%.17g,%.17g\\n", i / f, sin(i / f) }\'\n')


def script(directory: Path, name: str, body: str) -> Path:
    path = directory / name
    path.write_text("#!/bin/sh\n" + body)
    path.chmod(0o755)
    return path


def _running(pattern: str) -> list[str]:
    return subprocess.run(["pgrep", "-f", pattern], capture_output=True, text=True).stdout.split()


def test_a_programs_children_do_not_outlive_its_run(tmp_path):
    """Children left behind, in the program's group or in a session of their own (setsid), are killed when the run
    ends, though it ended well."""
    program = script(tmp_path, "leaves", "setsid sleep 61.75 >/dev/null 2>&1 &\n(sleep 62.75 &)\n" + GOOD)
    done = steadystep("audit", program, "--out", tmp_path / "out", *QUICK)
    assert done.returncode == 0, done.stderr
    time.sleep(0.2)
    assert _running("sleep 6[12].75") == []


def test_an_executables_output_is_bounded(tmp_path):
    program = script(tmp_path, "floods", "yes 0123456789\n")
    refused(steadystep("audit", program, "--out", tmp_path / "out", *QUICK), "floods", "bound of a run's output")


def test_cpu_time_counts_not_wall_time(tmp_path):
    """A run that sleeps less than the wall limit's idle guard but uses little CPU is not killed: the limit is CPU
    time (a busy machine does not make a working program bad)."""
    program = script(tmp_path, "slow", 'case "$*" in *fixed:1000*) sleep 1.3;; esac\n' + GOOD)
    done = steadystep("audit", program, "--out", tmp_path / "out", "--time-limit", "1", *QUICK)
    assert done.returncode == 0, done.stderr


def test_an_interrupted_audit_resumes(tmp_path):
    """Killed after some runs, the same command again runs only what had not finished: each finished run is kept in
    OUT/runs (written whole) and found again."""
    log = tmp_path / "invocations.log"
    program = script(tmp_path, "logs", f'echo "$*" >> {log}\nsleep 0.2\n' + GOOD)
    args = ["audit", program, "--out", tmp_path / "out", "--duration", "0.5", "--profiles", "fixed:30", "fixed:60",
            "--seeds", "1", "--policies", "naive", "implicit-euler", "fixed", "--executor", "serial", "--cost", "none",
            "--no-diagnosis"]
    process = subprocess.Popen([*COMMAND, *map(str, args)], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    while not (tmp_path / "out" / "runs").exists() or len(os.listdir(tmp_path / "out" / "runs")) < 4:
        time.sleep(0.05)
        assert process.poll() is None, "finished before it could be interrupted"
    process.send_signal(signal.SIGKILL)  # killed: no handler runs, what it finished must already be on disk
    process.wait(60)
    assert process.returncode == -signal.SIGKILL
    kept = sorted(os.listdir(tmp_path / "out" / "runs"))
    assert 4 <= len(kept) < 9 and not (tmp_path / "out" / "metrics.json").exists()
    first = log.read_text().splitlines()
    done = steadystep(*args)
    assert done.returncode == 0, done.stderr
    assert f"({len(kept)} finished runs kept in" in done.stdout
    again = log.read_text().splitlines()[len(first):]
    total = 2 + 3 * 2 + 1  # the reference, its check, three policies under two profiles, the repeat
    assert len(again) == total - len(kept), (len(again), total, len(kept))
    assert set(kept) <= set(os.listdir(tmp_path / "out" / "runs"))


def test_audit_writes_through_no_link(tmp_path):
    """Links planted in --out, to a file or dangling, are earlier files: refused without --force, and with it
    replaced by the audit's files, never written through (the figures' names too)."""
    program = script(tmp_path, "good", GOOD)
    out = tmp_path / "out"
    out.mkdir()
    victim = tmp_path / "victim.txt"
    victim.write_text("mine")
    (out / "metrics.json").symlink_to(victim)
    (out / "audit.html").symlink_to(tmp_path / "nowhere.html")
    (out / "metrics.csv").symlink_to(victim)
    (out / "audit_reference.png").symlink_to(tmp_path / "nowhere.png")
    refused(steadystep("audit", program, "--out", out, *QUICK), "symbolic link", "--force")
    done = steadystep("audit", program, "--out", out, "--force", *QUICK)
    assert done.returncode == 0, done.stderr
    assert victim.read_text() == "mine"
    assert not (tmp_path / "nowhere.html").exists() and not (tmp_path / "nowhere.png").exists()
    for name in ("metrics.json", "audit.html", "metrics.csv", "audit_reference.png"):
        assert not (out / name).is_symlink() and (out / name).stat().st_size > 0


def test_audit_refuses_a_linked_runs_directory(tmp_path):
    program = script(tmp_path, "good", GOOD)
    out = tmp_path / "out"
    out.mkdir()
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (out / "runs").symlink_to(elsewhere)
    refused(steadystep("audit", program, "--out", out, *QUICK), "runs", "symbolic link")
    assert list(elsewhere.iterdir()) == []


COMPARE = ["compare", "--scenes", "oscillator", "--profiles", "fixed:30", "--policies", "naive", "--duration", "0.2",
           "--executor", "serial"]


def test_compare_writes_through_no_link_and_replaces_only_when_forced(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    victim = tmp_path / "victim.txt"
    victim.write_text("mine")
    (out / "metrics.json").symlink_to(victim)
    (out / "article_figure.png").symlink_to(tmp_path / "nowhere.png")
    refused(steadystep(*COMPARE, "--out", out), "metrics.json", "earlier report", "--force")
    done = steadystep(*COMPARE, "--out", out, "--force", timeout=300)
    assert done.returncode == 0, done.stderr
    assert victim.read_text() == "mine" and not (tmp_path / "nowhere.png").exists()
    assert not any(path.is_symlink() for path in out.iterdir())
    before = (out / "report.html").read_bytes()
    refused(steadystep(*COMPARE, "--out", out), "report.html", "--force")
    assert (out / "report.html").read_bytes() == before


def test_probe_refuses_a_policy_that_takes_no_step():
    line = refused(steadystep("probe", "buggy", "--policies", "fixed", "--duration", "0.2", "--executor", "serial"),
                   "policy fixed takes no step", "0.25 s", "0.2 s")
    assert "internal error" not in line

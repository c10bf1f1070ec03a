"""`steadystep audit` on bad programs: each refused with exit 2, one line on stderr naming the program and what is
wrong, no traceback, and no file written; an earlier audit is not replaced unless --force."""

import subprocess
import sys
from pathlib import Path

import pytest

from steadystep.audit.run import BadProgram, parse_csv

SCRIPT = Path(sys.executable).parent / "steadystep"
COMMAND = [str(SCRIPT)] if SCRIPT.exists() else [sys.executable, "-m", "steadystep.cli"]
QUICK = ["--duration", "0.5", "--profiles", "fixed:30", "--seeds", "1", "--policies", "implicit-euler", "--executor",
         "serial"]


def audit(*args):
    return subprocess.run([*COMMAND, "audit", *map(str, args)], capture_output=True, text=True, timeout=120)


def script(directory: Path, name: str, body: str, executable: bool = True) -> Path:
    path = directory / name
    path.write_text("#!/bin/sh\n" + body)
    if executable:
        path.chmod(0o755)
    return path


def refused(done, *words) -> str:
    assert done.returncode == 2, (done.returncode, done.stderr)
    lines = done.stderr.splitlines()
    assert len(lines) == 1 and "Traceback" not in done.stderr, done.stderr
    for word in words:
        assert word in lines[0], (word, lines[0])
    return lines[0]


# A program that prints the protocol's CSV under fixed:FPS profiles: a row per frame of x = t (m).
GOOD = ('fps=30; d=1\n'
        'while [ $# -gt 0 ]; do case "$1" in --profile) fps=${2#fixed:}; shift;; --duration) d=$2; shift;; esac; '
        'shift; done\n'
        'awk -v f="$fps" -v d="$d" \'BEGIN { print "t_s,x_m"; n = int(f * d + 0.5); '
        'for (i = 0; i <= n; i++) printf "%.17g,%.17g\\n", i / f, i / f }\'\n')


@pytest.mark.parametrize("name, body, words", [
    ("nocsv", "exit 0\n", ["nocsv", "printed no CSV"]),
    ("malformed", "echo t_s,x_m; echo 0,0; echo 0.1,abc\n", ["malformed", "line 3", "not a number"]),
    ("nounit", "echo t_s,height; echo 0,0\n", ["'height'", "no unit"]),
    ("notime", "echo time,x_m; echo 0,0\n", ["not t_s"]),
    ("ragged", "echo t_s,x_m; echo 0,0; echo 0.1\n", ["line 3 has 1 fields"]),
    ("backwards", "echo t_s,x_m; echo 0,0; echo 0.2,0; echo 0.1,0\n", ["t_s goes back on line 4"]),
    ("crash", "echo t_s,x_m; kill -SEGV $$\n", ["crash", "signal 11 (SIGSEGV)"]),
    ("aborts", "kill -ABRT $$\n", ["signal 6 (SIGABRT)"]),
    ("refuses", "echo 'refuses: --policy: unknown flag' >&2; exit 2\n", ["exited 2", "unknown flag"]),
])
def test_bad_output_is_named(tmp_path, name, body, words):
    program = script(tmp_path, name, body)
    refused(audit(program, "--out", tmp_path / "out", *QUICK), *words)
    assert not (tmp_path / "out").exists()


def test_missing_and_not_executable(tmp_path):
    refused(audit(tmp_path / "nowhere", "--out", tmp_path / "out", *QUICK), "nowhere", "does not exist")
    plain = script(tmp_path, "plain", GOOD, executable=False)
    refused(audit(plain, "--out", tmp_path / "out", *QUICK), "plain", "is not executable")
    good = script(tmp_path, "good", GOOD)
    refused(audit(good, "--own", plain, "--out", tmp_path / "out", *QUICK), "--own", "is not executable")
    refused(audit(tmp_path, "--out", tmp_path / "out", *QUICK), "is a directory")
    refused(audit("--python", tmp_path / "none.py", "--out", tmp_path / "out", *QUICK), "none.py",
            "does not exist")
    no_functions = tmp_path / "empty.py"
    no_functions.write_text("x = 1\n")
    refused(audit("--python", no_functions, "--out", tmp_path / "out", *QUICK), "build_world()")
    assert not (tmp_path / "out").exists()


def test_usage_errors(tmp_path):
    good = script(tmp_path, "good", GOOD)
    refused(audit("--out", tmp_path / "out", *QUICK), "PROGRAM", "--python")
    refused(audit("--python", tmp_path / "x.py", "--own", good, "--out", tmp_path / "out", *QUICK), "--own",
            "own_frame")
    refused(audit(good, "--out", tmp_path / "out", "--profiles", "uniform:45:15"), "uniform:45:15")
    refused(audit(good, "--out", tmp_path / "out", "--policies", "sideways"), "sideways")
    refused(audit(good, "--out", tmp_path / "out", "--duration", "-1"), "-1")
    assert not (tmp_path / "out").exists()
    help_text = audit("--help")
    assert help_text.returncode == 0 and "usage: steadystep audit" in help_text.stdout


def test_a_hang_is_killed_at_the_time_limit(tmp_path):
    program = script(tmp_path, "hang", "sleep 61.25 & wait\n")  # a child of its own too
    done = audit(program, "--out", tmp_path / "out", "--time-limit", "0.5", *QUICK)
    refused(done, "hang", "time limit of 0.5 s", "--time-limit", "killed")
    # killed with its process group: neither the script nor its sleep left running
    left = subprocess.run(["pgrep", "-f", f"{program}|sleep 61.25"], capture_output=True, text=True).stdout.split()
    assert left == [], left


def test_a_program_that_ignores_the_profile(tmp_path):
    program = script(tmp_path, "deaf", "echo t_s,x_m; echo 0,0; echo 0.25,0.25; echo 0.5,0.5\n")
    refused(audit(program, "--out", tmp_path / "out", *QUICK), "fixed:1000", "printed 2 frames, not the profile's 500",
            "does not follow --profile")


def test_a_failed_frame_is_a_status_not_a_refusal(tmp_path):
    """Exit 1 after some rows: the run failed (shown as such), the audit goes on."""
    body = ('case "$*" in *"fixed:30"*"--policy naive"*) echo t_s,x_m; echo 0,0; echo "blew up" >&2; exit 1;; '
            'esac\n' + GOOD)
    program = script(tmp_path, "fails", body)
    done = audit(program, "--out", tmp_path / "out", "--duration", "0.5", "--profiles", "fixed:30", "fixed:60",
                 "--seeds", "1", "--policies", "naive", "implicit-euler")
    assert done.returncode == 0, done.stderr
    assert "Avoid: naive failed under fixed:30 seed 1" in done.stdout


def test_an_earlier_audit_is_kept_unless_forced(tmp_path):
    program = script(tmp_path, "good", GOOD)
    out = tmp_path / "out"
    assert audit(program, "--out", out, *QUICK).returncode == 0
    before = (out / "metrics.json").read_bytes()
    (out / "audit.html").write_text("mine")
    refused(audit(program, "--out", out, *QUICK), "audit.html", "--force")
    assert (out / "audit.html").read_text() == "mine" and (out / "metrics.json").read_bytes() == before
    assert audit(program, "--out", out, "--force", *QUICK).returncode == 0
    assert (out / "audit.html").read_text() != "mine"


def test_count_columns():
    columns = parse_csv("t_s,x_m,steps,rows_by_mapping\n0,1,0,0\n0.1,1,2,-1\n0.2,1,3,-1\n", "p")
    assert list(columns) == ["t_s", "x_m", "steps"]  # -1 on every frame: not counted, left out
    with pytest.raises(BadProgram, match="steps holds a value that is not a whole number"):
        parse_csv("t_s,x_m,steps\n0,1,0\n0.1,1,1.5\n", "p")

"""scripts/deps.sh without a Debian package it needs and without root (issue 28): one line on stderr naming the
missing package and the apt-get command that installs it, exit 2, no traceback, and nothing installed or made.

Nothing is uninstalled: the package is made to look missing by a pkg-config first on PATH that knows no `ode`
(deps.sh asks `pkg-config --exists ode` for libode-dev, and passes every other question to the real one), and
root is left by running the script as nobody (setpriv), or as the user running the tests when that is not root.
"""

import os
import shutil
import subprocess
import tempfile
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
SETPRIV = shutil.which("setpriv")

pytestmark = pytest.mark.skipif(os.geteuid() == 0 and SETPRIV is None,
                                reason="running as root without setpriv: no way to run deps.sh as another user")


def _as_non_root(command: list[str]) -> list[str]:
    if os.geteuid() != 0:
        return command
    return [SETPRIV, "--reuid=65534", "--regid=65534", "--clear-groups", *command]


@pytest.fixture
def no_libode_dev():
    """A PATH whose first pkg-config answers no to `--exists ode` and hands everything else to the real one (in a
    directory of its own that nobody can read too: pytest's tmp_path is private to the user running the tests)."""
    home = Path(tempfile.mkdtemp(prefix="steadystep-deps-"))
    home.chmod(0o755)
    shim = home / "bin"
    shim.mkdir()
    real = shutil.which("pkg-config")
    fake = shim / "pkg-config"
    fake.write_text("#!/bin/sh\n"
                    "case \" $* \" in *' --exists ode '*) exit 1;; esac\n"
                    + (f"exec {real} \"$@\"\n" if real else "exit 1\n"))
    fake.chmod(0o755)
    yield {**os.environ, "PATH": f"{shim}:{os.environ['PATH']}", "HOME": str(home)}
    shutil.rmtree(home)


def _one_line(done: subprocess.CompletedProcess) -> str:
    assert done.returncode == 2, (done.returncode, done.stdout, done.stderr)
    assert "Traceback" not in done.stderr and "Traceback" not in done.stdout
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1, done.stderr
    return lines[0]


def test_deps_without_libode_dev_and_without_root_names_the_package_and_the_command(no_libode_dev):
    venv_before = (REPO / ".venv").exists()
    done = subprocess.run(_as_non_root(["bash", str(REPO / "scripts" / "deps.sh")]), capture_output=True,
                          text=True, timeout=60, env=no_libode_dev, cwd="/")
    line = _one_line(done)
    assert line.startswith("steadystep: missing Debian packages ") and "libode-dev" in line, line
    packages = line[len("steadystep: missing Debian packages "):].split(":")[0].split()
    assert "libode-dev" in packages
    assert f"sudo apt-get install -y {' '.join(packages)}" in line, line
    assert done.stdout == ""  # nothing was installed: no "installing" line
    assert (REPO / ".venv").exists() == venv_before


def test_scripts_that_source_deps_stop_with_its_exit_code(no_libode_dev):
    """scripts/report sources deps.sh: it stops with 2 too, its last line deps.sh's, before running anything."""
    done = subprocess.run(_as_non_root(["bash", str(REPO / "scripts" / "report")]), capture_output=True, text=True,
                          timeout=60, env=no_libode_dev, cwd="/")
    assert done.returncode == 2, (done.returncode, done.stderr)
    assert "Traceback" not in done.stderr
    assert done.stderr.strip().splitlines()[-1].startswith("steadystep: missing Debian packages ")
    assert "report written" not in done.stdout

"""Errors a newcomer meets name the fix (issue 28): without libode.so.8, or without a module of the report extra, the
command says in one line what is missing and the Debian or pip package that provides it, and exits 2, with no
traceback. Nothing is uninstalled: libode is made unloadable by an empty libode.so.8 found first on LD_LIBRARY_PATH,
and a module by a sitecustomize on PYTHONPATH that makes its import fail."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

STEADYSTEP = Path(sys.executable).with_name("steadystep")


def _run(args, **env) -> subprocess.CompletedProcess:
    return subprocess.run(args, capture_output=True, text=True, timeout=120, env={**os.environ, **env})


@pytest.fixture
def no_libode(tmp_path):
    (tmp_path / "libode.so.8").write_bytes(b"")  # found first by the loader, and not a library
    return {"LD_LIBRARY_PATH": f"{tmp_path}:{os.environ.get('LD_LIBRARY_PATH', '')}".rstrip(":")}


def _one_line(done: subprocess.CompletedProcess) -> str:
    assert done.returncode == 2, (done.returncode, done.stderr)
    assert "Traceback" not in done.stderr and len(done.stderr.splitlines()) == 1, done.stderr
    return done.stderr.strip()


@pytest.mark.parametrize("args", [["--version"], ["convert", "--erp", "0.2", "--cfm", "1e-5", "--step", "0.01"]])
def test_the_command_without_libode_names_the_debian_package(no_libode, args):
    line = _one_line(_run([str(STEADYSTEP), *args], **no_libode))
    assert line.startswith("steadystep: cannot load libode.so.8") and "libode8" in line and "libode-dev" in line


def test_python_m_without_libode_is_one_line_too(no_libode):
    line = _one_line(_run([sys.executable, "-m", "steadystep.cli", "--version"], **no_libode))
    assert "apt-get install libode8" in line


def test_importing_without_libode_raises_an_import_error_naming_the_package(no_libode):
    done = _run([sys.executable, "-c", "import steadystep"], **no_libode)
    assert done.returncode == 1
    assert done.stderr.strip().splitlines()[-1].startswith(
        "steadystep.core._native.MissingLibrary: steadystep: cannot load libode.so.8")
    assert "libode8" in done.stderr


def _without(tmp_path, *modules) -> dict:
    shim = tmp_path / "shim"
    shim.mkdir()
    (shim / "sitecustomize.py").write_text("import sys\n" + "".join(f"sys.modules[{m!r}] = None\n" for m in modules))
    return {"PYTHONPATH": os.pathsep.join(p for p in (str(shim), os.environ.get("PYTHONPATH", "")) if p)}


@pytest.mark.parametrize("missing", ["jinja2", "tqdm", "matplotlib"])
def test_compare_without_a_module_of_the_report_extra_names_the_pip_extra(tmp_path, missing):
    line = _one_line(_run([str(STEADYSTEP), "compare", "--out", str(tmp_path / "out"), "--scenes", "oscillator"],
                          **_without(tmp_path, missing)))
    assert line == (f"steadystep compare: needs the report extra, {missing} not installed: "
                    "pip install 'steadystep[report]'")
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("missing", ["jinja2", "matplotlib"])
def test_audit_without_a_module_of_the_report_extra_names_the_pip_extra(tmp_path, missing):
    line = _one_line(_run([str(STEADYSTEP), "audit", "program", "--out", str(tmp_path / "out")],
                          **_without(tmp_path, missing)))
    assert line == (f"steadystep audit: needs the report extra, {missing} not installed: "
                    "pip install 'steadystep[report]'")
    assert not (tmp_path / "out").exists()


def test_figure_needs_matplotlib_only(tmp_path):
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    assert _run([str(STEADYSTEP), "figure", "--out", str(tmp_path), "--duration", "0.5"],
                **_without(tmp_path / "a", "jinja2", "tqdm")).returncode == 0
    line = _one_line(_run([str(STEADYSTEP), "figure", "--out", str(tmp_path)], **_without(tmp_path / "b", "matplotlib")))
    assert line == "steadystep figure: needs the report extra, matplotlib not installed: pip install 'steadystep[report]'"

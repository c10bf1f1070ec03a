"""Where the command's output goes is left as it was: a file path that is a FIFO, a symlink or a character device is
written through (in place), never replaced by a regular file; a failure names the path as given; standard output
closed or full is the one-line exit 2; and every --executor that cannot be had (a silent peer, a scheduler with no
workers, ucx://, tls://, a peer speaking another protocol) is the one-line exit 2 within a bounded wait.

Devices are only ever reached through symlinks or nodes made in a temporary directory: no test writes a path
under /dev itself, so that a regression could only replace a file of the test's own."""

import os
import socket
import stat
import subprocess
import sys
import threading
import time

import pytest

from test_cli import COMMAND, no_temporaries, steadystep

RUN = ["run", "oscillator", "--profile", "fixed:60", "--policy", "naive", "--duration", "0.1"]


def expected_csv() -> str:
    result = steadystep(*RUN)
    assert result.returncode == 0, result.stderr
    return result.stdout


def test_a_symlink_is_written_through_and_stays_a_symlink(tmp_path):
    target = tmp_path / "real.csv"
    target.write_text("old\n")
    target.chmod(0o600)
    link = tmp_path / "link.csv"
    link.symlink_to(target)
    result = steadystep(*RUN, "--csv", link)
    assert result.returncode == 0, result.stderr
    assert link.is_symlink() and os.readlink(link) == str(target)
    assert target.read_text() == expected_csv()
    assert stat.S_IMODE(target.stat().st_mode) == 0o600  # the file's own mode kept
    assert no_temporaries(tmp_path)


def test_a_fifo_is_written_in_place(tmp_path):
    fifo = tmp_path / "pipe.csv"
    os.mkfifo(fifo)
    received = []
    reader = threading.Thread(target=lambda: received.append(fifo.read_text()), daemon=True)
    reader.start()
    result = steadystep(*RUN, "--csv", fifo)
    reader.join(30)
    assert result.returncode == 0, result.stderr
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)
    assert received == [expected_csv()]
    assert no_temporaries(tmp_path)


def test_a_null_device_is_written_in_place(tmp_path):
    # Through a symlink to /dev/null, and, as root, a null device node of the test's own (mknod, major 1 minor 3).
    link = tmp_path / "null-link.csv"
    link.symlink_to(os.devnull)
    paths = [link]
    if os.geteuid() == 0:
        node = tmp_path / "null-node.csv"
        os.mknod(node, 0o666 | stat.S_IFCHR, os.makedev(1, 3))
        paths.append(node)
    for path in paths:
        result = steadystep(*RUN, "--csv", path)
        assert result.returncode == 0, result.stderr
    assert link.is_symlink() and stat.S_ISCHR(os.stat(link).st_mode)
    if len(paths) == 2:
        assert stat.S_ISCHR(os.lstat(paths[1]).st_mode)
    assert no_temporaries(tmp_path)


def test_a_full_device_is_a_refusal_naming_the_path(tmp_path):
    link = tmp_path / "full.csv"
    link.symlink_to("/dev/full")
    result = steadystep(*RUN, "--csv", link)
    assert result.returncode == 2 and result.stderr.count("\n") == 1
    assert str(link) in result.stderr and "No space left" in result.stderr
    assert ".tmp" not in result.stderr and link.is_symlink()


def test_a_failed_write_names_the_path_not_the_temporary_file(tmp_path):
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o500)
    try:
        result = steadystep(*RUN, "--csv", locked / "out.csv")
        if os.geteuid() == 0:  # root writes anyway: the write must then have worked
            assert result.returncode == 0 and (locked / "out.csv").read_text() == expected_csv()
        else:
            assert result.returncode == 2 and str(locked / "out.csv") in result.stderr
            assert ".tmp" not in result.stderr
    finally:
        locked.chmod(0o700)
    directory = tmp_path / "a-directory.csv"
    directory.mkdir()
    result = steadystep(*RUN, "--csv", directory)
    assert result.returncode == 2 and str(directory) in result.stderr and directory.is_dir()


@pytest.mark.parametrize("args", [
    ["convert", "--k", "40", "--c", "1", "--dt", "0.02"], RUN, ["probe", "oscillator", "--executor", "serial"],
    ["figure", "--out", "{tmp}"], ["compare", "--out", "{tmp}", "--scenes", "oscillator"]])
def test_every_command_with_stdout_closed_is_a_refusal(tmp_path, args):
    args = [str(a).replace("{tmp}", str(tmp_path / "out")) for a in args]
    result = subprocess.run([*COMMAND, *args], stdout=subprocess.DEVNULL, capture_output=False, text=True,
                            stderr=subprocess.PIPE, timeout=120, close_fds=True,
                            preexec_fn=lambda: os.close(1))
    assert result.returncode == 2, result.stderr
    assert result.stderr.count("\n") == 1 and "standard output is closed" in result.stderr
    assert not (tmp_path / "out").exists()  # refused before any work


def test_stdout_full_is_a_refusal():
    with open("/dev/full", "w") as full:
        result = subprocess.run([*COMMAND, *RUN], stdout=full, stderr=subprocess.PIPE, text=True, timeout=120)
    assert result.returncode == 2 and result.stderr.count("\n") == 1, result.stderr
    assert "No space left" in result.stderr and "internal error" not in result.stderr


# ---- executors that cannot be had ----------------------------------------------------------------------------

def _listening(serve) -> int:
    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen(8)

    def accept_all():
        kept = []
        while True:
            connection, _ = server.accept()
            kept.append(connection)  # held open: the peer neither closes nor speaks unless serve() does
            serve(connection)

    threading.Thread(target=accept_all, daemon=True).start()
    return server.getsockname()[1]


def _free_port() -> int:
    with socket.socket() as probe_socket:
        probe_socket.bind(("127.0.0.1", 0))
        return probe_socket.getsockname()[1]


@pytest.fixture
def scheduler_without_workers():
    port = _free_port()
    process = subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1",
                                "--port", str(port), "--no-dashboard"], stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        try:
            socket.create_connection(("127.0.0.1", port), timeout=1).close()
            break
        except OSError:
            time.sleep(0.2)
    yield f"tcp://127.0.0.1:{port}"
    process.terminate()
    process.wait(30)


def _refused_in_bounded_time(spec: str, *names: str):
    started = time.monotonic()
    result = steadystep("probe", "oscillator", "--duration", "0.1", "--executor", spec)
    waited = time.monotonic() - started
    assert result.returncode == 2, result.stderr
    assert result.stderr.count("\n") == 1 and "Traceback" not in result.stderr
    assert "internal error" not in result.stderr and f"executor = {spec!r}" in result.stderr
    assert all(name in result.stderr for name in names), result.stderr
    assert waited < 60  # the study's own timeouts are 10 s to connect and 10 s for a worker
    return result


def test_a_silent_peer_is_refused_within_the_timeout():
    port = _listening(lambda connection: None)
    _refused_in_bounded_time(f"dask:tcp://127.0.0.1:{port}", "no answer within 10 s")


def test_a_peer_speaking_another_protocol_is_refused():
    port = _listening(lambda connection: connection.sendall(b"HTTP/1.1 400 Bad Request\r\n\r\n" * 64))
    _refused_in_bounded_time(f"dask:tcp://127.0.0.1:{port}", "cannot reach the Dask scheduler")


def test_a_scheduler_without_workers_is_refused_within_the_timeout(scheduler_without_workers):
    _refused_in_bounded_time(f"dask:{scheduler_without_workers}", "has no workers")


@pytest.mark.parametrize("address", ["ucx://127.0.0.1:8786", "tls://127.0.0.1:8786"])
def test_transports_that_cannot_be_used_are_refused(address):
    _refused_in_bounded_time(f"dask:{address}", address)

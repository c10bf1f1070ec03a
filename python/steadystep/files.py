"""Writing output files without changing what their path is.

A regular file (or a path that does not exist yet) is written whole or not at all: to a temporary name in its own
directory, then renamed over it, so a reader (or a crash) never sees half a file. Through a symlink, the file it
points to is written that way and the symlink stays. Anything else at the path (a character device such as
/dev/null or /dev/full, a FIFO) is written in place, as a shell redirection would: renaming over it would replace
the device node or the pipe with a regular file. A failure raises OSError naming the path as given, never the
temporary file.

A file a command makes in its output directory (`compare`, `audit`, `figure` --out: pages, metrics, figures) is not
a path the user named: write_output_bytes writes it whole the same way, but whatever is at its name (a symbolic link
to a file or dangling, a device, a FIFO) is replaced, never written through, and a directory there is refused.
"""

from __future__ import annotations

import errno
import io
import os
import stat
import tempfile
from pathlib import Path


def write_bytes(path: str | Path, data: bytes) -> Path:
    """Writes data to path (see the module's docstring) and returns path. The directory must exist."""
    given = Path(path)
    try:
        _write(Path(os.path.realpath(given)), data)
    except OSError as error:
        raise OSError(error.errno, error.strerror or str(error), str(given)) from None
    return given


def _write(target: Path, data: bytes) -> None:
    try:
        mode = os.stat(target).st_mode
    except FileNotFoundError:
        mode = None
    if mode is not None and stat.S_ISDIR(mode):
        raise IsADirectoryError(errno.EISDIR, os.strerror(errno.EISDIR))
    if mode is not None and not stat.S_ISREG(mode):
        with open(target, "wb") as out:  # a device or a FIFO (which waits for its reader): in place
            out.write(data)
        return
    handle, temporary = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
    try:
        with os.fdopen(handle, "wb") as out:
            out.write(data)
        os.chmod(temporary, stat.S_IMODE(mode) if mode is not None else 0o644)
        os.replace(temporary, target)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise


def write_output_bytes(path: str | Path, data: bytes) -> Path:
    """Writes data to path, a file of a command's output directory (see the module's docstring): a link or any
    other file at path is replaced by the new file, never written through. Returns path. The directory must exist."""
    given = Path(path)
    try:
        try:
            mode = os.lstat(given).st_mode
        except FileNotFoundError:
            mode = None
        if mode is not None and stat.S_ISDIR(mode):
            raise IsADirectoryError(errno.EISDIR, os.strerror(errno.EISDIR))
        handle, temporary = tempfile.mkstemp(prefix=f".{given.name}.", suffix=".tmp", dir=given.parent)
        try:
            with os.fdopen(handle, "wb") as out:
                out.write(data)
            os.chmod(temporary, 0o644)
            os.replace(temporary, given)  # rename(2) replaces a link itself, never what it points to
        except BaseException:
            Path(temporary).unlink(missing_ok=True)
            raise
    except OSError as error:
        raise OSError(error.errno, error.strerror or str(error), str(given)) from None
    return given


def write_output_text(path: str | Path, content: str) -> Path:
    """write_output_bytes of text (UTF-8, lone surrogates as their backslash escapes)."""
    return write_output_bytes(path, content.encode("utf-8", errors="backslashreplace"))


def atomic_write_text(path: str | Path, content: str) -> Path:
    """Writes text (UTF-8) to path. A lone surrogate (an argument that was not UTF-8, quoted in a report) is written
    as its backslash escape rather than failing the write."""
    return write_bytes(path, content.encode("utf-8", errors="backslashreplace"))


def save_figure(figure, path: str | Path) -> Path:
    """Saves a matplotlib figure to path, a file of an output directory (write_output_bytes); the format follows
    path's suffix (.png, .svg)."""
    path = Path(path)
    buffer = io.BytesIO()
    figure.savefig(buffer, format=path.suffix[1:], dpi=150)
    return write_output_bytes(path, buffer.getvalue())

"""Writing output files whole or not at all: each is written to a temporary name in its own directory and renamed
over the target, so a reader (or a crash) never sees half a file."""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable
from pathlib import Path


def atomic_write(path: str | Path, write: Callable[[Path], None]) -> Path:
    """Calls write(temporary_path) and renames the result to path. The directory must exist."""
    path = Path(path)
    handle, temporary = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp" + path.suffix, dir=path.parent)
    os.close(handle)
    try:
        write(Path(temporary))
        os.chmod(temporary, 0o644)
        os.replace(temporary, path)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise
    return path


def atomic_write_text(path: str | Path, content: str) -> Path:
    """Writes text (UTF-8) to path atomically. A lone surrogate (an argument that was not UTF-8, quoted in a report)
    is written as its backslash escape rather than failing the write."""
    return atomic_write(path, lambda temporary: temporary.write_text(content, encoding="utf-8",
                                                                       errors="backslashreplace"))


def save_figure(figure, path: str | Path) -> Path:
    """Saves a matplotlib figure atomically; the format follows path's suffix (.png, .svg)."""
    path = Path(path)
    return atomic_write(path, lambda temporary: figure.savefig(temporary, format=path.suffix[1:], dpi=150))

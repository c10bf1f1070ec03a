"""The binding to libsteadystep: cffi in ABI mode over the packaged headers.

The headers are the one source of truth for every struct and function: they are read from the wheel's
``_native/include`` directory at import time, stripped of what cffi's parser does not take (preprocessor lines,
``extern "C"`` braces) and handed to ``ffi.cdef``. Nothing is re-typed here, so a field added in C reaches Python
with the next build. ``registry.h`` and ``stepper.h`` need ODE's types and are not read whole; only the two enums
(policy, solver) and the policy name functions are taken from ``stepper.h``, again verbatim.
"""

from __future__ import annotations

import re
from pathlib import Path

import cffi

_HERE = Path(__file__).resolve().parent / "_native"
INCLUDE_DIR = _HERE / "include" / "steadystep"
LIBRARY_PATH = _HERE / "libsteadystep.so"

# The headers cffi reads whole, in dependency order.
_WHOLE_HEADERS = ("status.h", "spring.h", "profile.h", "scene.h")
# Declarations taken verbatim from stepper.h (the rest of it needs ODE's types).
_STEPPER_ENUMS = ("ssPolicy", "ssSolver")
_STEPPER_FUNCTIONS = ("ssPolicyName", "ssPolicyParse")

_INTEGER_DEFINE = re.compile(r"^\s*#\s*define\s+(\w+)\s+(\d+)\s*$")


def _strip_comments(text: str) -> str:
    return re.sub(r"/\*.*?\*/|//[^\n]*", " ", text, flags=re.S)


def _declarations(text: str) -> str:
    """The header's C declarations: integer #defines kept (cffi understands them), other preprocessor lines and
    the extern "C" wrapper dropped."""
    kept = []
    for line in _strip_comments(text).splitlines():
        define = _INTEGER_DEFINE.match(line)
        if define:
            kept.append(f"#define {define.group(1)} {define.group(2)}")
        elif line.lstrip().startswith("#"):
            continue
        elif line.strip() in ('extern "C" {', "}"):
            # A lone "}" only closes the extern "C" block: struct and enum bodies close with "} name;".
            continue
        else:
            kept.append(line)
    return "\n".join(kept)


def _stepper_declarations(text: str) -> str:
    text = _strip_comments(text)
    parts = []
    for name in _STEPPER_ENUMS:
        match = re.search(r"typedef\s+enum\s+" + name + r"\s*\{.*?\}\s*" + name + r"\s*;", text, flags=re.S)
        if not match:
            raise ImportError(f"stepper.h: enum {name} not found in {INCLUDE_DIR}")
        parts.append(match.group(0))
    for name in _STEPPER_FUNCTIONS:
        match = re.search(r"[^;{}]*\b" + name + r"\s*\([^;]*\)\s*;", text, flags=re.S)
        if not match:
            raise ImportError(f"stepper.h: function {name} not found in {INCLUDE_DIR}")
        parts.append(match.group(0).strip())
    return "\n".join(parts)


def _cdef_source() -> str:
    sources = []
    for header in _WHOLE_HEADERS:
        sources.append(_declarations((INCLUDE_DIR / header).read_text()))
        if header == "spring.h":
            # scene.h's ssStepping holds policy and solver as ints; the enums come right after spring.h.
            sources.append(_stepper_declarations((INCLUDE_DIR / "stepper.h").read_text()))
    return "\n".join(sources)


ffi = cffi.FFI()
ffi.cdef(_cdef_source())
lib = ffi.dlopen(str(LIBRARY_PATH))


class SteadystepError(ValueError):
    """A failure reported by libsteadystep: ``status`` is the ssStatus name ("out of range", ...), ``code`` its
    value, and the message is the library's one line naming the value at fault."""

    def __init__(self, status: str, message: str, code: int = 0):
        super().__init__(message)
        self.status = status
        self.code = code
        self.message = message

    def __str__(self) -> str:
        return f"{self.message} ({self.status})" if self.message else self.status


def status_name(code: int) -> str:
    return ffi.string(lib.ssStatusName(code)).decode()


def last_error() -> str:
    return ffi.string(lib.ssLastError()).decode()


def check(code: int) -> None:
    """Raises SteadystepError for any status but SS_OK, with the thread's last message."""
    if code != lib.SS_OK:
        raise SteadystepError(status_name(code), last_error(), int(code))


def text(pointer) -> str | None:
    """A C string as str; None for NULL."""
    return None if pointer == ffi.NULL else ffi.string(pointer).decode()

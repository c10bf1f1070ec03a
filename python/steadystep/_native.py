"""The binding to libsteadystep: cffi in ABI mode over the packaged headers.

The headers are the one source of truth for every struct and function: they are read from the wheel's
``_native/include`` directory at import time, stripped of what cffi's parser does not take (preprocessor lines,
``extern "C"`` braces) and handed to ``ffi.cdef``. Nothing is re-typed here, so a field added in C reaches Python
with the next build. The headers read here (up to ``scene.h``) use no ODE types; ``stepping.h`` holds the stepper's
settings, so the lab and Python share the one struct and its validator.
"""

from __future__ import annotations

import re
from pathlib import Path

import cffi

_HERE = Path(__file__).resolve().parent / "_native"
INCLUDE_DIR = _HERE / "include" / "steadystep"
# The lab library: the core and the lab in one shared object (the core alone, libsteadystep, is for C programs).
LIBRARY_PATH = _HERE / "libsteadystep_lab.so"

# The headers cffi reads whole, in dependency order.
_WHOLE_HEADERS = ("status.h", "spring.h", "stepping.h", "lab/profile.h", "lab/scene.h")

_INTEGER_DEFINE = re.compile(r"^\s*#\s*define\s+(\w+)\s+(\d+)\s*$")
# The export marks (steadystep/export.h, steadystep/lab/export.h) expand to attributes cffi does not parse.
_EXPORT_MARK = re.compile(r"\bSS_(?:LAB_)?API\b")


def _strip_comments(text: str) -> str:
    return re.sub(r"/\*.*?\*/|//[^\n]*", " ", text, flags=re.S)


def _declarations(text: str) -> str:
    """The header's C declarations: integer #defines kept (cffi understands them), other preprocessor lines and
    the extern "C" wrapper and the export marks dropped."""
    kept = []
    for line in _EXPORT_MARK.sub("", _strip_comments(text)).splitlines():
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


def _cdef_source() -> str:
    return "\n".join(_declarations((INCLUDE_DIR / header).read_text()) for header in _WHOLE_HEADERS)


ffi = cffi.FFI()
ffi.cdef(_cdef_source())

# ---- the core for a program's own ODE world (registry, adoption, stepper) ------------------------------------------
# These headers take ODE's handles. ODE's own headers are not read: cffi needs only the handles' names, as opaque
# pointers (the Python side passes addresses, e.g. of an odepy world), dReal (a double build, as Debian's) and
# dContact, which the library reads and writes through a pointer only. limits.h brings the integer bounds
# (SS_MAX_RUN_STEPS ...); its floating-point #defines are not kept (cffi's ABI mode takes integer constants only).
_ODE_HANDLES = """
typedef struct dxWorld* dWorldID;
typedef struct dxBody* dBodyID;
typedef struct dxJoint* dJointID;
typedef struct dxSpace* dSpaceID;
typedef struct dxJointGroup* dJointGroupID;
typedef double dReal;
typedef struct dContact dContact;
"""
_CORE_HEADERS = ("limits.h", "registry.h", "adopt.h", "stepper.h", "interpolation.h")


def _core_cdef_source() -> str:
    return _ODE_HANDLES + "\n".join(_declarations((INCLUDE_DIR / header).read_text()) for header in _CORE_HEADERS)


ffi.cdef(_core_cdef_source())
# ---- end of the core for a program's own world ----------------------------------------------------------------------

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

    def __reduce__(self):
        # Pickled by its three fields (the default would call it with the message alone): a study's worker process
        # hands its refusal back to the caller this way.
        return type(self), (self.status, self.message, self.code)


def _decode(raw: bytes) -> str:
    # C messages are cut at 255 bytes, possibly inside a UTF-8 character, and may quote bytes from a file or an
    # argument that are not UTF-8 at all: such bytes become U+FFFD instead of an exception.
    return raw.decode("utf-8", errors="replace")


_CONTROL = re.compile(r"[\x00-\x1f\x7f-\x9f]")


def one_line(message: str) -> str:
    """message as one printable line: control characters (a newline, an escape sequence quoted from a binary
    file) as \\xNN escapes, so that a message can neither span lines nor drive the terminal."""
    return _CONTROL.sub(lambda match: f"\\x{ord(match.group()):02x}", message)


def status_name(code: int) -> str:
    return _decode(ffi.string(lib.ssStatusName(code)))


def last_error() -> str:
    return one_line(_decode(ffi.string(lib.ssLastError())))


def check(code: int) -> None:
    """Raises SteadystepError for any status but SS_OK, with the thread's last message."""
    if code != lib.SS_OK:
        raise SteadystepError(status_name(code), last_error(), int(code))


def text(pointer) -> str | None:
    """A C string as str (bytes that are not UTF-8 replaced by U+FFFD); None for NULL."""
    return None if pointer == ffi.NULL else _decode(ffi.string(pointer))


def printable(value: str) -> str:
    """value as text that any UTF-8 stream or file takes: arguments that were not UTF-8 reach Python as lone
    surrogates (surrogateescape), which print as U+FFFD here; any other lone surrogate as a backslash escape."""
    try:
        return value.encode("utf-8", "surrogateescape").decode("utf-8", "replace")
    except UnicodeEncodeError:
        return value.encode("utf-8", "backslashreplace").decode("utf-8")


def c_string(name: str, value) -> bytes:
    """value as the bytes of a C string for the parameter called name.

    Text that came from bytes that are not UTF-8 (surrogateescape, as in sys.argv and os.fsdecode) goes back to
    those bytes, so that a file name reaches C as it is on disk. Raises SteadystepError naming the value for
    anything that is not a str or bytes, for an embedded NUL (C would read only the text before it) and for text
    that has no bytes (a lone surrogate from elsewhere)."""
    if isinstance(value, str):
        try:
            raw = value.encode("utf-8", "surrogateescape")
        except UnicodeEncodeError:
            raise SteadystepError("out of range", f"{name} = {shown(value)}: has characters that are not text "
                                  "(lone surrogates)") from None
    elif isinstance(value, (bytes, bytearray)):
        raw = bytes(value)
    else:
        raise SteadystepError("out of range", f"{name} = {shown(value)}: must be a string")
    if b"\0" in raw:
        raise SteadystepError("out of range", f"{name} = {shown(value)}: contains a NUL character")
    return raw


def number(name: str, value, unit: str = "") -> float:
    """value as a float for the parameter called name; SteadystepError naming it when it is not a number."""
    if isinstance(value, (str, bytes, bytearray)):
        raise SteadystepError("out of range", f"{name} = {shown(value)}: must be a number{_unit(unit)}")
    try:
        return float(value)
    except (TypeError, ValueError, OverflowError):
        raise SteadystepError("out of range", f"{name} = {shown(value)}: must be a number{_unit(unit)}"
                              ) from None


def integer(name: str, value, low: int, high: int) -> int:
    """value as an int in [low, high] for the parameter called name; SteadystepError naming it otherwise."""
    if isinstance(value, bool) or not hasattr(value, "__index__"):
        raise SteadystepError("out of range", f"{name} = {shown(value)}: must be an integer")
    value = value.__index__()
    if not low <= value <= high:
        raise SteadystepError("out of range", f"{name} = {shown(value)}: must be in [{low}, {high}]")
    return value


def _unit(unit: str) -> str:
    return f" ({unit})" if unit else ""


def shown(value) -> str:
    """value for a message: its repr, cut to 80 characters (a message is one line, whatever it quotes)."""
    try:
        quoted = repr(value)
    except ValueError:  # an int too long to print in decimal
        return f"<an integer of {value.bit_length()} bits>" if isinstance(value, int) else "<unprintable>"
    except Exception:  # a foreign object whose repr fails: the message still has to be written
        return f"<a {type(value).__name__}>"
    return quoted if len(quoted) <= 80 else quoted[:77] + "..."

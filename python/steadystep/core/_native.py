"""The binding to libsteadystep: cffi in ABI mode, its declarations prepared from the headers when the package is
built.

The headers are the one source of truth for every struct and function: the build (CMakeLists.txt, STEADYSTEP_PYTHON)
runs ``core/_cdef_build.py`` over them and installs the result as ``steadystep/core/_native_ffi.py``, cffi's out-of-line
ABI module, which ``_cffi_backend`` loads without parsing anything. Nothing is typed again here, so a field added in C
reaches Python with the next build.
"""

from __future__ import annotations

import os

from steadystep.core._native_ffi import ffi

# The lab library: the core and the lab in one shared object (the core alone, libsteadystep, is for C programs).
LIBRARY_PATH = os.path.join(os.path.dirname(os.path.abspath(__file__)), "_native", "libsteadystep_lab.so")



class MissingLibrary(ImportError):
    """A shared library the binding needs cannot be loaded: the message is one line naming it and the package
    that provides it (Debian's libode8 for libode.so.8)."""


def _missing_library_line(error: OSError) -> str:
    text = " ".join(str(error).split())
    reason = text.split("': ", 1)[-1]  # cffi: "cannot load library 'PATH': " and the loader's own words
    if "libode.so" in text:
        return ("steadystep: cannot load libode.so.8 (ODE 0.16, double precision), which the steadystep library "
                f"links ({reason}): install Debian's libode8 (sudo apt-get install libode8; libode-dev to build)")
    return (f"steadystep: cannot load the package's library {LIBRARY_PATH} ({reason}): reinstall the package "
            "(pip install --force-reinstall steadystep, or scripts/deps.sh in the repository)")


def _is_the_command() -> bool:
    """Whether this process is the `steadystep` command (its console script, or python -m steadystep.cli, whose
    argv[0] is "-m" while the package is imported)."""
    import sys

    return os.path.basename(sys.argv[0] if sys.argv else "") in ("steadystep", "cli.py", "-m")


try:
    lib = ffi.dlopen(LIBRARY_PATH)
except OSError as _error:
    _line = _missing_library_line(_error)
    if _is_the_command():
        # The command dies here, on importing the package, before its main() could catch anything: one line on
        # stderr and exit 2 (a refusal), as every other thing the command cannot have.
        import sys

        print(_line, file=sys.stderr)
        raise SystemExit(2) from None
    raise MissingLibrary(_line) from None
# The library reads and writes ODE's dReal: a libode of the other precision loaded in its place would step every
# world wrongly without a word (ssCheckOdePrecision names both precisions).
if lib.ssCheckOdePrecision() != 0:
    raise ImportError("steadystep: " + ffi.string(lib.ssLastError()).decode("utf-8", "replace"))


class SteadystepError(Exception):
    """A failure of libsteadystep, or a value the binding refused before calling it: ``code`` is the C status
    (ssStatus, a steadystep.Status value), ``status`` the library's name for it (ssStatusName: "out of range", ...),
    ``message`` the one line naming the value at fault.

    SteadystepError(code, message) makes the subclass the status belongs to: SimulationFailure for a simulation that
    failed (a blow-up, a speed or position limit, a frame refused after a failure), InvalidValue (also a ValueError)
    for a value refused by name, SteadystepError itself for the rest (i/o, memory, re-entry)."""

    def __new__(cls, *args, **kwargs):
        if cls is SteadystepError:
            cls = _ERROR_CLASSES.get(int(args[0] if args else kwargs["code"]), SteadystepError)
        return super().__new__(cls)

    def __init__(self, code: int, message: str = ""):
        super().__init__(message)
        self.code = int(code)
        self.status = status_name(self.code)
        self.message = message

    def __str__(self) -> str:
        return f"{self.message} ({self.status})" if self.message else self.status

    def __reduce__(self):
        # Pickled by code and message (the default would call it with the message alone): a study's worker process
        # hands its refusal back to the caller this way.
        return type(self), (self.code, self.message)


class InvalidValue(SteadystepError, ValueError):
    """A value refused by name (not finite, out of range, no spring, no finite mapping, unsupported, not found,
    malformed); nothing was changed."""


class SimulationFailure(SteadystepError):
    """The simulation failed, not an argument: a body blew up (not finite), ran faster than the speed limit or
    beyond the position limit, or a frame was refused because an earlier one failed (reset the stepper)."""


_ERROR_CLASSES = {
    **dict.fromkeys((lib.SS_ERROR_NOT_FINITE, lib.SS_ERROR_OUT_OF_RANGE, lib.SS_ERROR_NO_SPRING,
                     lib.SS_ERROR_NO_FINITE_MAPPING, lib.SS_ERROR_UNSUPPORTED, lib.SS_ERROR_NOT_FOUND,
                     lib.SS_ERROR_PARSE), InvalidValue),
    **dict.fromkeys((lib.SS_ERROR_BLOWUP, lib.SS_ERROR_SPEED_LIMIT, lib.SS_ERROR_POSITION_LIMIT, lib.SS_ERROR_FAILED),
                    SimulationFailure),
}  # the rest (i/o, out of memory, re-entered): SteadystepError itself


def _decode(raw: bytes) -> str:
    # C messages are cut at 255 bytes, possibly inside a UTF-8 character, and may quote bytes from a file or an
    # argument that are not UTF-8 at all: such bytes become U+FFFD instead of an exception.
    return raw.decode("utf-8", errors="replace")


# Control characters (C0, DEL, C1) as \\xNN escapes; a table, so that the binding needs no regular expressions.
_CONTROL_ESCAPES = {code: f"\\x{code:02x}" for code in (*range(0x20), *range(0x7f, 0xa0))}


def one_line(message: str) -> str:
    """message as one printable line: control characters (a newline, an escape sequence quoted from a binary
    file) as \\xNN escapes, so that a message can neither span lines nor drive the terminal."""
    return message.translate(_CONTROL_ESCAPES)


def status_name(code: int) -> str:
    return _decode(ffi.string(lib.ssStatusName(code)))


def last_error() -> str:
    return one_line(_decode(ffi.string(lib.ssLastError())))


def check(code: int) -> None:
    """Raises SteadystepError for any status but SS_OK, with the thread's last message."""
    if code != lib.SS_OK:
        raise SteadystepError(code, last_error())


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
            raise SteadystepError(lib.SS_ERROR_OUT_OF_RANGE,
                                  f"{name} = {shown(value)}: has characters that are not text "
                                  "(lone surrogates)") from None
    elif isinstance(value, (bytes, bytearray)):
        raw = bytes(value)
    else:
        raise SteadystepError(lib.SS_ERROR_OUT_OF_RANGE, f"{name} = {shown(value)}: must be a string")
    if b"\0" in raw:
        raise SteadystepError(lib.SS_ERROR_OUT_OF_RANGE, f"{name} = {shown(value)}: contains a NUL character")
    return raw


def number(name: str, value, unit: str = "") -> float:
    """value as a float for the parameter called name; SteadystepError naming it when it is not a number."""
    if isinstance(value, (str, bytes, bytearray)):
        raise SteadystepError(lib.SS_ERROR_OUT_OF_RANGE, f"{name} = {shown(value)}: must be a number{_unit(unit)}")
    try:
        return float(value)
    except (TypeError, ValueError, OverflowError):
        raise SteadystepError(lib.SS_ERROR_OUT_OF_RANGE, f"{name} = {shown(value)}: must be a number{_unit(unit)}"
                              ) from None


def integer(name: str, value, low: int, high: int) -> int:
    """value as an int in [low, high] for the parameter called name; SteadystepError naming it otherwise."""
    if isinstance(value, bool) or not hasattr(value, "__index__"):
        raise SteadystepError(lib.SS_ERROR_OUT_OF_RANGE, f"{name} = {shown(value)}: must be an integer")
    value = value.__index__()
    if not low <= value <= high:
        raise SteadystepError(lib.SS_ERROR_OUT_OF_RANGE, f"{name} = {shown(value)}: must be in [{low}, {high}]")
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

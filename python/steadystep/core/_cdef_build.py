"""Build step, not imported at run time: writes the binding's cffi module from the library's headers.

    python core/_cdef_build.py CORE_INCLUDE_DIR LAB_INCLUDE_DIR OUTPUT.py

CMake runs this when it builds the Python package (CMakeLists.txt, STEADYSTEP_PYTHON), over the same header files it
installs, so that the headers stay the one source of truth for every struct and function: a field added in C reaches
Python with the next build, and nothing is typed again here. The headers are stripped of what cffi's parser does
not take (preprocessor lines but integer #defines, the extern "C" braces, the export marks) and parsed once, here,
with pycparser; cffi's out-of-line ABI mode then writes OUTPUT.py, which holds the parsed declarations in a compact
form that ``_cffi_backend`` loads in about a millisecond (``steadystep.core._native`` imports it: no parsing, no
pycparser at import time).
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

# The headers, in dependency order, as (directory key, file). Those up to scene.h use no ODE types; stepping.h holds
# the stepper's settings, so the lab and Python share the one struct and its validator.
_LAB_AND_SETTINGS = (("core", "status.h"), ("core", "spring.h"), ("core", "stepping.h"), ("lab", "profile.h"),
                     ("lab", "scene.h"))
# The core for a program's own ODE world (registry, adoption, stepper). Only integer #defines are kept (cffi's ABI
# mode takes integer constants only): the run bounds (SS_MAX_RUN_STEPS ...) come from scene.h, and of
# limits.h only SS_MAX_AVERAGE_SAMPLES is kept (its ranges are floating point).
_OWN_WORLD = (("core", "limits.h"), ("core", "registry.h"), ("core", "adopt.h"), ("core", "stepper.h"),
              ("core", "interpolation.h"))

# These headers take ODE's handles. ODE's own headers are not read: cffi needs only the handles' names, as opaque
# pointers (the Python side passes addresses, e.g. of an odepy world), dReal (a double build, as Debian's) and
# dContact, which the library reads and writes through a pointer only.
_ODE_HANDLES = """
typedef struct dxWorld* dWorldID;
typedef struct dxBody* dBodyID;
typedef struct dxJoint* dJointID;
typedef struct dxSpace* dSpaceID;
typedef struct dxJointGroup* dJointGroupID;
typedef double dReal;
typedef struct dContact dContact;
"""

_INTEGER_DEFINE = re.compile(r"^\s*#\s*define\s+(\w+)\s+(\d+)\s*$")
# The export marks (steadystep/export.h, steadystep/lab/export.h) expand to attributes cffi does not parse.
_EXPORT_MARK = re.compile(r"\bSS_(?:LAB_)?API\b")


def _strip_comments(text: str) -> str:
    return re.sub(r"/\*.*?\*/|//[^\n]*", " ", text, flags=re.S)


def declarations(text: str) -> str:
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


def cdef_source(core_dir: Path, lab_dir: Path) -> str:
    """Every declaration the binding uses, from the headers in core_dir (include/steadystep) and lab_dir
    (lab/include/steadystep/lab)."""
    directories = {"core": Path(core_dir), "lab": Path(lab_dir)}

    def read(headers) -> str:
        return "\n".join(declarations((directories[key] / name).read_text()) for key, name in headers)

    return read(_LAB_AND_SETTINGS) + _ODE_HANDLES + read(_OWN_WORLD)


def write_module(core_dir: Path, lab_dir: Path, output: Path) -> None:
    import cffi

    builder = cffi.FFI()
    builder.cdef(cdef_source(core_dir, lab_dir))
    builder.set_source("steadystep.core._native_ffi", None)  # None: ABI mode, no C compiled
    output = Path(output)
    output.parent.mkdir(parents=True, exist_ok=True)
    builder.emit_python_code(str(output))


if __name__ == "__main__":
    if len(sys.argv) != 4:
        sys.exit("usage: core/_cdef_build.py CORE_INCLUDE_DIR LAB_INCLUDE_DIR OUTPUT.py")
    write_module(Path(sys.argv[1]), Path(sys.argv[2]), Path(sys.argv[3]))

"""Importing steadystep parses nothing and loads no numpy: the cffi declarations were prepared from the headers when the package was
built (steadystep/core/_native_ffi.py, cffi's out-of-line ABI mode), and they are exactly what the installed headers
declare, so the headers stay the one source."""

import subprocess
import sys
from pathlib import Path

import cffi

import steadystep
from steadystep.core import _cdef_build
from steadystep.core._native import ffi

PACKAGE = Path(steadystep.__file__).parent / "core"  # the binding: its prepared module, the headers it was built from
INCLUDE = PACKAGE / "_native" / "include" / "steadystep"


def test_import_loads_no_c_parser_and_no_numpy():
    # Nor numpy (about 40 ms on an idle machine): it is imported where an array is made (runs, profiles' arrays,
    # conversions of arrays), so that the core's import stays in milliseconds.
    code = ("import sys, steadystep; print(sorted({m.split('.')[0] for m in sys.modules} & "
            "{'pycparser', 'cffi', 'numpy'}))")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "[]"


def test_the_importtime_of_the_binding_is_the_prepared_module():
    result = subprocess.run([sys.executable, "-X", "importtime", "-c", "import steadystep"], capture_output=True,
                            text=True, timeout=60)
    names = [line.rsplit("|", 1)[1].strip() for line in result.stderr.splitlines() if line.startswith("import time")]
    assert "steadystep.core._native_ffi" in names and "steadystep.core._native" in names
    assert not [name for name in names if name.startswith("pycparser")]


def test_the_prepared_declarations_are_those_of_the_installed_headers():
    fresh = cffi.FFI()
    fresh.cdef(_cdef_build.cdef_source(INCLUDE, INCLUDE / "lab"))
    typedefs, structs, unions = fresh.list_types()
    assert (typedefs, structs, unions) == ffi.list_types()
    for name in [*typedefs, *(f"struct {struct}" for struct in structs)]:
        try:
            kind = fresh.typeof(name)
        except cffi.CDefError:  # a function typedef (the callbacks): no typeof of its own, its users are compared
            continue
        built = ffi.typeof(name)
        assert kind.kind == built.kind, name
        if kind.kind == "struct" and kind.fields is not None:  # not an opaque ODE handle
            assert [(f, t.type.kind, fresh.sizeof(t.type), t.offset) for f, t in kind.fields] == \
                   [(f, t.type.kind, ffi.sizeof(t.type), t.offset) for f, t in built.fields], name
        elif kind.kind == "enum":
            assert kind.relements == built.relements, name
    assert PACKAGE.joinpath("_native_ffi.py").read_text().startswith("# auto-generated file")

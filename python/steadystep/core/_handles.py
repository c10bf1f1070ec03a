"""ODE handles from Python: an odepy handle as it is, a PyODE object (steadystep.core.pyode: its pointer read from its
checked layout), or a plain integer address, as the C type the library takes.

odepy (PyPI ode-python) types its handles as ctypes pointers to opaque structs named after ODE's own (dWorldID is
POINTER(dxWorld), dBodyID POINTER(dxBody), ...), so the kind of a handle is checked by that name, without importing
odepy. A NULL handle (None, 0, an odepy NULL pointer) is passed on: the library refuses it by name where one is
required, as it does in C. A handle of another kind, or any other object, is refused here by name. An integer is
taken as the address it is: the library cannot tell a stale or foreign address from a live object (nor can C).
"""

from __future__ import annotations

import ctypes

from steadystep.core import pyode
from steadystep.core._native import SteadystepError, ffi, shown
from steadystep.core.enums import Status

# The kind of handle, as the library's parameter names say it -> (ODE's struct name, the C type of the parameter).
KINDS = {
    "world": ("dxWorld", "dWorldID"),
    "body": ("dxBody", "dBodyID"),
    "joint": ("dxJoint", "dJointID"),
    "space": ("dxSpace", "dSpaceID"),
    "joint group": ("dxJointGroup", "dJointGroupID"),
}
_ADDRESS_LIMIT = 2**64
# The C types, and their NULLs, looked up once: a near callback converts its handles for every contact.
_C_TYPES = {kind: ffi.typeof(c_type) for kind, (_, c_type) in KINDS.items()}
_NULLS = {kind: ffi.cast(c_type, 0) for kind, c_type in _C_TYPES.items()}
_CONTACT_POINTER = ffi.typeof("dContact*")
_FIELD_TYPES = {kind: ffi.typeof(f"{c_type}*") for kind, (_, c_type) in KINDS.items()}  # a PyODE object's field
_PYODE_NAMES = {"world": "World", "body": "Body", "joint": "Joint", "space": "Space", "joint group": "JointGroup",
                "contact": "Contact"}


def _wrong(name: str, kind: str, value, what: str) -> SteadystepError:
    return SteadystepError(Status.OUT_OF_RANGE, f"{name} = {shown(value)}: {what}; must be an ODE {kind} (an odepy "
                           f"{KINDS[kind][1] if kind in KINDS else 'dContact'}, a PyODE {_PYODE_NAMES[kind]} or an "
                           "integer address)")


def address(name: str, kind: str, value, checked: bool = True) -> int:
    """The address of the ODE object `value` of the given kind ("world", "body", "joint", "space", "joint group"),
    0 for NULL. Raises SteadystepError naming the parameter for a handle of another kind or a foreign object. A
    PyODE object's pointer is read from its checked layout; checked: the object is also read through it and
    compared with PyODE's getters (steadystep.core.pyode.address)."""
    family = pyode.FAMILY.get(type(value))
    if family is not None:  # a PyODE object of a class already met: its pointer read at once when not checked
        if family == kind and not checked and kind != "space":
            pointer = pyode.pointer_of(value)
            if pointer:
                return pointer
        return pyode.address(name, kind, value, checked)
    struct_name, c_type = KINDS[kind]
    if value is None:
        return 0
    if isinstance(value, bool):
        raise _wrong(name, kind, value, "a bool")
    if isinstance(value, int):
        if not 0 <= value < _ADDRESS_LIMIT:
            raise _wrong(name, kind, value, "not an address")
        return value
    if isinstance(value, ctypes._Pointer):
        pointee = type(value)._type_.__name__
        if pointee != struct_name:
            raise _wrong(name, kind, value, f"a pointer to {pointee}, not to {struct_name}")
        return ctypes.cast(value, ctypes.c_void_p).value or 0
    if isinstance(value, ctypes.c_void_p):
        return value.value or 0
    if isinstance(value, ffi.CData):
        ctype = ffi.typeof(value)
        if ctype.kind == "pointer" and ctype.item.cname in (f"struct {struct_name}", "void"):
            return int(ffi.cast("uintptr_t", value))
        raise _wrong(name, kind, value, f"a C {ctype.cname}")
    if pyode.is_pyode(value):
        return pyode.address(name, kind, value, checked)
    raise _wrong(name, kind, value, f"a {type(value).__name__}")


def handle(name: str, kind: str, value, checked: bool = True):
    """value as the library's handle type (dWorldID ...), NULL included: see address()."""
    if value is None:
        return _NULLS[kind]
    if not checked and pyode.FAMILY.get(type(value)) == kind and kind != "space":
        held = ffi.cast(_FIELD_TYPES[kind], id(value) + pyode.FIELD_OFFSET)[0]  # its checked layout's field
        if held != ffi.NULL:
            return held
    return ffi.cast(_C_TYPES[kind], address(name, kind, value, checked))


def contacts(name: str, value, count: int):
    """count ODE dContacts in a row as the library's `dContact*`: an odepy dContact array (ctypes, at least count
    long), or what contact() takes for the first of them (an odepy dContact, a pointer, an address; a PyODE Contact
    only for count <= 1: PyODE keeps each contact in an object of its own)."""
    if isinstance(value, ctypes.Array):
        element = value._type_.__name__
        if element != "dContact":
            raise _wrong(name, "contact", value, f"an array of {element}, not of dContact")
        if count > len(value):
            raise SteadystepError(Status.OUT_OF_RANGE,
                                  f"count = {count}: more than the {len(value)} contacts of {name}")
        return ffi.cast("dContact*", ctypes.addressof(value))
    if count > 1 and (pyode.FAMILY.get(type(value)) == "contact" or pyode.is_pyode(value)):
        raise SteadystepError(Status.OUT_OF_RANGE, f"{name} = {shown(value)}: a PyODE Contact holds one contact, not "
                              f"count = {count} in a row; soften each with soften_contact")
    return contact(name, value)


def contact(name: str, value):
    """An ODE dContact as the library's `dContact*`: an odepy dContact (a ctypes Structure, by its address), a
    ctypes pointer to one, a PyODE Contact (the dContact it holds), or an integer address; None or 0 is NULL
    (refused by the library by name)."""
    if pyode.FAMILY.get(type(value)) == "contact":
        return ffi.cast(_CONTACT_POINTER, id(value) + pyode.FIELD_OFFSET)
    if value is None:
        return ffi.NULL
    if isinstance(value, bool):
        raise _wrong(name, "contact", value, "a bool")
    if isinstance(value, int):
        if not 0 <= value < _ADDRESS_LIMIT:
            raise _wrong(name, "contact", value, "not an address")
        return ffi.cast("dContact*", value)
    if isinstance(value, ctypes.Structure):
        if type(value).__name__ != "dContact":
            raise _wrong(name, "contact", value, f"a {type(value).__name__}, not a dContact")
        return ffi.cast("dContact*", ctypes.addressof(value))
    if isinstance(value, ctypes._Pointer):
        pointee = type(value)._type_.__name__
        if pointee != "dContact":
            raise _wrong(name, "contact", value, f"a pointer to {pointee}, not to dContact")
        return ffi.cast("dContact*", ctypes.cast(value, ctypes.c_void_p).value or 0)
    if pyode.is_pyode(value):
        return ffi.cast("dContact*", pyode.address(name, "contact", value))
    raise _wrong(name, "contact", value, f"a {type(value).__name__}")

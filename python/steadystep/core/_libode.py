"""The libode this process has loaded (the one libsteadystep links), through ctypes: the few ODE calls the binding
makes itself, to check PyODE's objects (steadystep.core.pyode) and to keep a joint group of a stepper's own.

Only the library already mapped into the process is opened (its path read from /proc/self/maps, found after the
package's own library pulled it in), so that these calls reach the very ODE whose objects they look at. The handles
are plain integers (addresses); ODE's struct dContact is laid out here for reading only, as ODE 0.16's headers
declare it in double precision (the package refuses a libode of the other precision when it loads).
"""

from __future__ import annotations

import ctypes
import ctypes.util
import functools

import steadystep.core._native  # noqa: F401 - loads libsteadystep_lab.so, and with it libode

_P = ctypes.c_void_p
_R = ctypes.c_double
_I = ctypes.c_int


class Surface(ctypes.Structure):
    """ODE 0.16's dSurfaceParameters (ode/contact.h)."""

    _fields_ = [("mode", _I), *((name, _R) for name in ("mu", "mu2", "rho", "rho2", "rhoN", "bounce", "bounce_vel",
                                                      "soft_erp", "soft_cfm", "motion1", "motion2", "motionN",
                                                      "slip1", "slip2"))]


class ContactGeom(ctypes.Structure):
    """ODE 0.16's dContactGeom."""

    _fields_ = [("pos", _R * 4), ("normal", _R * 4), ("depth", _R), ("g1", _P), ("g2", _P), ("side1", _I),
                ("side2", _I)]


class Contact(ctypes.Structure):
    """ODE 0.16's dContact: what a contact joint copies when it is made."""

    _fields_ = [("surface", Surface), ("geom", ContactGeom), ("fdir1", _R * 4)]


# name -> (result type, argument types)
_SIGNATURES = {
    "dWorldCreate": (_P, ()), "dWorldDestroy": (None, (_P,)), "dWorldGetERP": (_R, (_P,)),
    "dWorldGetCFM": (_R, (_P,)), "dWorldSetERP": (None, (_P, _R)),
    "dBodyGetWorld": (_P, (_P,)), "dBodyGetPosition": (ctypes.POINTER(_R), (_P,)),
    "dBodyGetQuaternion": (ctypes.POINTER(_R), (_P,)), "dBodyGetNumJoints": (_I, (_P,)),
    "dBodyGetJoint": (_P, (_P, _I)),
    "dGeomGetBody": (_P, (_P,)), "dGeomGetSpace": (_P, (_P,)), "dGeomIsSpace": (_I, (_P,)),
    "dGeomGetClass": (_I, (_P,)),
    "dJointGetType": (_I, (_P,)), "dJointGetBody": (_P, (_P, _I)),
    "dJointCreateHinge": (_P, (_P, _P)), "dJointGetHingeParam": (_R, (_P, _I)), "dJointDestroy": (None, (_P,)),
    "dJointGroupCreate": (_P, (_I,)), "dJointGroupDestroy": (None, (_P,)), "dJointGroupEmpty": (None, (_P,)),
    "dRandSetSeed": (None, (ctypes.c_ulong,)),
}


def _loaded_path() -> str:
    try:
        with open("/proc/self/maps", encoding="utf-8", errors="replace") as maps:
            for line in maps:
                path = line.rstrip("\n").split(maxsplit=5)[-1]
                if "/libode.so" in path:
                    return path
    except OSError:
        pass
    return ctypes.util.find_library("ode") or "libode.so.8"


@functools.cache
def ode():
    """libode as a ctypes library, each function this module uses typed."""
    library = ctypes.CDLL(_loaded_path())
    for name, (result, arguments) in _SIGNATURES.items():
        function = getattr(library, name)
        function.restype = result
        function.argtypes = arguments
    return library

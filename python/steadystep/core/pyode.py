"""PyODE (``import ode``: Debian's python3-pyode, Py3ODE) as a binding whose objects steadystep takes as they are.

Stepper, Registry, soften_contact, watch_body, interpolated_pose (and the audit, which steps through a Stepper) take
PyODE's World, Space, Body, Joint (every kind), JointGroup and Contact wherever they take an odepy handle:

    import ode, steadystep as ss
    stepper = ss.Stepper(world, space=space, tuned_step_s=1 / 60, solver=ss.Solver.QUICK, policy="implicit-euler",
                         collide=collide, contact_group=contactgroup)   # PyODE's own objects
    ...in the near callback: stepper.soften_contact(contact, body1, body2) before ode.ContactJoint(...)

PyODE shows an address only for spaces and geoms (``_id()``); the others hold their ODE pointer in a private field,
the first a Cython class declares, right after the object's header. Before the binding reads any of them it checks
that layout once, on objects PyODE makes for it, against what libode says from a geom's public address: the pointer
read from a Body must be the body dGeomGetBody gives for its geom, at the position PyODE's getPosition() gives; a
World's must be that body's dBodyGetWorld, with PyODE's getERP() and getCFM(); each joint class's must be one of the
body's joints (dBodyGetJoint), whose dJointGetType then stands for that class; a Contact's dContact must hold the
mode, mu, bounce, soft ERP/CFM and fdir1 PyODE's setters wrote, and the geometry ode.collide() gave it. No pointer
is handed to libode before it was found equal to one libode gave. A PyODE whose layout does not check out is refused
by name (InvalidValue, Status.UNSUPPORTED), never guessed at; each object is then checked as it comes (a world's
ERP/CFM, a body's pose and a joint's type read through the pointer agree with PyODE's getters; a joint PyODE let go
of, after JointGroup.empty(), is refused).

Contact groups. PyODE keeps a Python wrapper for every joint made in a JointGroup and forgets them only in its own
JointGroup.empty(): a group emptied in C (dJointGroupEmpty) leaves PyODE holding dangling joints, and grows for ever.
A Stepper given a PyODE JointGroup therefore empties it through PyODE, after every step and after a refused frame.

Contacts at the cost of C: ``ContactRule`` (steadystep.core.stepper) makes, softens and joins every contact of a step in
C, with the surface of one PyODE Contact: no Python call per contact.

PyODE's own traps. Debian's PyODE numbers joint parameters as ODE 0.15 did: from ParamFMax on, every ``ode.Param*``
names the parameter two places earlier in ODE 0.16 (ode.ParamFMax sets dParamLoVel: a motor gets no force and
never moves). Its ContactSlip1 and ContactSlip2 are ODE 0.16's dContactMotionN and dContactSlip1. Importing
steadystep with such a PyODE loaded (or meeting its first object) warns once (PyODEWarning), naming the constants
and the fix: ``Param`` and ``ContactMode`` below hold ODE 0.16's numbers, checked against the loaded ODE.

Importing this module does not import PyODE; steadystep never imports it on its own (PyODE initialises ODE when it
is imported): it looks at the ``ode`` module the program imported.
"""

from __future__ import annotations

import ctypes
import struct
import sys
import warnings
from enum import IntEnum, IntFlag

from steadystep.core import _libode
from steadystep.core._native import SteadystepError, shown
from steadystep.core.enums import Status

MODULE = "ode"  # PyODE's module name, which its classes carry in __module__
# Where a Cython class's first declared field lies: right after the object's header (PyObject_HEAD).
FIELD_OFFSET = object.__basicsize__

# ODE 0.16's joint parameter numbers (ode/common.h, D_ALL_PARAM_NAMES): the 14 of a group, for axes 1, 2, 3.
_PARAM_NAMES = ("LoStop", "HiStop", "Vel", "LoVel", "HiVel", "FMax", "FudgeFactor", "Bounce", "CFM", "StopERP",
                "StopCFM", "SuspensionERP", "SuspensionCFM", "ERP")
_PARAM_GROUP = 0x100
Param = IntEnum("Param", {f"{name}{suffix}": group * _PARAM_GROUP + index
                          for group, suffix in ((0, ""), (1, "2"), (2, "3"))
                          for index, name in enumerate(_PARAM_NAMES)})
Param.__doc__ = """ODE 0.16's joint parameter numbers, named as PyODE names them (Param.FMax for ode.ParamFMax,
Param.Vel2 for ode.ParamVel2): hinge.setParam(Param.FMax, 50). Checked against the loaded ODE (the defaults of a new
hinge: fudge factor 1, stop ERP the world's) before a warning recommends them."""


class ContactMode(IntFlag):
    """ODE 0.16's contact mode flags (ode/contact.h), named as PyODE names them without the 'Contact' prefix:
    contact.setMode(ContactMode.Bounce | ContactMode.Slip1). PyODE's ode.ContactSlip1 and ode.ContactSlip2 are
    ODE 0.15's numbers (0x80 and 0x100: ODE 0.16's MotionN and Slip1)."""

    Mu2 = 0x001
    FDir1 = 0x002
    Bounce = 0x004
    SoftERP = 0x008
    SoftCFM = 0x010
    Motion1 = 0x020
    Motion2 = 0x040
    MotionN = 0x080
    Slip1 = 0x100
    Slip2 = 0x200
    Rolling = 0x400
    Approx1_1 = 0x1000
    Approx1_2 = 0x2000
    Approx1_N = 0x4000
    Approx1 = 0x7000


class PyODEWarning(UserWarning):
    """The PyODE loaded disagrees with the loaded ODE on a number (its Param* or Contact* constants)."""


def _fail(message: str) -> SteadystepError:
    return SteadystepError(Status.UNSUPPORTED, message)


def loaded():
    """The PyODE module the program imported, or None (this never imports it)."""
    module = sys.modules.get(MODULE)
    return module if module is not None and hasattr(module, "World") and hasattr(module, "JointGroup") else None


def is_pyode(value) -> bool:
    """Whether value is an object of PyODE's (its class, or a class it derives from, is PyODE's)."""
    return any(getattr(cls, "__module__", None) == MODULE for cls in type(value).__mro__[:-1])


def _pointer_at(value, offset: int) -> int:
    return ctypes.c_void_p.from_address(id(value) + offset).value or 0


def _same_bits(a, b) -> bool:
    """Two sequences of floats equal to the bit (a NaN equal to itself)."""
    a, b = tuple(a), tuple(b)
    return len(a) == len(b) and struct.pack(f"{len(a)}d", *a) == struct.pack(f"{len(b)}d", *b)


class _Layout:
    """PyODE's classes as checked: where each holds its ODE pointer, and the ODE joint type of each joint class."""

    def __init__(self, module, joint_types: dict):
        self.module = module
        self.world, self.body, self.joint = module.World, module.Body, module.Joint
        self.contact, self.space, self.group = module.Contact, module.SpaceBase, module.JointGroup
        self.joint_types = joint_types  # PyODE joint class -> dJointGetType of its objects


_layout_of: dict = {}  # id(PyODE module) -> (module, _Layout or the SteadystepError that refused it)
# A class of PyODE's (or derived from one) -> the kind of ODE object its objects hold ("world", "body", "joint",
# "space", "joint group", "contact"), filled once PyODE's layout checked out: the fast path of the binding's calls.
FAMILY: dict = {}


def layout(module=None) -> _Layout:
    """PyODE's layout, checked once per PyODE module (steadystep.core.pyode's docstring); SteadystepError
    (Status.UNSUPPORTED) naming what did not check out."""
    module = module if module is not None else loaded()
    if module is None:
        raise _fail("PyODE (the module 'ode') is not loaded")
    known = _layout_of.get(id(module))
    if known is None or known[0] is not module:
        warn_if_mismatched(module)
        try:
            result = _check_layout(module)
        except SteadystepError as error:  # kept without its traceback, whose frames hold the probe's PyODE objects
            result = SteadystepError(error.code, error.message)
        except Exception as error:  # a PyODE without a class or method the check uses
            result = _fail(f"PyODE's layout could not be checked ({type(error).__name__}: {error}): a PyODE this "
                           "binding does not know; refused, not guessed")
        _layout_of[id(module)] = known = (module, result)
    if isinstance(known[1], SteadystepError):
        raise SteadystepError(known[1].code, known[1].message)
    return known[1]


def _family(value, known: _Layout) -> str | None:
    """The kind of ODE object value holds, remembered for its class (FAMILY)."""
    cls = type(value)
    family = FAMILY.get(cls)
    if family is None:
        family = next((kind for kind, base in (("world", known.world), ("body", known.body), ("joint", known.joint),
                                               ("space", known.space), ("joint group", known.group),
                                               ("contact", known.contact)) if isinstance(value, base)), None)
        if family is not None:
            FAMILY[cls] = family
    return family


def pointer_of(value) -> int:
    """The ODE pointer a PyODE World, Body or Joint holds (its class in FAMILY: its layout checked), 0 for none."""
    return ctypes.c_void_p.from_address(id(value) + FIELD_OFFSET).value or 0


def _check_layout(module) -> _Layout:
    """The layout check on objects made here (see the module's docstring)."""
    ode = _libode.ode()
    offset = FIELD_OFFSET
    pointer = ctypes.sizeof(ctypes.c_void_p)
    contact_size = ctypes.sizeof(_libode.Contact)
    for name, needed in (("World", pointer), ("Body", pointer), ("Joint", pointer), ("Contact", contact_size)):
        size = getattr(module, name).__basicsize__
        if size < offset + needed:
            held = "dContact" if name == "Contact" else "pointer"
            raise _fail(f"PyODE's {name} ({size} bytes) has no room for its ODE {held} at byte {offset}: a PyODE "
                        "this binding does not know; refused, not guessed")
    if module.Contact.__basicsize__ != offset + contact_size:
        raise _fail(f"PyODE's Contact ({module.Contact.__basicsize__} bytes) does not hold ODE 0.16's dContact "
                    f"({contact_size} bytes) at byte {offset}: built against another ODE; refused, not guessed")

    world = module.World()
    world.setERP(0.3125)
    world.setCFM(2.5e-6)
    space = module.SimpleSpace()
    body = module.Body(world)
    body.setPosition((0.25, -0.5, 0.375))
    geom = module.GeomSphere(space, 0.5)
    geom.setBody(body)
    plane = module.GeomPlane(space, (0.0, 0.0, 1.0), 0.0)
    group = module.JointGroup()
    try:
        geom_id = geom._id()
        trusted_body = ode.dGeomGetBody(geom_id) or 0
        read = _pointer_at(body, offset)
        if trusted_body == 0 or read != trusted_body:
            raise _fail(f"PyODE's Body: the pointer at byte {offset} ({read:#x}) is not its ODE body "
                        f"({trusted_body:#x}, dGeomGetBody of its geom); refused, not guessed")
        if not _same_bits(ode.dBodyGetPosition(trusted_body)[:3], body.getPosition()):
            raise _fail("PyODE's Body: its ODE body's position (dBodyGetPosition) is not its getPosition(); refused")
        trusted_world = ode.dBodyGetWorld(trusted_body) or 0
        read = _pointer_at(world, offset)
        if read != trusted_world:
            raise _fail(f"PyODE's World: the pointer at byte {offset} ({read:#x}) is not its ODE world "
                        f"({trusted_world:#x}, dBodyGetWorld of its body); refused, not guessed")
        if (ode.dWorldGetERP(trusted_world), ode.dWorldGetCFM(trusted_world)) != (world.getERP(), world.getCFM()):
            raise _fail("PyODE's World: its ODE world's ERP/CFM (dWorldGetERP/CFM) are not its getERP()/getCFM()")
        if ode.dGeomGetSpace(geom_id) != space._id() or not ode.dGeomIsSpace(space._id()):
            raise _fail("PyODE's Space: _id() is not the ODE space its geoms are in (dGeomGetSpace); refused")
        contact = module.Contact()
        contact.setMode(module.ContactBounce | module.ContactSoftERP | module.ContactSoftCFM | module.ContactFDir1)
        contact.setMu(0.75)
        contact.setBounce(0.375)
        contact.setSoftERP(0.625)
        contact.setSoftCFM(1.25e-3)
        contact.setFDir1((0.0, 0.6, 0.8))
        _check_contact(module, contact, offset, geometry=False)
        collided = module.collide(geom, plane)
        if not collided:
            raise _fail("PyODE's collide(): no contact for a ball half sunk into a plane; refused")
        _check_contact(module, collided[0], offset, geometry=True)
        other = module.Body(world)  # some joints (Hinge2) take two bodies: ODE aborts when given one
        other.setPosition((0.25, 0.5, 0.375))
        joint_types = _check_joints(module, ode, world, (body, other), group, contact, trusted_body, offset)
    finally:
        group.empty()  # PyODE's own way: its wrappers let go of the contact joint
    return _Layout(module, joint_types)


def _check_contact(module, contact, offset: int, geometry: bool) -> None:
    held = _libode.Contact.from_address(id(contact) + offset)
    surface = held.surface
    good = (surface.mode == contact.getMode() and
            _same_bits((surface.mu, surface.bounce, surface.soft_erp, surface.soft_cfm),
                       (contact.getMu(), contact.getBounce(), contact.getSoftERP(), contact.getSoftCFM())) and
            _same_bits(held.fdir1[:3], contact.getFDir1()))
    if good and geometry:
        pos, normal, depth, _, _ = contact.getContactGeomParams()
        good = _same_bits((*held.geom.pos[:3], *held.geom.normal[:3], held.geom.depth), (*pos, *normal, depth))
    if not good:
        raise _fail(f"PyODE's Contact: the dContact at byte {offset} does not hold what its getters give (mode, mu, "
                    "bounce, soft ERP/CFM, fdir1, position, normal, depth); refused, not guessed")


def _check_joints(module, ode, world, bodies, group, contact, trusted_body: int, offset: int) -> dict:
    """Each joint class PyODE has: one made and attached to the two bodies, its pointer found among the first
    body's joints (trusted_body)."""
    classes = [cls for cls in vars(module).values()
               if isinstance(cls, type) and issubclass(cls, module.Joint) and cls is not module.Joint]
    made = []
    for cls in classes:
        joint = cls(world, group, contact) if cls is module.ContactJoint else cls(world)
        joint.attach(*bodies)
        made.append((cls, joint))
    trusted = {ode.dBodyGetJoint(trusted_body, i) for i in range(ode.dBodyGetNumJoints(trusted_body))}
    joint_types = {}
    for cls, joint in made:
        if cls.__basicsize__ != module.Joint.__basicsize__:
            raise _fail(f"PyODE's {cls.__name__} ({cls.__basicsize__} bytes) is laid out otherwise than its Joint "
                        f"({module.Joint.__basicsize__}); refused, not guessed")
        read = _pointer_at(joint, offset)
        if read == 0 or read not in trusted:
            raise _fail(f"PyODE's {cls.__name__}: the pointer at byte {offset} ({read:#x}) is none of its body's ODE "
                        "joints (dBodyGetJoint); refused, not guessed")
        joint_types[cls] = ode.dJointGetType(read)
    if len(set(joint_types.values())) != len(joint_types):
        raise _fail("PyODE's joint classes: two of them make joints of one ODE type (dJointGetType); refused")
    return joint_types


# ---- one object ----------------------------------------------------------------------------------------------------

_KIND_NAMES = {"world": "World", "body": "Body", "joint": "Joint", "space": "Space", "joint group": "JointGroup",
               "contact": "Contact"}


def _wrong_kind(name: str, kind: str, value, family: str | None) -> SteadystepError:
    module, cls = loaded(), type(value)
    genuine = family is not None or any(getattr(module, base.__name__, None) is base for base in cls.__mro__[:-1])
    what = (f"a PyODE {cls.__name__}, not a {_KIND_NAMES[kind]}" if genuine else
            f"a {cls.__name__} of module 'ode' that is none of PyODE's classes")
    return SteadystepError(Status.OUT_OF_RANGE, f"{name} = {shown(value)}: {what}; must be an ODE {kind}")


def address(name: str, kind: str, value, checked: bool = True) -> int:
    """The ODE address behind PyODE's object value of the given kind ("world", "body", "joint", "space",
    "contact": the address of its dContact). checked: also read the object through the pointer and compare with
    PyODE's getters (a world's ERP/CFM, a body's pose, a joint's type). Raises SteadystepError naming the parameter
    for an object of another kind, a PyODE whose layout does not check out, or an object that does not check out
    (a joint PyODE let go of: emptied with its group)."""
    known = layout()
    family = _family(value, known)
    if kind == "joint group":
        if family == "joint group":
            raise SteadystepError(Status.OUT_OF_RANGE, f"{name} = {shown(value)}: a PyODE JointGroup, which PyODE "
                                  "empties itself: give it to Stepper(contact_group=...), which empties it through "
                                  "JointGroup.empty()")
        raise _wrong_kind(name, kind, value, family)
    if family != kind:
        raise _wrong_kind(name, kind, value, family)
    if kind == "contact":
        return id(value) + FIELD_OFFSET
    if kind == "space":
        space = value._id()
        if checked and not _libode.ode().dGeomIsSpace(space):
            raise SteadystepError(Status.OUT_OF_RANGE, f"{name} = {shown(value)}: its _id() is no ODE space")
        return space
    pointer = _pointer_at(value, FIELD_OFFSET)
    if pointer == 0:
        raise SteadystepError(Status.OUT_OF_RANGE, f"{name} = {shown(value)}: its ODE {kind} is gone (PyODE let go of "
                              f"it{': emptied with its JointGroup, or destroyed' if kind == 'joint' else ''})")
    if checked:
        _check_object(name, kind, value, pointer, known)
    return pointer


def _check_object(name: str, kind: str, value, pointer: int, known: _Layout) -> None:
    ode = _libode.ode()
    if kind == "world":
        good = _same_bits((ode.dWorldGetERP(pointer), ode.dWorldGetCFM(pointer)), (value.getERP(), value.getCFM()))
        what = "its ERP/CFM"
    elif kind == "body":
        good = (_same_bits(ode.dBodyGetPosition(pointer)[:3], value.getPosition()) and
                _same_bits(ode.dBodyGetQuaternion(pointer)[:4], value.getQuaternion()))
        what = "its position and rotation"
    else:
        expected = next((known.joint_types[cls] for cls in type(value).__mro__ if cls in known.joint_types), None)
        good = expected is not None and ode.dJointGetType(pointer) == expected
        what = f"its type (dJointGetType {ode.dJointGetType(pointer)}, a {type(value).__name__}'s is {expected})"
    if not good:
        raise SteadystepError(Status.OUT_OF_RANGE, f"{name} = {shown(value)}: its ODE {kind} ({pointer:#x}) does "
                              f"not check out: {what} through libode differ from PyODE's; refused")


def is_joint_group(value) -> bool:
    """Whether value is a PyODE JointGroup (without checking PyODE's layout: its pointer is never read)."""
    module = loaded()
    return module is not None and isinstance(value, module.JointGroup)


def forget_body(body) -> None:
    """After the library destroyed PyODE's body's ODE body (Stepper.destroy_body): the Body's pointer set to NULL,
    as PyODE's own JointGroup does for its joints, so that PyODE does not destroy it again when the Body goes. Only
    after address() checked the Body."""
    ctypes.c_void_p.from_address(id(body) + FIELD_OFFSET).value = None


# ---- PyODE's numbers ---------------------------------------------------------------------------------------------

_warned = False


def _loaded_ode_numbers_problem() -> str | None:
    """None when the loaded ODE numbers joint parameters as Param says (a new hinge's defaults read through libode:
    limits -inf/inf, fudge factor 1, stop ERP and CFM the world's); else what differs."""
    ode = _libode.ode()
    world = ode.dWorldCreate()
    try:
        ode.dWorldSetERP(world, 0.4375)
        hinge = ode.dJointCreateHinge(world, None)
        got = {name: ode.dJointGetHingeParam(hinge, Param[name]) for name in ("LoStop", "HiStop", "FudgeFactor",
                                                                             "StopERP", "StopCFM")}
        ode.dJointDestroy(hinge)
        cfm = ode.dWorldGetCFM(world)
    finally:
        ode.dWorldDestroy(world)
    expected = {"LoStop": float("-inf"), "HiStop": float("inf"), "FudgeFactor": 1.0, "StopERP": 0.4375, "StopCFM": cfm}
    wrong = [f"{name} ({Param[name].value}) reads {got[name]!r}, not {value!r}" for name, value in expected.items()
             if got[name] != value]
    return "; ".join(wrong) or None


def mismatch(module) -> str | None:
    """What PyODE's module numbers otherwise than the loaded ODE, as one message with the fix; None when nothing."""
    problem = _loaded_ode_numbers_problem()
    if problem is not None:
        return (f"the loaded ODE does not number joint parameters as ODE 0.16 (a new hinge's {problem}): PyODE's "
                "ode.Param* and steadystep.core.pyode.Param cannot be checked against it")
    wrong = [(f"Param{member.name}", getattr(module, f"Param{member.name}"), member.value) for member in Param
             if isinstance(getattr(module, f"Param{member.name}", None), int)
             and getattr(module, f"Param{member.name}") != member.value]
    lower = [f"param{member.name}" for member in Param if member.value < _PARAM_GROUP
             and isinstance(getattr(module, f"param{member.name}", None), int)
             and getattr(module, f"param{member.name}") != member.value]
    flags = [(f"Contact{member.name}", getattr(module, f"Contact{member.name}"), member) for member in ContactMode
             if isinstance(getattr(module, f"Contact{member.name}", None), int)
             and getattr(module, f"Contact{member.name}") not in (member.value, 0x3000 if member.name == "Approx1"
                                                                 else member.value)]
    if not wrong and not lower and not flags:
        return None
    parts = []
    if wrong or lower:
        by_value = {member.value: member.name for member in Param}
        first = [(name, value, right) for name, value, right in wrong if right < _PARAM_GROUP] or wrong
        shifts = sorted({right - value for _, value, right in wrong})
        shift = f"{shifts[0]} places" if len(shifts) == 1 else "other places"
        forms = [*(["their 2 and 3 forms"] if len(wrong) > len(first) else []),
                 *([f"ode.{lower[0]}..."] if lower else [])]
        parts.append(f"PyODE's ode.{', '.join(f'{name} ({value})' for name, value, _ in first)}"
                     + (f" ({' and '.join(forms)} too)" if forms else "")
                     + f" are not the loaded ODE's joint parameter numbers: each names the parameter {shift} earlier "
                     f"(ode.{first[0][0]} is dParam{by_value.get(first[0][1], '?')}"
                     + (": a motor given its force through ode.ParamFMax never moves)" if first[0][0] == "ParamFMax"
                        else ")")
                     + f". Fix: steadystep.core.pyode.Param holds the loaded ODE's (Param.FMax = {Param.FMax.value}, "
                     f"Param.FMax2 = {Param.FMax2.value}, ...)"
                     + (f", or add {shifts[0]} to each" if len(shifts) == 1 else ""))
    if flags:
        by_flag = {member.value: member.name for member in ContactMode}
        parts.append(f"PyODE's ode.{', '.join(f'{name} ({value:#x})' for name, value, _ in flags)} are the loaded "
                     f"ODE's dContact{', dContact'.join(by_flag.get(value, '?') for _, value, _ in flags)}. Fix: "
                     "steadystep.core.pyode.ContactMode (ContactMode.Slip1 ...)")
    return "; ".join(parts)


def warn_if_mismatched(module=None) -> None:
    """Warns once a process (PyODEWarning) when PyODE's numbers disagree with the loaded ODE (mismatch())."""
    global _warned
    module = module if module is not None else loaded()
    if _warned or module is None:
        return
    _warned = True
    problem = mismatch(module)
    if problem is not None:
        warnings.warn(problem, PyODEWarning, stacklevel=3)

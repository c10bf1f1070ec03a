"""The registry of what is soft in a program's own ODE world, and adoption of what the program tuned (registry.h,
adopt.h), for worlds built with odepy (PyPI ode-python) or any binding that gives the objects' addresses.

    registry = Registry(world)                        # an odepy dWorldID, or its integer address
    report = registry.adopt(1 / 60, space)            # everything reachable from the space, as tuned at 1/60 s
    registry.bind_joint(slider, JointParam.STOP, 1, Spring(40, 1))   # or bind rows one by one from springs

Units are SI: springs in N/m and N·s/m (N·m/rad and N·m·s/rad for angular rows), masses in kg (kg·m²), times in
s, rates in 1/s. Every failure raises SteadystepError with the library's message naming the value, and leaves the
registry and the world as they were. Handles are borrowed: the world must outlive the registry, and a joint or
body must be unbound (or destroyed through Stepper.destroy_joint/destroy_body) before ODE destroys it.
"""

from __future__ import annotations

import weakref

from steadystep.core import _handles
from steadystep.core._native import SteadystepError, check, ffi, integer, last_error, lib, number
from steadystep.core._structs import StructView
from steadystep.core.convert import Spring, spring_fields
from steadystep.core.enums import JointParam, Mapping, Status


class ServedCounts(StructView, c_type="ssServedCounts", docs={
        "by_mapping": "served by the stepping's own mapping (every one under implicit Euler)",
        "handed_to_matched": "exact only: served by matched (this step length gave exact no finite softness)",
        "handed_to_implicit_euler": "matched/exact only: served by implicit Euler (above the step's Nyquist "
                                    "frequency, undamped, no effective mass, a static load, no finite softness; "
                                    "every contact)"}):
    """Who served the rows or contacts of a step, or of a frame summed over its steps (ssServedCounts), read-only;
    each row or contact is counted once, in one of: by_mapping (the stepping's own mapping: every one under implicit
    Euler), handed_to_matched (exact only: no finite exact softness at this step length), handed_to_implicit_euler
    (matched/exact only: above the step's Nyquist frequency, undamped, no effective mass, a static load, no finite
    softness)."""

    __slots__ = ()


class ApplyReport(StructView, c_type="ssApplyReport", docs={
        "rows": "ServedCounts of every bound row, the world's included, once",
        "row_writes": "parameter sets actually written into ODE (unchanged values are skipped)"}):
    """What one Apply did (ssApplyReport), read-only: rows (ServedCounts: every bound row, the world's included,
    once), row_writes (parameter sets actually written into ODE; unchanged values are skipped)."""

    __slots__ = ()


class AdoptReport(StructView, c_type="ssAdoptReport", docs={
        "world": "1 when the world's ERP/CFM were adopted, else 0",
        "joints": "joints adopted (at least one row bound, or nothing soft but known)",
        "joint_rows": "JointParam.JOINT sets (ball, fixed, double ball, double hinge, transmission)",
        "stop_rows": "JointParam.STOP sets, one per axis",
        "motor_rows": "JointParam.MOTOR sets, one per axis",
        "suspension_rows": "JointParam.SUSPENSION sets",
        "hard_rows": "of all rows above (the world's included), those tuned with cfm = 0, kept hard",
        "bodies": "bodies adopted: known to the stepper, damping and auto-disable bound in seconds",
        "skipped_joints": "contact, null and plane-2D joints, not adopted"}):
    """What one adoption call bound, by kind (ssAdoptReport, adopt.h), read-only: world (1 when the world's ERP/CFM
    were adopted), joints, their rows by kind (joint_rows, stop_rows, motor_rows, suspension_rows), hard_rows (of
    those, tuned with cfm = 0, kept hard), bodies (known to the stepper), skipped_joints (contact, null, plane-2D),
    and any field adopt.h adds (FIELDS lists them)."""

    __slots__ = ()


def _param(param) -> int:
    # An int outside the enum goes on to the library, which refuses it by name (as in C).
    return integer("param", param, -2**31, 2**31 - 1)


def _axis(axis) -> int:
    return integer("axis", axis, -2**31, 2**31 - 1)


def _mapping(mapping) -> int:
    return integer("mapping", mapping, -2**31, 2**31 - 1)


class Registry:
    """What is soft in one ODE world, rewritten for each step length (ssRegistry).

    world: an odepy dWorldID or the world's integer address. Raises SteadystepError ("world = NULL: ...") for a
    NULL world and names any other kind of object."""

    def __init__(self, world):
        self._world = _handles.handle("world", "world", world)
        created = lib.ssRegistry_Create(self._world)
        if created == ffi.NULL:
            raise SteadystepError(Status.OUT_OF_RANGE if self._world == ffi.NULL else Status.OUT_OF_MEMORY,
                                  last_error())
        self._registry = ffi.gc(created, lib.ssRegistry_Destroy)
        self._steppers = weakref.WeakSet()  # the Steppers made with this registry (close() refuses while one lives)

    @property
    def world_address(self) -> int:
        """The address of the registry's world."""
        return int(ffi.cast("uintptr_t", self._world))

    def _handle(self):
        if self._registry is None:
            raise SteadystepError(Status.OUT_OF_RANGE, "registry: used after close()")
        return self._registry

    def close(self) -> None:
        """Destroys the registry now (ODE objects are left as they are). Raises SteadystepError naming the registry
        while a Stepper made with it is open: close the stepper first (a Stepper keeps its registry alive, so close()
        is needed only for a registry used alone)."""
        if self._registry is None:
            return
        open_steppers = [stepper for stepper in self._steppers if not stepper.closed]
        if open_steppers:
            raise SteadystepError(Status.OUT_OF_RANGE, f"registry.close(): {len(open_steppers)} open Stepper(s) "
                                  "still step with this registry; close them first (stepper.close())")
        ffi.release(self._registry)
        self._registry = None

    def _add_stepper(self, stepper) -> None:
        """A Stepper now steps with this registry: close() refuses until it is closed."""
        self._steppers.add(stepper)

    # ---- adoption (adopt.h) -----------------------------------------------------------------------------------

    def _adopt(self, call, *args) -> AdoptReport:
        out = AdoptReport.new()
        check(call(self._handle(), *args, out))
        return AdoptReport.of(out)

    def adopt(self, tuned_step_s: float, space) -> AdoptReport:
        """Adopts what the program tuned at tuned_step_s (s, > 0): the world's ERP/CFM, damping and auto-disable
        defaults, and every joint and body reachable from space (an odepy dSpaceID or an address). Either all is
        bound or, on an error, nothing is. Returns what this call bound."""
        return self._adopt(lib.ssRegistry_Adopt, number("tuned_step_s", tuned_step_s, "s"),
                           _handles.handle("space", "space", space))

    def adopt_world(self, tuned_step_s: float) -> AdoptReport:
        """Adopts the world's ERP/CFM, damping and auto-disable defaults only, as tuned at tuned_step_s (s)."""
        return self._adopt(lib.ssRegistry_AdoptWorld, number("tuned_step_s", tuned_step_s, "s"))

    def adopt_space(self, space) -> AdoptReport:
        """Adopts everything reachable from space at the registry's tuned step (adopt the world first)."""
        return self._adopt(lib.ssRegistry_AdoptSpace, _handles.handle("space", "space", space))

    def adopt_body(self, body) -> AdoptReport:
        """Adopts a body and everything reachable from it through joints, at the registry's tuned step."""
        return self._adopt(lib.ssRegistry_AdoptBody, _handles.handle("body", "body", body))

    def adopt_joint(self, joint) -> AdoptReport:
        """Adopts one joint's soft rows and its bodies, at the registry's tuned step."""
        return self._adopt(lib.ssRegistry_AdoptJoint, _handles.handle("joint", "joint", joint))

    @property
    def tuned_step_s(self) -> float:
        """The step length (s) the adopted values were tuned at; 0 before any adoption."""
        return float(lib.ssRegistry_TunedStep(self._handle()))

    # ---- bindings (registry.h) --------------------------------------------------------------------------------

    def bind_world(self, spring: Spring | tuple[float, float], effective_mass: float = 0.0) -> None:
        """Binds the world's ERP/CFM to spring (k N/m, c N·s/m); effective_mass (kg, >= 0; 0 = 1 kg) is what the
        matched and exact mappings need."""
        check(lib.ssRegistry_BindWorld(self._handle(), spring_fields(spring),
                                       number("effective_mass", effective_mass, "kg")))

    def bind_joint(self, joint, param: JointParam | int, axis: int, spring: Spring | tuple[float, float],
                   effective_mass: float = 0.0) -> None:
        """Binds one soft parameter set of joint (JointParam) on axis 1, 2 or 3 to spring (k N/m, c N·s/m; N·m/rad
        and N·m·s/rad for an angular row). effective_mass (kg or kg·m², >= 0): 0 computes it from the joint's
        bodies at each step. Binding the same joint, param and axis again replaces the binding. Raises
        SteadystepError ("unsupported") when the joint's type has no such parameter on that axis."""
        check(lib.ssRegistry_BindJoint(self._handle(), _handles.handle("joint", "joint", joint), _param(param),
                                       _axis(axis), spring_fields(spring),
                                       number("effective_mass", effective_mass, "kg")))

    def set_joint_load(self, joint, param: JointParam | int, axis: int, load: float) -> None:
        """Declares the steady load of a bound row: a force (N) or torque (N·m) on the joint's first body along the
        axis, so that matched and exact keep the rest position at load/k (registry.h)."""
        check(lib.ssRegistry_SetJointLoad(self._handle(), _handles.handle("joint", "joint", joint), _param(param),
                                          _axis(axis), number("load", load, "N")))

    def unbind_joint(self, joint) -> None:
        """Removes every binding of joint; raises SteadystepError ("not found") when it has none."""
        check(lib.ssRegistry_UnbindJoint(self._handle(), _handles.handle("joint", "joint", joint)))

    def bind_damping(self, body, linear_rate_per_s: float, angular_rate_per_s: float) -> None:
        """Binds velocity damping as rates (1/s, >= 0), the same fraction of velocity removed per second at every
        step length. body None binds the world's defaults (copied into bodies created later)."""
        check(lib.ssRegistry_BindDamping(self._handle(), _handles.handle("body", "body", body),
                                         number("linear_rate_per_s", linear_rate_per_s, "1/s"),
                                         number("angular_rate_per_s", angular_rate_per_s, "1/s")))

    def bind_auto_disable(self, body, idle_time_s: float, average_window_s: float = 0.0) -> None:
        """Binds auto-disable in seconds: idle_time_s (> 0) at rest, velocity averaged over average_window_s (s,
        >= 0). body None binds the world's defaults."""
        check(lib.ssRegistry_BindAutoDisable(self._handle(), _handles.handle("body", "body", body),
                                             number("idle_time_s", idle_time_s, "s"),
                                             number("average_window_s", average_window_s, "s")))

    def unbind_body(self, body) -> None:
        """Removes the damping and auto-disable bindings of body; raises SteadystepError ("not found")."""
        check(lib.ssRegistry_UnbindBody(self._handle(), _handles.handle("body", "body", body)))

    def apply(self, step_s: float, mapping: Mapping | int = Mapping.IMPLICIT_EULER,
              previous_step_s: float = 0.0) -> ApplyReport:
        """Writes every binding for a step of step_s (s, > 0) under mapping; previous_step_s (s; 0 = no history)
        is read by Mapping.EXACT only. Either all is written or, on an error, nothing is. A Stepper does this
        before each of its steps: call it yourself only to step the world with ODE directly."""
        out = ApplyReport.new()
        check(lib.ssRegistry_Apply(self._handle(), _mapping(mapping), number("step_s", step_s, "s"),
                                   number("previous_step_s", previous_step_s, "s"), out))
        return ApplyReport.of(out)

    @property
    def joint_binding_count(self) -> int:
        """The number of bound joint parameter sets (the world not counted)."""
        return int(lib.ssRegistry_JointBindingCount(self._handle()))


def joint_supports(joint, param: JointParam | int, axis: int) -> bool:
    """Whether the joint's type has that parameter set on that axis in ODE 0.16."""
    return bool(lib.ssJointSupports(_handles.handle("joint", "joint", joint), _param(param), _axis(axis)))


def joint_effective_mass(joint, param: JointParam | int, axis: int) -> float:
    """The effective mass (kg) or inertia (kg·m²) of the joint row that param/axis drives, from its bodies now."""
    out = ffi.new("double*")
    check(lib.ssJointEffectiveMass(_handles.handle("joint", "joint", joint), _param(param), _axis(axis), out))
    return float(out[0])


def contact_soften(contact, body1, body2, spring: Spring | tuple[float, float], mapping: Mapping | int,
                   step_s: float, previous_step_s: float = 0.0) -> None:
    """Writes the softness of spring (k N/m, c N·s/m) for a step of step_s (s) into an ODE contact (an odepy
    dContact or its address): surface.soft_erp, soft_cfm and both mode bits. Every mapping writes the
    implicit-Euler softness: matched and exact serve no contact, whose load is never known (docs/exact-mappings.md);
    body1, body2 (the contact's bodies, None for the static world) are checked but not read. On an error the contact
    is unchanged.
    With a Stepper, use Stepper.soften_contact instead, which knows the step."""
    pointer = _handles.contact("contact", contact)
    check(lib.ssContactSoften(pointer, _handles.handle("body1", "body", body1),
                              _handles.handle("body2", "body", body2), spring_fields(spring), _mapping(mapping),
                              number("step_s", step_s, "s"), number("previous_step_s", previous_step_s, "s")))

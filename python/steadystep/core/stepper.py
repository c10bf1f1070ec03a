"""The stepper for a program's own ODE world (stepper.h): one call per rendered frame instead of dWorldQuickStep.

    stepper = Stepper(world, space=space, tuned_step_s=1 / 60, solver=Solver.QUICK, policy="exact",
                      collide=collide, contact_group=contacts)   # adopts all the space reaches, as tuned at 1/60 s
    for frame_s in frames:                    # the frame's real length (s)
        odepy.dBodyAddForce(car, throttle, 0, 0)   # added once a frame: held at every step until the next frame's
        report = stepper.step(frame_s)        # FrameReport; SteadystepError on a blow-up: repair, then reset()

Callbacks are plain Python callables, called from C during step(): before_step(stepper) (or before_step(stepper,
step)) and collide(stepper) before each physics step, step_done(step_s) after each step that passed the checks.
stepper.current_step() tells the step about to be taken: its length step_s (s) and the simulated time at its start
time_s (s). The program's per-step logic goes in before_step, computed from those two: anything that depends on the
state or on the time (a controller, drag, a motor's target, a scripted input):

    def before_step(stepper, step):           # step: stepper.current_step(), a StepInfo
        odepy.dJointSetHingeParam(motor, odepy.dParamVel, target_speed(step.time_s))

Under the fixed policy the n-th step starts at the same time_s, to the bit, at every frame rate: logic computed there
makes the motion identical at every frame rate; the same logic run once a frame does not.

collide typically calls odepy.dSpaceCollide(space, None, near) and the near callback calls
stepper.soften_contact(contact, body1, body2) before dJointCreateContact. An exception raised by a callback does
not cross C: it is kept, the callbacks are not called again for the rest of that frame (whose remaining steps
ODE still takes), and step() raises it once the frame is over. The near callback is called by ODE through ctypes,
which prints an exception and goes on: a refusal of the stepper's own calls made there (soften_contact ...) is
kept for step() all the same, and wrapping the near callback, odepy.dNearCallback(stepper.near_callback(near)),
keeps any exception it raises.

Handles (world, bodies, joints, the contact group) are odepy handles, PyODE objects (steadystep.core.pyode) or integer
addresses, borrowed: the world and the registry must outlive the stepper (it keeps its Registry alive; close() the
stepper before dWorldDestroy). A PyODE JointGroup given as contact_group is emptied through PyODE's own
JointGroup.empty() (PyODE keeps a wrapper for each joint in it), after every step and after a refused frame.

Contacts at the cost of C: a ContactRule, contact_rule=ContactRule(surface, max_contacts=...), replaces a near
callback that gives every contact one surface: the stepper collides the space, softens and joins every contact in C
at every step (ssStepper_CollideByRule), with no Python call per contact; stepper.collide_by_rule(rule) does the
same from the program's own collide.
"""

from __future__ import annotations

import atexit
import dataclasses
import weakref
from collections.abc import Callable

from steadystep.core import _handles, _libode, pyode
from steadystep.core._native import SteadystepError, check, ffi, integer, last_error, lib, number, shown
from steadystep.core._structs import StructView, address_of
from steadystep.core.enums import Mapping, Solver, Status
from steadystep.core.registry import AdoptReport, Registry  # also declares ServedCounts, the view of rows, contacts
from steadystep.core.stepping import Stepping, stepping_from


class StepInfo(StructView, c_type="ssStepInfo", convert={"mapping": Mapping}, docs={
        "mapping": "the Mapping this step's softness is written with",
        "step_s": "the length of the physics step about to be taken (s)",
        "softness_step_s": "the step length the softness is for (s): step_s, or stepping.frozen_step_s",
        "previous_step_s": "the step before, for Mapping.EXACT (s); 0 when there is no usable history",
        "index": "0-based index of this step within the frame",
        "count": "steps this frame takes",
        "time_s": "the simulated time at this step's start (s), every step since the stepper was made added in "
                  "order; under the fixed cut the same bits for the n-th step at every frame rate"}):
    """The physics step about to be taken (ssStepInfo), as current_step() gives it inside the callbacks: mapping
    (the Mapping this step's softness is written with), step_s (the length of the step about to be taken, s),
    softness_step_s (the step length the softness is for, s: step_s, or stepping.frozen_step_s), previous_step_s
    (the step before, for Mapping.EXACT, s; 0 when there is no usable history), index (0-based, within the frame),
    count (steps this frame takes), time_s (the simulated time at the step's start, s: every step the stepper took
    since it was made, added in order; under the fixed cut the same bits for the n-th step at every frame rate).
    Fields as stepper.h declares them, read-only; a StepInfo is a copy, which keeps its values after the step."""

    __slots__ = ()


class FrameReport(StructView, c_type="ssFrameReport", convert={"failed_body": address_of}, docs={
        "steps": "physics steps taken",
        "step_s": "length of the last step taken (s); 0 when none",
        "simulated_s": "time simulated this frame (s)",
        "time_s": "the stepper's simulated time after this frame (s): the time to label the frame's state with "
                  "(the same bits after the same number of steps under the fixed cut at every frame rate)",
        "carried_s": "time not simulated yet, carried to the next frame (s): the fixed cut's accumulator, or a "
                     "frame too short to step",
        "dropped_s": "time dropped by stepping.max_steps_per_frame (s), never simulated",
        "interpolation": "the fixed cut's blend factor, accumulator / fixed_step_s in [0, 1): blend the last two "
                         "states with it to render",
        "rows": "ServedCounts of row-steps: every bound row (the world's included) once per physics step, by who "
                "served it",
        "contacts": "ServedCounts of the contacts softened with soften_contact (or a ContactRule), by who served them",
        "row_writes": "parameter sets written into ODE, summed over the frame's applies",
        "unsoftened_contact_steps": "steps whose collision made contacts on known bodies but softened none (a near "
                                    "callback that forgot soften_contact: those contacts keep the softness tuned "
                                    "for one step length)",
        "program_writes": "values the program wrote into ODE since the stepper last looked (the world's ERP/CFM, a "
                          "bound joint row, a body's damping or auto-disable), each taken as tuned at the tuned step",
        "failed_body": "the address of the body that blew up or ran too fast, else 0 (compare with "
                       "ctypes.cast(body, c_void_p).value)"}):
    """What one frame did (ssFrameReport), with the fields and meanings stepper.h gives them, read-only and read
    from the C report when asked for (FIELDS lists them; as_dict() copies them): steps, step_s (s), simulated_s (s),
    time_s (the stepper's simulated time after the frame, s: the time to label the frame's state with, the same
    bits after the same number of steps under the fixed cut at every frame rate), carried_s, dropped_s (s),
    interpolation (the fixed cut's blend factor, in [0, 1)), ... failed_body is the address of the body that failed,
    else 0 (compare with ctypes.cast(body, c_void_p).value). help(FrameReport) shows every field with its unit."""

    __slots__ = ()


class ContactRuleReport(StructView, c_type="ssContactRuleReport", docs={
        "pairs": "pairs of geoms dCollide was asked about (pairs of two static geoms are skipped)",
        "contacts": "contact joints made, each softened (counted in the frame report's contacts)",
        "dropped": "contacts whose position, normal or depth was not finite, dropped without a joint"}):
    """What one collision by a ContactRule made (ssContactRuleReport), read-only: pairs (pairs of geoms dCollide
    was asked about), contacts (contact joints made, each softened and counted in the frame report), dropped
    (contacts whose position, normal or depth was not finite, dropped without a joint)."""

    __slots__ = ()


@dataclasses.dataclass(frozen=True)
class ContactRule:
    """A near callback that gives every contact one surface, as a rule the stepper applies in C (ssContactRule,
    stepper.h): for every pair of geoms of space (the stepper's space when None) not both static, dCollide asks for
    up to max_contacts contacts (1 to 4096; PyODE's ode.collide asks 150, ODE's demos 4 to 10); each gets the
    surface (mode, mu, bounce, soft ERP/CFM as tuned, ...) and fdir1 of `surface`, is softened for the step as
    Stepper.soften_contact softens it, and becomes a contact joint attached to the geoms' bodies, in the order
    dSpaceCollide gives the pairs: the joints the near callback would make, bit for bit. skip_connected: no
    contact between two bodies a joint other than a contact connects (as ODE's demos do).

    surface: a PyODE ode.Contact, an odepy dContact or an address, read at every step (the rule keeps it alive):
    change it with its setters between frames and the next step uses the new surface."""

    surface: object
    max_contacts: int = 4
    skip_connected: bool = False
    space: object = None


# The per-frame path, looked up once. ssStepper_Step zeroes its report before anything else, on every path
# (src/stepper.c; tests/python/test_lifetimes.py holds it to that), so the report's memory is not cleared twice.
_FRAME_REPORT = ffi.typeof("ssFrameReport*")
_new_frame_report = ffi.new_allocator(should_clear_after_alloc=False)
_step_frame = lib.ssStepper_Step
_frame_report = FrameReport.of
_collide_by_rule = lib.ssStepper_CollideByRule
_soften = lib.ssStepper_SoftenContact
_soften_batch = lib.ssStepper_SoftenContacts
_body = _handles.handle
# PyODE's objects in the near callback (soften_contact), their classes' layout checked (steadystep.core.pyode.FAMILY)
_FAMILY = pyode.FAMILY
_OFFSET = pyode.FIELD_OFFSET
_cast = ffi.cast
_CONTACT_POINTER = ffi.typeof("dContact*")
_BODY_FIELD = ffi.typeof("dBodyID*")
_NULL_BODY = ffi.cast("dBodyID", 0)


def _contact(value):
    return _handles.contact("contact", value)

_RULE_REPORT = ffi.typeof("ssContactRuleReport*")


def _checked_callable(name: str, value):
    if value is not None and not callable(value):
        raise SteadystepError(Status.OUT_OF_RANGE, f"{name} = {shown(value)}: must be callable or None")
    return value


class Stepper:
    """Steps one ODE world frame by frame (ssStepper).

    world: an odepy dWorldID or an address. registry: a Registry of that world, or None (nothing soft is rewritten,
    only watched bodies are known). space: the program's space, or None: with it, the world and everything the
    space reaches are adopted as tuned at tuned_step_s (s, required with space), into registry or into one the
    stepper owns. solver: the ODE step the program calls, Solver.QUICK or Solver.STEP; required unless stepping
    says it. stepping: a Stepping, or policy: a preset's name (policy_names()), whose naive softness is frozen at
    reference_step_s (s; default the tuned step, else 1/60 s); neither: the defaults. max_step_s and fixed_step_s
    of 0 (the defaults) are the tuned step. before_step(stepper), collide(stepper): called before each physics
    step; step_done(step_s): after each step that passed the checks. contact_group: an odepy dJointGroupID (or an
    address) emptied in C after every step, a PyODE JointGroup emptied through its empty() after every step and
    after a refused frame, or None. contact_rule: a ContactRule applied at every step after collide (contacts made
    in contact_group, or in a group of the stepper's own when that is PyODE's or None). Raises SteadystepError
    naming a bad value.

    before_step is the program's per-step logic: it reads the step from stepper.current_step() (a StepInfo: time_s,
    the simulated time at the step's start, and step_s, its length, both in s). A before_step that requires two
    positional parameters, before_step(stepper, step), is given that StepInfo as its second argument; one that
    requires one (or cannot be inspected) is called before_step(stepper), as always."""

    def __init__(self, world, registry: Registry | None = None, *, space=None, tuned_step_s: float = 0.0,
                 solver: Solver | None = None, stepping: Stepping | None = None,
                 policy: str | None = None, reference_step_s: float | None = None,
                 before_step: Callable[["Stepper"], object] | Callable[["Stepper", StepInfo], object] | None = None,
                 collide: Callable[["Stepper"], object] | None = None,
                 step_done: Callable[[float], object] | None = None, contact_group=None,
                 contact_rule: ContactRule | None = None):
        if registry is not None and not isinstance(registry, Registry):
            raise SteadystepError(Status.OUT_OF_RANGE,
                                  f"registry = {shown(registry)}: must be a steadystep.Registry or "
                                  "None")
        tuned_step_s = number("tuned_step_s", tuned_step_s, "s")
        if reference_step_s is None:
            tuned = tuned_step_s or (registry.tuned_step_s if registry is not None else 0.0)
            reference_step_s = tuned if tuned > 0 else 1.0 / 60.0
        self._stepping = stepping_from(stepping, policy, reference_step_s)
        if solver is not None:
            self._stepping = dataclasses.replace(self._stepping, solver=solver)
        self._registry = registry  # kept alive: the C stepper borrows it
        before_step = _checked_callable("before_step", before_step)
        if before_step is not None and _takes_the_step(before_step):
            given = before_step
            before_step = lambda stepper: given(stepper, stepper.current_step())  # noqa: E731
        self._user = {"before_step": before_step,
                      "collide": _checked_callable("collide", collide),
                      "step_done": _checked_callable("step_done", step_done)}
        if contact_rule is not None and not isinstance(contact_rule, ContactRule):
            raise SteadystepError(Status.OUT_OF_RANGE, f"contact_rule = {shown(contact_rule)}: must be a "
                                  "steadystep.ContactRule or None")
        self._pending: BaseException | None = None  # the first exception a callback raised in this frame
        self._in_frame = False
        self._stepper = None
        self._rules: dict = {}  # id(ContactRule) -> (the rule, its ssContactRule): made once per rule
        # A PyODE JointGroup is emptied through PyODE (its wrappers); the C side then empties a group of its own,
        # where a ContactRule makes its joints (as it does when the program gives no group).
        self._pyode_group = contact_group if pyode.is_joint_group(contact_group) else None

        definition = ffi.new("ssStepperDef*", lib.ssDefaultStepperDef())
        definition.world = _handles.handle("world", "world", world)
        definition.space = _handles.handle("space", "space", space)
        definition.tuned_step_s = tuned_step_s
        definition.registry = registry._handle() if registry is not None else ffi.NULL
        definition.stepping = self._stepping.as_c_fields()
        if self._pyode_group is None:
            definition.contact_group = _handles.handle("contact_group", "joint group", contact_group)
        self._world = definition.world
        self._space = definition.space
        if self._stepping.solver == Solver.UNSET and definition.world != ffi.NULL:  # (C names a NULL world first)
            raise SteadystepError(Status.UNSUPPORTED, "solver = None: say which ODE step the program calls "
                                  "(Solver.QUICK for dWorldQuickStep, Solver.STEP for dWorldStep)")
        own_group = 0
        if definition.contact_group == ffi.NULL and (contact_rule is not None or self._pyode_group is not None):
            own_group = _libode.ode().dJointGroupCreate(0) or 0
            if own_group == 0:
                raise SteadystepError(Status.OUT_OF_MEMORY, "dJointGroupCreate: ODE made no joint group")
            definition.contact_group = ffi.cast("dJointGroupID", own_group)
        self._contact_group = definition.contact_group
        out = ffi.new("ssStepper**")
        try:
            # The C callbacks hold only a weak reference, so that the stepper can be collected; they live as long
            # as the stepper (self._callbacks), which is what C needs.
            me = weakref.ref(self)
            self._callbacks = []
            if before_step is not None:
                definition.before_step = self._callback("ssStepCallback*",
                                                        lambda context, handle: _call(me, "before_step"))
            if contact_rule is not None:
                self._c_rule(contact_rule)  # checked now (ssValidateContactRule): refused before anything is made
                self._user["collide"] = _collide_with_rule(self._user["collide"], contact_rule)
            if self._user["collide"] is not None:
                definition.collide = self._callback("ssStepCallback*", lambda context, handle: _call(me, "collide"))
            if self._pyode_group is not None:
                group = self._pyode_group
                definition.step_done = self._callback("ssStepDoneCallback*",
                                                      lambda context, step_s: _emptied_then(me, group, step_s))
            elif step_done is not None:
                definition.step_done = self._callback("ssStepDoneCallback*",
                                                      lambda context, step_s: _call(me, "step_done", step_s))
            check(lib.ssStepper_Create(definition, out))
        except BaseException:
            if own_group:
                _libode.ode().dJointGroupDestroy(own_group)
            raise
        # The destructor holds the C registry, so that however the two are collected, the stepper goes first (and
        # then the group of its own, which it empties); and what the program gave, so that PyODE, which destroys
        # an object when its last reference goes, keeps the world and the spaces until the stepper has written
        # the program's own numbers back into them (ssStepper_Destroy).
        kept = (registry._registry if registry is not None else None, world, space, contact_group, contact_rule)
        self._stepper = ffi.gc(out[0], lambda stepper, kept=kept, group=own_group: _destroy(stepper, group))
        if registry is not None:
            registry._add_stepper(self)
        if any(pyode.is_pyode(given) for given in (world, space, contact_group)):
            _PYODE_STEPPERS.add(self)  # closed at exit, before the program's PyODE objects go in any order

    def _callback(self, ctype: str, function):
        made = ffi.callback(ctype, function)
        self._callbacks.append(made)
        return made

    def _handle(self):
        if self._stepper is None:
            raise self._refused(SteadystepError(Status.OUT_OF_RANGE, "stepper: used after close()"))
        return self._stepper

    def _between_frames(self, what: str):
        if self._in_frame:
            raise self._refused(SteadystepError(Status.REENTERED, f"stepper.{what}: called from a callback of the same "
                                                "stepper, inside its frame"))
        return self._handle()

    def _refused(self, error: BaseException) -> BaseException:
        """error, also kept for step() to raise when it happens inside a frame: a call made from odepy's near
        callback (soften_contact, ...) raises into ctypes, which prints the exception and goes on."""
        if self._in_frame and self._pending is None:
            self._pending = error
        return error

    @property
    def closed(self) -> bool:
        """Whether close() was called (or the stepper was never made)."""
        return self._stepper is None

    @property
    def registry(self) -> Registry | None:
        return self._registry

    @property
    def stepping(self) -> Stepping:
        """How frames become steps now."""
        return Stepping.from_c(lib.ssStepper_Stepping(self._handle()))

    @stepping.setter
    def stepping(self, stepping: Stepping) -> None:
        """Changes the stepping between frames (resets the step history and the FIXED accumulator)."""
        stepping = stepping_from(stepping, None, 0.0)
        check(lib.ssStepper_SetStepping(self._between_frames("stepping"),
                                        ffi.new("ssStepping*", stepping.as_c_fields())))
        self._stepping = stepping

    def step(self, frame_s: float) -> FrameReport:
        """Advances the world by one frame of frame_s seconds (0 <= frame_s <= 3600; 0 takes no step). Forces the
        program added to known bodies before this call are held (a zero-order hold): they act, unchanged, at every
        physics step until the next frame's forces replace them, and time left unstepped carries them with it, so
        F·dt is exact over the run; an input that varies within a frame belongs in before_step. Returns the
        frame's FrameReport. Raises SteadystepError with the library's message (the world left as it was for a
        refused frame); for a body refused at the boundary before the frame or a step (a state or force ODE cannot step, Status.POSITION_LIMIT, ...) or one that blew
        up or ran away in a step (Status.BLOWUP, Status.SPEED_LIMIT) the error's `report` is the FrameReport, whose
        failed_body names the body, and every later frame is refused (Status.FAILED) until reset(). An exception
        raised by a callback, or by a call the near callback made (soften_contact ...), is raised here, after the
        frame, with the frame's FrameReport (or its error) as its `steadystep_report` (or `__context__`)."""
        if self._in_frame or self._stepper is None:
            self._between_frames("step")
        if type(frame_s) is not float:
            frame_s = number("frame_s", frame_s, "s")
        report = _new_frame_report(_FRAME_REPORT)
        self._in_frame = True
        try:
            status = _step_frame(self._stepper, frame_s, report)
        finally:
            self._in_frame = False
        if status or self._pending is not None:
            if self._pyode_group is not None:
                self._pyode_group.empty()  # a step refused before or after ODE's step: its contacts go, as in C
            self._raise_for_frame(status, _frame_report(report))
        return _frame_report(report)

    def _raise_for_frame(self, status: int, made: FrameReport):
        pending, self._pending = self._pending, None
        error = None
        if status:
            error = SteadystepError(status, last_error())
            if made.failed_body:  # a body refused at the boundary, or that blew up or ran away in a step
                error.report = made
        try:
            if pending is not None:
                try:
                    pending.steadystep_report = made
                except AttributeError:
                    pass
                if error is not None:
                    raise pending from error
                raise pending
            raise error
        finally:
            # No reference cycle through this frame (an error held by a local of the frame its traceback holds):
            # garbage in a cycle is freed by the cycle collector, which frees PyODE's objects in any order (a World
            # before its Bodies: a crash inside PyODE), and the caller's frames, with the program's objects, would
            # be part of it.
            pending = error = None

    @property
    def adopted(self) -> AdoptReport:
        """What the stepper's own adoption (space=...) reached, at creation and since (ssStepper_Adopted)."""
        return AdoptReport.of(lib.ssStepper_Adopted(self._handle()))

    @property
    def known_body_count(self) -> int:
        """How many bodies the stepper knows now (ssStepper_KnownBodyCount): forces held over a frame, checked at
        every step. A body nothing reaches (no geom in the space, no joint to a known body) is not among them:
        watch_body() it."""
        count = lib.ssStepper_KnownBodyCount(self._handle())
        if count < 0:
            check(lib.SS_ERROR_OUT_OF_MEMORY)
        return count

    def current_step(self) -> StepInfo:
        """The step about to be taken (a copy): meaningful inside before_step and collide, where time_s is the
        simulated time at its start and step_s its length (s). Between frames it describes no step to come: the
        stepper's simulated time is then the last FrameReport's time_s."""
        return StepInfo.of(lib.ssStepper_CurrentStep(self._handle()))

    def near_callback(self, near: Callable) -> Callable:
        """near (an odepy near callback, near(data, geom1, geom2)) wrapped so that an exception it raises during a
        frame is kept and raised by step(), as a callback's is, instead of being printed and lost by ctypes:
        odepy.dSpaceCollide(space, None, odepy.dNearCallback(stepper.near_callback(near)))."""
        me = weakref.ref(self)

        def kept_near(*args):
            stepper = me()
            try:
                near(*args)
            except BaseException as error:  # noqa: BLE001 - raised by step() after the frame
                if stepper is None or not stepper._in_frame:
                    raise
                stepper._refused(error)

        return kept_near

    def soften_contact(self, contact, body1, body2) -> None:
        """In the near callback, before dJointCreateContact: turns the contact's tuned softness (its soft_erp /
        soft_cfm where surface.mode has them, else the world's ERP/CFM, as tuned at the registry's tuned step) into
        the softness for the step about to be taken: implicit Euler's under every mapping (matched and exact serve no
        contact and count it in report.contacts.handed_to_implicit_euler). contact: an odepy dContact (or its
        address) or a PyODE Contact (before ode.ContactJoint copies it); body1, body2 its bodies (None for the
        static world). Raises SteadystepError with the contact unchanged (adopt first). One Python call per contact:
        a ContactRule makes a step's contacts in C."""
        stepper = self._stepper
        if stepper is not None and _FAMILY.get(type(contact)) == "contact":  # PyODE's: the fast path
            # its bodies (None, or PyODE Bodies whose ODE body is alive) read from their checked layout, inline
            first = second = _NULL_BODY
            if body1 is not None:
                first = (_cast(_BODY_FIELD, id(body1) + _OFFSET)[0] if _FAMILY.get(type(body1)) == "body"
                         else _NULL_BODY)
            if body2 is not None:
                second = (_cast(_BODY_FIELD, id(body2) + _OFFSET)[0] if _FAMILY.get(type(body2)) == "body"
                          else _NULL_BODY)
            if (body1 is None or first != _NULL_BODY) and (body2 is None or second != _NULL_BODY):
                status = _soften(stepper, _cast(_CONTACT_POINTER, id(contact) + _OFFSET), first, second)
                if status:
                    raise self._refused(SteadystepError(status, last_error()))
                return
        try:
            if stepper is None:
                self._handle()
            # the bodies are not read (stepper.h): a PyODE Body's pointer is taken from its checked layout alone
            status = _soften(stepper, _contact(contact), _body("body1", "body", body1, False),
                             _body("body2", "body", body2, False))
            if status:
                check(status)
        except SteadystepError as error:
            raise self._refused(error)

    def soften_contacts(self, contacts, count: int) -> None:
        """In the near callback, before dJointCreateContact: softens the count contacts one dCollide filled, each as
        soften_contact would, in one call (ssStepper_SoftenContacts): one Python call a pair instead of one a
        contact. contacts: an odepy dContact array (ctypes; count at most its length), or its first dContact, a
        pointer to it or its address; count: an integer, 0 or more. All or nothing: a refused batch raises
        SteadystepError naming the contact, with every contact left as given."""
        try:
            count = integer("count", count, 0, 2**31 - 1)
            check(_soften_batch(self._handle(), _handles.contacts("contacts", contacts, count), count))
        except SteadystepError as error:
            raise self._refused(error)

    def collide_by_rule(self, rule: ContactRule) -> ContactRuleReport:
        """In collide: what the near callback rule stands for, done in C for the step about to be taken
        (ssStepper_CollideByRule; see ContactRule): every contact made, softened and joined in the stepper's
        contact group (or its own), with no Python call per contact. Returns the ContactRuleReport. Raises
        SteadystepError naming a bad value, with no joint made (a stepper given no contact group and no
        contact_rule has no group to make them in)."""
        try:
            made = self._c_rule(rule)
            report = ffi.new(_RULE_REPORT)
            check(_collide_by_rule(self._handle(), made, report))
        except SteadystepError as error:
            raise self._refused(error)
        return ContactRuleReport.of(report)

    def _c_rule(self, rule: ContactRule):
        """rule as the library's ssContactRule, made and checked once per rule (the rule keeps its surface)."""
        known = self._rules.get(id(rule))
        if known is not None and known[0] is rule:
            return known[1]
        if not isinstance(rule, ContactRule):
            raise SteadystepError(Status.OUT_OF_RANGE, f"rule = {shown(rule)}: must be a steadystep.ContactRule")
        if self._contact_group == ffi.NULL:
            raise SteadystepError(Status.OUT_OF_RANGE, "rule: the stepper has no contact group to make the contacts "
                                  "in: make it with contact_group=... or contact_rule=...")
        made = ffi.new("ssContactRule*", lib.ssDefaultContactRule())
        made.world = self._world
        made.space = (_handles.handle("rule.space", "space", rule.space) if rule.space is not None
                      else self._space)
        if made.space == ffi.NULL:
            raise SteadystepError(Status.OUT_OF_RANGE, "rule.space = None: the stepper has no space either; give the "
                                  "rule the space to collide")
        made.contact_group = self._contact_group
        made.surface = _handles.contact("rule.surface", rule.surface)
        made.max_contacts = integer("rule.max_contacts", rule.max_contacts, -2**31, 2**31 - 1)
        if not isinstance(rule.skip_connected, bool):
            raise SteadystepError(Status.OUT_OF_RANGE,
                                  f"rule.skip_connected = {shown(rule.skip_connected)}: must be True or False")
        made.skip_connected = int(rule.skip_connected)
        check(lib.ssValidateContactRule(made))
        self._rules[id(rule)] = (rule, made)
        return made

    def interpolated_pose(self, body) -> tuple[tuple[float, float, float], tuple[float, float, float, float]]:
        """The pose to draw body at after the last frame (steadystep/interpolation.h): (position in m, rotation as
        ODE's quaternion w, x, y, z). Under the fixed cut, blended between its last two physics states at the
        frame's interpolation factor (drawn up to one fixed step behind; a body the program moved between frames is
        drawn where it put it); under the other cuts ODE's own pose. SteadystepError ("not found") for a body the
        stepper did not know at its last fixed frame."""
        position, quaternion = ffi.new("double[3]"), ffi.new("double[4]")
        check(lib.ssStepper_InterpolatedPose(self._between_frames("interpolated_pose"),
                                             _handles.handle("body", "body", body), position, quaternion))
        return tuple(position), tuple(quaternion)

    def set_interpolation(self, on: bool) -> None:
        """Keeps the poses to draw under the fixed cut (True, the default) or nothing (False: a program that draws
        nothing; interpolated_pose then gives ODE's pose)."""
        if not isinstance(on, bool):
            raise SteadystepError(Status.OUT_OF_RANGE, f"on = {shown(on)}: must be True or False")
        check(lib.ssStepper_SetInterpolation(self._between_frames("set_interpolation"), int(on)))

    def reset(self) -> None:
        """After a failure, once the program repaired or restored its bodies: accepts frames again. Also forgets
        the step history, the FIXED accumulator and the momentum carried over, and has ODE measure every
        transmission joint on a known body afresh at the next frame (see ssStepper_Reset)."""
        lib.ssStepper_Reset(self._between_frames("reset"))

    def reset_history(self) -> None:
        """Forgets the previous step length (after teleporting a body or setting its velocity), so that the next
        exact step maps the true velocities."""
        lib.ssStepper_ResetHistory(self._between_frames("reset_history"))

    def watch_body(self, body) -> None:
        """Makes a body known: its forces held for every step until the next frame, its state checked after each
        step."""
        try:
            check(lib.ssStepper_WatchBody(self._handle(), _handles.handle("body", "body", body)))
        except SteadystepError as error:
            raise self._refused(error)

    def unwatch_body(self, body) -> None:
        """Stops watching a body; SteadystepError ("not found") when it was not watched."""
        try:
            check(lib.ssStepper_UnwatchBody(self._handle(), _handles.handle("body", "body", body)))
        except SteadystepError as error:
            raise self._refused(error)

    def destroy_body(self, body) -> None:
        """Destroys a body the stepper may know (unwatched, unbound, its joints unbound, then dBodyDestroy). Use it
        instead of odepy.dBodyDestroy for any known body. A PyODE Body is left empty (its pointer NULL, so that
        PyODE does not destroy it again): drop it."""
        check(lib.ssStepper_DestroyBody(self._between_frames("destroy_body"), _handles.handle("body", "body", body)))
        if pyode.is_pyode(body):
            pyode.forget_body(body)  # PyODE must not destroy it again: the Body is left empty, drop it

    def destroy_joint(self, joint) -> None:
        """Destroys a joint (unbound, then dJointDestroy). Use it instead of odepy.dJointDestroy for a bound or
        adopted joint. A PyODE joint is then let go of as PyODE's JointGroup does (its _destroyed())."""
        check(lib.ssStepper_DestroyJoint(self._between_frames("destroy_joint"),
                                         _handles.handle("joint", "joint", joint)))
        if pyode.is_pyode(joint):
            joint._destroyed()  # PyODE's own way to let go of a joint destroyed behind it

    def close(self) -> None:
        """Destroys the stepper now (the world and the registry are left as they are). Call it before destroying
        the world."""
        if self._stepper is not None:
            self._between_frames("close")
            ffi.release(self._stepper)
            self._stepper = None


def _takes_the_step(function) -> bool:
    """Whether before_step wants the StepInfo as a second argument: it requires two positional parameters. A
    callable that requires one, takes *args or defaults its second, or whose signature cannot be read, is called
    with the stepper alone, as before_step always was."""
    import inspect

    try:
        parameters = inspect.signature(function).parameters.values()
    except (TypeError, ValueError):
        return False
    positional = (inspect.Parameter.POSITIONAL_ONLY, inspect.Parameter.POSITIONAL_OR_KEYWORD)
    return sum(1 for p in parameters if p.kind in positional and p.default is inspect.Parameter.empty) >= 2


def _call(stepper_ref, which: str, *args) -> None:
    """Runs a user callback from C. Nothing may propagate into C: the first exception is kept for step()."""
    stepper = stepper_ref()
    if stepper is None or stepper._pending is not None:
        return
    try:
        function = stepper._user[which]
        function(*args) if which == "step_done" else function(stepper)
    except BaseException as error:  # noqa: BLE001 - re-raised by step(), KeyboardInterrupt included
        stepper._pending = error


_PYODE_STEPPERS: weakref.WeakSet = weakref.WeakSet()


@atexit.register
def _close_pyode_steppers() -> None:
    """At exit, while the program's PyODE objects are all alive: every stepper of a PyODE world closed (when the
    interpreter clears the modules, PyODE destroys bodies and geoms in any order, and a stepper closed after one of
    its bodies went would read freed memory)."""
    for stepper in list(_PYODE_STEPPERS):
        if not stepper.closed and not stepper._in_frame:
            stepper.close()


def _destroy(stepper, own_group: int) -> None:
    lib.ssStepper_Destroy(stepper)
    if own_group:
        _libode.ode().dJointGroupDestroy(own_group)


def _collide_with_rule(collide, rule: ContactRule):
    """The program's collide (or none), then the rule, as one collide callback."""
    def collide_and_rule(stepper) -> None:
        if collide is not None:
            collide(stepper)
        stepper.collide_by_rule(rule)

    return collide_and_rule


def _emptied_then(stepper_ref, group, step_s: float) -> None:
    """step_done with a PyODE contact group: the group emptied through PyODE after every step (whatever a callback
    raised before), then the program's step_done."""
    stepper = stepper_ref()
    if stepper is None:
        return
    try:
        group.empty()
    except BaseException as error:  # noqa: BLE001 - raised by step(), as a callback's
        if stepper._pending is None:
            stepper._pending = error
    if stepper._user["step_done"] is not None:
        _call(stepper_ref, "step_done", step_s)


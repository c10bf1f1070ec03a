"""PyODE (``import ode``, Debian's python3-pyode) through steadystep: its objects taken as they are once its layout
checked out against libode, a layout that does not check out refused by name, its group emptied through PyODE, its
ODE 0.15 parameter numbers warned about, and the example program (examples/pyode_vehicle.py) adopted: bit for bit
its own loop under naive at 60, 30 and 15-45 fps, contacts by rule or in its near callback, its memory flat.

PyODE is required (scripts/deps.sh installs it and lets .venv see it); STEADYSTEP_NO_PYODE=1 skips this module
knowingly, by name. The truths are read from libode and PyODE's own getters, not from the library.
"""

import ctypes
import gc
import os
import re
import struct
import subprocess
import sys
import types
from pathlib import Path

import pytest

if os.environ.get("STEADYSTEP_NO_PYODE") == "1":
    pytest.skip("STEADYSTEP_NO_PYODE=1: PyODE's tests skipped on purpose", allow_module_level=True)
try:
    import ode
except ImportError as error:  # not a silent skip: CI must run these
    raise ImportError("PyODE (import ode) is not importable: run scripts/deps.sh (Debian's python3-pyode, seen by "
                      ".venv), or set STEADYSTEP_NO_PYODE=1 to skip these tests on purpose") from error

import steadystep as ss
from steadystep.core import _libode, pyode
from steadystep.core.enums import Status

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "examples"))
import pyode_vehicle  # noqa: E402

LIBODE = _libode.ode()


def state(bodies) -> bytes:
    """Every body's position, rotation and velocities, as bytes: equal means equal to the bit."""
    values = [v for b in bodies for v in (*b.getPosition(), *b.getQuaternion(), *b.getLinearVel(),
                                          *b.getAngularVel())]
    return struct.pack(f"{len(values)}d", *values)


def refusal(call, *args, **kwargs):
    """The (code, message) of the SteadystepError call raises. The error is not kept: its traceback's frames hold
    PyODE objects, and PyODE objects freed by the cycle collector go in any order (a body after its world: a crash
    inside PyODE), so a test never keeps one in a cycle."""
    try:
        call(*args, **kwargs)
    except ss.SteadystepError as error:
        return error.code, str(error)
    raise AssertionError(f"{call} raised nothing")


def joint_wrappers(group) -> list:
    """PyODE's list of the joint wrappers it keeps for a JointGroup (its one referent)."""
    return gc.get_referents(group)[0]


@pytest.fixture
def fresh_layout(monkeypatch):
    """The layout checked again from scratch, whatever the test patches, and forgotten after."""
    monkeypatch.setattr(pyode, "_layout_of", {})
    saved = dict(pyode.FAMILY)
    pyode.FAMILY.clear()
    yield
    pyode.FAMILY.clear()
    pyode.FAMILY.update(saved)


# ---- the objects ------------------------------------------------------------------------------------------------

def test_pyode_objects_reach_the_ode_objects_libode_gives():
    world = ode.World()
    world.setERP(0.35)
    space = ode.HashSpace()
    body = ode.Body(world)
    body.setPosition((0.5, 1.0, -2.0))
    geom = ode.GeomBox(space, (0.2, 0.2, 0.2))
    geom.setBody(body)
    other = ode.Body(world)
    hinge = ode.HingeJoint(world)
    hinge.attach(body, other)
    from steadystep.core import _handles

    assert _handles.address("body", "body", body) == LIBODE.dGeomGetBody(geom._id())
    assert _handles.address("world", "world", world) == LIBODE.dBodyGetWorld(LIBODE.dGeomGetBody(geom._id()))
    assert _handles.address("joint", "joint", hinge) == LIBODE.dBodyGetJoint(LIBODE.dGeomGetBody(geom._id()), 0)
    assert _handles.address("space", "space", space) == space._id()
    contact = ode.Contact()
    contact.setMu(0.625)
    held = _libode.Contact.from_address(int(ss.core._native.ffi.cast("uintptr_t", _handles.contact("c", contact))))
    assert held.surface.mu == 0.625 and held.surface.mode == contact.getMode()
    for name, kind, value, said in (("body", "body", world, "a PyODE World, not a Body"),
                                    ("joint", "joint", geom, "a PyODE GeomBox, not a Joint"),
                                    ("world", "world", types.new_class("World", exec_body=lambda ns: ns.update(
                                        __module__="ode"))(), "none of PyODE's")):
        with pytest.raises(ss.InvalidValue, match=said):
            _handles.address(name, kind, value)


def test_a_joint_pyode_let_go_of_is_refused_by_name():
    world = ode.World()
    body = ode.Body(world)
    group = ode.JointGroup()
    contact = ode.ContactJoint(world, group, ode.Contact())
    contact.attach(body, None)
    registry = ss.Registry(world)
    group.empty()  # PyODE destroys the joint and sets the wrapper's pointer to NULL
    with pytest.raises(ss.InvalidValue, match=r"joint = <ode.ContactJoint .*its ODE joint is gone"):
        registry.bind_joint(contact, ss.JointParam.JOINT, 0, ss.Spring(10.0, 1.0))


@pytest.mark.parametrize("offset", [8, 24, 32])
def test_a_layout_that_does_not_check_out_is_refused_by_name_never_guessed(monkeypatch, fresh_layout, offset):
    """The pointers looked for elsewhere than where PyODE's layout holds them (a PyODE built otherwise, simulated):
    every object refused by name, Status.UNSUPPORTED, nothing stepped, and nothing handed to libode (the process
    lives on)."""
    monkeypatch.setattr(pyode, "FIELD_OFFSET", offset)
    vehicle = pyode_vehicle.Vehicle()
    code, message = refusal(pyode_vehicle.adopt, vehicle, "naive")
    assert code == Status.UNSUPPORTED and re.search(r"PyODE's (World|Body|Contact)\b.*refused", message), message
    assert refusal(ss.Registry, vehicle.world) == (code, message)  # the refusal is kept, not tried again
    assert vehicle.chassis.getPosition() == (0.0, 0.75, 0.0)


def test_a_contact_that_does_not_hold_what_pyode_wrote_is_refused(monkeypatch, fresh_layout):
    """A dContact laid out otherwise (its mu two places off, simulated through ODE's struct as read here)."""
    swapped = [("mu2" if name == "mu" else "mu" if name == "mu2" else name, kind)
               for name, kind in _libode.Surface._fields_]
    Shifted = type("Contact", (ctypes.Structure,), {"_fields_": [
        ("surface", type("Surface", (ctypes.Structure,), {"_fields_": swapped})),
        ("geom", _libode.ContactGeom), ("fdir1", ctypes.c_double * 4)]})

    monkeypatch.setattr(_libode, "Contact", Shifted)
    with pytest.raises(ss.InvalidValue, match=r"PyODE's Contact: the dContact at byte 16 does not hold"):
        ss.Stepper(ode.World(), tuned_step_s=1 / 60, solver=ss.Solver.QUICK)


# ---- ODE 0.15's numbers -------------------------------------------------------------------------------------------

def test_importing_steadystep_after_a_pyode_of_ode_015_numbers_warns_once_naming_them_and_the_fix():
    program = ("import warnings; warnings.simplefilter('always'); import ode, steadystep as ss\n"
               "w = ode.World(); ss.Registry(w); ss.Stepper(w, tuned_step_s=1/60, solver=ss.Solver.QUICK)\n")
    done = subprocess.run([sys.executable, "-c", program], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stderr.count("PyODEWarning") == 1, done.stderr
    for said in ("ode.ParamFMax (3)", "ParamSuspensionCFM (10)", "2 places earlier", "dParamLoVel",
                 "Param.FMax = 5", "Param.FMax2 = 261", "ContactSlip1 (0x80)", "dContactMotionN"):
        assert said in done.stderr, (said, done.stderr)
    # Imported before PyODE: the first PyODE object met warns, once.
    later = ("import warnings; warnings.simplefilter('always'); import steadystep as ss, ode\n"
             "w = ode.World(); ss.Registry(w); ss.Registry(w)\n")
    done = subprocess.run([sys.executable, "-c", later], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0 and done.stderr.count("PyODEWarning") == 1, done.stderr


def test_the_numbers_are_read_from_the_loaded_ode_and_a_right_pyode_draws_nothing():
    # The loaded ODE numbers its parameters as Param says: a new hinge's defaults read through libode.
    assert pyode._loaded_ode_numbers_problem() is None
    world = ode.World()
    hinge = ode.HingeJoint(world)
    assert hinge.getParam(pyode.Param.FudgeFactor) == 1.0 and hinge.getParam(pyode.Param.StopERP) == world.getERP()
    assert hinge.getParam(ode.ParamFudgeFactor) != 1.0  # Debian's PyODE: ODE 0.15's number
    right = types.SimpleNamespace(**{f"Param{m.name}": m.value for m in pyode.Param},
                                  **{f"Contact{m.name}": m.value for m in pyode.ContactMode})
    assert pyode.mismatch(right) is None
    old = types.SimpleNamespace(ParamLoStop=0, ParamVel=2, ParamFMax=3, ParamFudgeFactor=4, ParamFMax2=259)
    said = pyode.mismatch(old)
    assert "ode.ParamFMax (3), ParamFudgeFactor (4)" in said and "their 2 and 3 forms" in said, said
    assert "ParamVel" not in said


# ---- the stepper -------------------------------------------------------------------------------------------------

def run(profile: str, variant: str, duration_s: float = 2.0) -> bytes:
    """The example under profile: its own loop ("own"), or adopted under naive with its contacts by rule or in
    its near callback; each from the same state of ODE's generator (QuickStep's row order)."""
    LIBODE.dRandSetSeed(1)
    vehicle = pyode_vehicle.Vehicle()
    stepper = None if variant == "own" else pyode_vehicle.adopt(vehicle, "naive", variant)
    contacts = 0
    for frame_s in ss.lab.profiles.frames_within(profile, duration_s, 1):
        if stepper is None:
            pyode_vehicle.own_step(vehicle, frame_s)
        else:
            report = stepper.step(frame_s)
            contacts += report.contacts.by_mapping
    if stepper is not None:
        assert contacts > 150 * duration_s * 15, contacts  # the crates' contacts, every step
        stepper.close()
    return state([vehicle.chassis, *vehicle.wheels, *vehicle.crates])


@pytest.mark.parametrize("profile", ["fixed:60", "fixed:30", "uniform:15:45"])
def test_the_example_adopted_under_naive_is_its_own_loop_to_the_bit(profile):
    own = run(profile, "own")
    assert run(profile, "rule") == own
    assert run(profile, "near") == own


def test_the_example_steps_under_every_policy_with_a_pyode_group_emptied_through_pyode():
    vehicle = pyode_vehicle.Vehicle()
    for policy in ss.policy_names():
        stepper = pyode_vehicle.adopt(vehicle, policy, "near")
        for _ in range(10):
            report = stepper.step(1 / 30)
            assert joint_wrappers(vehicle.contactgroup) == []  # PyODE let go of every contact joint
        assert report.contacts.by_mapping + report.contacts.handed_to_implicit_euler > 100
        stepper.close()
    assert all(abs(v) < 10 for v in vehicle.chassis.getPosition())


def test_a_refused_frame_leaves_no_contact_in_the_pyode_group():
    vehicle = pyode_vehicle.Vehicle()

    def collide(stepper):  # the contacts made, then a state the boundary refuses before the step
        vehicle.space.collide((vehicle, stepper), pyode_vehicle.near_callback)
        vehicle.crates[0].setLinearVel((1e30, 0.0, 0.0))

    stepper = ss.Stepper(vehicle.world, space=vehicle.space, tuned_step_s=1 / 60, solver=ss.Solver.QUICK,
                         policy="naive", collide=collide, contact_group=vehicle.contactgroup)
    with pytest.raises(ss.SimulationFailure, match="speed"):
        stepper.step(1 / 60)
    assert joint_wrappers(vehicle.contactgroup) == []
    assert vehicle.chassis.getPosition() == (0.0, 0.75, 0.0)  # nothing stepped
    stepper.close()


def test_pyode_bodies_and_joints_through_the_stepper():
    vehicle = pyode_vehicle.Vehicle()
    stepper = ss.Stepper(vehicle.world, space=vehicle.space, tuned_step_s=1 / 60, solver=ss.Solver.QUICK,
                         policy="fixed", contact_rule=ss.ContactRule(pyode_vehicle.surface(), max_contacts=150))
    assert stepper.adopted.joints == 4 and stepper.adopted.suspension_rows == 4
    hung = ode.Body(vehicle.world)  # nothing reaches it: no geom, no joint
    mass = ode.Mass()
    mass.setBoxTotal(1.0, 0.1, 0.1, 0.1)
    hung.setMass(mass)
    hung.setPosition((0.0, 5.0, 5.0))
    stepper.watch_body(hung)
    hung.addForce((0.0, 9.81, 0.0))  # held over the frame: it floats
    stepper.step(1 / 20)
    position, quaternion = stepper.interpolated_pose(hung)
    assert position[1] == pytest.approx(5.0, abs=1e-9) and len(quaternion) == 4
    position, _ = stepper.interpolated_pose(vehicle.chassis)
    assert 0.5 < position[1] < 1.0
    stepper.unwatch_body(hung)
    joint = vehicle.joints[0]
    stepper.destroy_joint(joint)  # through the stepper, then PyODE lets go of it (no double destroy)
    with pytest.raises(ss.InvalidValue, match="its ODE joint is gone"):
        stepper.destroy_joint(joint)
    stepper.destroy_body(hung)
    with pytest.raises(ss.InvalidValue, match="its ODE body is gone"):
        stepper.watch_body(hung)
    stepper.step(1 / 60)
    rule = ss.ContactRule(pyode_vehicle.surface(), max_contacts=1)
    report = stepper.collide_by_rule(rule)  # between frames: made and left for the next step's emptying
    assert report.pairs > 50 and report.contacts == report.pairs and report.dropped == 0
    stepper.close()
    del hung
    gc.collect()


def test_contact_rules_are_refused_by_name_before_anything_is_made():
    vehicle = pyode_vehicle.Vehicle()
    surface = pyode_vehicle.surface()
    kwargs = dict(space=vehicle.space, tuned_step_s=1 / 60, solver=ss.Solver.QUICK)
    for rule, said in ((ss.ContactRule(surface, max_contacts=0), r"rule.max_contacts = 0: must be in \[1, 4096\]"),
                       (ss.ContactRule(surface, skip_connected=1), "rule.skip_connected = 1: must be True or False"),
                       (ss.ContactRule(vehicle.chassis), r"rule.surface = <ode.Body .*not a Contact"),
                       (ss.ContactRule(None), "rule.surface = NULL")):
        with pytest.raises(ss.InvalidValue, match=said):
            ss.Stepper(vehicle.world, contact_rule=rule, **kwargs)
    surface.setBounce(2.0)
    with pytest.raises(ss.InvalidValue, match=r"rule surface.bounce = 2: must be in \[0, 1\]"):
        ss.Stepper(vehicle.world, contact_rule=ss.ContactRule(surface), **kwargs)
    with pytest.raises(ss.InvalidValue, match="must be a steadystep.ContactRule"):
        ss.Stepper(vehicle.world, contact_rule=surface, **kwargs)
    bare = ss.Stepper(vehicle.world, **kwargs)  # no group to make contacts in
    with pytest.raises(ss.InvalidValue, match="no contact group"):
        bare.collide_by_rule(ss.ContactRule(pyode_vehicle.surface()))
    bare.close()
    assert vehicle.chassis.getNumJoints() == 4  # its wheels' joints: no contact made


MEMORY = """
import resource, sys
sys.path.insert(0, {examples!r})
import pyode_vehicle
vehicle = pyode_vehicle.Vehicle()
stepper = pyode_vehicle.adopt(vehicle, "implicit-euler", {contacts!r})
for frame in range(3600):  # 60 s of frames of 1/60 s
    stepper.step(1 / 60)
    if frame in (599, 3599):
        print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)
"""


@pytest.mark.parametrize("contacts", ["rule", "near"])
def test_the_example_adopted_keeps_its_memory_flat_over_60_s(contacts):
    """PyODE's group emptied through PyODE: its wrappers go at every step (emptied in C, they stayed for ever:
    19.7 MB grew to 56.4 MB in 20 s)."""
    done = subprocess.run([sys.executable, "-W", "ignore", "-c",
                           MEMORY.format(examples=str(REPO / "examples"), contacts=contacts)],
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    at_10_s, at_60_s = (int(line) for line in done.stdout.split())
    assert at_60_s - at_10_s < 1024, (at_10_s, at_60_s)  # KB


def test_the_example_audited_with_python_completes(tmp_path):
    """steadystep audit --python on the PyODE example: its world handed over as PyODE's objects, stepped by the
    audit's Stepper (contacts by rule through stepper.collide_by_rule, PyODE's group emptied through PyODE)."""
    out = tmp_path / "audit"
    done = subprocess.run([sys.executable, "-W", "ignore", "-m", "steadystep.cli", "audit", "--python",
                           str(REPO / "examples" / "pyode_vehicle.py"), "--out", str(out), "--profiles", "fixed:60",
                           "uniform:15:45", "--seeds", "1", "--policies", "naive", "implicit-euler", "--duration", "1"],
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    assert (out / "audit.html").is_file() and (out / "metrics.json").is_file()

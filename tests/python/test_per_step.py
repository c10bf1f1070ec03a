"""The program's per-step logic in Python (stepper.h, issue 24): before_step sees each step's simulated time and
length, and under the fixed policy logic computed from them, or a force added once a frame (held), gives the same
motion to the bit at every frame rate.

The world is built here with odepy: a motorised hinge with stops, a ball-jointed link hanging from it and a box that
falls on the ground and slides on it (contacts with friction, softened through the stepper), under gravity. The
states are compared at the starts of the physics steps that every run took, keyed by the exact bits of time_s.
"""

import ctypes
import functools
import math
import struct

import odepy
import pytest

import steadystep as ss
from steadystep.core.stepper import _takes_the_step

H = 1 / 60  # s: the step the world is tuned for, and the fixed step
DURATION_S = 2.0
PROFILES = [("fixed:60", 1), ("fixed:30", 1), ("fixed:144", 1), ("uniform:15:45", 1), ("uniform:15:45", 2)]


@pytest.fixture(scope="module", autouse=True)
def ode():
    odepy.dInitODE2(0)
    yield  # dCloseODE is left to the process: other modules may still hold worlds


def frames(spec: str, seed: int, duration_s: float = DURATION_S) -> list[float]:
    profile = ss.Profile(spec, seed)
    out, elapsed = [], 0.0
    while duration_s - elapsed > 1e-9:
        out.append(min(profile.next(), duration_s - elapsed))
        elapsed += out[-1]
    return out


def _box(world, space, mass_kg, sides, position):
    body = odepy.dBodyCreate(world)
    mass = odepy.dMass()
    odepy.dMassSetBoxTotal(ctypes.byref(mass), mass_kg, *sides)
    odepy.dBodySetMass(body, ctypes.byref(mass))
    odepy.dBodySetPosition(body, *position)
    odepy.dGeomSetBody(odepy.dCreateBox(space, *sides), body)
    return body


class Scene:
    """The world and its handles; step_inputs(time_s) and the contacts are the program's logic."""

    def __init__(self):
        self.world = odepy.dWorldCreate()
        odepy.dWorldSetGravity(self.world, 0.0, 0.0, -9.81)
        odepy.dWorldSetERP(self.world, 0.2)
        odepy.dWorldSetCFM(self.world, 1e-5)
        self.space = odepy.dSimpleSpaceCreate(0)
        self.group = odepy.dJointGroupCreate(0)
        odepy.dCreatePlane(self.space, 0.0, 0.0, 1.0, 0.0)
        self.arm = _box(self.world, self.space, 1.0, (0.4, 0.1, 0.1), (0.0, 0.0, 1.0))
        self.hinge = odepy.dJointCreateHinge(self.world, 0)
        odepy.dJointAttach(self.hinge, self.arm, 0)
        odepy.dJointSetHingeAnchor(self.hinge, -0.2, 0.0, 1.0)
        odepy.dJointSetHingeAxis(self.hinge, 0.0, 1.0, 0.0)
        for param, value in ((odepy.dParamLoStop, -0.6), (odepy.dParamHiStop, 0.6), (odepy.dParamFMax, 4.0)):
            odepy.dJointSetHingeParam(self.hinge, param, value)
        self.link = _box(self.world, self.space, 0.5, (0.1, 0.1, 0.3), (0.2, 0.0, 0.8))
        ball = odepy.dJointCreateBall(self.world, 0)
        odepy.dJointAttach(ball, self.arm, self.link)
        odepy.dJointSetBallAnchor(ball, 0.2, 0.0, 0.95)
        self.crate = _box(self.world, self.space, 2.0, (0.2, 0.2, 0.2), (1.5, 0.0, 0.3))
        odepy.dBodySetAngularVel(self.crate, 0.3, 0.2, 0.0)
        self.bodies = (self.arm, self.link, self.crate)
        self.contacts = 0
        self.near = odepy.dNearCallback(self._near)
        self.stepper = None

    def _near(self, data, g1, g2):
        b1, b2 = odepy.dGeomGetBody(g1), odepy.dGeomGetBody(g2)
        if b1 and b2:
            return
        contacts = (odepy.dContact * 4)()
        count = odepy.dCollide(g1, g2, 4, ctypes.byref(contacts[0].geom), ctypes.sizeof(odepy.dContact))
        for i in range(count):
            contacts[i].surface.mode = odepy.dContactApprox1
            contacts[i].surface.mu = 0.4
            self.stepper.soften_contact(contacts[i], b1, b2)
            odepy.dJointAttach(odepy.dJointCreateContact(self.world, self.group, ctypes.byref(contacts[i])), b1, b2)
            self.contacts += 1

    def make_stepper(self, **callbacks) -> ss.Stepper:
        self.stepper = ss.Stepper(self.world, space=self.space, tuned_step_s=H, solver=ss.Solver.QUICK,
                                  policy="fixed", contact_group=self.group,
                                  collide=lambda s: odepy.dSpaceCollide(self.space, None, self.near), **callbacks)
        return self.stepper

    def inputs(self, time_s: float) -> None:
        """Inputs that change with time: the motor's target speed and a push on the crate."""
        odepy.dJointSetHingeParam(self.hinge, odepy.dParamVel, 3.0 * math.sin(2 * math.pi * time_s / 1.3))
        odepy.dBodyAddForce(self.crate, 15.0 * math.cos(2 * math.pi * time_s / 0.9), 4.0, 0.0)

    def state(self) -> bytes:
        """Every body's position, rotation and velocities, as their exact bytes."""
        values = []
        for body in self.bodies:
            values += odepy.dBodyGetPosition(body)[:3] + odepy.dBodyGetQuaternion(body)[:4]
            values += odepy.dBodyGetLinearVel(body)[:3] + odepy.dBodyGetAngularVel(body)[:3]
        return struct.pack(f"<{len(values)}d", *values)

    def close(self) -> None:
        self.stepper.close()
        odepy.dJointGroupDestroy(self.group)
        odepy.dSpaceDestroy(self.space)
        odepy.dWorldDestroy(self.world)


def per_step_run(spec: str, seed: int) -> tuple[dict[float, bytes], int]:
    """The state at the start of every step, by time_s, with the inputs computed in before_step from the step."""
    scene, states = Scene(), {}
    odepy.dRandSetSeed(1000 * seed + len(spec))  # whatever ODE's generator held: each step seeds it (step_seed)

    def before_step(stepper, step):
        states[step.time_s] = scene.state()
        scene.inputs(step.time_s)

    stepper = scene.make_stepper(before_step=before_step)
    for frame_s in frames(spec, seed):
        stepper.step(frame_s)
    scene.close()
    return states, scene.contacts


def once_a_frame_run(spec: str, seed: int, inputs) -> dict[float, bytes]:
    """The state at the start of every step, with inputs(scene, time_s) run once before each frame (held)."""
    scene, states = Scene(), {}
    stepper = scene.make_stepper(before_step=lambda stepper: states.__setitem__(stepper.current_step().time_s,
                                                                                scene.state()))
    time_s = 0.0
    for frame_s in frames(spec, seed):
        inputs(scene, time_s)
        time_s = stepper.step(frame_s).time_s
    scene.close()
    return states


def assert_identical_at_shared_times(runs: dict) -> None:
    first_key, first = next(iter(runs.items()))
    for key, states in runs.items():
        shared = first.keys() & states.keys()
        assert len(shared) >= 0.95 * DURATION_S / H, (key, len(shared))  # the same step times, to the bit
        differ = [t for t in sorted(shared) if states[t] != first[t]]
        assert not differ, f"{key} differs from {first_key} from t = {differ[0]!r} s on ({len(differ)} steps)"
    # and something moved: the states are not the same one throughout
    assert len(set(first.values())) > 0.9 * len(first)


def test_before_step_gets_the_time_and_length_of_each_step():
    scene, seen, given = Scene(), [], []

    def old_style(stepper):  # one parameter: called as always, reads the step from the stepper
        step = stepper.current_step()
        seen.append((step.time_s, step.step_s, step.index, step.count))

    stepper = ss.Stepper(scene.world, space=scene.space, tuned_step_s=H, solver=ss.Solver.QUICK,
                         policy="implicit-euler", before_step=old_style)
    reports = [stepper.step(f) for f in (0.05, 0.01, 0.03)]
    stepper.close()
    # 0.05 s: 3 substeps; 0.01 s: one step; 0.03 s, beyond the slack (1.25 x 1/60 s): 2 substeps.
    assert [r.steps for r in reports] == [3, 1, 2]
    lengths = [0.05 / 3] * 3 + [0.01] + [0.015] * 2
    assert [s[1] for s in seen] == pytest.approx(lengths, rel=1e-15)
    time_s = 0.0
    for (start, step_s, _, _), length in zip(seen, lengths):
        assert start == time_s  # every step the stepper took, added in order: the same bits
        time_s += step_s
    assert [r.time_s for r in reports] == [seen[3][0], seen[4][0], time_s]
    assert [(s[2], s[3]) for s in seen] == [(0, 3), (1, 3), (2, 3), (0, 1), (0, 2), (1, 2)]

    def new_style(stepper, step):  # two parameters: given the StepInfo, the same as current_step()
        assert step == stepper.current_step()
        given.append(step)

    stepper = ss.Stepper(scene.world, space=scene.space, tuned_step_s=H, solver=ss.Solver.QUICK,
                         policy="fixed", before_step=new_style)
    assert stepper.step(0.04).time_s == H + H  # two steps, 0.04 - 2 H s carried
    assert stepper.step(0.02).time_s == H + H + H  # one step, the rest carried
    assert [(s.time_s, s.step_s) for s in given] == [(0.0, H), (H, H), (H + H, H)]  # kept: copies, not views
    stepper.close()
    odepy.dJointGroupDestroy(scene.group)
    odepy.dSpaceDestroy(scene.space)
    odepy.dWorldDestroy(scene.world)


def test_only_a_callable_that_requires_two_arguments_is_given_the_step():
    def one(stepper): ...
    def two(stepper, step): ...
    def optional(stepper, step=None): ...
    def star(*args): ...

    class Controller:
        def __call__(self, stepper, step): ...

        def method(self, stepper): ...

    assert [_takes_the_step(f) for f in (one, two, optional, star, lambda s: None, Controller(),
                                         Controller().method, functools.partial(two, None), print)] == \
        [False, True, False, False, False, True, False, False, False]


def test_inputs_computed_per_step_from_time_s_give_the_same_bits_at_every_frame_rate():
    runs, contacts = {}, 0
    for spec, seed in PROFILES:
        runs[spec, seed], made = per_step_run(spec, seed)
        contacts += made
    assert contacts > 0  # the crate landed and slid: contacts, whose row order QuickStep shuffles
    assert_identical_at_shared_times(runs)


def test_the_same_inputs_run_once_a_frame_depend_on_the_frame_rate():
    """The control: the logic of the test above, run once a frame from the frame's time, is not the same motion."""
    runs = {(spec, seed): once_a_frame_run(spec, seed, Scene.inputs) for spec, seed in PROFILES[::3]}
    (_, first), (_, other) = runs.items()
    shared = sorted(first.keys() & other.keys())
    assert any(first[t] != other[t] for t in shared)


def test_a_constant_force_added_once_a_frame_is_held_and_gives_the_same_bits_at_every_frame_rate():
    def wind(scene, time_s):  # the same 3 N every frame, and a torque: held until the next frame's
        for body in scene.bodies:
            odepy.dBodyAddForce(body, 3.0, -1.0, 0.0)
        odepy.dBodyAddTorque(scene.crate, 0.0, 0.0, 0.4)

    runs = {(spec, seed): once_a_frame_run(spec, seed, wind) for spec, seed in PROFILES}
    assert_identical_at_shared_times(runs)

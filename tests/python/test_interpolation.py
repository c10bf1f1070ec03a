"""Smooth rendering of fixed steps from Python (Stepper.interpolated_pose), on real ODE with odepy: the pose drawn
after a frame is (1 - a) p_prev + a p_curr and the slerp of the two rotations (here by the relative rotation's
axis and angle) to 1e-12, where prev and curr are the poses this test records just before and after the frame's
last step; at frames of no step, one and several; a teleport drawn at once."""

import ctypes
import math

import numpy as np
import odepy
import pytest

import steadystep as ss
from steadystep.core.enums import Solver


def multiply(a, b):
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return np.array([w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                     w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2])


def slerp(prev, curr, a):
    relative = multiply(np.array(prev) * [1, -1, -1, -1], curr)
    if relative[0] < 0:
        relative = -relative
    s = np.linalg.norm(relative[1:])
    angle = 2 * math.atan2(s, relative[0])
    part = np.concatenate(([math.cos(a * angle / 2)], relative[1:] / s * math.sin(a * angle / 2) if s else [0] * 3))
    return multiply(prev, part)


@pytest.fixture
def rig():
    odepy.dInitODE2(0)
    world = odepy.dWorldCreate()
    odepy.dWorldSetGravity(world, 0.0, 0.0, -9.81)
    bodies = []
    for i in range(2):
        body = odepy.dBodyCreate(world)
        mass = odepy.dMass()
        odepy.dMassSetBoxTotal(ctypes.byref(mass), 1.0 + i, 0.1, 0.2, 0.3)
        odepy.dBodySetMass(body, ctypes.byref(mass))
        odepy.dBodySetPosition(body, float(i), 0.0, 10.0)
        odepy.dBodySetLinearVel(body, 1.0, -0.5, 2.0)
        odepy.dBodySetAngularVel(body, 3.0 + i, -2.0, 1.5)
        bodies.append(body)
    before, after = [], []

    def pose(body):
        return list(odepy.dBodyGetPosition(body)[:3]), list(odepy.dBodyGetQuaternion(body)[:4])

    stepping = ss.Stepping.for_policy("fixed", fixed_step_s=0.01, solver=Solver.QUICK)
    stepper = ss.Stepper(world, stepping=stepping,
                         before_step=lambda s: before.append([pose(b) for b in bodies]),
                         step_done=lambda h: after.append([pose(b) for b in bodies]))
    for body in bodies:
        stepper.watch_body(body)
    yield stepper, bodies, before, after, pose
    stepper.close()
    odepy.dWorldDestroy(world)


def expect_blend(stepper, bodies, prev, curr, a):
    for b, body in enumerate(bodies):
        position, quaternion = stepper.interpolated_pose(body)
        np.testing.assert_allclose(position, (1 - a) * np.array(prev[b][0]) + a * np.array(curr[b][0]), rtol=0,
                                   atol=1e-12)
        np.testing.assert_allclose(quaternion, slerp(prev[b][1], curr[b][1], a), rtol=0, atol=1e-12)


def test_frames_of_none_one_and_several_steps(rig):
    stepper, bodies, before, after, pose = rig
    start = [pose(b) for b in bodies]
    counts = []
    for frame_s in (0.004, 0.007, 0.035, 0.002, 0.005, 0.05):  # steps 0, 1, 3, 0, 1, 5 of 0.01 s
        report = stepper.step(frame_s)
        counts.append(report.steps)
        if not after:
            expect_blend(stepper, bodies, start, start, report.interpolation)
        else:
            assert report.interpolation > 0
            expect_blend(stepper, bodies, before[-1], after[-1], report.interpolation)
    assert counts == [0, 1, 3, 0, 1, 5]


def test_a_teleport_is_drawn_where_the_program_put_it(rig):
    stepper, bodies, before, after, pose = rig
    assert stepper.step(0.025).steps == 2
    odepy.dBodySetPosition(bodies[0], 5.0, 6.0, 7.0)
    assert stepper.step(0.001).steps == 0
    position, _ = stepper.interpolated_pose(bodies[0])
    assert position == (5.0, 6.0, 7.0)
    stranger = odepy.dBodyCreate(odepy.dBodyGetWorld(bodies[0]))
    with pytest.raises(ss.SteadystepError, match="not known"):
        stepper.interpolated_pose(stranger)
    stepper.set_interpolation(False)
    stepper.step(0.013)
    assert stepper.interpolated_pose(bodies[1])[0] == tuple(odepy.dBodyGetPosition(bodies[1])[:3])
    with pytest.raises(ss.SteadystepError, match="True or False"):
        stepper.set_interpolation(1)

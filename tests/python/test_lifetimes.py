"""What a program's Python objects may do to each other on real ODE (odepy worlds): a Registry is not freed under a
live Stepper, and every exception raised during a frame, by a callback or by a stepper call made from odepy's near
callback (where ctypes would print it and go on), is raised by step() after the frame."""

import ctypes
import gc
import math

import odepy
import pytest

import steadystep as ss
from steadystep.core._native import ffi, lib


pytestmark = pytest.mark.usefixtures("odepy_initialised")


@pytest.fixture
def world():
    made = odepy.dWorldCreate()
    odepy.dWorldSetGravity(made, 0.0, 0.0, -9.81)
    yield made
    odepy.dWorldDestroy(made)


def ball_on_plane(world, space, radius=0.1):
    odepy.dCreatePlane(space, 0.0, 0.0, 1.0, 0.0)
    ball = odepy.dBodyCreate(world)
    mass = odepy.dMass()
    odepy.dMassSetSphereTotal(ctypes.byref(mass), 1.0, radius)
    odepy.dBodySetMass(ball, ctypes.byref(mass))
    odepy.dBodySetPosition(ball, 0.0, 0.0, radius * 0.9)  # already touching: a contact in the first step
    odepy.dGeomSetBody(odepy.dCreateSphere(space, radius), ball)
    return ball


def test_a_registry_is_not_closed_under_an_open_stepper(world):
    space = odepy.dSimpleSpaceCreate(0)
    ball = ball_on_plane(world, space)
    registry = ss.Registry(world)
    registry.adopt(1 / 60, space)
    stepper = ss.Stepper(world, registry, solver=ss.Solver.QUICK, policy="implicit-euler")
    with pytest.raises(ss.SteadystepError, match=r"registry.close\(\): 1 open Stepper") as refused:
        registry.close()
    assert refused.value.code == ss.Status.OUT_OF_RANGE
    # Still alive and in use: the stepper steps with it, the registry answers.
    assert stepper.step(1 / 60).steps == 1 and registry.tuned_step_s == 1 / 60
    stepper.close()
    registry.close()  # now nothing uses it
    with pytest.raises(ss.SteadystepError, match="used after close"):
        registry.tuned_step_s
    odepy.dSpaceDestroy(space)
    del ball


def test_a_stepper_collected_with_its_registry_goes_first(world):
    # Both unreachable in one cycle: whatever order the collector takes, the C stepper is destroyed while its
    # registry still exists (the stepper's destructor holds it). Under valgrind or ASan a wrong order reads freed
    # memory; here the process must simply survive many rounds and step a fresh pair afterwards.
    space = odepy.dSimpleSpaceCreate(0)
    ball_on_plane(world, space)
    for _ in range(50):
        registry = ss.Registry(world)
        registry.adopt(1 / 60, space)
        stepper = ss.Stepper(world, registry, solver=ss.Solver.QUICK, policy="exact", before_step=lambda s: None)
        stepper.cycle = stepper  # a reference cycle: only the cyclic collector frees the pair
        stepper.step(1 / 60)
        del stepper, registry
        gc.collect()
    registry = ss.Registry(world)
    registry.adopt(1 / 60, space)
    stepper = ss.Stepper(world, registry, solver=ss.Solver.QUICK, policy="exact")
    assert stepper.step(1 / 30).steps == 2
    stepper.close()
    odepy.dSpaceDestroy(space)


@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")  # ctypes reports it, then goes on
def test_a_soften_contact_error_in_the_near_callback_is_raised_by_step(world, capfd):
    space = odepy.dSimpleSpaceCreate(0)
    group = odepy.dJointGroupCreate(0)
    ball = ball_on_plane(world, space)
    registry = ss.Registry(world)
    registry.adopt(1 / 60, space)
    tried, tuned_erp = [], [1.5]  # a tuned softness no step has: erp above 1, refused by name

    def near(data, g1, g2):
        contacts = (odepy.dContact * 4)()
        count = odepy.dCollide(g1, g2, 4, ctypes.byref(contacts[0].geom), ctypes.sizeof(odepy.dContact))
        for i in range(count):
            contacts[i].surface.mode = odepy.dContactSoftERP
            contacts[i].surface.soft_erp = tuned_erp[0]
            tried.append(contacts[i].surface.soft_erp)
            stepper.soften_contact(contacts[i], odepy.dGeomGetBody(g1), odepy.dGeomGetBody(g2))
            odepy.dJointAttach(odepy.dJointCreateContact(world, group, ctypes.byref(contacts[i])),
                               odepy.dGeomGetBody(g1), odepy.dGeomGetBody(g2))

    callback = odepy.dNearCallback(near)
    stepper = ss.Stepper(world, registry, solver=ss.Solver.QUICK, policy="implicit-euler", contact_group=group,
                         collide=lambda s: odepy.dSpaceCollide(space, None, callback))
    with pytest.raises(ss.SteadystepError, match="1.5") as raised:
        stepper.step(1 / 60)
    assert tried and raised.value.code in (ss.Status.OUT_OF_RANGE, ss.Status.NOT_FINITE)
    assert raised.value.steadystep_report.steps == 1
    assert raised.value.steadystep_report.contacts.by_mapping == 0
    capfd.readouterr()  # ctypes printed the exception it could not raise
    tuned_erp[0] = 0.2  # the next frame is stepped as usual once the program makes good contacts
    assert stepper.step(1 / 60).contacts.by_mapping == len(tried) - 1 > 0  # implicit Euler serves every one
    stepper.close()
    odepy.dJointGroupDestroy(group)
    odepy.dSpaceDestroy(space)
    del ball


@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")
def test_re_entering_the_stepper_from_the_near_callback_is_raised_by_step(world, capfd):
    space = odepy.dSimpleSpaceCreate(0)
    ball = ball_on_plane(world, space)

    def near(data, g1, g2):
        stepper.reset()  # not allowed inside a frame

    callback = odepy.dNearCallback(near)
    stepper = ss.Stepper(world, None, tuned_step_s=1 / 60, solver=ss.Solver.QUICK, policy="implicit-euler",
                         collide=lambda s: odepy.dSpaceCollide(space, None, callback))
    stepper.watch_body(ball)
    with pytest.raises(ss.SteadystepError, match="stepper.reset: called from a callback") as raised:
        stepper.step(1 / 60)
    assert raised.value.steadystep_report.steps == 1
    capfd.readouterr()
    stepper.close()
    odepy.dSpaceDestroy(space)


def test_an_exception_in_a_wrapped_near_callback_is_raised_by_step(world):
    space = odepy.dSimpleSpaceCreate(0)
    ball = ball_on_plane(world, space)
    calls = []

    def near(data, g1, g2):
        calls.append(1)
        return 1 / 0  # the program's own bug in its near callback

    stepper = ss.Stepper(world, None, tuned_step_s=1 / 60, solver=ss.Solver.QUICK, policy="implicit-euler",
                         collide=lambda s: odepy.dSpaceCollide(space, None, callback))
    callback = odepy.dNearCallback(stepper.near_callback(near))
    stepper.watch_body(ball)
    with pytest.raises(ZeroDivisionError) as raised:
        stepper.step(1 / 30)  # two substeps: the first raises, the second is taken without the callbacks
    assert calls == [1] and raised.value.steadystep_report.steps == 2
    with pytest.raises(ZeroDivisionError):  # outside a frame, the wrapper hides nothing
        stepper.near_callback(near)(None, None, None)
    stepper.close()
    odepy.dSpaceDestroy(space)


def test_every_frame_zeroes_its_report_whatever_its_memory_held(world):
    # Stepper.step hands C an uncleared report: ssStepper_Step must zero it on every path, refusals included.
    space = odepy.dSimpleSpaceCreate(0)
    ball = ball_on_plane(world, space)
    stepper = ss.Stepper(world, None, tuned_step_s=1 / 60, solver=ss.Solver.QUICK, policy="implicit-euler")
    stepper.watch_body(ball)
    size = ffi.sizeof("ssFrameReport")
    report = ffi.new("ssFrameReport*")

    def step(frame_s):
        ffi.memmove(report, b"\xff" * size, size)  # what an earlier allocation may have left
        return lib.ssStepper_Step(stepper._stepper, frame_s, report)

    for refused in (-1.0, math.nan, 1e9):
        assert step(refused) != lib.SS_OK
        assert bytes(ffi.buffer(report)) == bytes(size), refused
    odepy.dBodyAddForce(ball, 1e300, 0.0, 0.0)  # a force beyond the bound: refused at the boundary, naming the body
    assert step(1 / 60) != lib.SS_OK
    refused = ss.FrameReport.of(report).as_dict()
    assert refused.pop("failed_body") == ctypes.cast(ball, ctypes.c_void_p).value
    expected = ss.FrameReport().as_dict()
    del expected["failed_body"]
    assert refused == expected
    stepper.reset()
    odepy.dBodySetForce(ball, 0.0, 0.0, 0.0)
    assert step(1 / 60) == lib.SS_OK and report.steps == 1 and report.dropped_s == 0.0
    # A frame of 0 s takes no step: its report is zero but for time_s, the stepper's simulated time after it (the
    # one step of 1/60 s before), padding included.
    stepped = ss.FrameReport(time_s=1 / 60)
    assert step(0.0) == lib.SS_OK and bytes(ffi.buffer(report)) == bytes(ffi.buffer(stepped._c))
    stepper.close()
    odepy.dSpaceDestroy(space)

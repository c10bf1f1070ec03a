"""Every error tells the truth about its status: each kind of failure, produced by a real call (real ODE worlds
through odepy, the lab's runs, an address-space limit for memory), raises the SteadystepError subclass of its C
status with code equal to that status and status equal to the library's own name for it (ssStatusName)."""

import ctypes
import math
import pickle
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import odepy
import pytest

import steadystep as ss
from steadystep.lab import runs
from steadystep.core._native import InvalidValue, SimulationFailure, ffi, lib

S = ss.Status


pytestmark = pytest.mark.usefixtures("odepy_initialised")


def _world_with_a_box(max_speed=0.0):
    world = odepy.dWorldCreate()
    odepy.dWorldSetGravity(world, 0.0, 0.0, 0.0)
    body = odepy.dBodyCreate(world)
    mass = odepy.dMass()
    odepy.dMassSetBoxTotal(ctypes.byref(mass), 1.0, 0.1, 0.1, 0.1)
    odepy.dBodySetMass(body, ctypes.byref(mass))
    stepper = ss.Stepper(world, None, tuned_step_s=1 / 60, solver=ss.Solver.QUICK,
                         stepping=ss.Stepping(max_speed=max_speed))
    stepper.watch_body(body)
    return world, body, stepper


def slider_unsupported_axis():
    world = odepy.dWorldCreate()
    slider = odepy.dJointCreateSlider(world, 0)
    try:
        ss.Registry(world).bind_joint(slider, ss.JointParam.SUSPENSION, 1, ss.Spring(40.0, 1.0))
    finally:
        odepy.dWorldDestroy(world)


def unbind_what_was_never_bound():
    world = odepy.dWorldCreate()
    try:
        ss.Registry(world).unbind_joint(odepy.dJointCreateBall(world, 0))
    finally:
        odepy.dWorldDestroy(world)


def step_an_infinite_velocity():
    world, body, stepper = _world_with_a_box()
    odepy.dBodySetLinearVel(body, math.inf, 0.0, 0.0)  # a state the program set: ODE would make it infinite
    try:
        stepper.step(1 / 60)
    finally:
        stepper.close()
        odepy.dWorldDestroy(world)


def _run_too_fast(then_step_again: bool):
    world, body, stepper = _world_with_a_box(max_speed=1.0)
    odepy.dBodyAddForce(body, 1000.0, 0.0, 0.0)  # 16.7 m/s after a frame of 1/60 s
    try:
        try:
            stepper.step(1 / 60)
        except SimulationFailure:
            if not then_step_again:
                raise
        stepper.step(1 / 60)  # refused: an earlier frame failed
    finally:
        stepper.close()
        odepy.dWorldDestroy(world)


def step_a_body_beyond_the_position_limit():
    world, body, stepper = _world_with_a_box()
    odepy.dBodySetPosition(body, 1e12, 0.0, 0.0)  # a teleport far beyond any collision space's reach
    try:
        stepper.step(1 / 60)
    finally:
        stepper.close()
        odepy.dWorldDestroy(world)


def step_from_a_callback_of_the_same_stepper():
    world, body, stepper = _world_with_a_box()
    reentering = ss.Stepper(world, None, tuned_step_s=1 / 60, solver=ss.Solver.QUICK,
                            before_step=lambda s: s.step(1 / 60))
    try:
        reentering.step(1 / 60)
    finally:
        reentering.close()
        stepper.close()
        odepy.dWorldDestroy(world)


def out_of_memory_in_a_child_process():
    # The C run records every step; under an address-space limit its allocation fails, and the child prints the
    # error it got. (A limit in this process would starve the test runner too.)
    script = textwrap.dedent("""
        import resource, sys
        import steadystep as ss
        from steadystep.lab import runs
        size = int(open("/proc/self/statm").read().split()[0]) * resource.getpagesize()
        resource.setrlimit(resource.RLIMIT_AS, (size + 64 * 2**20, resource.RLIM_INFINITY))
        try:
            runs.run("oscillator", "fixed:60", "fixed", 20000.0, 1, stepping={"fixed_step_s": 1 / 500})
        except ss.SteadystepError as error:
            print(error.code, type(error).__name__, error.message, sep="|")
    """)
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
    code, kind, message = out.stdout.strip().split("|")
    raise ss.SteadystepError(int(code), message) if kind == "SteadystepError" else AssertionError(out.stdout)


CASES = {
    S.NOT_FINITE: lambda: ss.implicit_euler_softness((math.nan, 1.0), 0.1),
    S.OUT_OF_RANGE: lambda: ss.implicit_euler_softness((-1.0, 1.0), 0.1),
    S.NO_SPRING: lambda: ss.implicit_euler_softness((0.0, 0.0), 0.1),
    S.NO_FINITE_MAPPING: lambda: ss.matched_softness((40.0, 0.0), 1.0, 0.1),
    S.UNSUPPORTED: slider_unsupported_axis,
    S.NOT_FOUND: unbind_what_was_never_bound,
    S.IO: lambda: ss.Profile("trace:/nonexistent/steadystep/frames.txt", 1),
    S.PARSE: lambda: ss.Stepping.for_policy("fastest"),
    S.BLOWUP: step_an_infinite_velocity,
    S.SPEED_LIMIT: lambda: _run_too_fast(then_step_again=False),
    S.OUT_OF_MEMORY: out_of_memory_in_a_child_process,
    S.FAILED: lambda: _run_too_fast(then_step_again=True),
    S.POSITION_LIMIT: step_a_body_beyond_the_position_limit,
    S.REENTERED: step_from_a_callback_of_the_same_stepper,
}
SIMULATION = {S.BLOWUP, S.SPEED_LIMIT, S.FAILED, S.POSITION_LIMIT}
VALUES = {S.NOT_FINITE, S.OUT_OF_RANGE, S.NO_SPRING, S.NO_FINITE_MAPPING, S.UNSUPPORTED, S.NOT_FOUND, S.PARSE}


def test_every_status_has_a_case():
    assert set(CASES) == set(ss.Status) - {S.OK}


@pytest.mark.parametrize("status", list(CASES), ids=lambda status: status.name)
def test_each_failure_raises_its_own_status(status):
    with pytest.raises(ss.SteadystepError) as raised:
        CASES[status]()
    error = raised.value
    assert error.code == status
    assert error.status == ffi.string(lib.ssStatusName(status)).decode()
    assert error.message and str(error) == f"{error.message} ({error.status})"
    assert isinstance(error, SimulationFailure) == (status in SIMULATION)
    assert isinstance(error, ValueError) == isinstance(error, InvalidValue) == (status in VALUES)
    again = pickle.loads(pickle.dumps(error))  # as a study's worker hands it back
    assert (type(again), again.code, again.message) == (type(error), error.code, error.message)


def test_a_blow_up_carries_its_frame_report():
    with pytest.raises(SimulationFailure) as raised:
        _run_too_fast(then_step_again=False)
    report = raised.value.report
    assert report.steps == 1 and report.failed_body != 0


def test_refusals_made_in_python_carry_the_status_too():
    world = odepy.dWorldCreate()
    stepper = ss.Stepper(world, None, tuned_step_s=1 / 60, solver=ss.Solver.QUICK)
    try:
        for call in (lambda: ss.Registry(world).bind_world("stiff"), lambda: ss.Registry("a world"),
                     lambda: stepper.step("1/60"), lambda: runs.scene_info("nowhere")):
            with pytest.raises(ss.SteadystepError) as raised:
                call()
            assert raised.value.code in (S.OUT_OF_RANGE, S.NOT_FOUND)
            assert raised.value.status == ffi.string(lib.ssStatusName(raised.value.code)).decode()
    finally:
        stepper.close()
        odepy.dWorldDestroy(world)


def test_no_raise_site_types_a_status_name():
    # Every SteadystepError in the package is made from a status value (Status.X, lib.SS_..., error.code).
    package = Path(ss.__file__).parent
    typed = [f"{path.name}: {line.strip()}" for path in sorted(package.glob("*.py"))
             for line in path.read_text().splitlines() if re.search(r'SteadystepError\(\s*["\']', line)]
    assert typed == []

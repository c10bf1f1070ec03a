"""The Python binding's overhead, measured in this one run, two ways:

1. Stepper.step's own cost a frame: a one-body odepy world stepped with steadystep.Stepper against the same C
   stepper called through cffi directly (lib.ssStepper_Step with a report allocated once), interleaved repeats,
   medians; the difference is what the Python frame adds (target: at most 2 us, issue 19).
2. The lab from Python: the pile scene driven frame by frame from Python (ssScene_Frame through cffi, one sample per
   frame) against the same run driven from C in one call (ssRun_Execute, one record per step): the ratio Python /
   C of the stepping wall time (target: at most 1.05 for 500 bodies or more). Scene building is excluded.

Usage: python bench/bench_python.py [BODIES] [SECONDS]    (needs ode-python, the test extra, for part 1)
"""

from __future__ import annotations

import statistics
import sys
import time

from steadystep import runs
from steadystep.profiles import Profile

PROFILE = "uniform:15:45"
SEED = 1
REPEATS = 3

FRAME_S = 1.0 / 60.0     # one substep a frame: the stepper's cost, not ODE's, dominates a one-body world
FRAMES_A_REPEAT = 20_000
FRAME_REPEATS = 15


def _one_body_world():
    import ctypes

    import odepy

    world = odepy.dWorldCreate()
    odepy.dWorldSetGravity(world, 0.0, 0.0, 0.0)  # at rest for ever: every repeat steps the same state
    body = odepy.dBodyCreate(world)
    mass = odepy.dMass()
    odepy.dMassSetBoxTotal(ctypes.byref(mass), 1.0, 0.1, 0.1, 0.1)
    odepy.dBodySetMass(body, ctypes.byref(mass))
    return world, body


def _per_frame_s(step, argument, report) -> float:
    started = time.perf_counter()
    for _ in range(FRAMES_A_REPEAT):
        step(argument, FRAME_S, report)
    return (time.perf_counter() - started) / FRAMES_A_REPEAT


def frame_overhead() -> None:
    """Prints Stepper.step's cost a frame against the C stepper called through cffi directly."""
    import odepy

    import steadystep as ss
    from steadystep._native import check, ffi, lib

    odepy.dInitODE2(0)
    stepping = ss.Stepping(solver=ss.Solver.QUICK)
    python_world, python_body = _one_body_world()
    stepper = ss.Stepper(python_world, None, tuned_step_s=FRAME_S, stepping=stepping)
    stepper.watch_body(python_body)

    direct_world, direct_body = _one_body_world()
    definition = ffi.new("ssStepperDef*", lib.ssDefaultStepperDef())
    definition.world = ffi.cast("dWorldID", ss._handles.address("world", "world", direct_world))
    definition.stepping = stepping.as_c_fields()
    definition.tuned_step_s = FRAME_S
    made = ffi.new("ssStepper**")
    check(lib.ssStepper_Create(definition, made))
    direct = made[0]
    check(lib.ssStepper_WatchBody(direct, ffi.cast("dBodyID", ss._handles.address("body", "body", direct_body))))
    direct_report = ffi.new("ssFrameReport*")

    def through_stepper(stepper, frame_s, _):
        return stepper.step(frame_s)

    python_s, direct_s = [], []
    for _ in range(FRAME_REPEATS):  # interleaved, so that a slow moment of the machine hits both sides
        direct_s.append(_per_frame_s(lib.ssStepper_Step, direct, direct_report))
        python_s.append(_per_frame_s(through_stepper, stepper, None))
    assert stepper.step(FRAME_S).steps == 1 and lib.ssStepper_Step(direct, FRAME_S, direct_report) == lib.SS_OK
    # The loop's own call (a Python function around stepper.step) is counted on the Python side only: it
    # overstates the overhead by one Python call, about 0.05 us.
    overhead_us = (statistics.median(python_s) - statistics.median(direct_s)) * 1e6
    print(f"one-body world, frames of {FRAME_S * 1e3:.2f} ms (1 step each), {FRAMES_A_REPEAT} frames x "
          f"{FRAME_REPEATS} interleaved repeats, medians:")
    print(f"  C stepper through cffi directly  {statistics.median(direct_s) * 1e6:7.2f} us a frame  "
          f"(min {min(direct_s) * 1e6:.2f})")
    print(f"  steadystep.Stepper.step          {statistics.median(python_s) * 1e6:7.2f} us a frame  "
          f"(min {min(python_s) * 1e6:.2f})")
    print(f"  Python frame overhead            {overhead_us:7.2f} us a frame  (target <= 2)")
    stepper.close()
    lib.ssStepper_Destroy(direct)
    odepy.dWorldDestroy(python_world)
    odepy.dWorldDestroy(direct_world)


def python_loop(bodies: int, duration_s: float) -> tuple[float, int]:
    scene = runs.Scene("pile", "implicit-euler", params={"body_count": bodies})
    profile = Profile(PROFILE, SEED)
    steps = 0
    elapsed_s = 0.0
    started = time.perf_counter()
    while elapsed_s < duration_s:
        frame_s = min(profile.next(), duration_s - elapsed_s)  # as ssRun_Execute cuts its last frame
        steps += scene.frame(frame_s)
        scene.sample()
        elapsed_s += frame_s
    wall_s = time.perf_counter() - started
    scene.close()
    return wall_s, steps


def c_run(bodies: int, duration_s: float) -> tuple[float, int]:
    result = runs.run("pile", PROFILE, "implicit-euler", duration_s, SEED, params={"body_count": bodies})
    return result.wall_s, result.step_count


def main() -> int:
    frame_overhead()
    bodies = int(sys.argv[1]) if len(sys.argv) > 1 else 500
    duration_s = float(sys.argv[2]) if len(sys.argv) > 2 else 3.0
    python_times, c_times = [], []
    for _ in range(REPEATS):  # interleaved, so that a slow moment of the machine hits both sides
        c_wall, c_steps = c_run(bodies, duration_s)
        py_wall, py_steps = python_loop(bodies, duration_s)
        if py_steps != c_steps:
            print(f"bench_python: the runs differ: {py_steps} steps from Python, {c_steps} from C", file=sys.stderr)
            return 1
        c_times.append(c_wall)
        python_times.append(py_wall)
    ratio = min(python_times) / min(c_times)
    print(f"pile, {bodies} bodies, {PROFILE}, {duration_s:g} s simulated, {c_steps} steps, best of {REPEATS}:")
    print(f"  C      (ssRun_Execute)         {min(c_times) * 1e3:9.1f} ms  (median {statistics.median(c_times) * 1e3:.1f})")
    print(f"  Python (ssScene_Frame loop)    {min(python_times) * 1e3:9.1f} ms  "
          f"(median {statistics.median(python_times) * 1e3:.1f})")
    print(f"  ratio Python / C               {ratio:9.3f}  (target <= 1.05)")
    return 0


if __name__ == "__main__":
    sys.exit(main())

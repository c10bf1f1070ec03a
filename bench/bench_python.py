"""The Python binding's overhead, measured in this one run, three ways, by the thread's CPU time (time.thread_time:
what another process does to the machine is not counted), with the load average and the cores printed beside:

1. Stepper.step's own cost a frame: a one-body odepy world stepped with steadystep.Stepper against the same C
   stepper called through cffi directly (lib.ssStepper_Step with a report allocated once), interleaved repeats,
   medians; the difference is what the Python frame adds (target: at most 2 us, issue 19).
2. Contacts at the cost of C (issue 29): a program with about 200 contacts a step, adopted under naive, against its
   own loop, for both bindings: PyODE (examples/pyode_vehicle.py: a vehicle among 50 crates, PyODE's near callback
   in its own loop) and odepy (50 crates on the ground, odepy's near callback). Adopted, its contacts are made by a
   ContactRule in C (target: at most 1.05 of its own loop), or kept in its near callback with one soften_contact a
   contact, or (odepy, whose dCollide fills an array) one soften_contacts a pair (for comparison). Each variant is checked bit for bit against its own loop first; interleaved repeats.
3. The lab from Python: the pile scene driven frame by frame from Python (ssScene_Frame through cffi, one sample per
   frame) against the same run driven from C in one call (ssRun_Execute, one record per step): the ratio Python /
   C (target: at most 1.05 for 500 bodies or more). Scene building is counted on both sides (a few ms).

Usage: python bench/bench_python.py [BODIES] [SECONDS]    (needs ode-python, the test extra, and PyODE: Debian's
python3-pyode, which scripts/deps.sh lets .venv see)
"""

from __future__ import annotations

import ctypes
import os
import statistics
import struct
import sys
import time
from pathlib import Path

from steadystep.lab import runs
from steadystep.lab.profiles import Profile

PROFILE = "uniform:15:45"
SEED = 1
REPEATS = 3

FRAME_S = 1.0 / 60.0     # one substep a frame: the stepper's cost, not ODE's, dominates a one-body world
FRAMES_A_REPEAT = 20_000
FRAME_REPEATS = 15

CONTACT_FRAMES = 180     # 3 s at 60 fps, from the same state every repeat
CONTACT_REPEATS = 7
CRATES = 50


def machine() -> str:
    """What the figures were measured on: the load average and the cores this process may use."""
    one, five, fifteen = os.getloadavg()
    return (f"load average {one:.2f} {five:.2f} {fifteen:.2f}, {len(os.sched_getaffinity(0))} of "
            f"{os.cpu_count()} cores usable; times are this thread's CPU time")


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
    started = time.thread_time()
    for _ in range(FRAMES_A_REPEAT):
        step(argument, FRAME_S, report)
    return (time.thread_time() - started) / FRAMES_A_REPEAT


def frame_overhead() -> None:
    """Prints Stepper.step's cost a frame against the C stepper called through cffi directly."""
    import odepy

    import steadystep as ss
    from steadystep.core._native import check, ffi, lib

    odepy.dInitODE2(0)
    stepping = ss.Stepping(solver=ss.Solver.QUICK)
    python_world, python_body = _one_body_world()
    stepper = ss.Stepper(python_world, None, tuned_step_s=FRAME_S, stepping=stepping)
    stepper.watch_body(python_body)

    direct_world, direct_body = _one_body_world()
    definition = ffi.new("ssStepperDef*", lib.ssDefaultStepperDef())
    definition.world = ffi.cast("dWorldID", ss.core._handles.address("world", "world", direct_world))
    definition.stepping = stepping.as_c_fields()
    definition.tuned_step_s = FRAME_S
    made = ffi.new("ssStepper**")
    check(lib.ssStepper_Create(definition, made))
    direct = made[0]
    check(lib.ssStepper_WatchBody(direct, ffi.cast("dBodyID", ss.core._handles.address("body", "body", direct_body))))
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
          f"{FRAME_REPEATS} interleaved repeats, medians ({machine()}):")
    print(f"  C stepper through cffi directly  {statistics.median(direct_s) * 1e6:7.2f} us a frame  "
          f"(min {min(direct_s) * 1e6:.2f})")
    print(f"  steadystep.Stepper.step          {statistics.median(python_s) * 1e6:7.2f} us a frame  "
          f"(min {min(python_s) * 1e6:.2f})")
    print(f"  Python frame overhead            {overhead_us:7.2f} us a frame  (target <= 2)")
    stepper.close()
    lib.ssStepper_Destroy(direct)
    odepy.dWorldDestroy(python_world)
    odepy.dWorldDestroy(direct_world)


# ---- 2. contacts at the cost of C ---------------------------------------------------------------------------

class PyodeProgram:
    """examples/pyode_vehicle.py: its own loop, or adopted under naive with its contacts by rule or in its near
    callback."""

    name = "PyODE (examples/pyode_vehicle.py)"

    def __init__(self):
        sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))
        import pyode_vehicle

        self.example = pyode_vehicle

    def build(self, variant: str):
        vehicle = self.example.Vehicle()
        if variant == "own":
            return vehicle, lambda frame_s: self.example.own_step(vehicle, frame_s), None
        stepper = self.example.adopt(vehicle, "naive", variant)
        return vehicle, stepper.step, stepper

    def state(self, vehicle) -> bytes:
        bodies = [vehicle.chassis, *vehicle.wheels, *vehicle.crates]
        return struct.pack(f"{7 * len(bodies)}d", *(v for b in bodies for v in (*b.getPosition(),
                                                                               *b.getQuaternion())))


class OdepyProgram:
    """50 crates on the ground in a hash space, built with odepy, stepped by odepy's near callback of the tests and
    README (dCollide, bounce 0.2, mu 5000, dJointCreateContact in a joint group emptied after each step)."""

    name = "odepy (50 crates on the ground)"
    variants = ("own", "rule", "near", "pair")

    def __init__(self):
        import odepy

        self.odepy = odepy
        odepy.dInitODE2(0)

    def build(self, variant: str):
        import steadystep as ss

        odepy = self.odepy
        world = odepy.dWorldCreate()
        odepy.dWorldSetGravity(world, 0.0, -9.81, 0.0)
        odepy.dWorldSetERP(world, 0.2)
        odepy.dWorldSetCFM(world, 1e-5)
        space = odepy.dHashSpaceCreate(None)
        group = odepy.dJointGroupCreate(0)
        odepy.dCreatePlane(space, 0.0, 1.0, 0.0, 0.0)
        crates = []
        for i in range(CRATES):
            body = odepy.dBodyCreate(world)
            mass = odepy.dMass()
            odepy.dMassSetBoxTotal(ctypes.byref(mass), 4.0, 0.5, 0.5, 0.5)
            odepy.dBodySetMass(body, ctypes.byref(mass))
            odepy.dBodySetPosition(body, 0.52 * (i % 10), 0.25, 0.52 * (i // 10))
            odepy.dGeomSetBody(odepy.dCreateBox(space, 0.5, 0.5, 0.5), body)
            crates.append(body)
        made = {"world": world, "space": space, "group": group, "crates": crates}
        contacts = (odepy.dContact * 150)()
        size = ctypes.sizeof(odepy.dContact)
        stepper = None

        def near(data, g1, g2):
            count = odepy.dCollide(g1, g2, 150, ctypes.byref(contacts[0].geom), size)
            b1, b2 = odepy.dGeomGetBody(g1), odepy.dGeomGetBody(g2)
            for i in range(count):
                contact = contacts[i]
                contact.surface.mode = odepy.dContactBounce
                contact.surface.mu = 5000.0
                contact.surface.bounce = 0.2
                if stepper is not None:
                    stepper.soften_contact(contact, b1, b2)
                odepy.dJointAttach(odepy.dJointCreateContact(world, group, ctypes.byref(contact)), b1, b2)

        def near_by_pair(data, g1, g2):  # the same contacts, softened with one soften_contacts a pair
            count = odepy.dCollide(g1, g2, 150, ctypes.byref(contacts[0].geom), size)
            b1, b2 = odepy.dGeomGetBody(g1), odepy.dGeomGetBody(g2)
            for i in range(count):
                contact = contacts[i]
                contact.surface.mode = odepy.dContactBounce
                contact.surface.mu = 5000.0
                contact.surface.bounce = 0.2
            stepper.soften_contacts(contacts, count)
            for i in range(count):
                odepy.dJointAttach(odepy.dJointCreateContact(world, group, ctypes.byref(contacts[i])), b1, b2)

        callback = odepy.dNearCallback(near_by_pair if variant == "pair" else near)
        made["callback"] = callback
        if variant == "own":
            def frame(frame_s):
                odepy.dSpaceCollide(space, None, callback)
                odepy.dWorldQuickStep(world, frame_s)
                odepy.dJointGroupEmpty(group)

            return made, frame, None
        surface = odepy.dContact()
        surface.surface.mode = odepy.dContactBounce
        surface.surface.mu = 5000.0
        surface.surface.bounce = 0.2
        made["surface"] = surface
        adopted = ({"contact_rule": ss.ContactRule(surface, max_contacts=150)} if variant == "rule" else
                   {"collide": lambda s: odepy.dSpaceCollide(space, None, callback)})
        stepper = ss.Stepper(world, space=space, tuned_step_s=1 / 60, solver=ss.Solver.QUICK, policy="naive",
                             contact_group=group, **adopted)
        return made, stepper.step, stepper

    def state(self, made) -> bytes:
        odepy = self.odepy
        return struct.pack(f"{7 * CRATES}d", *(v for b in made["crates"] for v in (
            *odepy.dBodyGetPosition(b)[:3], *odepy.dBodyGetQuaternion(b)[:4])))

    def close(self, made, stepper) -> None:
        if stepper is not None:
            stepper.close()
        self.odepy.dJointGroupDestroy(made["group"])
        self.odepy.dSpaceDestroy(made["space"])
        self.odepy.dWorldDestroy(made["world"])


def _contact_run(program, variant: str) -> tuple[float, bytes, int]:
    """One run of CONTACT_FRAMES frames from ODE's generator at seed 1: (thread CPU s, the final state, contacts)."""
    from steadystep.core import _libode

    _libode.ode().dRandSetSeed(1)  # naive leaves QuickStep's row order to ODE's generator, as the own loop does
    made, frame, stepper = program.build(variant)
    contacts = 0
    started = time.thread_time()
    for _ in range(CONTACT_FRAMES):
        report = frame(FRAME_S)
        if stepper is not None:
            contacts += report.contacts.by_mapping
    spent_s = time.thread_time() - started
    state = program.state(made)
    if hasattr(program, "close"):
        program.close(made, stepper)
    elif stepper is not None:
        stepper.close()
    return spent_s, state, contacts


def contacts_at_the_cost_of_c() -> int:
    """Prints part 2; 1 when an adopted variant is not its own loop to the bit."""
    print(f"contacts at the cost of C: {CONTACT_FRAMES} frames of {FRAME_S * 1e3:.2f} ms under naive, "
          f"{CONTACT_REPEATS} interleaved repeats, medians ({machine()}):")
    for program in (PyodeProgram(), OdepyProgram()):
        variants = getattr(program, "variants", ("own", "rule", "near"))
        times = {variant: [] for variant in variants}
        contacts = 0
        for _ in range(CONTACT_REPEATS):
            states = {}
            for variant in variants:
                spent_s, states[variant], counted = _contact_run(program, variant)
                times[variant].append(spent_s)
                contacts = max(contacts, counted)
            for variant in variants[1:]:
                if states[variant] != states["own"]:
                    print(f"bench_python: {program.name} adopted ({variant}) is not its own loop to the bit",
                          file=sys.stderr)
                    return 1
        own = statistics.median(times["own"])
        print(f"  {program.name}: {contacts / CONTACT_FRAMES:.0f} contacts a step, bit for bit its own loop")
        print(f"    own loop (its near callback)                   {own / CONTACT_FRAMES * 1e3:7.3f} ms a frame")
        for variant, label in (("rule", "adopted, ContactRule (contacts in C)"),
                               ("near", "adopted, soften_contact in its near callback"),
                               ("pair", "adopted, soften_contacts a pair (odepy)")):
            if variant not in variants:
                continue
            ratios = [a / b for a, b in zip(times[variant], times["own"])]
            print(f"    {label:<46} {statistics.median(times[variant]) / CONTACT_FRAMES * 1e3:7.3f} ms a frame, "
                  f"ratio {statistics.median(ratios):.3f} (range {min(ratios):.3f}-{max(ratios):.3f})"
                  + ("  (target <= 1.05)" if variant == "rule" else ""))
    return 0


# ---- 3. the lab from Python -----------------------------------------------------------------------------------

def python_loop(bodies: int, duration_s: float) -> tuple[float, int]:
    started = time.thread_time()
    scene = runs.Scene("pile", "implicit-euler", params={"body_count": bodies})
    profile = Profile(PROFILE, SEED)
    steps = 0
    elapsed_s = 0.0
    while elapsed_s < duration_s:
        frame_s = min(profile.next(), duration_s - elapsed_s)  # as ssRun_Execute cuts its last frame
        steps += scene.frame(frame_s)
        scene.sample()
        elapsed_s += frame_s
    scene.close()
    return time.thread_time() - started, steps


def c_run(bodies: int, duration_s: float) -> tuple[float, int]:
    started = time.thread_time()
    result = runs.run("pile", PROFILE, "implicit-euler", duration_s, SEED, params={"body_count": bodies})
    return time.thread_time() - started, result.step_count


def main() -> int:
    frame_overhead()
    if contacts_at_the_cost_of_c():
        return 1
    bodies = int(sys.argv[1]) if len(sys.argv) > 1 else 500
    duration_s = float(sys.argv[2]) if len(sys.argv) > 2 else 3.0
    python_times, c_times = [], []
    for _ in range(REPEATS):  # interleaved, so that a slow moment of the machine hits both sides
        c_cpu, c_steps = c_run(bodies, duration_s)
        py_cpu, py_steps = python_loop(bodies, duration_s)
        if py_steps != c_steps:
            print(f"bench_python: the runs differ: {py_steps} steps from Python, {c_steps} from C", file=sys.stderr)
            return 1
        c_times.append(c_cpu)
        python_times.append(py_cpu)
    ratio = min(python_times) / min(c_times)
    print(f"pile, {bodies} bodies, {PROFILE}, {duration_s:g} s simulated, {c_steps} steps, best of {REPEATS} "
          f"({machine()}):")
    print(f"  C      (ssRun_Execute)         {min(c_times) * 1e3:9.1f} ms  (median {statistics.median(c_times) * 1e3:.1f})")
    print(f"  Python (ssScene_Frame loop)    {min(python_times) * 1e3:9.1f} ms  "
          f"(median {statistics.median(python_times) * 1e3:.1f})")
    print(f"  ratio Python / C               {ratio:9.3f}  (target <= 1.05)")
    return 0


if __name__ == "__main__":
    sys.exit(main())

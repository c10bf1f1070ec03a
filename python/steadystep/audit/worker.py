"""A Python program's run for `steadystep audit`, in a process of its own (docs/audit.md):

    python -m steadystep.audit.worker PROGRAM.py --profile SPEC --seed N --duration S [--policy NAME]
        [--max-step-scale F] [--iterations-scale N]
    python -m steadystep.audit.worker PROGRAM.py --check

It follows the executables' protocol (audit/run.py): CSV on stdout, a header ``t_s,<quantity>_<unit>,...`` and one
row per frame, exit 0 when every frame stepped and 1 when one failed. The frames are the profile's, read from the
file STEADYSTEP_AUDIT_FRAMES names (or made from --profile and --seed).

The program is imported with its own directory first on sys.path (its sibling modules import as they do when it
runs), and only the ODE binding it imports itself is loaded: ODE is initialised through the libode the library
already loaded. It defines

- build_world(): builds its world and returns a steadystep.audit.PythonWorld (audit/run.py);
- read_quantities(world): {column name with its unit: number} of that PythonWorld now;
- own_frame(world, time_s, frame_s), optional: one frame of the program's own stepping, without the library (its
  collide, its dWorldQuickStep, its per-frame logic), starting at time_s (s) and frame_s long; it may return the
  number of physics steps it took (default 1). With it, the audit has an "own" variant.

Under --policy the world is stepped by a steadystep Stepper a frame at a time, PythonWorld.before_frame(time_s)
once a frame and PythonWorld.before_step(time_s, step_s) before every physics step; without --policy,
before_frame(time_s) then own_frame(world, time_s, frame_s). After the run the stepper is closed, then the world
(PythonWorld.close), and the process ends without a garbage collection: a binding whose objects free themselves in
any order cannot crash it.

What the program does wrong is refused in one line on stderr, marked for the audit (REFUSAL_MARK), with exit
REFUSED_EXIT: an import or a call that raises anything (SystemExit and KeyboardInterrupt included), a build_world()
that returns something else than a PythonWorld, quantities that are not numbers or change their names. The
program's own output on stdout goes to stderr, so that it cannot corrupt the CSV.
"""

from __future__ import annotations

import ctypes
import importlib.util
import json
import math
import numbers
import os
import sys
import time
from pathlib import Path

from steadystep.audit.run import (DIAGNOSIS_BASE, DONE_MARK, FRAMES_VARIABLE, LOOP_CPU_MARK, OWN, REFUSAL_MARK,
                                  REFUSED_EXIT, SERVED_COLUMNS, STEP_COLUMN, TIME_COLUMN, UNSOFTENED_COLUMN,
                                  PythonWorld)


class Refusal(BaseException):
    """The program cannot take part: the message says why (a BaseException, so that no handler of the program's
    own catches it on its way out of a callback)."""


def _value_text(value) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def call_user(shown: str, name: str, function, *args, **keywords):
    """function(*args), what it raises (anything) a Refusal naming it."""
    try:
        return function(*args, **keywords)
    except Refusal:
        raise
    except BaseException as error:  # the program's code: SystemExit and KeyboardInterrupt are its faults too
        detail = f": {error}" if str(error) else ""
        raise Refusal(f"{shown}: {name}() raised {type(error).__name__}{detail}") from None


def load(path: str):
    """The program's module, imported with its directory first on sys.path; Refusal when it cannot be."""
    file = Path(path).resolve()
    shown = f"--python {path}"
    sys.path.insert(0, str(file.parent))
    name = file.stem if file.stem.isidentifier() and file.stem not in sys.modules else "steadystep_audit_program"
    spec = importlib.util.spec_from_file_location(name, file)
    if spec is None or spec.loader is None:
        raise Refusal(f"{shown}: cannot be imported as a Python module")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # what its dataclasses and pickles look their module up by
    try:
        spec.loader.exec_module(module)
    except BaseException as error:  # noqa: BLE001 - the user's file: its failure named, not a traceback
        detail = f": {error}" if str(error) else ""
        raise Refusal(f"{shown}: importing it failed: {type(error).__name__}{detail}") from None
    for function in ("build_world", "read_quantities"):
        if not callable(getattr(module, function, None)):
            raise Refusal(f"{shown}: defines no function {function}() (see docs/audit.md)")
    own = getattr(module, "own_frame", None)
    if own is not None and not callable(own):
        raise Refusal(f"{shown}: own_frame = {_value_text(own)}: must be a function own_frame(world, time_s, "
                      "frame_s)")
    return module


def _ode():
    """libode as the library loaded it (whatever binding the program uses links the same one)."""
    import steadystep.core._native  # noqa: F401 - loads the library, and with it libode

    with open("/proc/self/maps") as maps:
        paths = [line.split()[-1] for line in maps if "libode" in line and "/" in line]
    ode = ctypes.CDLL(paths[0] if paths else "libode.so.8")
    ode.dWorldGetQuickStepNumIterations.restype = ctypes.c_int
    ode.dWorldGetQuickStepNumIterations.argtypes = [ctypes.c_void_p]
    return ode


def _frames(profile: str, seed: int, duration_s: float):
    """The frame durations (s) within duration_s: from the frames file the audit handed over, else the profile's."""
    path = os.environ.get(FRAMES_VARIABLE)
    if not path:
        from steadystep.lab.profiles import frames_within

        yield from frames_within(profile, duration_s, seed)
        return
    durations = [float(line) for line in Path(path).read_text().split() if line]
    elapsed_s, end_tolerance_s, index = 0.0, 1e-9 * max(1.0, duration_s), 0
    while duration_s - elapsed_s > end_tolerance_s:
        frame_s = min(durations[index % len(durations)], duration_s - elapsed_s)
        index += 1
        elapsed_s += frame_s
        yield frame_s


class Recorder:
    """The CSV rows: t_s, the program's quantities (checked to be numbers under the same names every time), the
    counts."""

    def __init__(self, shown: str, module, world: PythonWorld, out):
        self.shown, self.module, self.world, self.out = shown, module, world, out
        self.names = None

    def row(self, time_s: float, counts: dict) -> None:
        values = call_user(self.shown, "read_quantities", self.module.read_quantities, self.world)
        if not isinstance(values, dict) or not values:
            raise Refusal(f"{self.shown}: read_quantities() returned {_value_text(values)}, not a dict of "
                          "{column name with its unit: number}")
        if self.names is None:
            from steadystep.audit.run import BadProgram, parse_csv

            self.names = list(values)
            if not all(isinstance(name, str) for name in self.names):
                raise Refusal(f"{self.shown}: read_quantities() returned the keys {_value_text(self.names)}: "
                              "each must be a column name (str) with its unit, e.g. x_m")
            try:
                parse_csv(",".join([TIME_COLUMN, *self.names, *counts]) + "\n", self.shown, allow_empty=True)
            except BadProgram as error:
                raise Refusal(error.message.replace("malformed CSV: ", "read_quantities(): ")) from None
            self.out.write(",".join([TIME_COLUMN, *self.names, *counts]) + "\n")
        elif list(values) != self.names:
            raise Refusal(f"{self.shown}: read_quantities() returned the quantities {_value_text(list(values))}, "
                          f"first {_value_text(self.names)}: the same names every time")
        fields = [repr(float(time_s))]
        for name in self.names:
            value = values[name]
            if isinstance(value, bool) or not isinstance(value, numbers.Real):
                raise Refusal(f"{self.shown}: read_quantities() returned {_value_text(value)} for {name}, not a "
                              "number")
            fields.append(repr(float(value)))
        fields += [str(int(count)) for count in counts.values()]
        self.out.write(",".join(fields) + "\n")


def _stepping(variant: str, world: PythonWorld, max_step_scale: float, iterations_scale: int, ode, shown: str):
    """The Stepper's stepping for a policy, or for implicit-euler with the diagnosis flags applied."""
    import dataclasses

    from steadystep.core import _handles
    from steadystep.core.stepping import Stepping

    stepping = Stepping.for_policy(variant)
    if max_step_scale != 1.0:
        stepping = dataclasses.replace(stepping, max_step_s=max_step_scale * world.tuned_step_s)
    if iterations_scale != 1:
        address = call_user(shown, "the world's handle", _handles.address, "PythonWorld.world", "world", world.world)
        iterations = ode.dWorldGetQuickStepNumIterations(ctypes.c_void_p(address))
        stepping = dataclasses.replace(stepping, quick_iterations=iterations_scale * iterations)
    return stepping


def _per_step(shown: str, before_step):
    if before_step is None:
        return None
    if not callable(before_step):
        raise Refusal(f"{shown}: PythonWorld.before_step = {_value_text(before_step)}: must be callable as "
                      "before_step(time_s, step_s), or None")
    return lambda stepper, step: call_user(shown, "before_step", before_step, step.time_s, step.step_s)


def _served(report) -> dict:
    """The frame's served counts and its steps that made contacts but softened none."""
    rows, contacts = report.rows, report.contacts
    return {**dict(zip(SERVED_COLUMNS, (rows.by_mapping, rows.handed_to_matched, rows.handed_to_implicit_euler,
                                        contacts.by_mapping, contacts.handed_to_matched,
                                        contacts.handed_to_implicit_euler))),
            UNSOFTENED_COLUMN: report.unsoftened_contact_steps}


def run(path: str, profile: str, seed: int, duration_s: float, policy: str | None, max_step_scale: float,
        iterations_scale: int, out) -> int:
    """One run, CSV to out; returns the exit code (0 done, 1 a frame failed). Raises Refusal."""
    from steadystep.core._native import SteadystepError
    from steadystep.core.enums import Solver

    variant = policy or OWN
    shown = f"{path} ({variant}, {profile}, seed {seed})"
    module = load(path)
    if policy is None and not callable(getattr(module, "own_frame", None)):
        raise Refusal(f"--python {path}: defines no own_frame(world, time_s, frame_s): no own stepping to run")
    ode = _ode()
    ode.dInitODE2(0)
    ode.dRandSetSeed(1)  # QuickStep shuffles rows with ODE's global generator: the same run every time
    built = call_user(shown, "build_world", module.build_world)
    if not isinstance(built, PythonWorld):
        raise Refusal(f"{shown}: build_world() returned {type(built).__name__}, not a steadystep.audit.PythonWorld")
    for hook in ("collide", "before_frame", "close"):
        value = getattr(built, hook)
        if value is not None and not callable(value):
            raise Refusal(f"{shown}: PythonWorld.{hook} = {_value_text(value)}: must be callable, or None")
    stepper = None
    recorder = Recorder(shown, module, built, out)
    code = 0
    try:
        if policy is not None:
            from steadystep.core.stepper import Stepper

            solver = {"quick": Solver.QUICK, "step": Solver.STEP}.get(built.solver)
            if solver is None:
                raise Refusal(f"{shown}: PythonWorld.solver = {_value_text(built.solver)}: must be 'quick' "
                              "(dWorldQuickStep) or 'step' (dWorldStep)")
            collide = built.collide
            stepping = _stepping(policy, built, max_step_scale, iterations_scale, ode, shown)
            stepper = call_user(shown, "the Stepper of build_world()'s PythonWorld", Stepper, built.world,
                                built.registry, space=built.space, tuned_step_s=built.tuned_step_s, solver=solver,
                                stepping=stepping,
                                collide=None if collide is None else
                                (lambda s: call_user(shown, "collide", collide, s)),
                                contact_group=built.contact_group, before_step=_per_step(shown, built.before_step))
        time_s = 0.0
        recorder.row(time_s, {STEP_COLUMN: 0,
                              **({name: 0 for name in (*SERVED_COLUMNS, UNSOFTENED_COLUMN)} if stepper else {})})
        started_cpu = time.process_time()
        for frame_s in _frames(profile, seed, duration_s):
            if built.before_frame is not None:
                call_user(shown, "before_frame", built.before_frame, time_s)
            if stepper is None:
                steps = call_user(shown, "own_frame", module.own_frame, built, time_s, frame_s)
                if steps is None:
                    steps = 1
                if isinstance(steps, bool) or not isinstance(steps, numbers.Integral) or steps < 0:
                    raise Refusal(f"{shown}: own_frame() returned {_value_text(steps)}: the number of physics "
                                  "steps it took (a whole number >= 0), or None for one")
                time_s += frame_s
                recorder.row(time_s, {STEP_COLUMN: steps})
                continue
            try:
                report = stepper.step(frame_s)
            except Refusal:
                raise
            except SteadystepError as error:
                print(f"{shown}: t = {time_s:.6g} s: {error}", file=sys.stderr)
                code = 1
                break
            except BaseException as error:  # a callback's fault the stepper re-raised
                raise Refusal(f"{shown}: a callback raised {type(error).__name__}: {error}") from None
            time_s = report.time_s  # every step taken, added: under fixed, the same bits at every frame rate
            recorder.row(time_s, {STEP_COLUMN: report.steps, **_served(report)})
        print(f"{LOOP_CPU_MARK}{time.process_time() - started_cpu!r}", file=sys.stderr)
    finally:
        out.flush()
        if stepper is not None:
            stepper.close()
    if built.close is not None:
        call_user(shown, "close", built.close)
    return code


def _number(flag: str, text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise Refusal(f"audit_worker: {flag} {text}: not a number") from None
    if not math.isfinite(value):
        raise Refusal(f"audit_worker: {flag} {text}: not finite")
    return value


def main(argv: list[str]) -> None:
    csv = os.fdopen(os.dup(1), "w", buffering=1 << 16)
    os.dup2(2, 1)  # the program's own prints go to stderr, never into the CSV
    code = REFUSED_EXIT
    try:
        if not argv:
            raise Refusal("audit_worker: usage: python -m steadystep.audit.worker PROGRAM.py [--check | flags]")
        path, flags = argv[0], argv[1:]
        if flags == ["--check"]:
            module = load(path)
            csv.write(json.dumps({"own": callable(getattr(module, "own_frame", None))}) + "\n")
            code = 0
        else:
            given = dict(zip(flags[::2], flags[1::2]))
            known = {"--profile", "--seed", "--duration", "--policy", "--max-step-scale", "--iterations-scale"}
            if len(flags) % 2 or set(given) - known:
                raise Refusal(f"audit_worker: flags {' '.join(flags)!r}: expected pairs of {', '.join(sorted(known))}")
            policy = given.get("--policy")
            if policy is None and ("--max-step-scale" in given or "--iterations-scale" in given):
                raise Refusal("audit_worker: --max-step-scale and --iterations-scale need --policy "
                              f"{DIAGNOSIS_BASE}")
            code = run(path, given.get("--profile", "fixed:60"), int(_number("--seed", given.get("--seed", "1"))),
                       _number("--duration", given.get("--duration", "10")), policy,
                       _number("--max-step-scale", given.get("--max-step-scale", "1")),
                       int(_number("--iterations-scale", given.get("--iterations-scale", "1"))), csv)
        csv.flush()
        print(DONE_MARK, file=sys.stderr, flush=True)
    except Refusal as refusal:
        sys.stderr.write(f"\n{REFUSAL_MARK}{str(refusal).replace(chr(10), ' ')}\n")
        code = REFUSED_EXIT
    except BaseException as error:  # the worker's own fault, or the library's: named, one line
        sys.stderr.write(f"\n{REFUSAL_MARK}{argv[0] if argv else 'audit_worker'}: {type(error).__name__}: "
                         f"{str(error).replace(chr(10), ' ')}\n")
        code = REFUSED_EXIT
    finally:
        with_flush = [csv, sys.stderr, sys.stdout]
        for stream in with_flush:
            try:
                stream.flush()
            except (OSError, ValueError):
                pass
        os._exit(code)  # no garbage collection: the program's objects are not freed behind its back


if __name__ == "__main__":
    main(sys.argv[1:])

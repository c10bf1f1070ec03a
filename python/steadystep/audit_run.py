"""Running a user's program for the audit (docs/audit.md): one run is the program under one frame-time profile, seed,
duration and policy (or its own stepping), read back as columns.

A program takes part in one of two ways:

- an executable (C, C++, anything) that takes ``--profile SPEC --seed N --duration S`` and, when it runs through the
  library, ``--policy NAME``, and prints CSV on stdout: a header ``t_s,<quantity>_<unit>,...`` then one row per
  frame (a row at t = 0 first is usual). Optional count columns (``steps``, ``rows_by_mapping``, ...:
  OPTIONAL_COLUMNS) say what each frame did (-1 on every frame: not counted, left out). Exit 0 when every frame stepped, 1 when a frame failed (the rows up to
  it are kept, the run's status says so), anything else is a bad program. ``lab/include/steadystep/lab/audit_flags.h``
  parses the flags and prints the rows for a C program.
- a Python file defining ``build_world()``, which builds its odepy world and returns a PythonWorld, and
  ``read_quantities(world)``, which returns {column name with its unit: value} of that PythonWorld; the audit steps
  the world itself with a steadystep Stepper, a frame at a time, and counts what each frame's report says. The
  PythonWorld's hooks carry the program's logic: before_frame(time_s) once a frame, before_step(time_s, step_s)
  before every physics step, under every policy. A Python program has no own stepping (no "own" variant): naive
  is the nearest, one step of the whole frame with the softness as tuned.

A program that cannot take part raises BadProgram, one line naming the program, the run and what is wrong: it does
not exist or is not executable, it refused the flags (exit 2), printed no CSV or malformed CSV, did not finish
within the time limit (killed), or was killed by a signal (named); audit.measure adds a program that ignores
--profile and runs that follow different quantities.
"""

from __future__ import annotations

import contextlib
import dataclasses
import importlib.util
import os
import shlex
import signal
import subprocess
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from steadystep._native import InvalidValue, SteadystepError, one_line, printable
from steadystep.enums import Status

OWN = "own"  # the variant name of a program's own stepping (a second program, without the library)
TIME_COLUMN = "t_s"
STEP_COLUMN = "steps"
SERVED_COLUMNS = ("rows_by_mapping", "rows_handed_to_matched", "rows_handed_to_implicit_euler",
                  "contacts_by_mapping", "contacts_handed_to_matched", "contacts_handed_to_implicit_euler")
OPTIONAL_COLUMNS = (STEP_COLUMN, *SERVED_COLUMNS)  # counts per frame, not followed quantities
NOT_COUNTED = -1  # a count column holding this on every frame (after the t = 0 row) is one the program cannot count
STDERR_SHOWN = 300  # characters of a program's stderr quoted in a message


class BadProgram(InvalidValue):
    """A program that cannot take part in the audit; the message names the program, the run and the fault. The
    program is a value the audit refuses by name: its code is Status.OUT_OF_RANGE, shown as "(bad program)"."""

    def __init__(self, message: str):
        super().__init__(Status.OUT_OF_RANGE, message)

    def __str__(self) -> str:
        return f"{self.message} (bad program)"

    def __reduce__(self):
        return type(self), (self.message,)


def _bad(message: str) -> BadProgram:
    return BadProgram(one_line(printable(message)))


@dataclass(frozen=True)
class Run:
    """What one run of a variant under one profile and seed gave: its columns, status and cost."""

    variant: str
    profile: str
    seed: int
    columns: dict            # name -> np.ndarray (t_s, the followed quantities, the optional counts present)
    status: str              # "ok", or "failed: <the program's last line on stderr>"
    cpu_s: float             # the run's CPU time (s): the whole process for an executable, the loop for Python
    wall_s: float

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    def quantities(self) -> list[str]:
        return [name for name in self.columns if name != TIME_COLUMN and name not in OPTIONAL_COLUMNS]

    @property
    def frames(self) -> int:
        """Frames stepped: the rows after the t = 0 row."""
        t = self.columns[TIME_COLUMN]
        return len(t) - 1 if len(t) and t[0] == 0.0 else len(t)


# ---- the programs ----------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Executable:
    """A program run as a process: command (the program and any fixed arguments of its own) for the policies, own
    (likewise) for its own stepping, or None. Plain data, so that a unit can be pickled to a worker."""

    command: tuple[str, ...]
    own: tuple[str, ...] | None = None
    time_limit_s: float = 60.0

    @property
    def name(self) -> str:
        return Path(self.command[0]).name

    def check(self) -> None:
        """Refuses a program that does not exist or cannot be executed, before anything runs."""
        for command, flag in ((self.command, "PROGRAM"), (self.own, "--own")):
            if command is None:
                continue
            path = Path(command[0])
            if not path.exists():
                raise _bad(f"{flag} {command[0]}: does not exist")
            if path.is_dir():
                raise _bad(f"{flag} {command[0]}: is a directory, not a program")
            if not os.access(path, os.X_OK):
                raise _bad(f"{flag} {command[0]}: is not executable (chmod +x it, or put its interpreter "
                           f"first: 'python3 {command[0]}')")


@dataclass(frozen=True)
class PythonProgram:
    """A Python file defining build_world() and read_quantities(world) (the module's docstring)."""

    path: str  # steps in the audit's own process (or worker): the time limit is for executables

    @property
    def name(self) -> str:
        return Path(self.path).name

    @property
    def own(self):
        return None  # a world handed to the audit is stepped by the library

    def check(self) -> None:
        load_python_program(self.path)


@dataclass
class PythonWorld:
    """What a Python program's build_world() returns: its odepy world and what the stepper needs to step it.

    world: the odepy dWorldID (required). registry: a steadystep Registry of it, or None. space: the program's space,
    or None: with it, the stepper adopts the world and everything the space reaches as tuned at tuned_step_s (s),
    into registry or into one of its own. tuned_step_s: the step the program tuned its numbers for, which the
    stepper also takes as its longest (and fixed) step. collide(stepper): called before
    each physics step (its near callback calls stepper.soften_contact). contact_group: emptied after each step.
    before_frame(time_s): the program's per-frame logic, called before each frame with the simulated time (s) the
    frame starts at; a force it adds is held for every step of the frame. before_step(time_s, step_s): the
    program's per-step logic, called before every physics step under every policy, after the frame's held forces
    are put back and before collide, with the simulated time (s) at the step's start and the step's length (s):
    whatever depends on the time or the state (a motor's target, a controller, a scripted push) belongs here, and
    under the fixed policies it then gives the same motion at every frame rate. close(): destroys what build_world
    made (the world last); the audit closes its stepper (and a registry it made) first. solver: "quick"
    (dWorldQuickStep) or "step" (dWorldStep)."""

    world: object
    space: object = None
    registry: object = None
    tuned_step_s: float = 1.0 / 60.0
    collide: Callable | None = None
    contact_group: object = None
    before_frame: Callable[[float], object] | None = None
    before_step: Callable[[float, float], object] | None = None
    close: Callable[[], object] | None = None
    solver: str = "quick"
    extra: dict = dataclasses.field(default_factory=dict)  # the program's own handles, for read_quantities


def load_python_program(path: str):
    """The module at path, with its build_world and read_quantities checked; BadProgram otherwise."""
    file = Path(path)
    if not file.is_file():
        raise _bad(f"--python {path}: does not exist" if not file.exists() else f"--python {path}: is not a file")
    spec = importlib.util.spec_from_file_location(f"steadystep_audit_program_{abs(hash(str(file.resolve())))}", file)
    module = importlib.util.module_from_spec(spec)
    try:
        spec.loader.exec_module(module)
    except Exception as error:  # the user's file: its failure named, not a traceback
        raise _bad(f"--python {path}: importing it failed: {type(error).__name__}: {error}") from None
    for name in ("build_world", "read_quantities"):
        if not callable(getattr(module, name, None)):
            raise _bad(f"--python {path}: defines no function {name}() (see docs/audit.md)")
    return module


# ---- one run -----------------------------------------------------------------------------------------------------

def run(program, variant: str, profile: str, seed: int, duration_s: float) -> Run:
    """One run of program (Executable or PythonProgram) as variant (a policy name, or OWN) under profile and seed
    for duration_s simulated seconds. Raises BadProgram as the module's docstring says."""
    if isinstance(program, PythonProgram):
        return _run_python(program, variant, profile, seed, duration_s)
    return _run_executable(program, variant, profile, seed, duration_s)


def _command_line(program: Executable, variant: str, profile: str, seed: int, duration_s: float) -> list[str]:
    base = list(program.own if variant == OWN else program.command)
    flags = ["--profile", profile, "--seed", str(seed), "--duration", repr(float(duration_s))]
    return base + flags + ([] if variant == OWN else ["--policy", variant])


def _run_executable(program: Executable, variant: str, profile: str, seed: int, duration_s: float) -> Run:
    command = _command_line(program, variant, profile, seed, duration_s)
    shown = shlex.join(command)
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        started = time.perf_counter()
        try:
            process = subprocess.Popen(command, stdin=subprocess.DEVNULL, stdout=out, stderr=err,
                                       start_new_session=True,  # its own group: a hung program is killed whole
                                       preexec_fn=_die_with_parent)
        except OSError as error:
            raise _bad(f"{shown}: cannot be started: {error.strerror or error}") from None
        status, usage = _wait(process, program.time_limit_s, shown)
        wall_s = time.perf_counter() - started
        out.seek(0)
        err.seek(0)
        stdout = out.read().decode("utf-8", errors="replace")
        stderr = err.read().decode("utf-8", errors="replace").strip()
    cpu_s = usage.ru_utime + usage.ru_stime
    if os.WIFSIGNALED(status):
        number = os.WTERMSIG(status)
        raise _bad(f"{shown}: crashed, killed by signal {number} ({_signal_name(number)}){_quoted(stderr)}")
    code = os.WEXITSTATUS(status)
    if code not in (0, 1):
        raise _bad(f"{shown}: exited {code} (0: done, 1: a frame failed; 2 usually means it refused a flag)"
                   f"{_quoted(stderr)}")
    columns = parse_csv(stdout, shown, allow_empty=code == 1)
    run_status = "ok"
    if code == 1:
        last = stderr.splitlines()[-1] if stderr else "no message on stderr"
        run_status = f"failed: {one_line(last)[:STDERR_SHOWN]}"
    elif not all(np.all(np.isfinite(columns[q])) for q in columns):
        run_status = "failed: a value that is not finite, with exit 0"
    return Run(variant, profile, seed, columns, run_status, cpu_s, wall_s)


def _die_with_parent() -> None:
    """In the child, before exec (Linux): killed when the process that started it dies, so that a worker stopped
    by Ctrl-C or a failure elsewhere leaves no program running."""
    import ctypes

    with contextlib.suppress(OSError, AttributeError):
        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG


def _wait(process: subprocess.Popen, time_limit_s: float, shown: str):
    """(wait status, resource usage) of the process, killed with its group after time_limit_s (BadProgram) or
    when this wait is interrupted."""
    deadline = time.monotonic() + time_limit_s
    pause = 0.0005
    try:
        while True:
            pid, status, usage = os.wait4(process.pid, os.WNOHANG)
            if pid == process.pid:
                process.returncode = 0  # reaped here: Popen must not wait for it again
                return status, usage
            if time.monotonic() > deadline:
                raise _bad(f"{shown}: did not finish within the time limit of {time_limit_s:g} s per run "
                           "(--time-limit): killed")
            time.sleep(pause)
            pause = min(2 * pause, 0.02)
    except BaseException:  # the time limit, or Ctrl-C: the program and its children go
        with contextlib.suppress(ProcessLookupError):
            os.killpg(process.pid, signal.SIGKILL)
        with contextlib.suppress(ChildProcessError):
            os.wait4(process.pid, 0)
        process.returncode = -signal.SIGKILL
        raise


def _signal_name(number: int) -> str:
    try:
        return signal.Signals(number).name
    except ValueError:
        return "unknown signal"


def _quoted(stderr: str) -> str:
    if not stderr:
        return ""
    text = " | ".join(line for line in stderr.splitlines()[-3:] if line.strip())
    return f"; its stderr: {text[:STDERR_SHOWN]}"


def parse_csv(text: str, shown: str, allow_empty: bool = False) -> dict:
    """The columns of a program's CSV (name -> float array). BadProgram naming the line at fault for: no output, a
    header without t_s first or with a column without a unit, a repeated column, a row of another width or with a
    field that is not a number, times that go back or are not finite, an optional count column that is not a whole
    number >= 0."""
    lines = text.splitlines()
    if not lines or not lines[0].strip():
        raise _bad(f"{shown}: printed no CSV on stdout (expected a header t_s,<quantity>_<unit>,... and a row "
                   "per frame)")
    names = [name.strip() for name in lines[0].split(",")]
    if names[0] != TIME_COLUMN:
        raise _bad(f"{shown}: malformed CSV: the header's first column is {names[0][:60]!r}, not t_s "
                   f"(header {lines[0][:120]!r})")
    if len(names) < 2:
        raise _bad(f"{shown}: malformed CSV: the header {lines[0][:120]!r} names no quantity after t_s")
    for name in names[1:]:
        if name not in OPTIONAL_COLUMNS and ("_" not in name.strip("_") or not name.replace("_", "").isalnum()):
            raise _bad(f"{shown}: malformed CSV: column {name[:60]!r} of the header has no unit in its name "
                       "(write it <quantity>_<unit>, e.g. height_m, pitch_rad, force_N)")
    if len(set(names)) != len(names):
        repeated = next(name for name in names if names.count(name) > 1)
        raise _bad(f"{shown}: malformed CSV: column {repeated!r} appears twice in the header")
    rows = []
    for number, line in enumerate(lines[1:], start=2):
        fields = line.split(",")
        if len(fields) != len(names):
            raise _bad(f"{shown}: malformed CSV: line {number} has {len(fields)} fields, the header {len(names)}: "
                       f"{line[:120]!r}")
        try:
            rows.append([float(field) for field in fields])
        except ValueError:
            raise _bad(f"{shown}: malformed CSV: line {number} holds a field that is not a number: "
                       f"{line[:120]!r}") from None
    if not rows and not allow_empty:
        raise _bad(f"{shown}: malformed CSV: a header and no rows")
    table = np.array(rows, dtype=float).reshape(len(rows), len(names))
    columns = {name: table[:, i].copy() for i, name in enumerate(names)}
    t = columns[TIME_COLUMN]
    if not np.all(np.isfinite(t)):
        raise _bad(f"{shown}: malformed CSV: t_s is not finite on line {int(np.flatnonzero(~np.isfinite(t))[0]) + 2}")
    back = np.flatnonzero(np.diff(t) < 0)
    if len(back):
        raise _bad(f"{shown}: malformed CSV: t_s goes back on line {int(back[0]) + 3} ({t[back[0]]!r} then "
                   f"{t[back[0] + 1]!r})")
    for name in OPTIONAL_COLUMNS:
        values = columns.get(name)
        if values is None:
            continue
        if len(values) > 1 and np.all(values[1:] == NOT_COUNTED):  # the program does not count it
            del columns[name]
        elif not np.all((values >= 0) & (values == np.floor(values))):
            raise _bad(f"{shown}: malformed CSV: column {name} holds a value that is not a whole number >= 0 "
                       f"(or {NOT_COUNTED} on every frame: not counted)")
    return columns


def _run_python(program: PythonProgram, variant: str, profile: str, seed: int, duration_s: float) -> Run:
    """The Python program's world stepped here by a Stepper under variant, a frame of the profile at a time."""
    import odepy

    from steadystep.enums import Solver
    from steadystep.profiles import frames_within
    from steadystep.stepper import Stepper

    if variant == OWN:
        raise _bad(f"--python {program.path}: a Python program is stepped by the library: no own stepping")
    module = load_python_program(program.path)
    shown = f"{program.path} ({variant}, {profile}, seed {seed})"
    odepy.dInitODE2(0)
    odepy.dRandSetSeed(1)  # QuickStep shuffles rows with ODE's global generator: the same run every time
    built = _call_user(shown, "build_world", module.build_world)
    if not isinstance(built, PythonWorld):
        raise _bad(f"{shown}: build_world() returned {type(built).__name__}, not a steadystep.audit.PythonWorld")
    stepper = None
    try:
        solver = {"quick": Solver.QUICK, "step": Solver.STEP}.get(built.solver)
        if solver is None:
            raise _bad(f"{shown}: PythonWorld.solver = {built.solver!r}: must be 'quick' (dWorldQuickStep) or "
                       "'step' (dWorldStep)")
        stepper = _call_user(shown, "the Stepper of build_world()'s PythonWorld", Stepper, built.world,
                             built.registry, space=built.space,
                             tuned_step_s=built.tuned_step_s, solver=solver,
                             policy=variant, collide=built.collide, contact_group=built.contact_group,
                             before_step=_per_step(shown, built.before_step))
        names, rows = None, []
        status = "ok"
        time_s, started_cpu, started = 0.0, time.process_time(), time.perf_counter()

        def record(counts: dict) -> None:
            nonlocal names
            values = _call_user(shown, "read_quantities", module.read_quantities, built)
            if names is None:
                names = [TIME_COLUMN, *values, *counts]
                parse_csv(",".join(names) + "\n", shown, allow_empty=True)  # the names checked as a CSV's
            rows.append([time_s, *(float(values[name]) for name in names[1:len(values) + 1]), *counts.values()])

        record({STEP_COLUMN: 0, **{name: 0 for name in SERVED_COLUMNS}})
        for frame_s in frames_within(profile, duration_s, seed):
            if built.before_frame is not None:
                _call_user(shown, "before_frame", built.before_frame, time_s)
            try:
                report = stepper.step(frame_s)
            except BadProgram:  # its before_step raised: a fault of the program, not of a frame
                raise
            except SteadystepError as error:
                status = f"failed: {error}"
                break
            time_s = report.time_s  # every step taken, added: under fixed, the same bits at every frame rate
            record({STEP_COLUMN: report.steps, **served_counts(report)})
        cpu_s, wall_s = time.process_time() - started_cpu, time.perf_counter() - started
    finally:
        if stepper is not None:
            stepper.close()
        if built.close is not None:
            _call_user(shown, "close", built.close)
        odepy.dCloseODE()
    columns = {name: np.array([row[i] for row in rows], dtype=float) for i, name in enumerate(names)}
    if status == "ok" and not all(np.all(np.isfinite(v)) for v in columns.values()):
        status = "failed: a value that is not finite"
    return Run(variant, profile, seed, columns, status, cpu_s, wall_s)


def _per_step(shown: str, before_step):
    """The Stepper's before_step for a PythonWorld's before_step(time_s, step_s), or None; what it raises becomes a
    BadProgram naming it, which step() raises after the frame."""
    if before_step is None:
        return None
    if not callable(before_step):
        raise _bad(f"{shown}: PythonWorld.before_step = {before_step!r}: must be callable as "
                   "before_step(time_s, step_s), or None")

    def per_step(stepper, step) -> None:
        try:
            before_step(step.time_s, step.step_s)
        except Exception as error:  # the user's code: its failure named in one line
            raise _bad(f"{shown}: before_step() raised {type(error).__name__}: {error}") from None

    return per_step


def served_counts(report) -> dict:
    """The frame's served counts (SERVED_COLUMNS) from a Stepper's FrameReport."""
    rows, contacts = report.rows, report.contacts
    return dict(zip(SERVED_COLUMNS, (rows.by_mapping, rows.handed_to_matched, rows.handed_to_implicit_euler,
                                     contacts.by_mapping, contacts.handed_to_matched,
                                     contacts.handed_to_implicit_euler)))


def _call_user(shown: str, name: str, function, *args, **keywords):
    try:
        return function(*args, **keywords)
    except Exception as error:  # the user's code: its failure named in one line
        raise _bad(f"{shown}: {name}() raised {type(error).__name__}: {error}") from None


"""Running a user's program for the audit (docs/audit.md): one run is the program under one frame-time profile, seed,
duration and variant (a policy, a diagnosis variant, or its own stepping), read back as columns.

A program takes part in one of two ways, and both run as a process of their own, one per run:

- an executable (C, C++, anything) that takes ``--profile SPEC --seed N --duration S`` and, when it runs through the
  library, ``--policy NAME`` (the diagnosis variants add ``--max-step-scale F`` or ``--iterations-scale N``), and
  prints CSV on stdout: a header ``t_s,<quantity>_<unit>,...`` then one row per frame (a row at t = 0 first).
  Optional count columns (``steps``, ``rows_by_mapping``, ..., ``unsoftened_contact_steps``: OPTIONAL_COLUMNS) say
  what each frame did (-1 on every frame: not counted, left out). Exit 0 when every frame stepped, 1 when a frame
  failed (the rows up to it are kept, the run's status says so), anything else is a bad program. The frame
  durations are also handed over in a file named by STEADYSTEP_AUDIT_FRAMES (steadystep/audit/protocol.h reads
  them; the lab's audit_flags.h makes the same frames from --profile).
- a Python file defining ``build_world()`` and ``read_quantities(world)`` (and, for its own stepping,
  ``own_frame(world, time_s, frame_s)``): run by ``python -m steadystep.audit.worker``, which follows the same
  protocol (audit/worker.py).

Every run is bounded: CPU time (RLIMIT_CPU) and a wall-clock guard against a program that sleeps (killed once it has
used no CPU for IDLE_S after the time limit), output (RLIMIT_FSIZE), and its children: the process group is killed
when the run ends, and processes it left behind in a session of their own are found (this process is their
subreaper) and killed too.

A program that cannot take part raises BadProgram, one line naming the program, the run and what is wrong.
"""

from __future__ import annotations

import contextlib
import dataclasses
import hashlib
import json
import os
import re
import resource
import select
import shlex
import signal
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from steadystep.core._native import InvalidValue, one_line, printable
from steadystep.core.enums import Status

OWN = "own"  # the variant name of a program's own stepping (without the library)
TIME_COLUMN = "t_s"
STEP_COLUMN = "steps"
SERVED_COLUMNS = ("rows_by_mapping", "rows_handed_to_matched", "rows_handed_to_implicit_euler",
                  "contacts_by_mapping", "contacts_handed_to_matched", "contacts_handed_to_implicit_euler")
UNSOFTENED_COLUMN = "unsoftened_contact_steps"  # steps that made contacts but softened none (ssFrameReport's)
OPTIONAL_COLUMNS = (STEP_COLUMN, *SERVED_COLUMNS, UNSOFTENED_COLUMN)  # counts per frame, not followed quantities
NOT_COUNTED = -1  # a count column holding this on every frame (after the t = 0 row) is one the program cannot count
STDERR_SHOWN = 300  # characters of a program's stderr quoted in a message
FRAMES_VARIABLE = "STEADYSTEP_AUDIT_FRAMES"  # steadystep/audit/protocol.h's SS_AUDIT_RUN_FRAMES_VARIABLE

# The diagnosis variants (docs/audit.md, "Where the dependence comes from"): implicit-euler with one thing changed.
HALF_STEP = "half-step"              # the largest step halved (--max-step-scale 0.5)
MORE_ITERATIONS = "more-iterations"  # QuickStep's iterations times 4 (--iterations-scale 4)
DIAGNOSIS_FLAGS = {HALF_STEP: ("--max-step-scale", "0.5"), MORE_ITERATIONS: ("--iterations-scale", "4")}
DIAGNOSIS_BASE = "implicit-euler"

DEFAULT_TIME_LIMIT_S = 60.0  # CPU seconds a run may use
IDLE_S = 1.0                 # after the time limit, a program that used no CPU for this long is a hang
WALL_FACTOR = 20.0           # and none may take more than this many times the limit in wall time
OUTPUT_BYTES_PER_FRAME = 1024  # what a run may write: this much a frame, plus OUTPUT_BYTES_SLACK
OUTPUT_BYTES_SLACK = 1 << 20
COUNT_TIME_FACTOR = 60.0     # a run counted under valgrind may take this many times the limit

# Lines the Python worker writes on stderr for the audit (audit/worker.py), never shown as the program's own.
REFUSAL_MARK = "steadystep-audit-refusal: "
LOOP_CPU_MARK = "steadystep-audit-loop-cpu-s: "
DONE_MARK = "steadystep-audit-done"
REFUSED_EXIT = 3  # the worker's exit code after a refusal line


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
    cpu_s: float             # the run's CPU time (s): the whole process, or a Python program's stepping loop
    wall_s: float
    instructions: int | None = None  # counted under valgrind (a cost run), else None

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

    def as_json(self) -> dict:
        data = dataclasses.asdict(self)
        data["columns"] = {name: values.tolist() for name, values in self.columns.items()}
        return data

    @classmethod
    def from_json(cls, data: dict) -> "Run":
        data = dict(data)
        data["columns"] = {name: np.array(values, dtype=float) for name, values in data["columns"].items()}
        return cls(**data)


def _file_digest(path: str) -> str:
    digest = hashlib.sha256()
    with contextlib.suppress(OSError), open(path, "rb") as file:
        for block in iter(lambda: file.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


# ---- the programs ----------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Executable:
    """A program run as a process: command (the program and any fixed arguments of its own) for the policies, own
    (likewise) for its own stepping, or None. Plain data, so that a unit can be pickled to a worker."""

    command: tuple[str, ...]
    own: tuple[str, ...] | None = None
    time_limit_s: float = DEFAULT_TIME_LIMIT_S

    @property
    def name(self) -> str:
        return Path(self.command[0]).name

    @property
    def language(self) -> str:
        return "C"

    def check(self) -> bool:
        """Refuses a program that does not exist or cannot be executed, before anything runs. Returns whether it
        has its own stepping."""
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
        return self.own is not None

    def identity(self) -> dict:
        """What a kept run depends on: the commands and the content of the programs they name."""
        return {"command": list(self.command), "own": list(self.own) if self.own else None,
                "files": [_file_digest(c[0]) for c in (self.command, self.own) if c]}

    def command_line(self, variant: str, profile: str, seed: int, duration_s: float) -> list[str]:
        base = list(self.own if variant == OWN else self.command)
        return base + _flags(variant, profile, seed, duration_s)


@dataclass(frozen=True)
class PythonProgram:
    """A Python file defining build_world() and read_quantities(world), and for its own stepping
    own_frame(world, time_s, frame_s) (audit/worker.py); each run is a process of its own."""

    path: str
    time_limit_s: float = DEFAULT_TIME_LIMIT_S

    @property
    def name(self) -> str:
        return Path(self.path).name

    @property
    def language(self) -> str:
        return "Python"

    @property
    def own(self):
        return None  # not a second command: its own stepping is own_frame(), found by check()

    def check(self) -> bool:
        """Refuses a file that does not exist, fails to import or lacks the functions (importing it in a process of
        its own, bounded as a run is). Returns whether it defines own_frame()."""
        file = Path(self.path)
        if not file.is_file():
            raise _bad(f"--python {self.path}: does not exist" if not file.exists() else
                       f"--python {self.path}: is not a file")
        shown = f"--python {self.path}"
        status, usage, stdout, stderr, _ = run_process(self.command_line_check(), None, self.time_limit_s,
                                                       OUTPUT_BYTES_SLACK, shown)
        _refused(status, stderr, shown)
        try:
            return bool(json.loads(stdout.strip().splitlines()[-1])["own"])
        except (ValueError, KeyError, IndexError, TypeError):
            raise _bad(f"{shown}: importing it did not finish (exit {_exit_text(status)}){_quoted(stderr)}") from None

    def identity(self) -> dict:
        return {"python": str(Path(self.path).resolve()), "files": [_file_digest(self.path)]}

    def command_line_check(self) -> list[str]:
        return [sys.executable, "-m", "steadystep.audit.worker", str(self.path), "--check"]

    def command_line(self, variant: str, profile: str, seed: int, duration_s: float) -> list[str]:
        return [sys.executable, "-m", "steadystep.audit.worker", str(self.path)] + \
            _flags(variant, profile, seed, duration_s)


def _flags(variant: str, profile: str, seed: int, duration_s: float) -> list[str]:
    flags = ["--profile", profile, "--seed", str(seed), "--duration", repr(float(duration_s))]
    if variant == OWN:
        return flags
    if variant in DIAGNOSIS_FLAGS:
        return flags + ["--policy", DIAGNOSIS_BASE, *DIAGNOSIS_FLAGS[variant]]
    return flags + ["--policy", variant]


def supports(program, variant: str) -> bool:
    """Whether the program takes a diagnosis variant's flag: a run of one frame with it ends with exit 0 or 1 (a
    refusal, exit 2, or anything else, says it does not). A Python program always does."""
    if isinstance(program, PythonProgram) or variant not in DIAGNOSIS_FLAGS:
        return True
    command = program.command_line(variant, "fixed:60", 1, 1.0 / 60)
    with tempfile.TemporaryDirectory(prefix="steadystep-audit-") as scratch:
        env = _frames_env(Path(scratch), "fixed:60", 1, 1.0 / 60)
        status, *_ = run_process(command, env, program.time_limit_s, OUTPUT_BYTES_SLACK, shlex.join(command))
    return os.WIFEXITED(status) and os.WEXITSTATUS(status) in (0, 1)


@dataclass
class PythonWorld:
    """What a Python program's build_world() returns: its ODE world and what the stepper needs to step it.

    world: the world's handle, of the binding the program uses (required). registry: a steadystep Registry of it, or
    None. space: the program's space, or None: with it, the stepper adopts the world and everything the space
    reaches as tuned at tuned_step_s (s), into registry or into one of its own. tuned_step_s: the step the program
    tuned its numbers for, which the stepper also takes as its longest (and fixed) step. collide(stepper): called
    before each physics step (its near callback calls stepper.soften_contact). contact_group: emptied after each
    step. before_frame(time_s): the program's per-frame logic, called before each frame with the simulated time (s)
    the frame starts at; a force it adds is held for every step of the frame. before_step(time_s, step_s): the
    program's per-step logic, called before every physics step under every policy, after the frame's held forces are
    put back and before collide, with the simulated time (s) at the step's start and the step's length (s): whatever
    depends on the time or the state (a motor's target, a controller, a scripted push) belongs here, and under the
    fixed policies it then gives the same motion at every frame rate. close(): destroys what build_world made (the
    world last); the audit closes its stepper (and a registry it made) first. solver: "quick" (dWorldQuickStep) or
    "step" (dWorldStep). The program's own stepping is the module's own_frame(world, time_s, frame_s), not a field
    here (audit/worker.py)."""

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


# ---- one run -----------------------------------------------------------------------------------------------------

def run(program, variant: str, profile: str, seed: int, duration_s: float, count: bool = False) -> Run:
    """One run of program (Executable or PythonProgram) as variant (a policy name, a diagnosis variant or OWN) under
    profile and seed for duration_s simulated seconds, in a process of its own. count: under valgrind, counting the
    instructions it executes (Run.instructions). Raises BadProgram as the module's docstring says."""
    from steadystep.lab.profiles import frame_count

    command = program.command_line(variant, profile, seed, duration_s)
    shown = (f"{program.path} ({variant}, {profile}, seed {seed})" if isinstance(program, PythonProgram)
             else shlex.join(command))
    limit_s = program.time_limit_s * (COUNT_TIME_FACTOR if count else 1.0)
    output_bytes = OUTPUT_BYTES_SLACK + OUTPUT_BYTES_PER_FRAME * (frame_count(profile, duration_s, seed) + 1)
    with tempfile.TemporaryDirectory(prefix="steadystep-audit-") as scratch:
        scratch = Path(scratch)
        env = _frames_env(scratch, profile, seed, duration_s)
        log = scratch / "valgrind.log"
        if count:
            command = ["valgrind", "--tool=cachegrind", "--cache-sim=no", "--cachegrind-out-file=/dev/null",
                       f"--log-file={log}", *command]
        status, usage, stdout, stderr, wall_s = run_process(command, env, limit_s, output_bytes, shown)
        instructions = _instructions(log) if count else None
    cpu_s = usage.ru_utime + usage.ru_stime
    python = isinstance(program, PythonProgram)
    if python:
        _refused(status, stderr, shown)
        stderr, loop_cpu_s, done = _worker_marks(stderr)
    if os.WIFSIGNALED(status):
        raise _bad(f"{shown}: {_signal_text(os.WTERMSIG(status), limit_s)}{_quoted(stderr)}")
    code = os.WEXITSTATUS(status)
    if python:
        if not done:
            raise _bad(f"{shown}: the process ended (exit {code}) before the run did: the program ended it "
                       f"itself (os._exit, or exit from a thread){_quoted(stderr)}")
        cpu_s = loop_cpu_s if loop_cpu_s is not None else cpu_s
    if code not in (0, 1):
        raise _bad(f"{shown}: exited {code} (0: done, 1: a frame failed; 2 usually means it refused a flag)"
                   f"{_quoted(stderr)}")
    if count and instructions is None:
        raise _bad(f"{shown}: valgrind counted no instructions (its log: {_tail(log)})")
    columns = parse_csv(stdout, shown, allow_empty=code == 1)
    run_status = "ok"
    if code == 1:
        last = stderr.splitlines()[-1] if stderr else "no message on stderr"
        run_status = f"failed: {one_line(last)[:STDERR_SHOWN]}"
    elif not all(np.all(np.isfinite(columns[q])) for q in columns):
        run_status = "failed: a value that is not finite, with exit 0"
    else:
        expected = frame_count(profile, duration_s, seed)
        made = Run(variant, profile, seed, columns, run_status, cpu_s, wall_s)
        if abs(made.frames - expected) > 1:
            raise _bad(f"{shown}: printed {made.frames} frames, not the profile's {expected}: it does not follow "
                       f"--profile (one CSV row per frame of the profile, after a t = 0 row)")
    return Run(variant, profile, seed, columns, run_status, cpu_s, wall_s, instructions)


def _tail(path: Path) -> str:
    try:
        return one_line(path.read_text(errors="replace").strip().splitlines()[-1])[:STDERR_SHOWN]
    except (OSError, IndexError):
        return "none"


def _instructions(log: Path) -> int | None:
    try:
        found = re.findall(r"I\s+refs:\s+([\d,]+)", log.read_text(errors="replace"))
    except OSError:
        return None
    return int(found[-1].replace(",", "")) if found else None


def _frames_env(scratch: Path, profile: str, seed: int, duration_s: float) -> dict:
    """The environment of a run: the profile's frames (enough to cover the duration) in a file, named by
    FRAMES_VARIABLE, one duration a line at full precision."""
    from steadystep.lab.profiles import Profile

    frames = Profile(profile, seed)
    lines, elapsed_s = [], 0.0
    while elapsed_s < duration_s:
        frame_s = frames.next()
        lines.append(repr(frame_s))
        elapsed_s += frame_s
    lines.append(repr(frames.next()))
    path = scratch / "frames.txt"
    path.write_text("\n".join(lines) + "\n")
    return {**os.environ, FRAMES_VARIABLE: str(path)}


def _exit_text(status: int) -> str:
    return f"signal {os.WTERMSIG(status)}" if os.WIFSIGNALED(status) else str(os.WEXITSTATUS(status))


def _refused(status: int, stderr: str, shown: str) -> None:
    """The Python worker's refusal (its exit code and marked line), as BadProgram with its words."""
    if os.WIFEXITED(status) and os.WEXITSTATUS(status) == REFUSED_EXIT:
        for line in stderr.splitlines():
            if line.startswith(REFUSAL_MARK):
                raise _bad(line[len(REFUSAL_MARK):])
        raise _bad(f"{shown}: exited {REFUSED_EXIT}{_quoted(stderr)}")


def _worker_marks(stderr: str) -> tuple[str, float | None, bool]:
    """The Python worker's stderr without its marked lines, the loop's CPU time (s) and whether it finished."""
    kept, loop_cpu_s, done = [], None, False
    for line in stderr.splitlines():
        if line.startswith(LOOP_CPU_MARK):
            with contextlib.suppress(ValueError):
                loop_cpu_s = float(line[len(LOOP_CPU_MARK):])
        elif line == DONE_MARK:
            done = True
        else:
            kept.append(line)
    return "\n".join(kept).strip(), loop_cpu_s, done


def _signal_text(number: int, limit_s: float) -> str:
    if number == signal.SIGXCPU:
        return (f"used more than the time limit of {limit_s:g} s of CPU time per run (--time-limit): killed")
    return f"crashed, killed by signal {number} ({_signal_name(number)})"


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


# ---- the process -------------------------------------------------------------------------------------------------

def _limits(cpu_s: float, output_bytes: int) -> Callable[[], None]:
    parent = os.getpid()

    def limit() -> None:
        """In the child, before exec: its CPU time and file size bounded, killed when its parent dies (Linux), or
        gone at once when the parent died before that was set."""
        seconds = max(1, int(cpu_s + 0.999))
        resource.setrlimit(resource.RLIMIT_CPU, (seconds, seconds + 2))
        resource.setrlimit(resource.RLIMIT_FSIZE, (output_bytes, output_bytes))
        import ctypes

        with contextlib.suppress(OSError, AttributeError):
            ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
        if os.getppid() != parent:
            os._exit(1)

    return limit


def _become_subreaper() -> None:
    """Orphans of the programs this process runs become its children (PR_SET_CHILD_SUBREAPER), so that a program's
    process that left its group (setsid) can still be found and killed when the run ends."""
    import ctypes

    with contextlib.suppress(OSError, AttributeError):
        ctypes.CDLL(None, use_errno=True).prctl(36, 1, 0, 0, 0)


def _process_stats():
    """Every live process as (pid, the fields of /proc/PID/stat after its name: state, ppid, pgrp, ...)."""
    for entry in os.scandir("/proc"):
        if not entry.name.isdigit():
            continue
        try:
            yield int(entry.name), Path(entry.path, "stat").read_text().rsplit(")", 1)[1].split()
        except (OSError, IndexError):
            continue


def _children() -> set[int]:
    """This process's children (from /proc)."""
    me = os.getpid()
    return {pid for pid, fields in _process_stats() if int(fields[1]) == me}


def _group_cpu_s(group: int) -> float | None:
    """CPU time (s) of every live process of a process group, from /proc."""
    ticks = os.sysconf("SC_CLK_TCK")
    times = [(int(fields[11]) + int(fields[12])) / ticks for _, fields in _process_stats() if int(fields[2]) == group]
    return sum(times) if times else None


def _kill_leftovers(before: set[int], group: int) -> None:
    """Kills what the run left behind: its process group, then any process that became this one's child since
    (an orphan in a session of its own), with its group, until none is left."""
    with contextlib.suppress(ProcessLookupError, PermissionError):
        os.killpg(group, signal.SIGKILL)
    for _ in range(50):
        left = _children() - before
        if not left:
            return
        for pid in left:
            with contextlib.suppress(ProcessLookupError, PermissionError):
                os.killpg(os.getpgid(pid), signal.SIGKILL)
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)
            with contextlib.suppress(ChildProcessError):
                os.waitpid(pid, 0)
        time.sleep(0.01)


def run_process(command: list[str], env: dict | None, limit_s: float, output_bytes: int, shown: str):
    """Runs command with stdin empty and stdout and stderr to files, bounded (the module's docstring). Returns
    (wait status, resource usage, stdout, stderr, wall seconds); BadProgram when it cannot start, hangs or writes past
    output_bytes. This process becomes a subreaper (PR_SET_CHILD_SUBREAPER) on the first call: orphans of what it
    runs become its children, and those born during a run are killed when it ends."""
    _become_subreaper()
    before = _children()
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        started = time.perf_counter()
        try:
            process = subprocess.Popen(command, stdin=subprocess.DEVNULL, stdout=out, stderr=err, env=env,
                                       start_new_session=True,  # its own group: killed whole
                                       preexec_fn=_limits(limit_s, output_bytes))
        except OSError as error:
            raise _bad(f"{shown}: cannot be started: {error.strerror or error}") from None
        try:
            status, usage = _wait(process, limit_s, shown)
        finally:
            _kill_leftovers(before | {process.pid}, process.pid)
        wall_s = time.perf_counter() - started
        out.seek(0)
        err.seek(0)
        stdout = out.read(output_bytes + 1)
        stderr = err.read(output_bytes + 1)
    if max(len(stdout), len(stderr)) >= output_bytes:  # stopped by RLIMIT_FSIZE (SIGXFSZ, or EFBIG when ignored)
        raise _bad(f"{shown}: wrote {'stdout' if len(stdout) >= output_bytes else 'stderr'} up to the bound of a "
                   f"run's output, {output_bytes / 2**20:.3g} MiB ({OUTPUT_BYTES_PER_FRAME} bytes a frame and "
                   f"{OUTPUT_BYTES_SLACK >> 20} MiB): stopped")
    return (status, usage, stdout.decode("utf-8", errors="replace"),
            stderr.decode("utf-8", errors="replace").strip(), wall_s)


def _wait(process: subprocess.Popen, limit_s: float, shown: str):
    """(wait status, resource usage) of the process. Its CPU time is bounded by RLIMIT_CPU; here, a process that
    sleeps is killed with its group once, after limit_s of wall time, it has used no CPU for IDLE_S (or after
    WALL_FACTOR times limit_s in any case), and when this wait is interrupted. Between looks it waits on a pidfd of
    the process (Linux 5.3 on), which wakes it as the process ends, else sleeps."""
    started = time.monotonic()
    pause, watched = 0.0005, None  # watched: (time, group CPU) of the last look after the limit
    try:
        ended = os.pidfd_open(process.pid)  # readable once the process has ended
    except (AttributeError, OSError):
        ended = None
    try:
        while True:
            pid, status, usage = os.wait4(process.pid, os.WNOHANG)
            if pid == process.pid:
                process.returncode = 0  # reaped here: Popen must not wait for it again
                return status, usage
            now = time.monotonic()
            if now - started > limit_s:
                cpu_s = _group_cpu_s(process.pid) or 0.0
                if watched is None:
                    watched = (now, cpu_s)
                elif now - watched[0] >= IDLE_S:
                    if cpu_s - watched[1] < 0.01 * (now - watched[0]):
                        raise _bad(f"{shown}: did not finish within the time limit of {limit_s:g} s per run "
                                   f"(--time-limit) and then used no CPU for {IDLE_S:g} s (a hang): killed")
                    watched = (now, cpu_s)
                if now - started > WALL_FACTOR * limit_s:
                    raise _bad(f"{shown}: still running after {WALL_FACTOR * limit_s:g} s of wall time, "
                               f"{WALL_FACTOR:g} times the time limit (--time-limit): killed")
            if ended is None:
                time.sleep(pause)
            else:
                select.select([ended], [], [], pause)
            pause = min(2 * pause, 0.05)
    except BaseException:  # a hang, or Ctrl-C: the program and its children go
        with contextlib.suppress(ProcessLookupError):
            os.killpg(process.pid, signal.SIGKILL)
        with contextlib.suppress(ChildProcessError):
            os.wait4(process.pid, 0)
        process.returncode = -signal.SIGKILL
        raise
    finally:
        if ended is not None:
            os.close(ended)


# ---- the CSV -----------------------------------------------------------------------------------------------------

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
    if all(name in OPTIONAL_COLUMNS for name in names[1:]):
        raise _bad(f"{shown}: malformed CSV: the header {lines[0][:120]!r} names only count columns, no quantity")
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

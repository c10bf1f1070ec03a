"""Scenes, policies and runs on real ODE through scene.h, with results as numpy arrays.

A run is one scene under one frame-time profile and one stepping policy for a simulated duration; it records the
scene's followed quantities after every physics step. The reference run is the same scene at a fine fixed step
(1/1000 s, the article's mapping), against which the others are measured.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from steadystep.core._native import SteadystepError, c_string, check, ffi, lib, number, shown, text
from steadystep.core.enums import Status
from steadystep.lab.limits import MAX_RUN_FRAMES, MAX_RUN_STEPS
from steadystep.lab.profiles import frame_count, seed_value
from steadystep.core.stepping import policy_names  # noqa: F401 - the lab's policies are the library's presets

REFERENCE_STEP_S = 1.0 / 1000.0
REFERENCE_PROFILE = "fixed:1000"


def scene_names() -> list[str]:
    """The library's scenes by name (scene.h): oscillator, buggy, drop, chain, pile ..."""
    return [text(lib.ssSceneInfoAt(i).name) for i in range(lib.ssSceneCount())]


@dataclass(frozen=True)
class SceneInfo:
    """A scene's name, description and followed quantities with their units."""

    name: str
    description: str
    quantities: tuple[str, ...]
    units: tuple[str, ...]


def column_name(name: str, unit: str) -> str:
    """A quantity's column name in the lab's tables (scene.h, ssColumnName): "t", "s" gives "t_s", "v", "m/s" gives
    "v_m_per_s", "erp", "" gives "erp". The one spelling the CSV, the JSON and examples/oscillator.c share."""
    name_c, unit_c = c_string("name", name), c_string("unit", unit)
    length = lib.ssColumnName(name_c, unit_c, ffi.NULL, 0)
    if length < 0:
        check(lib.SS_ERROR_OUT_OF_RANGE)
    out = ffi.new("char[]", length + 1)
    lib.ssColumnName(name_c, unit_c, out, length + 1)
    return text(out)


def _scene_info(info) -> SceneInfo:
    count = info.quantity_count
    return SceneInfo(text(info.name), text(info.description),
                     tuple(text(info.quantity_names[i]) for i in range(count)),
                     tuple(text(info.quantity_units[i]) for i in range(count)))


def scenes() -> list[SceneInfo]:
    """Every scene the library knows."""
    return [_scene_info(lib.ssSceneInfoAt(i)) for i in range(lib.ssSceneCount())]


def scene_info(name: str) -> SceneInfo:
    """One scene's description. Raises SteadystepError ("not found") for an unknown name."""
    info = lib.ssSceneFind(c_string("scene", name))
    if info == ffi.NULL:
        known = ", ".join(s.name for s in scenes())
        raise SteadystepError(Status.NOT_FOUND, f"scene = {shown(name)}: unknown (known: {known})")
    return _scene_info(info)


def _as_dict(cdata) -> dict:
    """A C struct as a dict of its fields (nested structs as dicts), read from the header's own layout."""
    out = {}
    for name, fieldtype in ffi.typeof(cdata).fields:
        value = getattr(cdata, name)
        out[name] = _as_dict(value) if fieldtype.type.kind == "struct" else value
    return out


# Followed quantities that are settings the stepper wrote, not motion: not measured against the reference.
NOT_MOTION = frozenset({"erp", "cfm"})


def motion_quantities(scene: str) -> list[str]:
    """The scene's quantities that describe its motion (the oscillator's erp and cfm do not)."""
    return [q for q in scene_info(scene).quantities if q not in NOT_MOTION]


def default_params(scene: str) -> dict:
    """The scene's default parameters (ssSceneParams as a dict: spring {stiffness, damping}, mass, x0, ...)."""
    out = ffi.new("ssSceneParams*")
    check(lib.ssDefaultSceneParams(c_string("scene", scene), out))
    return _as_dict(out[0])


def default_stepping() -> dict:
    """The stepper's defaults (ssStepping as a dict: cut, mapping, frozen_step_s, solver, max_step_s, ...)."""
    return _as_dict(lib.ssDefaultStepping())


def _merge(base: dict, changes: dict | None, what: str) -> dict:
    """base with the fields in changes replaced (nested dicts field by field); SteadystepError naming a field that
    does not exist or a value its C type cannot hold."""
    if changes is None:
        return dict(base)
    if not isinstance(changes, dict):
        raise SteadystepError(Status.OUT_OF_RANGE, f"{what} = {shown(changes)}: must be a dict of fields")
    merged = dict(base)
    for key, value in changes.items():
        if key not in base:
            raise SteadystepError(Status.OUT_OF_RANGE, f"{what}: no field {shown(key)} (fields: {', '.join(base)})")
        if isinstance(base[key], dict):
            merged[key] = _merge(base[key], value, f"{what}.{key}")
        else:
            merged[key] = _field_value(f"{what}.{key}", base[key], value)
    return merged


def _field_value(name: str, default, value):
    """value for a struct field whose default is default: an int field takes integers within C's int, a double
    field any real number."""
    if isinstance(default, int):
        if isinstance(value, bool) or not hasattr(value, "__index__"):
            raise SteadystepError(Status.OUT_OF_RANGE, f"{name} = {shown(value)}: must be an integer")
        value = value.__index__()
        if not -2**31 <= value < 2**31:
            raise SteadystepError(Status.OUT_OF_RANGE, f"{name} = {shown(value)}: outside C's int")
        return value
    return number(name, value)


def make_stepping(policy: str, **changes) -> dict:
    """The lab's stepping of the named policy (ssLabStepping: its cut and mapping, naive frozen at 1/30 s) with any
    field changed (max_step_s=..., solver=...). Raises SteadystepError ("parse error") naming an unknown policy."""
    out = ffi.new("ssStepping*")
    check(lib.ssLabStepping(c_string("policy", policy), out))
    return _merge(_as_dict(out[0]), changes, "stepping")


def reference_stepping() -> dict:
    """How the reference run steps: implicit Euler at a fixed 1/1000 s, one step a frame."""
    return _as_dict(lib.ssReferenceStepping(REFERENCE_STEP_S))


# How a run ends (RunResult.status): "ok" ran to the end within the scene's sanity bounds; "blow-up", "speed limit"
# and "position limit" (the library's names for those statuses) ended early with a state that was not finite,
# absurdly fast or absurdly far; "broken" ended early, finite but physically wrong: a step left one of the scene's
# sanity bounds (scene.h: a torn joint, a box through the floor, energy made). Only "ok" is a run to measure: a
# report counts every other status as failed.
BLOW_UP_STATUSES = frozenset(text(lib.ssStatusName(status)) for status in (
    lib.SS_ERROR_BLOWUP, lib.SS_ERROR_SPEED_LIMIT, lib.SS_ERROR_POSITION_LIMIT))
BROKEN = "broken"


@dataclass
class RunResult:
    """One run's records (one per physics step, after the step), the state before the first step, and its summary."""

    scene: str
    profile: str
    policy: str
    seed: int
    duration_s: float
    params: dict
    stepping: dict
    times: np.ndarray                  # s, after each step
    step_lengths: np.ndarray           # s
    quantities: dict[str, np.ndarray]  # by quantity name, in the scene's units
    units: dict[str, str]
    frame_count: int
    wall_s: float                      # wall-clock seconds of stepping (scene building excluded)
    status: str                        # "ok", "broken", or a blow-up status (BLOW_UP_STATUSES)
    message: str = ""                  # why a run that is not "ok" ended: the bound, body or joint, value, time
    initial: dict[str, float] = field(default_factory=dict)  # the quantities before the first step (t = 0)
    bound_use: float = 0.0             # the largest value/bound ratio of the scene's sanity bounds (> 1: broken)
    extra: dict = field(default_factory=dict)
    # ssRun_Counters (ssSceneCounters), summed over the run: frames, steps, rows and contacts (each a dict of
    # by_mapping, handed_to_matched, handed_to_implicit_euler), row_writes
    counters: dict = field(default_factory=dict)

    @property
    def step_count(self) -> int:
        return len(self.times)

    @property
    def failed(self) -> bool:
        """Not a run to measure: it blew up or broke."""
        return self.status != "ok"

    @property
    def blew_up(self) -> bool:
        """Ended by a blow-up: a state that was not finite, or faster than the scene's speed limit."""
        return self.status in BLOW_UP_STATUSES

    @property
    def broken(self) -> bool:
        """Ended at the first step outside one of the scene's sanity bounds: finite, but physically wrong."""
        return self.status == BROKEN

    def trajectory(self) -> dict[str, np.ndarray]:
        """The run as a table from t = 0, by column name with its unit (column_name: "t_s", "x_m", "v_m_per_s",
        ...): the state before the first step, then one row per physics step."""
        return {column_name("t", "s"): np.concatenate(([0.0], self.times)),
                **{column_name(name, self.units[name]): np.concatenate(([self.initial[name]], values))
                   for name, values in self.quantities.items()}}

    @property
    def simulated_s(self) -> float:
        return float(self.times[-1]) if len(self.times) else 0.0


def check_run_size(profile: str, duration_s: float, seed: int, stepping: dict) -> None:
    """Refuses, before anything runs, a run larger than the bound of lab/limits.py: duration_s (s) must be finite and
    positive, duration_s / step_s at most MAX_RUN_STEPS (step_s: stepping's fixed_step_s under policy fixed, its
    max_step_s otherwise; under the fixed cut, its fixed_step_s), and the profile may hand out at most
    MAX_RUN_FRAMES frames within duration_s. Raises SteadystepError naming the value."""
    duration_s = number("duration_s", duration_s, "s")
    if not math.isfinite(duration_s):
        raise SteadystepError(Status.NOT_FINITE, f"duration_s = {duration_s} s: must be a finite number of seconds")
    if duration_s <= 0:
        raise SteadystepError(Status.OUT_OF_RANGE, f"duration_s = {duration_s} s: must be positive")
    fixed = stepping.get("cut") == lib.SS_CUT_FIXED
    step_name = "fixed_step_s" if fixed else "max_step_s"
    step_s = number(f"stepping.{step_name}", stepping.get(step_name, math.nan), "s")
    if math.isfinite(step_s) and step_s > 0 and duration_s / step_s > MAX_RUN_STEPS:
        raise SteadystepError(Status.OUT_OF_RANGE, f"duration_s = {duration_s:g} s: more than the bound of "
                              f"{MAX_RUN_STEPS} steps of {step_name} = {step_s:g} s per run")
    # A bad step length is left to the library, which names it; the frames are counted on the profile itself.
    frames = frame_count(profile, duration_s, seed, MAX_RUN_FRAMES)
    if frames > MAX_RUN_FRAMES:
        raise SteadystepError(Status.OUT_OF_RANGE,
                              f"profile = {shown(profile)}: more than the bound of {MAX_RUN_FRAMES} "
                              f"frames per run within duration_s = {duration_s:g} s")


def run(scene: str, profile: str, policy: str, duration_s: float = 5.0, seed: int = 1,
        params: dict | None = None, stepping: dict | None = None) -> RunResult:
    """Runs a scene under a profile and a policy for duration_s simulated seconds.

    params changes fields of the scene's defaults (e.g. {"spring": {"stiffness": 80}}); stepping changes fields of
    make_stepping(policy). seed is an integer in [0, 2^64). A run is bounded (lab/limits.py): duration_s / step at most
    MAX_RUN_STEPS = 1e7 steps of the longest step allowed (max_step_s, or fixed_step_s under policy fixed), and at
    most MAX_RUN_FRAMES = 1e7 frames of the profile. Raises SteadystepError naming the value for bad input or a run
    above the bound, before anything runs; a blow-up is recorded in the result instead.
    """
    scene_c = ffi.new("char[]", c_string("scene", scene))
    profile_c = ffi.new("char[]", c_string("profile", profile))
    full_params = _merge(default_params(scene), params, "params")
    full_stepping = _merge(make_stepping(policy), stepping, "stepping")
    seed = seed_value(seed)
    check_run_size(profile, duration_s, seed, full_stepping)
    duration_s = float(duration_s)
    # The C strings must stay alive for the whole call: cffi frees them with these names.
    definition = ffi.new("ssRunDef*")
    definition.scene = scene_c
    definition.profile = profile_c
    definition.params = full_params
    definition.stepping = full_stepping
    definition.seed = seed
    definition.duration_s = duration_s
    out = ffi.new("ssRun**")
    check(lib.ssRun_Execute(definition, out))
    handle = out[0]
    try:
        return _collect(handle, scene, profile, policy, seed, duration_s, full_params, full_stepping)
    finally:
        lib.ssRun_Destroy(handle)


def _copy(pointer, count: int) -> np.ndarray:
    """A copy of count doubles from C memory (the run frees it)."""
    if count == 0 or pointer == ffi.NULL:
        return np.empty(0)
    return np.frombuffer(ffi.buffer(pointer, count * ffi.sizeof("double")), dtype=np.float64).copy()


def _collect(handle, scene, profile, policy, seed, duration_s, params, stepping) -> RunResult:
    info = scene_info(scene)
    count = max(0, int(lib.ssRun_StepCount(handle)))
    quantities = {name: _copy(lib.ssRun_Quantity(handle, i), count) for i, name in enumerate(info.quantities)}
    initial = lib.ssRun_Initial(handle)
    status = int(lib.ssRun_Status(handle))
    status_name = BROKEN if lib.ssRun_Outcome(handle) == lib.SS_RUN_BROKEN else text(lib.ssStatusName(status))
    return RunResult(
        scene=scene, profile=profile, policy=policy, seed=seed, duration_s=duration_s, params=params,
        stepping=stepping, times=_copy(lib.ssRun_Times(handle), count),
        step_lengths=_copy(lib.ssRun_StepLengths(handle), count), quantities=quantities,
        units=dict(zip(info.quantities, info.units)), frame_count=int(lib.ssRun_FrameCount(handle)),
        wall_s=float(lib.ssRun_WallSeconds(handle)),
        status=status_name, message=text(lib.ssRun_Message(handle)) or "",
        initial={name: float(initial[i]) for i, name in enumerate(info.quantities)},
        bound_use=float(lib.ssRun_BoundUse(handle)), counters=_as_dict(lib.ssRun_Counters(handle)))


def reference_run(scene: str, duration_s: float = 5.0, params: dict | None = None) -> RunResult:
    """The scene at a fine fixed step (1/1000 s, the article's mapping): what the other runs are measured against."""
    return run(scene, REFERENCE_PROFILE, "implicit-euler", duration_s, seed=1, params=params, stepping=reference_stepping())


class Scene:
    """A scene driven frame by frame from Python (ssScene_Frame), for programs and for the binding benchmark."""

    def __init__(self, name: str, policy: str = "implicit-euler", params: dict | None = None,
                 stepping: dict | None = None):
        self.info = scene_info(name)
        full_params = ffi.new("ssSceneParams*", _merge(default_params(name), params, "params"))
        full_stepping = ffi.new("ssStepping*", _merge(make_stepping(policy), stepping, "stepping"))
        out = ffi.new("ssScene**")
        check(lib.ssScene_Create(c_string("scene", name), full_params, full_stepping, out))
        self._scene = ffi.gc(out[0], lib.ssScene_Destroy)
        self._steps = ffi.new("int*")
        self._sample = ffi.new("double[]", max(1, len(self.info.quantities)))

    def _handle(self):
        if self._scene is None:
            raise SteadystepError(Status.OUT_OF_RANGE, f"scene {self.info.name!r}: used after close()")
        return self._scene

    def frame(self, frame_s: float) -> int:
        """Advances one frame of frame_s seconds; returns the physics steps taken. Raises SteadystepError for a bad
        frame time (named by the library) and on a blow-up."""
        check(lib.ssScene_Frame(self._handle(), number("frame_s", frame_s, "s"), self._steps))
        return self._steps[0]

    def sample(self) -> dict[str, float]:
        """The followed quantities now, by name."""
        lib.ssScene_Sample(self._handle(), self._sample)
        return {name: self._sample[i] for i, name in enumerate(self.info.quantities)}

    @property
    def time_s(self) -> float:
        return lib.ssScene_Time(self._handle())

    @property
    def broken(self) -> str | None:
        """None while every step kept the scene within its sanity bounds (scene.h); after the first step that left
        one, its message (time, bound, body or joint, value). Stepping goes on either way: the caller decides."""
        message = lib.ssScene_Broken(self._handle())
        return None if message == ffi.NULL else text(message)

    @property
    def bound_use(self) -> float:
        """The largest value/bound ratio of the scene's sanity bounds over the steps so far (above 1: broken)."""
        return lib.ssScene_BoundUse(self._handle())

    def counters(self) -> dict[str, int]:
        """What the scene's stepper did so far (ssScene_Counters): frames, steps, the row-steps and contacts by who
        served them (rows, contacts: dicts of by_mapping, handed_to_matched, handed_to_implicit_euler), and the
        parameter sets written (row_writes)."""
        return _as_dict(lib.ssScene_Counters(self._handle()))

    def awake_bodies(self) -> int:
        """The scene's bodies that are awake now (ssScene_AwakeBodies: dBodyIsEnabled, each body its space reaches
        counted once); scenes with auto-disable (stack, wall) fall asleep at rest."""
        return int(lib.ssScene_AwakeBodies(self._handle()))

    def points(self, interpolated: bool = False) -> np.ndarray:
        """The scene's drawing now (ssScene_Points): an (n, 3) array of polyline points in m; (0, 3) when the scene
        has none (only the chain has one). interpolated: on the poses the stepper gives to draw
        (ssScene_InterpolatedPoints: under the fixed cut blended between the last two physics states)."""
        read = lib.ssScene_InterpolatedPoints if interpolated else lib.ssScene_Points
        count = read(self._handle(), ffi.NULL, 0)
        xyz = ffi.new("double[]", max(1, 3 * count))
        read(self._handle(), xyz, count)
        return np.frombuffer(ffi.buffer(xyz, 3 * count * ffi.sizeof("double")), dtype=np.float64).reshape(count, 3).copy()

    def time_frames(self, frames_s, plain: bool = False) -> float:
        """Steps the frames (s each) and returns the CPU seconds they took on this thread (ssScene_TimeFrames,
        CLOCK_THREAD_CPUTIME_ID: other work on the machine does not count): through the
        stepper, or plain (one dWorldQuickStep a frame, softness as last written; needs one frame() first). Raises
        SteadystepError named by the library (a bad frame, a plain frame before any frame(), a blow-up)."""
        frames = np.ascontiguousarray(frames_s, dtype=np.float64)
        cpu = ffi.new("double*")
        check(lib.ssScene_TimeFrames(self._handle(), ffi.cast("const double*", ffi.from_buffer(frames)),
                                     len(frames), int(bool(plain)), cpu))
        return cpu[0]

    def close(self) -> None:
        """Destroys the scene and its ODE world now rather than at garbage collection."""
        if self._scene is not None:
            ffi.release(self._scene)  # runs ssScene_Destroy now, once
            self._scene = None

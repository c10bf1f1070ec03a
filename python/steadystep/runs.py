"""Scenes, policies and runs on real ODE through scene.h, with results as numpy arrays.

A run is one scene under one frame-time profile and one stepping policy for a simulated duration; it records the
scene's followed quantities after every physics step. The reference run is the same scene at a fine fixed step
(1/1000 s, the article's mapping), against which the others are measured.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from steadystep._native import SteadystepError, check, ffi, lib, text

REFERENCE_STEP_S = 1.0 / 1000.0
REFERENCE_PROFILE = "fixed:1000"


def policy_names() -> list[str]:
    """The stepper's policies by name, in enum order: naive, spring, matched, exact, fixed."""
    names = []
    while (name := text(lib.ssPolicyName(len(names)))) is not None:
        names.append(name)
    return names


def policy_value(name: str) -> int:
    """The ssPolicy value of a policy name. Raises SteadystepError ("parse error") naming it."""
    out = ffi.new("ssPolicy*")
    check(lib.ssPolicyParse(name.encode(), out))
    return int(out[0])


@dataclass(frozen=True)
class SceneInfo:
    """A scene's name, description and followed quantities with their units."""

    name: str
    description: str
    quantities: tuple[str, ...]
    units: tuple[str, ...]


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
    info = lib.ssSceneFind(name.encode())
    if info == ffi.NULL:
        known = ", ".join(s.name for s in scenes())
        raise SteadystepError("not found", f"scene = {name!r}: unknown (known: {known})")
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
    check(lib.ssDefaultSceneParams(scene.encode(), out))
    return _as_dict(out[0])


def default_stepping() -> dict:
    """The stepper's defaults (ssStepping as a dict: policy, solver, max_step_s, ...)."""
    return _as_dict(lib.ssDefaultStepping())


def _merge(base: dict, changes: dict | None, what: str) -> dict:
    merged = dict(base)
    for key, value in (changes or {}).items():
        if key not in base:
            raise SteadystepError("out of range", f"{what}: no field {key!r} (fields: {', '.join(base)})")
        merged[key] = {**base[key], **value} if isinstance(base[key], dict) else value
    return merged


def make_stepping(policy: str, **changes) -> dict:
    """The default stepping with the named policy and any field changed (max_step_s=..., solver=...)."""
    return _merge(default_stepping(), {"policy": policy_value(policy), **changes}, "stepping")


def reference_stepping() -> dict:
    """How the reference run steps: the article's mapping at a fixed 1/1000 s, one step a frame."""
    try:
        return _as_dict(lib.ssReferenceStepping(REFERENCE_STEP_S))
    except AttributeError:  # a library built before scene.h had ssReferenceStepping
        return make_stepping("spring", max_step_s=REFERENCE_STEP_S, fixed_step_s=REFERENCE_STEP_S)


@dataclass
class RunResult:
    """One run's records (one per physics step, after the step) and its summary."""

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
    status: str                        # "ok" or the blow-up status that ended the run early
    message: str = ""
    extra: dict = field(default_factory=dict)

    @property
    def step_count(self) -> int:
        return len(self.times)

    @property
    def blew_up(self) -> bool:
        return self.status != "ok"

    @property
    def simulated_s(self) -> float:
        return float(self.times[-1]) if len(self.times) else 0.0


def run(scene: str, profile: str, policy: str, duration_s: float = 5.0, seed: int = 1,
        params: dict | None = None, stepping: dict | None = None) -> RunResult:
    """Runs a scene under a profile and a policy for duration_s simulated seconds.

    params changes fields of the scene's defaults (e.g. {"spring": {"stiffness": 80}}); stepping changes fields of
    make_stepping(policy). Raises SteadystepError for bad input; a blow-up is recorded in the result instead.
    """
    full_params = _merge(default_params(scene), params, "params")
    full_stepping = _merge(make_stepping(policy), stepping, "stepping")
    if not isinstance(duration_s, (int, float)) or not math.isfinite(duration_s):
        raise SteadystepError("not finite", f"duration_s = {duration_s}: must be a finite number of seconds")
    # The C strings must stay alive for the whole call: cffi frees them with these names.
    scene_c = ffi.new("char[]", scene.encode())
    profile_c = ffi.new("char[]", profile.encode())
    definition = ffi.new("ssRunDef*")
    definition.scene = scene_c
    definition.profile = profile_c
    definition.params = full_params
    definition.stepping = full_stepping
    definition.seed = int(seed)
    definition.duration_s = float(duration_s)
    out = ffi.new("ssRun**")
    check(lib.ssRun_Execute(definition, out))
    handle = out[0]
    try:
        return _collect(handle, scene, profile, policy, int(seed), float(duration_s), full_params, full_stepping)
    finally:
        lib.ssRun_Destroy(handle)


def _copy(pointer, count: int) -> np.ndarray:
    """A copy of count doubles from C memory (the run frees it)."""
    if count == 0 or pointer == ffi.NULL:
        return np.empty(0)
    return np.frombuffer(ffi.buffer(pointer, count * ffi.sizeof("double")), dtype=np.float64).copy()


def _collect(handle, scene, profile, policy, seed, duration_s, params, stepping) -> RunResult:
    info = scene_info(scene)
    count = lib.ssRun_StepCount(handle)
    quantities = {name: _copy(lib.ssRun_Quantity(handle, i), count) for i, name in enumerate(info.quantities)}
    status = int(lib.ssRun_Status(handle))
    return RunResult(
        scene=scene, profile=profile, policy=policy, seed=seed, duration_s=duration_s, params=params,
        stepping=stepping, times=_copy(lib.ssRun_Times(handle), count),
        step_lengths=_copy(lib.ssRun_StepLengths(handle), count), quantities=quantities,
        units=dict(zip(info.quantities, info.units)), frame_count=int(lib.ssRun_FrameCount(handle)),
        wall_s=float(lib.ssRun_WallSeconds(handle)),
        status=text(lib.ssStatusName(status)), message=text(lib.ssRun_Message(handle)) or "")


def reference_run(scene: str, duration_s: float = 5.0, params: dict | None = None) -> RunResult:
    """The scene at a fine fixed step (1/1000 s, the article's mapping): what the other runs are measured against."""
    return run(scene, REFERENCE_PROFILE, "spring", duration_s, seed=1, params=params, stepping=reference_stepping())


class Scene:
    """A scene driven frame by frame from Python (ssScene_Frame), for programs and for the binding benchmark."""

    def __init__(self, name: str, policy: str = "spring", params: dict | None = None,
                 stepping: dict | None = None):
        self.info = scene_info(name)
        full_params = ffi.new("ssSceneParams*", _merge(default_params(name), params, "params"))
        full_stepping = ffi.new("ssStepping*", _merge(make_stepping(policy), stepping, "stepping"))
        out = ffi.new("ssScene**")
        check(lib.ssScene_Create(name.encode(), full_params, full_stepping, out))
        self._scene = ffi.gc(out[0], lib.ssScene_Destroy)
        self._steps = ffi.new("int*")
        self._sample = ffi.new("double[]", max(1, len(self.info.quantities)))

    def frame(self, frame_s: float) -> int:
        """Advances one frame of frame_s seconds; returns the physics steps taken. Raises on a blow-up."""
        check(lib.ssScene_Frame(self._scene, frame_s, self._steps))
        return self._steps[0]

    def sample(self) -> dict[str, float]:
        """The followed quantities now, by name."""
        lib.ssScene_Sample(self._scene, self._sample)
        return {name: self._sample[i] for i, name in enumerate(self.info.quantities)}

    @property
    def time_s(self) -> float:
        return lib.ssScene_Time(self._scene)

    def close(self) -> None:
        """Destroys the scene and its ODE world now rather than at garbage collection."""
        if self._scene is not None:
            ffi.release(self._scene)  # runs ssScene_Destroy now, once
            self._scene = None

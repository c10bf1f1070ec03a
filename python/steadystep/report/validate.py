"""The comparison's inputs checked before anything runs or is written: scenes, profiles, policies, duration, grid
and scene parameters, each refused by name."""

from __future__ import annotations

import math

from steadystep.lab import runs, study
from steadystep.core._native import SteadystepError, number
from steadystep.core.enums import Status
from steadystep.lab.limits import MIN_MEASURED_DURATION_S
from steadystep.lab.profiles import Profile

# The pile is there for timing; the report keeps it small so that the whole report takes a few minutes.
REPORT_PARAMS = {"pile": {"body_count": 150}}
GRID_AXES = {"stiffness": "N/m", "damping": "N·s/m", "max_step_s": "s"}  # what a study may sweep, with units
GRID_CSV_COLUMNS = {"stiffness": "stiffness_N_per_m", "damping": "damping_N_s_per_m", "max_step_s": "max_step_s"}


def policies_for(scene: str, policies) -> list[str]:
    """The policies a scene runs: the given ones, or every policy the library names (runs.policy_names())."""
    if policies:
        return list(policies)
    return runs.policy_names()


def grid_points(grid: dict | None) -> tuple[list[dict], list[dict]]:
    """The spring points (stiffness x damping) and step points (max_step_s) of a grid, each [{}] when not swept."""
    grid = grid or {}
    unknown = set(grid) - set(GRID_AXES)
    if unknown:
        raise SteadystepError(Status.OUT_OF_RANGE, f"grid: no axis {sorted(unknown)[0]!r} (axes: {', '.join(GRID_AXES)})")
    springs = study.grid(**{axis: grid[axis] for axis in ("stiffness", "damping") if axis in grid})
    steps = study.grid(**{axis: grid[axis] for axis in ("max_step_s",) if axis in grid})
    return springs, steps


def with_spring(scene_params: dict | None, point: dict) -> dict | None:
    """A scene's parameters with a spring point's stiffness and damping (None: the scene's defaults)."""
    if not point:
        return scene_params
    merged = dict(scene_params or {})
    merged["spring"] = {**merged.get("spring", {}), **point}
    return merged


def validate(scenes, profiles, policies, duration_s: float = 5.0, seed: int = 1, grid: dict | None = None,
             params: dict | None = None) -> list[str]:
    """Checks every name, spec and number before anything runs or is written; returns the scenes (default: all).

    duration_s (s) is at least MIN_MEASURED_DURATION_S (0.1 s), and every run within the bound of lab/limits.py (the
    reference's 1 ms steps: at most 1000 s). grid: a list of values per axis of GRID_AXES (stiffness N/m, damping
    N·s/m, max_step_s s), each non-empty; every spring is checked on each scene by the library. Raises
    SteadystepError naming the value."""
    scenes = list(scenes) if scenes else [info.name for info in runs.scenes()]
    for scene in scenes:
        runs.scene_info(scene)
    profiles = list(profiles)
    if not profiles:
        raise SteadystepError(Status.OUT_OF_RANGE, "profiles = []: name at least one frame-time profile")
    for profile in profiles:
        Profile(profile, seed)
    for policy in policies or ():
        runs.make_stepping(policy)
    duration_s = number("duration_s", duration_s, "s")
    if not duration_s >= MIN_MEASURED_DURATION_S or not math.isfinite(duration_s):
        raise SteadystepError(Status.OUT_OF_RANGE, f"duration_s = {duration_s:g} s: must be finite and at least "
                              f"{MIN_MEASURED_DURATION_S:g} s to be measured")
    for axis, values in (grid or {}).items():
        if axis in GRID_AXES and not isinstance(values, (list, tuple)):
            raise SteadystepError(Status.OUT_OF_RANGE, f"grid.{axis} = {values!r}: must be a list of values")
        if axis in GRID_AXES and not values:
            raise SteadystepError(Status.OUT_OF_RANGE, f"grid.{axis} = []: give at least one value or leave it out")
        for value in values if axis in GRID_AXES else ():
            number(f"grid.{axis}", value, GRID_AXES[axis])
    springs, steps = grid_points(grid)
    params = REPORT_PARAMS if params is None else params
    for scene in scenes:
        for point in springs if springs != [{}] else ():
            runs.Scene(scene, params=with_spring(params.get(scene), point)).close()  # the library checks it
    runs.check_run_size(runs.REFERENCE_PROFILE, duration_s, 1, runs.reference_stepping())
    for policy in sorted({p for scene in scenes for p in policies_for(scene, policies)}):
        for step in steps:
            stepping = runs.make_stepping(policy, **step)
            for profile in profiles:
                runs.check_run_size(profile, duration_s, seed, stepping)
    return scenes

"""Frame-time profiles from profile.h: the sequences of frame durations (s) a renderer produces.

Specs: fixed:FPS, uniform:MINFPS:MAXFPS, jitter:FPS:SPREAD_MS, hitch:FPS:EVERY:SECONDS, vsync:FPS_A:FPS_B,
trace:FILE. Every random kind is seeded and reproducible.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from typing import TYPE_CHECKING

from steadystep.core._native import SteadystepError, c_string, check, ffi, integer, lib, number, shown
from steadystep.core.enums import Status
from steadystep.lab.limits import MAX_RUN_FRAMES

if TYPE_CHECKING:  # numpy is imported where an array is made, not by `import steadystep`
    import numpy as np

DEFAULT_PROFILES = ("fixed:30", "uniform:15:45", "jitter:30:3", "hitch:60:30:0.1", "vsync:60:30")
SEED_RANGE = (0, 2**64 - 1)


def seed_value(seed) -> int:
    """A profile seed as the C library takes it: an integer in [0, 2^64). SteadystepError naming it otherwise."""
    return integer("seed", seed, *SEED_RANGE)


class Profile:
    """A frame-time profile made by the C library. Raises SteadystepError for a bad spec or trace file."""

    def __init__(self, spec: str, seed: int = 1):
        raw_spec = c_string("profile", spec)
        seed = seed_value(seed)
        out = ffi.new("ssProfile**")
        check(lib.ssProfile_Create(raw_spec, seed, out))
        self._profile = ffi.gc(out[0], lib.ssProfile_Destroy)
        self.spec = spec
        self.seed = seed

    def next(self) -> float:
        """The next frame duration (s)."""
        return lib.ssProfile_Next(self._profile)

    def frames(self, count: int) -> np.ndarray:
        """The next `count` frame durations (s); count in [0, MAX_RUN_FRAMES] (lab/limits.py)."""
        count = integer("count", count, 0, MAX_RUN_FRAMES)
        import numpy as np

        return np.array([lib.ssProfile_Next(self._profile) for _ in range(count)], dtype=float)

    def reset(self) -> None:
        """Restarts the sequence from its seed."""
        lib.ssProfile_Reset(self._profile)


def frame_times(spec: str, count: int, seed: int = 1) -> np.ndarray:
    """`count` frame durations (s) of a profile from its start; count in [0, MAX_RUN_FRAMES] (lab/limits.py)."""
    count = integer("count", count, 0, MAX_RUN_FRAMES)
    return Profile(spec, seed).frames(count)


def frames_within(spec: str, duration_s: float, seed: int = 1) -> Iterator[float]:
    """The frame durations (s) the profile hands out within duration_s (s), as a run plays them: the last one
    shortened to end at duration_s, a rounding remainder of at most 1e-9 of the duration not one more frame (as
    run.c). Raises SteadystepError for a bad spec, and naming the frame when the profile hands out one that is not a
    finite positive duration."""
    duration_s = number("duration_s", duration_s, "s")
    profile = Profile(spec, seed)
    end_tolerance_s = 1e-9 * max(1.0, duration_s)
    elapsed_s, count = 0.0, 0
    next_frame, handle = lib.ssProfile_Next, profile._profile  # looked up once: a run may have 10^7 frames
    while duration_s - elapsed_s > end_tolerance_s:
        frame_s = next_frame(handle)
        if not (math.isfinite(frame_s) and frame_s > 0):
            raise SteadystepError(Status.OUT_OF_RANGE,
                                  f"profile = {shown(spec)}: frame {count + 1} lasts {frame_s!r} s, "
                                  "not a finite positive duration")
        frame_s = min(frame_s, duration_s - elapsed_s)
        elapsed_s += frame_s
        count += 1
        yield frame_s


def frame_count(spec: str, duration_s: float, seed: int = 1, limit: int = MAX_RUN_FRAMES) -> int:
    """How many frames frames_within hands out, counted up to limit + 1 (a profile may hand out more than a run may
    take). Raises as frames_within."""
    count = 0
    for _ in frames_within(spec, duration_s, seed):
        count += 1
        if count > limit:
            break
    return count

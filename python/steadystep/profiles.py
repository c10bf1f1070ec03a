"""Frame-time profiles from profile.h: the sequences of frame durations (s) a renderer produces.

Specs: fixed:FPS, uniform:MINFPS:MAXFPS, jitter:FPS:SPREAD_MS, hitch:FPS:EVERY:SECONDS, vsync:FPS_A:FPS_B,
trace:FILE. Every random kind is seeded and reproducible.
"""

from __future__ import annotations

import numpy as np

from steadystep._native import check, ffi, lib

DEFAULT_PROFILES = ("fixed:30", "uniform:15:45", "jitter:30:3", "hitch:60:30:0.1", "vsync:60:30")


class Profile:
    """A frame-time profile made by the C library. Raises SteadystepError for a bad spec or trace file."""

    def __init__(self, spec: str, seed: int = 1):
        out = ffi.new("ssProfile**")
        check(lib.ssProfile_Create(spec.encode(), int(seed), out))
        self._profile = ffi.gc(out[0], lib.ssProfile_Destroy)
        self.spec = spec
        self.seed = int(seed)

    def next(self) -> float:
        """The next frame duration (s)."""
        return lib.ssProfile_Next(self._profile)

    def frames(self, count: int) -> np.ndarray:
        """The next `count` frame durations (s)."""
        return np.array([lib.ssProfile_Next(self._profile) for _ in range(int(count))])

    def reset(self) -> None:
        """Restarts the sequence from its seed."""
        lib.ssProfile_Reset(self._profile)


def frame_times(spec: str, count: int, seed: int = 1) -> np.ndarray:
    """`count` frame durations (s) of a profile from its start."""
    return Profile(spec, seed).frames(count)

"""Frame-rate consistency: how much a policy's motion differs between frame-time profiles, whatever the reference.

The deviation (metrics.rms_deviation) measures a run against the fine-step reference: accuracy. A policy can be far
from the reference and still give the same motion at every frame rate (a fixed step does, by construction), or
the other way round. Consistency compares the runs of one policy with each other: every run's quantity is
interpolated on the reference's times, the mean over the profiles is taken at each time, and the consistency is
the RMS over profiles and times of each run minus that mean, divided by the reference's amplitude (max - min).
0: the same motion under every profile; inf: a run blew up or broke.
"""

from __future__ import annotations

import math

import numpy as np


def consistency(runs_by_profile: dict, reference, quantity: str) -> float:
    """runs_by_profile: {profile: RunResult} of one scene and policy; reference: the scene's reference RunResult.
    Returns the RMS over profiles and the reference's times (within every run's span) of the run minus the mean
    over profiles, relative to the reference's amplitude. inf when a run is not "ok" or holds a non-finite value;
    nan with fewer than two profiles."""
    results = list(runs_by_profile.values())
    if len(results) < 2:
        return math.nan
    if any(r.status != "ok" or r.step_count == 0 or not np.all(np.isfinite(r.quantities[quantity]))
           for r in results):
        return math.inf
    t = reference.times
    end = min(float(r.times[-1]) for r in results)
    start = max(float(r.times[0]) for r in results)
    t = t[(t >= start) & (t <= end)]
    if len(t) == 0:
        return math.nan
    curves = np.array([np.interp(t, r.times, r.quantities[quantity]) for r in results])
    values = reference.quantities[quantity]
    amplitude = float(np.max(values) - np.min(values))
    rms = float(np.sqrt(np.mean((curves - curves.mean(axis=0)) ** 2)))
    if amplitude == 0.0:
        return 0.0 if rms == 0.0 else math.inf
    return rms / amplitude

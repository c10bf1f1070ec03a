"""The audit's numbers from its runs (docs/audit.md, "What it measures"): how runs are compared, the reference's
checks (where it holds, whether its check was finer, whether it is physical), the scale of each quantity, which
quantities decide, spread and deviation with their noise, and the cost.

Plain functions of Run columns (run.Run); no process is started here.
"""

from __future__ import annotations

import math
import re

import numpy as np

from steadystep.audit.run import STEP_COLUMN, TIME_COLUMN

# The reference holds until the reference and its check part: their RMS difference over a centred window of
# REFERENCE_WINDOW_S (a fifth of the run, if shorter) exceeds REFERENCE_TOLERANCE of a quantity's scale. After the
# first parting nothing counts as held (two chaotic runs that meet again by chance do not hold).
REFERENCE_TOLERANCE = 0.05
REFERENCE_WINDOW_S = 1.0
# A reference that holds for less than this fraction of the run leaves too little for a claim on deviation.
MIN_WINDOW_FRACTION = 0.2
# The check must take steps at most this fraction of the reference's to check it (it is meant to take a quarter).
FINER = 0.75
# The reference is unphysical when, for a quantity, it changes more than SANITY_RATE times as fast as in any run at
# the audited frame rates and reaches beyond every such run's range by more than that range.
SANITY_RATE = 3.0
# Two runs are compared at the simulated times they share when they share at least this fraction of the rows of the
# one with fewer; otherwise the run is interpolated linearly onto the first's times.
SHARED_FRACTION = 0.5
# A quantity whose scale is below this fraction of the largest scale among the quantities of the same unit is
# error-like (a contact depth beside heights, a joint gap beside positions): it is measured and shown, but it does
# not decide a claim alone.
TINY_RANGE = 0.05
# Noise: a difference between two values counts when it exceeds NOISE_SIGMAS standard errors (from the spread over
# runs) of the two, plus twice the repeat's difference (and, for deviation, the reference's own uncertainty).
NOISE_SIGMAS = 2.0
# Instruction counts (valgrind) this close, relative, are not told apart: a count is not a time (caches, branches).
COUNT_RESOLUTION = 0.02

# Units a column name may end with, longest first (docs/audit.md: <quantity>_<unit>).
_UNITS = ("m_per_s2", "rad_per_s2", "m_per_s", "rad_per_s", "N_m", "N_s", "kg_m2", "m", "rad", "deg", "N", "J", "W",
          "kg", "s", "Pa", "Hz", "count")


def unit_of(quantity: str) -> str:
    """The unit a column's name ends with (a known unit, else its last part after '_')."""
    for unit in _UNITS:
        if quantity.endswith("_" + unit):
            return unit
    return quantity.rsplit("_", 1)[-1]


def by_time(run_columns: dict) -> tuple[np.ndarray, dict]:
    """The run's distinct times and, at each, its last row's values (a frame that took no step repeats a time)."""
    t = run_columns[TIME_COLUMN]
    keep = np.ones(len(t), bool)
    keep[:-1] = t[1:] != t[:-1]
    return t[keep], {name: values[keep] for name, values in run_columns.items()}


def compared(run_columns: dict, base_columns: dict, quantity: str, holds=None) -> tuple[float, str, int]:
    """(RMS of run - base over the comparison's times, how they were compared, times compared). At the simulated
    times the two share exactly, when they share at least SHARED_FRACTION of the rows of the one with fewer (two
    runs identical at every shared time give exactly 0); else the run interpolated linearly onto base's times.
    holds(t): the times that count (None: all)."""
    t_run, run = by_time(run_columns)
    t_base, base = by_time(base_columns)
    shared, in_run, in_base = np.intersect1d(t_run, t_base, assume_unique=True, return_indices=True)
    if len(shared) >= max(2, SHARED_FRACTION * min(len(t_run), len(t_base))):
        t, a, b, how = shared, run[quantity][in_run], base[quantity][in_base], "shared"
    else:
        t, a, b, how = t_base, np.interp(t_base, t_run, run[quantity]), base[quantity], "interpolated"
    if holds is not None:
        inside = holds(t)
        t, a, b = t[inside], a[inside], b[inside]
    if len(t) == 0:
        return math.nan, how, 0
    return float(np.sqrt(np.mean((a - b) ** 2))), how, len(t)


def against_reference(run_columns: dict, reference_columns: dict, quantity: str, holds=None) -> tuple[float, int]:
    """(RMS over the run's own times (those holds(t) keeps) of the run minus the reference interpolated there,
    times compared): the fine reference, not the coarse run, is interpolated."""
    t_run, run = by_time(run_columns)
    t_ref, reference = by_time(reference_columns)
    inside = np.ones(len(t_run), bool) if holds is None else holds(t_run)
    if not np.any(inside):
        return math.nan, 0
    truth = np.interp(t_run[inside], t_ref, reference[quantity])
    return float(np.sqrt(np.mean((run[quantity][inside] - truth) ** 2))), int(np.sum(inside))


def step_length(run_columns: dict) -> tuple[float | None, float]:
    """(The run's mean physics step (s): its simulated time over the steps it took, None without a steps column;
    the fraction of its frames that took no step)."""
    t = run_columns[TIME_COLUMN]
    steps = run_columns.get(STEP_COLUMN)
    if steps is None or len(t) < 2:
        return None, 0.0
    total = float(np.sum(steps))
    idle = float(np.mean(steps[1:] == 0))
    return (float(t[-1] - t[0]) / total if total > 0 else None), idle


def check_reference(reference: dict, check: dict, quantities: list[str], scales: dict, duration_s: float,
                    deciding_quantities: list[str] | None = None) -> dict:
    """Where the reference holds, and whether its check could check it. On the reference's distinct times, the check
    (interpolated) minus the reference, per quantity over its scale, as an RMS over a centred moving window; the
    reference holds until the first time any deciding quantity's (deciding(): an error-like quantity does not end
    it alone) exceeds REFERENCE_TOLERANCE, and never again after. The
    check is finer when its mean step (from the steps column) is at most FINER of the reference's; without a steps
    column, a check identical to the reference at every shared time took the same steps."""
    t, ref = by_time(reference)
    width_s = min(REFERENCE_WINDOW_S, duration_s / 5)
    spacing = float(np.median(np.diff(t))) if len(t) > 1 else duration_s
    half = max(1, int(round(width_s / 2 / spacing))) if spacing > 0 else 1
    index = np.arange(len(t))
    lo, hi = np.clip(index - half, 0, len(t)), np.clip(index + half + 1, 0, len(t))
    moving, largest, parted_by = {}, {}, []
    parted_index = len(t)
    t_check, chk = by_time(check)
    for q in quantities:
        d = (np.interp(t, t_check, chk[q]) - ref[q]) / scales[q]
        squares = np.concatenate(([0.0], np.cumsum(d ** 2)))
        moving[q] = np.sqrt(np.maximum(squares[hi] - squares[lo], 0.0) / (hi - lo))
        largest[q] = float(np.max(moving[q])) if len(t) else 0.0
        over = np.flatnonzero(moving[q] > REFERENCE_TOLERANCE)
        if len(over) and (deciding_quantities is None or q in deciding_quantities):
            parted_by.append(q)
            parted_index = min(parted_index, int(over[0]))
    parted_at = float(t[parted_index]) if parted_index < len(t) else None
    held_s = (parted_at - float(t[0])) if parted_at is not None else duration_s
    holds = np.arange(len(t)) < parted_index
    uncertainty = {q: (float(np.sqrt(np.mean(((np.interp(t[holds], t_check, chk[q]) - ref[q][holds])
                                              / scales[q]) ** 2))) if np.any(holds) else math.nan)
                   for q in quantities}
    reference_step_s, _ = step_length(reference)
    check_step_s, check_idle = step_length(check)
    same_steps = False
    if reference_step_s is not None and check_step_s is not None:
        finer = check_step_s <= FINER * reference_step_s
    else:  # no steps column: identical values at every shared time mean the same steps
        shared = np.intersect1d(t, t_check)
        identical = len(shared) >= 10 and all(
            np.array_equal(ref[q][np.searchsorted(t, shared)], chk[q][np.searchsorted(t_check, shared)])
            for q in quantities)
        finer, same_steps = not identical, identical
    floor_s = check_step_s if (not finer and check_idle > 0) else None
    return {"tolerance": REFERENCE_TOLERANCE, "window_s": 2 * half * spacing, "parted_at": parted_at,
            "parted_by": [q for q in quantities if q in parted_by], "held_s": held_s,
            "holds_whole_run": parted_at is None, "largest_moving_difference": largest,
            "difference_in_window": uncertainty, "reference_step_s": reference_step_s, "check_step_s": check_step_s,
            "check_idle_frames": check_idle, "check_finer": bool(finer), "identical_to_check": same_steps,
            "clock_floor_s": floor_s, "_t": t, "_moving": moving}


def holds_at(checked: dict):
    """A function of times (s): True before the reference and its check part (every time if they never do)."""
    parted_at = checked["parted_at"]
    if parted_at is None:
        return lambda times: np.ones(len(times), bool)
    return lambda times: np.asarray(times) < parted_at


def _rate(columns: dict, quantity: str) -> np.ndarray:
    t, values = by_time(columns)
    if len(t) < 2:
        return np.zeros(1)
    return np.abs(np.diff(values[quantity]) / np.diff(t))


def reference_sanity(reference: dict, runs: list[dict], quantities: list[str]) -> dict:
    """Whether the fine-step reference is physical, against the runs at the audited frame rates (every variant's):
    for each quantity, its largest rate of change (|dq/dt| between rows) and its range in the reference and in
    those runs. Unphysical when, for some quantity, the reference changes more than SANITY_RATE times as fast as
    any run does (a speed or energy jump) and reaches beyond the runs' joint range by more than that range (it goes
    where no run goes). Returns {"sane": bool, "unphysical": [{quantity, rate, runs_rate, at_s, reached, low,
    high}]}."""
    found = []
    if not runs:  # nothing to hold it against
        return {"sane": True, "unphysical": found}
    t_ref, ref = by_time(reference)
    for q in quantities:
        runs_rate = max((float(np.max(_rate(r, q))) for r in runs), default=0.0)
        low = min((float(np.min(r[q])) for r in runs), default=0.0)
        high = max((float(np.max(r[q])) for r in runs), default=0.0)
        rate = _rate(reference, q)
        width = high - low
        beyond = max(float(np.max(ref[q])) - high, low - float(np.min(ref[q])))
        if len(rate) and float(np.max(rate)) > SANITY_RATE * runs_rate and beyond > max(width, 0.0) and width >= 0:
            fast = np.flatnonzero(rate > SANITY_RATE * runs_rate)
            reached = float(np.max(ref[q])) if float(np.max(ref[q])) - high >= low - float(np.min(ref[q])) \
                else float(np.min(ref[q]))
            found.append({"quantity": q, "rate": float(np.max(rate)), "runs_rate": runs_rate,
                          "at_s": float(t_ref[fast[0]]), "reached": reached, "low": low, "high": high})
    return {"sane": not found, "unphysical": found}


def scales_of(runs: list[dict], quantities: list[str]) -> dict:
    """Each quantity's scale: the range (max - min) it covers over all the runs given together; a quantity held
    constant: its largest magnitude, or 1 (its own unit) when that is 0 too."""
    out = {}
    for q in quantities:
        values = np.concatenate([np.asarray(r[q], dtype=float) for r in runs])
        values = values[np.isfinite(values)]
        span = float(np.ptp(values)) if len(values) else 0.0
        out[q] = span if span > 0 else ((float(np.max(np.abs(values))) if len(values) else 0.0) or 1.0)
    return out


def deciding(quantities: list[str], scales: dict) -> list[str]:
    """The quantities that decide claims: all but the error-like ones (scale below TINY_RANGE of the largest scale of
    the same unit); all of them when every one is error-like."""
    kept = []
    for q in quantities:
        alike = [scales[o] for o in quantities if unit_of(o) == unit_of(q)]
        if scales[q] >= TINY_RANGE * max(alike):
            kept.append(q)
    return kept or list(quantities)


def rms_and_error(values: list[float]) -> tuple[float, float]:
    """(sqrt(mean of the squares), its standard error over the values: sd(values) / sqrt(count), 0 for one)."""
    values = [v for v in values if not math.isnan(v)]
    if not values:
        return math.nan, 0.0
    if any(math.isinf(v) for v in values):
        return math.inf, 0.0
    rms = math.sqrt(sum(v * v for v in values) / len(values))
    error = float(np.std(values, ddof=1)) / math.sqrt(len(values)) if len(values) > 1 else 0.0
    return rms, error


def noise(error_a: float, error_b: float, repeat: float, extra: float = 0.0) -> float:
    """The noise of a difference between two measured values (docs/audit.md): NOISE_SIGMAS combined standard errors,
    twice the repeat's difference, and extra (the reference's uncertainty, for deviation)."""
    return NOISE_SIGMAS * math.hypot(error_a, error_b) + 2.0 * repeat + extra


def sanitize_name(text: str) -> str:
    """A file-name-safe rendering of a profile or variant."""
    return re.sub(r"[^A-Za-z0-9.+-]+", "_", text)[:60]

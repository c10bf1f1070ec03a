"""The comparison as data: metrics.json (strict JSON) and metrics.csv, their schema in docs/metrics.md."""

from __future__ import annotations

import csv
import dataclasses
import io
import json
import math

import numpy as np
from pathlib import Path

from steadystep.lab import runs
from steadystep.report.model import Report
from steadystep.report.validate import GRID_AXES, GRID_CSV_COLUMNS

CSV_COLUMNS = ("scene", "profile", "policy", "quantity", "deviation_per_amplitude", "quantity_unit",
               "rms_vs_exact_per_x0", "steps_per_frame", "steps_per_s", "rows_by_mapping",
               "rows_handed_to_matched", "rows_handed_to_implicit_euler", "contacts_by_mapping",
               "contacts_handed_to_matched", "contacts_handed_to_implicit_euler", "status")
SERVED_COLUMNS = ("by_mapping", "handed_to_matched", "handed_to_implicit_euler")


def as_json_text(report: Report, command: str) -> str:
    """metrics.json's text: every float that is not finite as null."""
    return json.dumps(strict_json(as_json(report, command)), indent=1, default=_json_default, allow_nan=False)


def _json_default(value):
    if isinstance(value, Path):
        return value.name
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(type(value))


def strict_json(value):
    """value with every float that is not finite (a blow-up's inf, a rate with no frames) as None, and numpy's
    numbers as Python's: metrics.json and the audit's JSON are strict JSON, which has no NaN or Infinity (null: failed
    or none)."""
    if isinstance(value, dict):
        return {key: strict_json(item) for key, item in value.items()}
    if isinstance(value, (list, tuple)):
        return [strict_json(item) for item in value]
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else None
    if isinstance(value, (np.integer, np.bool_)):
        return value.item()
    return value


def as_json(report: Report, command: str) -> dict:
    """metrics.json; its schema is docs/metrics.md."""
    return {
        "command": command, "duration_s": report.duration_s, "seed": report.seed, "profiles": report.profiles,
        "policies": report.policies, "params": report.params, "elapsed_s": report.elapsed_s,
        "phases_s": report.phases_s, "machine": report.machine,
        "rows": [{"scene": r.scene, "profile": r.profile, "policy": r.policy, "status": r.status,
                  "deviation": dict(r.deviations),
                  "steps_per_frame": r.steps_per_frame, "steps_per_second": r.steps_per_second,
                  "rms_vs_exact": r.rms_vs_exact, "rows_served": r.rows_served, "contacts_served": r.contacts_served,
                  "rows_handed_to_implicit_euler": r.rows_handed_to_implicit_euler,
                  "contacts_handed_to_implicit_euler": r.contacts_handed_to_implicit_euler,
                  **({"grid": r.grid} if r.grid else {})}
                 for r in report.rows],
        "spread": report.spreads,
        "consistency": report.consistency,
        "repeat": {"profiles": report.repeat_profiles, "seed": report.seed + 1,
                   "deviation": report.repeat_deviation, "consistency": report.repeat_consistency},
        "served": report.served,
        "oscillator_side_by_side": report.side_by_side,
        "largest_stable_step": {s: [{"policy": r.policy, "stable_s": r.stable_s,
                                     "unstable_s": r.unstable_s, "reason": r.reason,
                                     **({"grid": r.grid} if r.grid else {})}
                                    for r in results] for s, results in report.probes.items()},
        "not_probed": report.not_probed,
        "cost": {"wall_s": report.cost_wall_s,
                 "runs": [dataclasses.asdict(c) for c in report.costs]},
    }


def swept_axes(report: Report) -> list[str]:
    """The grid axes the report's rows carry, in GRID_AXES's order."""
    return [axis for axis in GRID_AXES if any(axis in r.grid for r in report.rows)]


def as_csv(report: Report) -> str:
    """metrics.csv: one line per run and motion quantity; columns CSV_COLUMNS (a study's grid columns after
    policy), documented in docs/metrics.md."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    swept = swept_axes(report)
    writer.writerow([*CSV_COLUMNS[:3], *(GRID_CSV_COLUMNS[a] for a in swept), *CSV_COLUMNS[3:]])
    for r in report.rows:
        units = dict(zip(runs.scene_info(r.scene).quantities, runs.scene_info(r.scene).units))
        for q, v in r.deviations.items():
            exact = "" if r.rms_vs_exact is None else f"{r.rms_vs_exact:.6g}"
            writer.writerow([r.scene, r.profile, r.policy, *(f"{r.grid[a]!r}" for a in swept), q, f"{v:.6g}",
                             units.get(q, ""), exact, f"{r.steps_per_frame:.6g}", f"{r.steps_per_second:.6g}",
                             *(r.rows_served.get(k, 0) for k in SERVED_COLUMNS),
                             *(r.contacts_served.get(k, 0) for k in SERVED_COLUMNS), r.status])
    return buffer.getvalue()

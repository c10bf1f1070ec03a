"""The comparison's results as plain data: one Row per run, and the Report that the aggregation fills and the
exports (export.py, html.py) read."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from steadystep.lab import cost, probe


@dataclass
class Row:
    """One run's line in the table."""

    scene: str
    profile: str
    policy: str
    deviations: dict[str, float]     # per motion quantity: RMS deviation from the reference / its amplitude
    steps_per_frame: float
    steps_per_second: float
    wall_us_per_step: float
    status: str
    rms_vs_exact: float | None = None
    # Who served the run's row-steps and softened contacts (ssRun_Counters, ssServedCounts): by_mapping,
    # handed_to_matched, handed_to_implicit_euler.
    rows_served: dict[str, int] = field(default_factory=dict)
    contacts_served: dict[str, int] = field(default_factory=dict)
    grid: dict[str, float] = field(default_factory=dict)  # the swept values of this row (GRID_AXES), {} if none

    @property
    def rows_handed_to_implicit_euler(self) -> int:
        return self.rows_served.get("handed_to_implicit_euler", 0)

    @property
    def contacts_handed_to_implicit_euler(self) -> int:
        return self.contacts_served.get("handed_to_implicit_euler", 0)


@dataclass
class Report:
    scenes: list[str]
    profiles: list[str]
    policies: dict[str, list[str]]
    duration_s: float
    seed: int
    rows: list[Row] = field(default_factory=list)
    spreads: dict[str, dict[str, dict[str, float]]] = field(default_factory=dict)  # scene -> policy -> quantity
    side_by_side: list[dict] = field(default_factory=list)
    probes: dict[str, list[probe.ProbeResult]] = field(default_factory=dict)  # scene -> one per policy (grid point)
    params: dict[str, dict] = field(default_factory=dict)
    figures: dict[str, list[Path]] = field(default_factory=dict)
    elapsed_s: float = 0.0
    consistency: dict[str, dict[str, dict[str, float]]] = field(default_factory=dict)  # scene -> policy -> quantity
    costs: list[cost.Cost] = field(default_factory=list)   # one per scene and policy, from one benchmark run
    cost_wall_s: float = 0.0                                # the benchmark's wall time (s)
    animation: dict | None = None                           # animation.record(): the chain to watch
    # The measured spread of repeats (aggregate.repeat_spreads): scene -> policy -> quantity -> how much the
    # deviation and the consistency moved when the random profiles were run again with the next seed.
    repeat_deviation: dict[str, dict[str, dict[str, float]]] = field(default_factory=dict)
    repeat_consistency: dict[str, dict[str, dict[str, float]]] = field(default_factory=dict)
    repeat_profiles: list[str] = field(default_factory=list)  # the profiles run again (those a seed changes)
    # scene -> policy -> {"rows": {...}, "contacts": {...}}: ssServedCounts summed over the scene's runs.
    served: dict[str, dict[str, dict[str, dict[str, int]]]] = field(default_factory=dict)
    not_probed: list[str] = field(default_factory=list)       # scenes the report does not probe (why: NOT_PROBED)
    phases_s: dict[str, float] = field(default_factory=dict)  # wall time of each phase of compare (s)
    # What the timings ran on (tasks.machine_state): cores, the cores this process may use, and the 1-minute
    # load average when compare started and before and after the cost benchmark.
    machine: dict[str, float | None] = field(default_factory=dict)

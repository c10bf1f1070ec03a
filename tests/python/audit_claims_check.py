"""An independent reader of an audit's metrics.json: checks every claim of its recommendation against the tables of
the same file, with none of steadystep's code (plain json and math). Used by test_audit*.py."""

from __future__ import annotations

import math

import pytest

KNOWN_KINDS = {"reference", "failed", "least_spread", "least_deviation", "cheapest", "recommend", "served"}
TIE = 1e-9  # docs/audit.md: values this close are the same numbers; the first in the order of variants wins


def _value(x):
    return math.inf if x is None else x  # null in a table: a failed variant


def _worst(metrics: dict, table: str, variant: str) -> float:
    return max(_value(metrics[table]["window"][variant][q]) for q in metrics["quantities"])


def _check_best(metrics: dict, claim: dict, values: dict) -> None:
    order = metrics["variants"]
    finite = {v: x for v, x in values.items() if math.isfinite(x)}
    lowest = min(finite.values())
    tied = [v for v in order if v in finite and finite[v] <= lowest + TIE * abs(lowest)]
    assert claim["variant"] == tied[0], (claim["kind"], claim["variant"], tied)
    assert claim["tied"] == tied[1:], claim
    assert claim["variant"] in claim["text"]


def check(metrics: dict) -> list[str]:
    """Checks every claim; returns the kinds checked (AssertionError at the first false one)."""
    claims = metrics["claims"]
    kinds = [c["kind"] for c in claims]
    assert set(kinds) <= KNOWN_KINDS, kinds
    assert kinds[:2] == ["reference", "failed"], kinds
    reference = metrics["reference_check"]
    duration = metrics["duration_s"]
    for claim in claims:
        assert claim["table"], claim
        kind = claim["kind"]
        if kind == "reference":
            largest = max(reference["largest_moving_difference"].values())
            holds = largest <= reference["tolerance"]
            assert claim["holds_whole_run"] == holds and claim["not_held"] == reference["not_held"]
            assert (claim["not_held"] == []) == holds
            if holds:
                assert claim["held_s"] == pytest.approx(duration) and "whole run" in claim["text"]
            else:
                assert set(claim["parted_by"]) == {q for q, d in reference["largest_moving_difference"].items()
                                                   if d > reference["tolerance"]}
                not_held = sum(b - a for a, b in claim["not_held"])
                assert claim["held_s"] == pytest.approx(duration - not_held, abs=0.01 * duration)
                assert all(f"{a:.3g}-{b:.3g} s" in claim["text"] for a, b in claim["not_held"][:4])
            assert claim["usable"] == (claim["held_s"] >= 0.2 * duration)
        elif kind == "failed":
            failed = {}
            for run in metrics["runs"]:
                if run["status"] != "ok":
                    failed.setdefault(run["variant"], []).append(f"{run['profile']} seed {run['seed']}")
            assert claim["failed"] == failed
            assert ("No run failed" in claim["text"]) == (not failed)
        elif kind in ("least_spread", "least_deviation"):
            table = "spread" if kind == "least_spread" else "deviation"
            values = {v: _worst(metrics, table, v) for v in metrics["variants"]}
            assert {v: _value(x) for v, x in claim["values"].items()} == values
            _check_best(metrics, claim, values)
            assert claim["value"] == values[claim["variant"]]
            if kind == "least_deviation":
                assert claim["reference_uncertainty"] == max(reference["difference_in_window"].values())
        elif kind == "cheapest":
            costs = {v: c for v, c in metrics["cost_cpu_ms_per_simulated_s"].items() if v != "own" and c is not None}
            lowest = min(costs.values())
            alike = {v for v, c in costs.items() if c <= lowest * (1 + claim["tie"])}
            assert set(claim["variants"]) == alike and claim["values"] == costs
            assert all(v in claim["text"] for v in alike)
        elif kind == "recommend":
            failed = {run["variant"] for run in metrics["runs"] if run["status"] != "ok"}
            scores = {v: max(_worst(metrics, "spread", v), _worst(metrics, "deviation", v))
                      for v in metrics["variants"] if v != "own" and v not in failed}
            scores = {v: s for v, s in scores.items() if math.isfinite(s)}
            assert claim["scores"] == scores
            _check_best(metrics, claim, scores)
            assert claim["score"] == scores[claim["variant"]]
            assert claim["variant"] not in failed
        elif kind == "served":
            for variant, counts in claim["served"].items():
                assert variant in ("matched", "exact", "fixed-matched", "fixed-exact")
                runs = [r for r in metrics["runs"] if r["variant"] == variant]
                for name, count in counts.items():
                    assert count == sum(r["served"][name] for r in runs), (variant, name)
        if kind not in ("reference", "failed", "served", "cheapest") and not reference["holds_whole_run"]:
            assert claim["window"] == f"the {reference['held_s']:.3g} s of {duration:g} s where the reference holds"
    if not reference["usable"]:
        assert not set(kinds) & {"least_spread", "least_deviation", "cheapest", "recommend"}
    return kinds

"""An independent reader of an audit's metrics.json: checks every claim of its recommendation against the tables of
the same file, with none of steadystep's code (plain json and math), by the rule docs/audit.md states. Used by
test_audit*.py.

What it recomputes: each spread and deviation from its per-run values, their standard errors, which quantities
decide (scales and units), the noise of every comparison, and from those every claim's choice, its margin and what
it says about the program's own stepping."""

from __future__ import annotations

import math

import pytest

KNOWN_KINDS = {"reference", "failed", "least_spread", "least_deviation", "cheapest", "recommend", "diagnosis",
               "served", "unsoftened"}
UNITS = ("m_per_s2", "rad_per_s2", "m_per_s", "rad_per_s", "N_m", "N_s", "kg_m2", "m", "rad", "deg", "N", "J", "W",
         "kg", "s", "Pa", "Hz", "count")


def _value(x):
    return math.inf if x is None else x  # null in a table: a failed variant (or nothing measured)


def unit(quantity: str) -> str:
    return next((u for u in UNITS if quantity.endswith("_" + u)), quantity.rsplit("_", 1)[-1])


def deciding(metrics: dict) -> list[str]:
    """docs/audit.md: a quantity below tiny_range of the largest scale of its unit does not decide alone."""
    scales, quantities = metrics["scales"], metrics["quantities"]
    tiny = metrics["noise_rule"]["tiny_range"]
    kept = [q for q in quantities if scales[q] >= tiny * max(scales[o] for o in quantities if unit(o) == unit(q))]
    return kept or quantities


def rms_and_error(values: list) -> tuple[float, float]:
    values = [_value(v) for v in values]
    if any(math.isinf(v) for v in values):
        return math.inf, 0.0
    rms = math.sqrt(sum(v * v for v in values) / len(values))
    if len(values) < 2:
        return rms, 0.0
    mean = sum(values) / len(values)
    sd = math.sqrt(sum((v - mean) ** 2 for v in values) / (len(values) - 1))
    return rms, sd / math.sqrt(len(values))


class Reader:
    def __init__(self, metrics: dict):
        self.m = metrics
        self.deciding = deciding(metrics)
        self.sigmas = metrics["noise_rule"]["sigmas"]
        self.repeat = metrics["repeat"]["difference"]
        self.uncertainty = {q: _value(x) for q, x in metrics["reference_check"]["difference_in_window"].items()}

    def largest(self, table: dict, variant: str) -> tuple[float, str | None]:
        values = [(_value(table[variant][q]), q) for q in self.deciding]
        values = [(x, q) for x, q in values if not math.isnan(x)]
        return max(values, key=lambda item: item[0]) if values else (math.nan, None)

    def spread(self, v):
        return self.largest(self.m["spread"], v)

    def deviation(self, v):
        return self.largest(self.m["deviation"]["window"], v)

    def _noise(self, error: dict, a, qa, b, qb, extra=0.0) -> float:
        ea = _value(error[a][qa]) if qa else 0.0
        eb = _value(error[b][qb]) if qb else 0.0
        quantities = [q for q in (qa, qb) if q]
        repeat = max((self.repeat[q] for q in quantities), default=0.0)
        return self.sigmas * math.hypot(ea, eb) + 2 * repeat + extra

    def exact_zero(self, v, q) -> bool:
        """docs/audit.md: every run identical to the first (all per-run values 0) in a program that repeats itself."""
        runs = self.m["spread_runs"][v].get(q) if q else None
        return bool(runs) and all(x == 0 for x in runs) and self.repeat[q] == 0

    def spread_noise(self, a, qa, b, qb):
        if self.exact_zero(a, qa) or self.exact_zero(b, qb):
            return 0.0
        return self._noise(self.m["spread_error"], a, qa, b, qb)

    def deviation_noise(self, a, qa, b, qb):
        quantities = [q for q in (qa, qb) if q]
        return self._noise(self.m["deviation_error"], a, qa, b, qb,
                           max((self.uncertainty[q] for q in quantities), default=0.0))

    def best(self, values: dict, noise_of) -> tuple[str, list, dict]:
        order = self.m["variants"]
        finite = {v: x for v, x in values.items() if math.isfinite(x[0])}
        best = min(finite, key=lambda v: (finite[v][0], order.index(v)))
        noises = {v: noise_of(v, finite[v][1], best, finite[best][1]) for v in finite}
        within = []
        for v in sorted((v for v in finite if v != best), key=lambda v: (finite[v][0], order.index(v))):
            if finite[v][0] - finite[best][0] > noises[v]:
                break
            within.append(v)
        return best, [v for v in order if v in within], noises


def _check_tables(metrics: dict) -> None:
    """Each spread and deviation is the RMS of its per-run values, with their standard error."""
    for v in metrics["variants"]:
        for q in metrics["quantities"]:
            runs = metrics["spread_runs"][v][q]
            if runs:
                value, error = rms_and_error(runs)
                assert _value(metrics["spread"][v][q]) == pytest.approx(value, rel=1e-12, abs=1e-15), (v, q)
                assert metrics["spread_error"][v][q] == pytest.approx(error, rel=1e-9, abs=1e-15), (v, q)
            runs = metrics["deviation_runs"][v][q]
            if runs and all(x is None or not math.isnan(x) for x in runs):
                value, error = rms_and_error(runs)
                assert _value(metrics["deviation"]["window"][v][q]) == pytest.approx(value, rel=1e-12, abs=1e-15)


def _check_reference(metrics: dict, claim: dict, reader: Reader) -> None:
    r = metrics["reference_check"]
    duration = metrics["duration_s"]
    parting = {q for q, d in r["largest_moving_difference"].items() if d > r["tolerance"] and q in reader.deciding}
    assert set(r["parted_by"]) == parting
    assert r["holds_whole_run"] == (not parting) == (r["parted_at"] is None)
    if r["parted_at"] is None:
        assert r["held_s"] == pytest.approx(duration)
    else:
        assert r["held_s"] == pytest.approx(r["parted_at"], abs=0.01 * duration)
        assert f"part at {r['parted_at']:.3g} s" in claim["text"] or not r["check_finer"]
    if r["reference_step_s"] and r["check_step_s"]:
        assert r["check_finer"] == (r["check_step_s"] <= 0.75 * r["reference_step_s"])
    if not r["check_finer"]:
        assert "not finer" in claim["text"] and "unchecked" in claim["text"]
        if r["clock_floor_s"]:
            assert "floor" in claim["text"]
    assert r["sane"] == (not r["unphysical"])
    for found in r["unphysical"]:
        assert found["rate"] > 3 * found["runs_rate"]
        assert max(found["reached"] - found["high"], found["low"] - found["reached"]) > found["high"] - found["low"]
        assert "unphysical" in claim["text"] and found["quantity"] in claim["text"]
    usable = r["sane"] and r["check_finer"] and r["held_s"] >= 0.2 * duration
    assert r["usable"] == claim["usable"] == usable
    assert ("No claim about deviation" in claim["text"]) == (not usable)
    assert "whole run, whatever the reference does" in claim["text"]


def _check_least(metrics: dict, claim: dict, reader: Reader, values: dict, noise_of) -> None:
    values = {v: x for v, x in values.items() if metrics["roles"][v] != "diagnosis"}
    best, within, noises = reader.best(values, noise_of)
    assert claim["variant"] == best and claim["within_noise"] == within, (claim["kind"], best, within)
    assert claim["value"] == values[best][0] and claim["quantity"] == values[best][1]
    beyond = [v for v in values if math.isfinite(values[v][0]) and v != best and v not in within]
    nearest = min(beyond, key=lambda v: (values[v][0], metrics["variants"].index(v))) if beyond else None
    assert claim["nearest_beyond"] == nearest
    if nearest:
        assert claim["margin"] == pytest.approx(values[nearest][0] - values[best][0])
        assert values[nearest][0] - values[best][0] > noises[nearest]  # a margin beyond the noise
    assert claim["quantity"] in claim["text"]


def _worse(metrics: dict, reader: Reader, v: str, base: str) -> list[tuple[str, str]]:
    out = []
    for q in metrics["quantities"]:
        a, b = _value(metrics["spread"][v][q]), _value(metrics["spread"][base][q])
        if math.isfinite(a) and math.isfinite(b) and a - b > reader.spread_noise(v, q, base, q):
            out.append(("spread", q))
    if metrics["reference_check"]["usable"]:
        for q in metrics["quantities"]:
            a = _value(metrics["deviation"]["window"][v][q])
            b = _value(metrics["deviation"]["window"][base][q])
            if math.isfinite(a) and math.isfinite(b) and a - b > reader.deviation_noise(v, q, base, q):
                out.append(("deviation", q))
    return out


def _check_recommend(metrics: dict, claim: dict, reader: Reader) -> None:
    order = metrics["variants"]
    failed = {run["variant"] for run in metrics["runs"] if run["status"] != "ok"}
    spread = {v: reader.spread(v) for v in order}
    candidates = {v: spread[v] for v in order if metrics["roles"][v] == "advice" and v not in failed
                  and math.isfinite(spread[v][0])}
    assert claim["candidates"] == list(candidates)
    assert "substeps-frozen" not in candidates and claim["variant"] in candidates  # a control is never advice
    best, within, _ = reader.best(candidates, reader.spread_noise)
    near = [best] + within
    assert claim["least"] == best and claim["within_noise"] == within
    assert claim["variant"] in near  # its largest spread is within the noise of the smallest
    base = "own" if "own" in order else ("naive" if "naive" in order else None)
    assert claim["base"] == base
    worse = {v: (_worse(metrics, reader, v, base) if base and base != v and base not in failed else []) for v in near}
    pool = [v for v in near if not worse[v]] or near
    assert claim["variant"] in pool
    if len(pool) == 1:
        assert claim["variant"] == pool[0]
    elif claim["chosen_by"] == "deviation":
        assert metrics["reference_check"]["usable"]
        values = {v: reader.deviation(v) for v in pool if math.isfinite(reader.deviation(v)[0])}
        closest, tied, _ = reader.best(values, reader.deviation_noise)
        assert len(tied) + 1 < len(pool)
        assert claim["variant"] == min([closest] + tied, key=order.index)
    else:
        assert claim["chosen_by"] == "order" and claim["variant"] == min(pool, key=order.index)
    listed = [(w["table"], w["quantity"]) for w in claim["worse_than_base"]]
    assert listed == worse[claim["variant"]]
    for table, q in listed:  # never hidden: said in words
        assert f"the {table} of {q}" in claim["text"]
    if not listed and base and base != claim["variant"]:
        assert "no worse than" in claim["text"]
    assert claim["text"].startswith(f"For this program: {claim['variant']}.")


def _check_diagnosis(metrics: dict, claim: dict, reader: Reader) -> None:
    for step in claim["steps"]:
        a, qa = reader.spread(step["from"])
        b, qb = reader.spread(step["to"])
        assert step["from_value"] == a and step["to_value"] == b
        noise = reader.spread_noise(step["from"], qa, step["to"], qb)
        expected = "removes" if a - b > noise else ("adds" if b - a > noise else "no change beyond the noise")
        assert step["verdict"] == expected, step
    if claim["residue"] is not None:
        assert "once-a-frame logic or input read once a frame" in claim["text"]


def check(metrics: dict) -> list[str]:
    """Checks every claim; returns the kinds checked (AssertionError at the first false one)."""
    claims = metrics["claims"]
    kinds = [c["kind"] for c in claims]
    assert set(kinds) <= KNOWN_KINDS, kinds
    assert kinds[:2] == ["reference", "failed"], kinds
    reader = Reader(metrics)
    assert metrics["deciding"] == reader.deciding
    _check_tables(metrics)
    for claim in claims:
        assert claim["table"], claim
        kind = claim["kind"]
        if kind == "reference":
            _check_reference(metrics, claim, reader)
        elif kind == "failed":
            failed = {}
            for run in metrics["runs"]:
                if run["status"] != "ok":
                    failed.setdefault(run["variant"], []).append(f"{run['profile']} seed {run['seed']}")
            assert claim["failed"] == failed
            assert ("No run failed" in claim["text"]) == (not failed)
        elif kind == "least_spread":
            _check_least(metrics, claim, reader, {v: reader.spread(v) for v in metrics["variants"]},
                         reader.spread_noise)
        elif kind == "least_deviation":
            assert metrics["reference_check"]["usable"]
            _check_least(metrics, claim, reader, {v: reader.deviation(v) for v in metrics["variants"]},
                         reader.deviation_noise)
        elif kind == "cheapest":
            cost = metrics["cost"]
            values = {v: c for v, c in cost["per_simulated_s"].items() if v != "own"}
            noise = cost["noise"]
            lowest = min(values, key=lambda v: (values[v], metrics["variants"].index(v)))
            alike = [v for v in metrics["variants"] if v in values
                     and values[v] - values[lowest] <= noise[v] + noise[lowest]]
            assert claim["variants"] == alike and claim["values"] == values
            if cost["method"] == "time":
                for v, samples in cost["samples"].items():
                    assert noise[v] == pytest.approx(max(samples) - min(samples))
            else:
                for v, value in values.items():
                    assert noise[v] >= metrics["noise_rule"]["count_resolution"] * value * (1 - 1e-12)
        elif kind == "recommend":
            _check_recommend(metrics, claim, reader)
        elif kind == "diagnosis":
            _check_diagnosis(metrics, claim, reader)
        elif kind == "unsoftened":
            counts = {}
            for run in metrics["runs"]:
                if run.get("unsoftened_contact_steps"):
                    counts[run["variant"]] = counts.get(run["variant"], 0) + run["unsoftened_contact_steps"]
            assert claim["steps"] == counts and claim["total"] == sum(counts.values()) > 0, (claim, counts)
            assert f"{claim['total']} steps made contacts but softened none" in claim["text"]
            assert "ssStepper_SoftenContact" in claim["text"]
        elif kind == "served":
            for variant, counts in claim["served"].items():
                assert variant in ("matched", "exact", "fixed-matched", "fixed-exact")
                runs = [r for r in metrics["runs"] if r["variant"] == variant]
                for name, count in counts.items():
                    assert count == sum(r["served"][name] for r in runs), (variant, name)
    if not metrics["reference_check"]["usable"]:
        assert "least_deviation" not in kinds
    # a run that made contacts without softening them is never left unsaid
    assert ("unsoftened" in kinds) == any(r.get("unsoftened_contact_steps") for r in metrics["runs"]), kinds
    return kinds

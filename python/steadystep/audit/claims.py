"""The audit's recommendation for one program, as claims computed from its own tables (docs/audit.md, "The
recommendation": the rule and its reasons).

Each claim is plain data in metrics.json: its kind, the sentence shown on the page, the anchor of the table that
shows it, and the numbers it rests on, so that a reader (tests/python/audit_claims_check.py) can check every claim
against the tables without this code.

The rule, in short:
- a variant's spread (how much its motion changes with the frame rate) is over the whole run, whatever the
  reference does; its deviation (how far from the fine-step reference) only over the time the reference holds, and
  only when the reference is usable (checked by a finer check, physical, held long enough);
- a variant is summed up by its largest value over the deciding quantities (measure.deciding: error-like
  quantities of a tiny range do not decide alone), and that quantity is named;
- one value is better than another only beyond the noise of their difference (measure.noise: the standard
  errors over runs, the repeat's difference, and for deviation the reference's own uncertainty);
- the recommendation is a policy (never the control substeps-frozen, never a diagnosis variant) none of whose runs
  failed, whose largest spread is within the noise of the smallest; among those, one no worse than the program's
  own stepping (or naive, without it) beyond the noise in any quantity if there is one, then the closest to the
  reference beyond the noise, then the first in the library's order (the simplest). Where it is worse than own
  stepping in a quantity beyond the noise, the claim says so in words.
"""

from __future__ import annotations

import math

from steadystep.audit import measure as measure_

ACCURATE = ("matched", "exact", "fixed-matched", "fixed-exact")
OWN = "own"


def _g(value: float) -> str:
    return "failed" if math.isinf(value) else ("-" if math.isnan(value) else f"{value:.3g}")


def _name(variant: str) -> str:
    return "own stepping" if variant == OWN else variant


def largest(table: dict, variant: str, quantities: list[str]) -> tuple[float, str | None]:
    """(The largest value of table[variant] over quantities, the quantity it is in): inf if any is, nan if all are."""
    values = [(table[variant][q], q) for q in quantities if not math.isnan(table[variant][q])]
    if not values:
        return math.nan, None
    value, quantity = max(values, key=lambda item: item[0])
    return value, quantity


class Tables:
    """The numbers a claim rests on, and the noise between two of them (the module's docstring)."""

    def __init__(self, result):
        self.result = result
        self.deciding = result.deciding
        self.repeat = result.repeat["difference"]
        self.uncertainty = result.reference["difference_in_window"]

    def spread(self, variant: str) -> tuple[float, str | None]:
        return largest(self.result.spread, variant, self.deciding)

    def deviation(self, variant: str) -> tuple[float, str | None]:
        return largest(self.result.deviation["window"], variant, self.deciding)

    def exact_zero(self, variant: str, quantity: str | None) -> bool:
        """Whether the variant's spread in quantity is an exact 0: every run identical to the first at every
        compared time, in a program that repeats itself exactly (no noise to it: any positive value is beyond)."""
        runs = self.result.spread_runs[variant].get(quantity) if quantity else None
        return bool(runs) and all(x == 0 for x in runs) and self.repeat[quantity] == 0

    def spread_noise(self, a: str, qa: str | None, b: str, qb: str | None) -> float:
        if self.exact_zero(a, qa) or self.exact_zero(b, qb):
            return 0.0
        error = self.result.spread_error
        return measure_.noise(error[a][qa] if qa else 0.0, error[b][qb] if qb else 0.0,
                              max(self.repeat[q] for q in (qa, qb) if q) if (qa or qb) else 0.0)

    def deviation_noise(self, a: str, qa: str | None, b: str, qb: str | None) -> float:
        error = self.result.deviation_error
        quantities = [q for q in (qa, qb) if q]
        return measure_.noise(error[a][qa] if qa else 0.0, error[b][qb] if qb else 0.0,
                              max((self.repeat[q] for q in quantities), default=0.0),
                              max((self.uncertainty[q] for q in quantities), default=0.0))


def _best(values: dict, noise_of, order: list[str]) -> tuple[str, list[str], dict]:
    """The variant with the smallest finite value (ties: the first in order), the others within the noise of it (in
    order), and each one's noise against it."""
    finite = {v: x for v, x in values.items() if math.isfinite(x[0])}
    best = min(finite, key=lambda v: (finite[v][0], order.index(v)))
    noises = {v: noise_of(v, finite[v][1], best, finite[best][1]) for v in finite}
    # Within the noise: from the smallest up, until the first beyond it (a larger value is never "within" when a
    # smaller one is not).
    ranked = sorted((v for v in finite if v != best), key=lambda v: (finite[v][0], order.index(v)))
    within = []
    for v in ranked:
        if finite[v][0] - finite[best][0] > noises[v]:
            break
        within.append(v)
    return best, [v for v in order if v in within], noises


def _nearest_beyond(values: dict, best: str, within: list[str], noises: dict, order: list[str]):
    """The variant beyond the noise of best with the smallest value (or None)."""
    beyond = [v for v in order if v in values and math.isfinite(values[v][0]) and v != best and v not in within]
    return min(beyond, key=lambda v: (values[v][0], order.index(v))) if beyond else None


def _ranked(values: dict) -> str:
    return ", ".join(f"{_name(v)} {_g(x)}" + (f" ({q})" if q and math.isfinite(x) else "")
                     for v, (x, q) in sorted(values.items(), key=lambda item: (math.isnan(item[1][0]), item[1][0])))


def recommended(result) -> str | None:
    """The policy the recommendation names (its "recommend" claim), or None when it names none."""
    return next((c["variant"] for c in result.claims if c["kind"] == "recommend"), None)


def claims(result) -> list[dict]:
    tables = Tables(result)
    out = [_reference(result), _failed(result)]
    unsoftened = _unsoftened(result)
    if unsoftened:
        out.append(unsoftened)
    spread = {v: tables.spread(v) for v in result.variants}
    chosen = [v for v in result.variants if result.roles[v] != "diagnosis"]  # what a program can step with
    if any(math.isfinite(spread[v][0]) for v in chosen):
        out.append(_least("least_spread", "spread", {v: spread[v] for v in chosen}, tables.spread_noise, result,
                          "Least dependent on the frame rate", "largest spread", "over the whole run"))
    deviation = {v: tables.deviation(v) for v in result.variants}
    if result.reference["usable"] and any(math.isfinite(deviation[v][0]) for v in chosen):
        claim = _least("least_deviation", "deviation", {v: deviation[v] for v in chosen}, tables.deviation_noise,
                       result,
                       "Closest to the fine-step reference", "largest deviation", window_text(result))
        out.append(claim)
    cheapest = _cheapest(result)
    if cheapest:
        out.append(cheapest)
    recommend = _recommend(result, tables, spread, deviation)
    if recommend:
        out.append(recommend)
    diagnosis = _diagnosis(result, tables, spread)
    if diagnosis:
        out.append(diagnosis)
    return out + _served(result)


def window_text(result) -> str:
    """Where deviation is measured: the whole run, or the time before the reference and its check part."""
    r = result.reference
    if r["holds_whole_run"]:
        return "over the whole run"
    return f"over the first {r['held_s']:.3g} s of {result.duration_s:g} s, before the reference and its check part"


def _least(kind: str, table: str, values: dict, noise_of, result, title: str, what: str, where: str) -> dict:
    order = result.variants
    best, within, noises = _best(values, noise_of, order)
    nearest = _nearest_beyond(values, best, within, noises, order)
    value, quantity = values[best]
    text = f"{title}: {_name(best)}, {what} {_g(value)} (in {quantity}) {where}"
    if within:
        text += "; within the noise of it: " + ", ".join(
            f"{_name(v)} {_g(values[v][0])} (noise {_g(noises[v])})" for v in within)
    if nearest:
        text += (f"; the nearest beyond the noise: {_name(nearest)} {_g(values[nearest][0])} (in {values[nearest][1]}"
                 f"), a margin of {_g(values[nearest][0] - value)} over a noise of {_g(noises[nearest])}")
    text += f". Every variant: {_ranked(values)}."
    claim = {"kind": kind, "table": table, "variant": best, "quantity": quantity, "value": value,
             "within_noise": within, "nearest_beyond": nearest,
             "margin": (values[nearest][0] - value) if nearest else None,
             "noise": {v: noises[v] for v in noises}, "values": {v: x for v, (x, _) in values.items()},
             "deciding_quantity": {v: q for v, (_, q) in values.items()}, "text": text}
    if kind == "least_deviation":
        claim["reference_uncertainty"] = max(result.reference["difference_in_window"].values())
    return claim


def _failed(result) -> dict:
    failed: dict[str, list[str]] = {}
    for r in result.runs:
        if r["status"] != "ok":
            failed.setdefault(r["variant"], []).append(f"{r['profile']} seed {r['seed']}")
    if not failed:
        text = "No run failed: every variant stepped every frame under every profile."
    else:
        text = "Avoid: " + "; ".join(f"{_name(v)} failed under {', '.join(runs)}" for v, runs in failed.items()) + "."
    return {"kind": "failed", "table": "runs", "failed": failed, "text": text}


def _reference(result) -> dict:
    r = result.reference
    data = {"kind": "reference", "table": "reference"}
    for name in ("holds_whole_run", "parted_at", "parted_by", "held_s", "usable", "not_usable_because",
                 "check_finer", "sane", "tolerance"):
        data[name] = r[name]
    pair = (f"The fine-step reference (implicit-euler, {r['reference_fps']} frames a second) and its check "
            f"({r['check_fps']} frames a second)")
    parts = []
    if not r["check_finer"]:
        if r["identical_to_check"]:
            why = "it printed the same values as the reference at every time they share: it took the same steps"
        else:
            why = (f"its steps averaged {1000 * r['check_step_s']:.3g} ms, the reference's "
                   f"{1000 * r['reference_step_s']:.3g} ms")
        floor = ""
        if r["clock_floor_s"] is not None:
            floor = (f"; {r['check_idle_frames']:.0%} of its frames took no step: the program's clock has a floor of "
                     f"about {1000 * r['clock_floor_s']:.3g} ms (whole milliseconds?), so frames shorter than that "
                     "step nothing")
        parts.append(f"The check is not finer than the reference: {why}{floor}. The reference is unchecked.")
    elif r["holds_whole_run"]:
        parts.append(f"{pair} agree over the whole run, within {r['tolerance']:.0%} of each quantity's scale (at "
                     f"most {_g(max(r['largest_moving_difference'].values()))}, RMS over {r['window_s']:.3g} s).")
    else:
        parts.append(f"{pair} part at {r['parted_at']:.3g} s, by more than {r['tolerance']:.0%} of the scale of "
                     f"{', '.join(r['parted_by'])}: from there on the motion depends on the step itself (chaos, or an "
                     "impact whose outcome depends on the step), and nothing after counts as held, even where the "
                     "two meet again.")
    if not r["sane"]:
        for found in r["unphysical"][:2]:
            parts.append(f"The reference is unphysical: its {found['quantity']} changes at up to "
                         f"{found['rate']:.3g} per s from t = {found['at_s']:.3g} s, "
                         f"{found['rate'] / max(found['runs_rate'], 1e-300):.3g} times as fast as in any run at the "
                         f"audited frame rates, and reaches {found['reached']:.3g}, where every such run stays within "
                         f"[{found['low']:.3g}, {found['high']:.3g}]: an energy or speed jump that only the fine "
                         "steps make (a per-step force or impulse sized for long steps, or contacts tuned for them).")
        parts.append(f"Each quantity is scaled by its range under {result.scale_source} instead.")
    if r["usable"]:
        parts.append(f"Deviation from the reference is measured {window_text(result)}.")
    else:
        reason = {"unphysical": "the reference is unphysical", "unchecked": "the reference is unchecked",
                  "parted early": f"the reference holds for only {r['held_s']:.3g} s"}
        parts.append("No claim about deviation is made (" + ", ".join(reason[x] for x in r["not_usable_because"])
                     + ").")
    parts.append("Spread across frame rates is claimed over the whole run, whatever the reference does.")
    data["text"] = " ".join(parts)
    return data


def _cheapest(result) -> dict | None:
    cost = result.cost
    values = {v: c for v, c in cost.get("per_simulated_s", {}).items() if v != OWN}
    if not values:
        return None
    noise = cost["noise"]
    lowest = min(values, key=lambda v: (values[v], result.variants.index(v)))
    alike = [v for v in result.variants if v in values and values[v] - values[lowest] <= noise[v] + noise[lowest]]
    how = ("instructions counted by valgrind (a count repeats to " +
           f"{cost.get('repeat_difference', 0):.2g}; counts within {measure_.COUNT_RESOLUTION:.0%} are not told apart)"
           if cost["method"] == "instructions" else
           "CPU time, the median of repeated runs (the noise: their range)")
    own = f"; own stepping {_g(cost['per_simulated_s'][OWN])}" if OWN in cost["per_simulated_s"] else ""
    text = (f"Cheapest: {', '.join(alike)} (within the noise of the cheapest), in {cost['unit']} under "
            f"{cost['profile']} seed {cost['seed']}, {how}: "
            + ", ".join(f"{v} {_g(c)}" for v, c in sorted(values.items(), key=lambda i: i[1])) + f"{own}.")
    return {"kind": "cheapest", "table": "cost", "variants": alike, "values": values, "noise": dict(noise),
            "method": cost["method"], "text": text}


def _worse_than(result, tables: Tables, variant: str, base: str) -> list[dict]:
    """Where variant is worse than base beyond the noise: spread in every quantity, deviation too when the reference
    is usable."""
    out = []
    for q in result.quantities:
        a, b = result.spread[variant][q], result.spread[base][q]
        n = tables.spread_noise(variant, q, base, q)
        if math.isfinite(a) and math.isfinite(b) and a - b > n:
            out.append({"table": "spread", "quantity": q, "value": a, "base": b, "noise": n})
    if result.reference["usable"]:
        for q in result.quantities:
            a, b = result.deviation["window"][variant][q], result.deviation["window"][base][q]
            n = tables.deviation_noise(variant, q, base, q)
            if math.isfinite(a) and math.isfinite(b) and a - b > n:
                out.append({"table": "deviation", "quantity": q, "value": a, "base": b, "noise": n})
    return out


def _recommend(result, tables: Tables, spread: dict, deviation: dict) -> dict | None:
    failed = {r["variant"] for r in result.runs if r["status"] != "ok"}
    order = result.variants
    candidates = {v: spread[v] for v in order if result.roles[v] == "advice" and v not in failed
                  and math.isfinite(spread[v][0])}
    if not candidates:
        return None
    best, within, noises = _best(candidates, tables.spread_noise, order)
    near = [best] + within
    base = OWN if OWN in order else ("naive" if "naive" in order else None)
    worse = {v: (_worse_than(result, tables, v, base) if base and base != v and base not in failed else [])
             for v in near}
    pool = [v for v in near if not worse[v]] or near
    if len(pool) == 1:
        pick, chosen_by = pool[0], ("spread" if len(near) == 1 else "own")
    else:
        pick, chosen_by = min(pool, key=order.index), "order"
        values = {v: deviation[v] for v in pool if math.isfinite(deviation[v][0])}
        if result.reference["usable"] and values:
            closest, tied, _ = _best(values, tables.deviation_noise, order)
            if len(tied) + 1 < len(pool):  # the deviation told some of them apart
                pick, chosen_by = min([closest] + tied, key=order.index), "deviation"
    value, quantity = spread[pick]
    nearest = _nearest_beyond(candidates, best, within, noises, order)
    parts = [f"For this program: {pick}. Its largest spread across frame rates is {_g(value)} (in {quantity})"]
    if pick == best and not within:
        parts[0] += ", the least of the policies"
    else:
        parts[0] += (f"; within the noise of the least ({best} {_g(spread[best][0])}) are "
                     + ", ".join(f"{v} {_g(candidates[v][0])}" for v in near if v != pick)
                     + {"order": "; it is the simplest of them (the library's order)",
                        "own": "; it is the one no worse than " + _name(base) + " beyond the noise",
                        "deviation": (f"; it is the closest of them to the reference, largest deviation "
                                      f"{_g(deviation[pick][0])} (in {deviation[pick][1]})"),
                        "spread": ""}[chosen_by])
    if nearest:
        parts.append(f"the nearest policy beyond the noise is {nearest} {_g(candidates[nearest][0])} (in "
                     f"{candidates[nearest][1]}), a margin of {_g(candidates[nearest][0] - spread[best][0])} over a "
                     f"noise of {_g(noises[nearest])}")
    if base and base != pick and math.isfinite(spread[base][0]):
        against = f"against {_name(base)}'s {_g(spread[base][0])} (in {spread[base][1]})"
        parts.append(against)
    if worse[pick]:
        parts.append(f"it is worse than {_name(base)} beyond the noise in " + ", ".join(
            f"the {w['table']} of {w['quantity']}: {_g(w['value'])} against {_g(w['base'])} (noise {_g(w['noise'])})"
            for w in worse[pick]))
    elif base and base != pick:
        parts.append(f"it is no worse than {_name(base)} beyond the noise in any quantity")
    if result.roles.get("substeps-frozen"):
        parts.append("substeps-frozen is a control (what the cut alone gives), shown, never recommended")
    text = "; ".join(parts) + "."
    return {"kind": "recommend", "table": "spread", "variant": pick, "quantity": quantity, "value": value,
            "least": best, "within_noise": within, "chosen_by": chosen_by, "candidates": list(candidates),
            "nearest_beyond": nearest, "margin": (candidates[nearest][0] - spread[best][0]) if nearest else None,
            "base": base, "worse_than_base": worse[pick], "text": text}


DIAGNOSIS_STEPS = (("the cut", None, "substeps-frozen"), ("the mapping", "substeps-frozen", "implicit-euler"),
                   ("the step length", "implicit-euler", "half-step"),
                   ("the solver", "implicit-euler", "more-iterations"),
                   ("identical steps", "implicit-euler", "fixed"))


def _share(fraction: float) -> str:
    return f"{fraction:.0%}" if fraction >= 0.1 else f"{100 * fraction:.2g}%"


def _diagnosis(result, tables: Tables, spread: dict) -> dict | None:
    base = OWN if OWN in result.variants else ("naive" if "naive" in result.variants else None)
    if base is None or not math.isfinite(spread[base][0]) or spread[base][0] <= 0:
        return None
    total = spread[base][0]
    steps, sentences = [], []
    for label, start, end in DIAGNOSIS_STEPS:
        start = start or base
        if start not in spread or end not in spread:
            why = result.not_measured.get(end) or result.not_measured.get(start)
            if why:
                sentences.append(f"{label}: {why}")
            continue
        a, qa = spread[start]
        b, qb = spread[end]
        if not (math.isfinite(a) and math.isfinite(b)):
            continue
        n = tables.spread_noise(start, qa, end, qb)
        share = (a - b) / a if a > 0 else 0.0
        verdict = "removes" if a - b > n else ("adds" if b - a > n else "no change beyond the noise")
        steps.append({"step": label, "from": start, "to": end, "from_value": a, "to_value": b, "noise": n,
                      "share_removed": share, "verdict": verdict})
        what = f"{label} ({_name(start)} → {end}, {_g(a)} → {_g(b)})"
        if verdict == "removes":
            sentences.append(f"{what}: removes {_share(share)} of it")
        elif verdict == "adds":
            sentences.append(f"{what}: adds {_share(-share)} to it")
        else:
            sentences.append(f"{what}: no change beyond the noise ({_g(n)})")
    residue = None
    if "fixed" in spread and math.isfinite(spread["fixed"][0]):
        value, quantity = spread["fixed"]
        n = tables.spread_noise("fixed", quantity, "fixed", quantity) / math.sqrt(2)
        if value > n:
            residue = value
            sentences.append(f"what no policy fixes: even identical steps (fixed) leave a spread of {_g(value)} (in "
                             f"{quantity}); every step has the same length and time at every frame rate there, so "
                             "what still differs is the program's once-a-frame logic or input read once a frame "
                             "(move it into before_step, computed from the step's time_s)")
        elif "implicit-euler" in spread and spread["implicit-euler"][0] > n:
            chaos = (f"; the reference and its check part at {result.reference['parted_at']:.3g} s: impacts and "
                     "chaos amplify any difference between steps" if result.reference["parted_at"] is not None
                     else "")
            sentences.append(f"what only identical steps remove: the steps' lengths differ with the frame rate "
                             f"under every other policy{chaos}; fixed leaves {_g(value)}")
    if not steps and not sentences:
        return None
    text = f"Where {_name(base)}'s spread ({_g(total)}, in {spread[base][1]}) comes from: " + "; ".join(sentences) + "."
    return {"kind": "diagnosis", "table": "diagnosis", "base": base, "base_value": total, "steps": steps,
            "residue": residue, "text": text}


def _unsoftened(result) -> dict | None:
    """Steps that made contacts on the stepper's bodies but softened none (the program's unsoftened_contact_steps
    column): its near callback forgot ssStepper_SoftenContact, so those contacts keep the softness tuned for one step
    length under every policy."""
    counts = {}
    for run in result.runs:
        if run.get("unsoftened_contact_steps"):
            counts[run["variant"]] = counts.get(run["variant"], 0) + run["unsoftened_contact_steps"]
    if not counts:
        return None
    total = sum(counts.values())
    text = (f"{total} steps made contacts but softened none ("
            + ", ".join(f"{_name(v)} {n}" for v, n in counts.items())
            + "): call ssStepper_SoftenContact (Python: Stepper.soften_contact) on every contact in the near "
            "callback; without it those contacts keep the softness tuned for one step length under every policy, "
            "and this audit compares them so.")
    return {"kind": "unsoftened", "table": "runs", "steps": counts, "total": total, "text": text}


def _served(result) -> list[dict]:
    served = {v: s for v, s in result.served.items() if v in ACCURATE}
    if not served:
        return []
    parts = []
    for variant, counts in served.items():
        rows = ", ".join(f"{n.removeprefix('rows_').replace('_', ' ')} {c}" for n, c in counts.items()
                         if n.startswith("rows_"))
        contacts = ", ".join(f"{n.removeprefix('contacts_').replace('_', ' ')} {c}" for n, c in counts.items()
                             if n.startswith("contacts_"))
        parts.append(f"{variant}: row-steps {rows or '-'}; contacts {contacts or '-'}")
    return [{"kind": "served", "table": "served", "served": served,
             "text": "What each accurate mapping served, summed over its runs: " + "; ".join(parts) + ". They serve "
             "springs a program binds itself, free or with a declared load (the lab's oscillator); every adopted row "
             "and every contact of the programs measured so far was handed on to implicit Euler."}]

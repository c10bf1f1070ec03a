"""The audit's recommendation for one program, as claims computed from its own tables.

Each claim is plain data in metrics.json: its kind, the sentence shown on the page, the anchor of the table that
shows it, and the numbers it rests on, so that a reader (tests/python/test_audit_claims.py) can check every claim
against the tables without this code. Every claim about motion uses the window where the reference holds.

Kinds, in the order the page lists them:
- reference: whether the fine-step reference holds over the whole run (its check at a finer step agrees), else
  where it parts; when the window is too short (not usable), no motion claim follows.
- failed: the runs that failed, by variant (none: every run stepped every frame).
- least_spread: the variant whose worst quantity's spread is the smallest (worst = the largest over quantities).
- least_deviation: likewise for the deviation from the reference, with the reference's own uncertainty.
- cheapest: the policies whose CPU time per simulated second is within COST_TIE of the cheapest policy's.
- recommend: among the policies none of whose runs failed, the one with the smallest worst-quantity
  max(spread, deviation).
Ties (within TIE) go to the first in the audit's order of variants (own, then the library's order of policies).
- served: what each accurate mapping served, summed over its runs (only when the program prints those columns).
"""

from __future__ import annotations

import math

ACCURATE = ("matched", "exact", "fixed-matched", "fixed-exact")


def worst(table: dict, variant: str) -> float:
    """The largest value over the quantities of table[variant] (inf if any is inf, nan only if all are)."""
    values = [v for v in table[variant].values() if not math.isnan(v)]
    return max(values) if values else math.nan


def _g(value: float) -> str:
    return "failed" if math.isinf(value) else ("-" if math.isnan(value) else f"{value:.3g}")


def _ranked(values: dict) -> str:
    return ", ".join(f"{v} {_g(x)}" for v, x in sorted(values.items(), key=lambda item: (math.isnan(item[1]),
                                                                                           item[1], item[0])))


# Values this close (relative) are the same motion printed twice (a mapping that handed every row to implicit Euler):
# a tie, broken by the library's order of policies (the simpler first), never by noise.
TIE = 1e-9


def best_of(values: dict, order: list[str]) -> tuple[str, list[str]]:
    """The variant with the smallest finite value, and the others tied with it (within TIE), in order's order."""
    finite = {v: x for v, x in values.items() if math.isfinite(x)}
    lowest = min(finite.values())
    tied = [v for v in order if v in finite and finite[v] <= lowest + TIE * abs(lowest)]
    return tied[0], tied[1:]


def _tied(others: list[str]) -> str:
    return f" (tied with {', '.join(others)}: the same numbers)" if others else ""


def claims(result) -> list[dict]:
    from steadystep.audit import COST_TIE  # one definition of the tie

    out = [_reference(result)]
    out.append(_failed(result))
    if not result.reference["usable"]:
        return out + _served(result)
    window = window_text(result.reference, result.duration_s)
    spread = {v: worst(result.spread["window"], v) for v in result.variants}
    deviation = {v: worst(result.deviation["window"], v) for v in result.variants}
    if any(math.isfinite(x) for x in spread.values()):
        best, tied = best_of(spread, result.variants)
        own = f" The program's own stepping: {_g(spread['own'])}." if "own" in spread else ""
        out.append({"kind": "least_spread", "table": "spread", "variant": best, "tied": tied, "value": spread[best],
                    "values": spread, "window": window,
                    "text": f"Most alike at every frame rate: {best}{_tied(tied)}, spread {_g(spread[best])} of the "
                            "range in its "
                            f"worst quantity over {window} (every variant: {_ranked(spread)}).{own}"})
    if any(math.isfinite(x) for x in deviation.values()):
        best, tied = best_of(deviation, result.variants)
        floor = max(result.reference["difference_in_window"].values())
        out.append({"kind": "least_deviation", "table": "deviation", "variant": best, "tied": tied,
                    "value": deviation[best], "values": deviation, "reference_uncertainty": floor, "window": window,
                    "text": f"Closest to the fine-step reference: {best}{_tied(tied)}, deviation "
                            f"{_g(deviation[best])} of the range in its worst quantity over {window} (every variant: {_ranked(deviation)}); the "
                            f"reference itself is uncertain by {_g(floor)} (its check at a finer step)."})
    costs = {v: c for v, c in result.cost.items() if v != "own" and c is not None}
    if costs:
        lowest = min(costs.values())
        alike = sorted((v for v, c in costs.items() if c <= lowest * (1 + COST_TIE)), key=costs.get)
        own = f"; the program's own stepping {result.cost['own']:.3g}" if result.cost.get("own") else ""
        out.append({"kind": "cheapest", "table": "cost", "variants": alike, "tie": COST_TIE, "values": costs,
                    "text": f"Cheapest: {' and '.join(alike)} (within {COST_TIE:.0%} of the cheapest policy), CPU "
                            f"ms per simulated second (median over runs): "
                            + ", ".join(f"{v} {c:.3g}" for v, c in sorted(costs.items(), key=lambda i: i[1]))
                            + f"{own}."})
    candidates = {v: max(spread[v], deviation[v]) for v in result.variants if v != "own"
                  and not any(r["variant"] == v and r["status"] != "ok" for r in result.runs)
                  and math.isfinite(max(spread[v], deviation[v]))}
    if candidates:
        pick, tied = best_of(candidates, result.variants)
        best_score = candidates[pick]
        compared = ""
        if "own" in spread and math.isfinite(spread["own"]) and spread[pick] > 0:
            compared = (f" Against the program's own stepping its spread is {spread[pick] / spread['own']:.3g} of "
                        f"own's ({_g(spread[pick])} against {_g(spread['own'])}).")
        out.append({"kind": "recommend", "table": "spread", "variant": pick, "tied": tied, "score": best_score,
                    "scores": candidates, "window": window,
                    "text": f"For this program: {pick}{_tied(tied)}. Of the policies none of whose runs failed, its worst "
                            f"quantity's larger of spread and deviation is the smallest, {_g(best_score)} of the "
                            f"range over {window} (every policy: {_ranked(candidates)}).{compared}"})
    return out + _served(result)


def window_text(reference: dict, duration_s: float) -> str:
    """Where the motion claims are measured: the whole run, or the time the reference holds."""
    if reference["holds_whole_run"]:
        return "the whole run"
    return f"the {reference['held_s']:.3g} s of {duration_s:g} s where the reference holds"


def _stretch_text(stretches: list) -> str:
    shown = [f"{a:.3g}-{b:.3g} s" for a, b in stretches[:4]]
    return ", ".join(shown) + (f" and {len(stretches) - 4} more" if len(stretches) > 4 else "")


def _reference(result) -> dict:
    r = result.reference
    data = {"kind": "reference", "table": "reference", "holds_whole_run": r["holds_whole_run"],
            "not_held": r["not_held"], "held_s": r["held_s"], "parted_by": r["parted_by"], "usable": r["usable"],
            "tolerance": r["tolerance"]}
    pair = (f"{REFERENCE_FPS_TEXT.format(r['reference_fps'])} and its check at {r['check_fps']} frames a second "
            f"(RMS over {r['window_s']:.3g} s windows)")
    if r["holds_whole_run"]:
        text = (f"The reference holds over the whole run: {pair} stay within {r['tolerance']:.0%} of each "
                f"quantity's range (at most {_g(max(r['largest_moving_difference'].values()))}).")
    else:
        text = (f"The reference does not hold at {_stretch_text(r['not_held'])}: there {pair} part by more than "
                f"{r['tolerance']:.0%} of the range of {', '.join(r['parted_by'])}, so the motion there depends on "
                "the step itself (chaos, or an event such as an impact), not a frame-rate dependence to measure. ")
        text += (f"Every claim below is measured on the other {r['held_s']:.3g} s." if r["usable"] else
                 f"It holds for {r['held_s']:.3g} s, less than {MIN_FRACTION_TEXT} of the run: no claim about the "
                 "motion is made; audit a shorter duration.")
    data["text"] = text
    return data


REFERENCE_FPS_TEXT = "the reference (implicit-euler at {} frames a second, one step each)"
MIN_FRACTION_TEXT = "a fifth"


def _failed(result) -> dict:
    failed: dict[str, list[str]] = {}
    for r in result.runs:
        if r["status"] != "ok":
            failed.setdefault(r["variant"], []).append(f"{r['profile']} seed {r['seed']}")
    if not failed:
        text = "No run failed: every variant stepped every frame under every profile."
    else:
        text = "Avoid: " + "; ".join(f"{v} failed under {', '.join(runs)}" for v, runs in failed.items()) + "."
    return {"kind": "failed", "table": "runs", "failed": failed, "text": text}


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
             "text": "What each accurate mapping served, summed over its runs: " + "; ".join(parts) + "."}]

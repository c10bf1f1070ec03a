"""The report's opening: the policies defined, and the recommendation computed from this run's numbers.

Every sentence of the recommendation is made from the metrics on the page (never typed once and left to go
stale), and links to the table or figure that shows it. The needs it answers:

- consistency: the same motion at every frame rate (consistency.py: runs of one policy against each other);
- accuracy: closest to the exact solution (the oscillator at 15-45 fps) and to the fine-step reference (the
  deviation, RMS over profiles);
- cost: wall time against plain ODE in one interleaved benchmark (cost.py);
- the largest stable step (probe.py);
and which policies failed (blew up or broke) on some run.
"""

from __future__ import annotations

import html
import math
import statistics

from steadystep import runs
from steadystep._native import lib

# The mapping enum (stepping.h) by value; each mapping's one-line meaning (DESIGN.md, docs/exact-mappings.md).
MAPPINGS = {
    lib.SS_MAPPING_IMPLICIT_EULER: ("implicit Euler", "the article's erp = hk/(hk+c), cfm = 1/(hk+c) for each step "
                                    "h: ODE's step is then the implicit-Euler step of the spring-damper"),
    lib.SS_MAPPING_MATCHED: ("matched", "erp and cfm chosen so that a step of h decays and turns exactly as the "
                             "spring-damper does over h (exact at a constant step)"),
    lib.SS_MAPPING_EXACT: ("exact", "erp and cfm solved from the step before, so that a linear spring-damper's "
                           "samples equal the exact solution under any sequence of steps"),
}


def _ms(seconds: float) -> str:
    return f"{1000 * seconds:.3g} ms"


def cut_text(stepping: dict) -> str:
    """How a policy cuts a frame, from its stepping's numbers."""
    cut = stepping["cut"]
    if cut == lib.SS_CUT_WHOLE_FRAME:
        return "one step of the whole frame"
    if cut == lib.SS_CUT_SUBSTEPS:
        return f"equal substeps of at most max_step_s = {_ms(stepping['max_step_s'])}"
    return (f"constant steps of fixed_step_s = {_ms(stepping['fixed_step_s'])} from an accumulator (at most "
            f"{stepping['max_steps_per_frame']} a frame), the drawn state interpolated")


def mapping_text(stepping: dict) -> str:
    """Which softness each step gets, from its stepping's numbers."""
    name, meaning = MAPPINGS.get(stepping["mapping"], (f"mapping {stepping['mapping']}", ""))
    if stepping["frozen_step_s"] > 0:
        return (f"{name} frozen at {_ms(stepping['frozen_step_s'])} (as a program tuned once for "
                f"{1 / stepping['frozen_step_s']:.0f} fps): the softness does not follow the step")
    return f"{name}: {meaning}"


def definitions(policies: list[str]) -> str:
    """A table: each policy's cut and mapping, read from the library's own presets (runs.make_stepping)."""
    rows = []
    for policy in policies:
        stepping = runs.make_stepping(policy)
        rows.append(f"<tr><td><b>{html.escape(policy)}</b></td><td>{html.escape(cut_text(stepping))}</td>"
                    f"<td>{html.escape(mapping_text(stepping))}</td></tr>")
    return ("<table id='policies'><thead><tr><th>policy</th><th>how a frame is cut</th><th>softness of each step"
            "</th></tr></thead><tbody>" + "".join(rows) + "</tbody></table>")


def _first(report, scene: str) -> str:
    return runs.motion_quantities(scene)[0]


def _finite(value) -> bool:
    return value is not None and isinstance(value, (int, float)) and math.isfinite(value)


def _link(anchor: str, text: str) -> str:
    return f"<a href='#{html.escape(anchor)}'>{html.escape(text)}</a>"


def _x(value: float) -> str:
    return f"×{value:.3g}" if math.isfinite(value) else "∞"


def _ranking(per_scene: dict[str, dict[str, float]]) -> list[tuple[str, float, int]]:
    """Policies by the geometric mean over scenes of (value / the scene's best value): (policy, that mean, scenes
    where it is the best). A policy with an infinite value on a scene ranks last. Lower values are better."""
    policies = sorted({p for values in per_scene.values() for p in values})
    scored = []
    for policy in policies:
        logs, wins = [], 0
        for values in per_scene.values():
            if policy not in values:
                continue
            finite = [v for v in values.values() if _finite(v)]
            best = min(finite) if finite else math.nan
            value = values[policy]
            if not _finite(value):
                logs.append(math.inf)
                continue
            if value <= best:
                wins += 1
            logs.append(0.0 if value == best else math.log(max(value, 1e-300) / max(best, 1e-300)))
        mean = math.exp(sum(logs) / len(logs)) if logs and all(math.isfinite(v) for v in logs) else math.inf
        scored.append((policy, mean, wins))
    return sorted(scored, key=lambda item: (item[1], -item[2], item[0]))


# Consistency at or below this (relative to the amplitude) is rounding: the runs are the same motion.
IDENTICAL = 1e-9


def _consistency(report) -> str | None:
    per_scene = {s: {p: report.consistency[s][p][_first(report, s)] for p in report.policies[s]}
                 for s in report.scenes if s in report.consistency}
    if not per_scene:
        return None
    policies = list(dict.fromkeys(p for values in per_scene.values() for p in values))
    same = [p for p in policies if all(_finite(v.get(p)) and v[p] <= IDENTICAL for v in per_scene.values())]
    moving = {s: {p: v for p, v in values.items() if p not in same} for s, values in per_scene.items()}
    ranking = _ranking(moving) if any(moving.values()) else []
    parts = []
    if same:
        parts.append(" and ".join(f"<b>{html.escape(p)}</b>" for p in same)
                     + f": the same motion under every frame-time profile on all {len(per_scene)} scenes "
                     f"(consistency ≤ {IDENTICAL:g}): every physics step has the same length whatever the frames")
    if ranking and math.isfinite(ranking[0][1]):
        best = ranking[0][0]
        text = ", ".join(f"{html.escape(p)} {_x(m)}" for p, m, _ in ranking)
        lead = "among the policies whose steps follow the frames, " if same else ""
        parts.append(f"{lead}<b>{html.escape(best)}</b> is the most alike across profiles (consistency as a multiple "
                     f"of each scene's best, geometric mean over scenes: {text})")
    return "; ".join(parts) + ". " + _link("consistency", "consistency table")


def _accuracy_exact(report) -> str | None:
    entries = [e for e in report.side_by_side if e["profile"] == "uniform:15:45" and _finite(e["rms_vs_exact"])]
    if not entries:
        return None
    entries.sort(key=lambda e: e["rms_vs_exact"])
    best = entries[0]
    others = ", ".join(f"{html.escape(e['policy'])} {e['rms_vs_exact']:.2g}" for e in entries[1:])
    return (f"<b>{html.escape(best['policy'])}</b>: closest to the exact solution of the oscillator at 15-45 fps, "
            f"RMS error {best['rms_vs_exact']:.2g}·x0 (then {others}). " + _link("exact", "oscillator table"))


def _accuracy_reference(report) -> str | None:
    per_scene = {s: {p: report.spreads[s][p][_first(report, s)] for p in report.policies[s]}
                 for s in report.scenes if s in report.spreads}
    ranking = _ranking(per_scene)
    if not ranking or not math.isfinite(ranking[0][1]):
        return None
    best, mean, wins = ranking[0]
    runner = [f"{html.escape(p)} {_x(m)}" for p, m, _ in ranking[1:4]]
    return (f"<b>{html.escape(best)}</b>: closest to the fine-step reference over all scenes: its deviation (RMS over "
            f"profiles) is {_x(mean)} the best policy's of each scene, as a geometric mean over the "
            f"{len(per_scene)} scenes, " + (f"and the lowest on {wins} of them" if wins else
                                             "though the lowest on none of them alone")
            + f" (next: {', '.join(runner)}). "
            + _link("deviation", "deviation table"))


CHEAP_TIE = 0.1


def _cost(report) -> str | None:
    by_policy: dict[str, list[float]] = {}
    overhead: dict[str, list[float]] = {}
    for c in report.costs:
        if _finite(c.ratio_median):
            by_policy.setdefault(c.policy, []).append(c.ratio_median)
        if _finite(c.overhead_median):
            overhead.setdefault(c.policy, []).append(c.overhead_median)
    if not by_policy:
        return None
    medians = {p: statistics.median(v) for p, v in by_policy.items()}
    order = sorted(medians, key=medians.get)
    accurate = [p for p in order if p != "naive"]
    text = ", ".join(f"{html.escape(p)} {_x(medians[p])}" for p in order)
    cheapest = accurate[0] if accurate else order[0]
    # Medians within CHEAP_TIE of the cheapest are not told apart by one benchmark run.
    alike = [p for p in accurate if medians[p] <= medians[cheapest] * (1 + CHEAP_TIE)] or [cheapest]
    profile = report.costs[0].profile
    who = " and ".join(f"<b>{html.escape(p)}</b>" for p in alike)
    library = ", ".join(f"{html.escape(p)} {_x(statistics.median(v))}" for p, v in overhead.items())
    return (f"{who}: the cheapest {'policy' if len(alike) == 1 else f'policies (within {CHEAP_TIE:.0%})'} whose "
            f"softness follows the step. Wall time per frame against a program's own loop (one plain ODE step a "
            f"frame) under {html.escape(profile)} frames, median over scenes: {text}. That is the substeps (steps "
            f"per frame in the table): against plain ODE taking the same steps, the library itself costs "
            f"{library}. " + _link("cost", "cost table"))


def _stable(report) -> str | None:
    """The policies stable up to the longest steps: best on the worst probed scene, then on the geometric mean over
    the probed scenes; where the others fall short of the best, and where they go further."""
    by_policy: dict[str, dict[str, float]] = {}
    for scene, results in report.probes.items():
        for r in results:
            by_policy.setdefault(r.policy, {})[scene] = r.stable_s
    if not by_policy:
        return None

    def score(policy):
        values = list(by_policy[policy].values())
        worst = min(values)
        mean = math.exp(statistics.fmean(math.log(max(v, 1e-9)) for v in values))
        return worst, mean

    best_score = max(score(p) for p in by_policy)
    best = [p for p in by_policy if score(p) == best_score]
    reference = by_policy[best[0]]
    worst_scene = min(reference, key=reference.get)
    text = (" and ".join(f"<b>{html.escape(p)}</b>" for p in best)
            + f": stable up to the longest steps, {_ms(reference[worst_scene])} on the hardest scene ({worst_scene}), "
            f"{_ms(best_score[1])} as the geometric mean over the {len(reference)} probed scenes")
    shortfalls = []
    for policy, values in by_policy.items():
        short = [f"{scene} {_ms(v)} against {_ms(reference[scene])}" for scene, v in values.items()
                 if scene in reference and v < reference[scene]]
        if short and policy not in best:
            shortfalls.append(f"{html.escape(policy)} is shorter on {', '.join(short)}")
    if shortfalls:
        text += "; " + "; ".join(shortfalls)
    # Ranked on the hardest scene and the mean, the best may still be beaten on one scene: say where.
    beaten = []
    for scene, best_value in reference.items():
        further = [f"{html.escape(p)} {_ms(v[scene])}" for p, v in by_policy.items()
                   if p not in best and v.get(scene, 0) > best_value]
        if further:
            beaten.append(f"on {scene}, {', '.join(further)} against {_ms(best_value)}")
    if beaten:
        text += "; longer than the best elsewhere: " + "; ".join(beaten)
    return text + ". " + _link("stable", "largest stable step")


def _failures(report) -> str | None:
    failed: dict[str, list[str]] = {}
    for r in report.rows:
        if r.status != "ok":
            failed.setdefault(r.policy, []).append(f"{r.scene} {r.profile} ({r.status})")
    if not failed:
        return "No run blew up or broke. " + _link("runs", "every run")
    items = "; ".join(f"<b>{html.escape(p)}</b>: {len(v)} run{'s' if len(v) > 1 else ''} "
                      f"({html.escape(', '.join(v[:3]))}{', ...' if len(v) > 3 else ''})" for p, v in failed.items())
    return f"Failed (blew up or broke): {items}. " + _link("runs", "every run")


def recommendation(report) -> str:
    """The opening section: one line per need, each made from this run's numbers and linked to its evidence."""
    lines = [("Same motion at every frame rate", _consistency(report)),
             ("Closest to the exact solution", _accuracy_exact(report)),
             ("Closest to the fine-step reference", _accuracy_reference(report)),
             ("Cheapest", _cost(report)),
             ("Largest stable step", _stable(report)),
             ("Avoid", _failures(report))]
    items = "".join(f"<li><b>{html.escape(need)}:</b> {text}</li>" for need, text in lines if text)
    return ("<section id='recommendation'><h2>Which policy for which need</h2>"
            "<p class=small>Every line below is computed from this run's numbers and links to the table that shows "
            "it.</p>"
            f"<ul class='answers'>{items}</ul>"
            "<h3>The policies</h3>" + definitions(runs.policy_names()) + "</section>")

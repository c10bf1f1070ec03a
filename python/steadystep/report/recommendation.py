"""The report's opening: the policies defined, and the recommendation computed from this run's numbers.

Every sentence of the recommendation is made from the metrics on the page (never typed once and left to go
stale), says for which scenes it holds (each scene a kind of program: its description, in the table "per scene"),
and links to the table or figure that shows it. The needs it answers:

- consistency: the same motion at every frame rate (lab/consistency.py: runs of one policy against each other);
- what cutting the frame gives and what each mapping adds: naive, then the control substeps-frozen (the same
  frozen softness, the frame cut into substeps), then implicit-euler, matched and exact (the same cut, the
  softness mapped to each step);
- accuracy: closest to the exact solution (the oscillator at 15-45 fps) and to the fine-step reference (the
  deviation, RMS over profiles);
- where the accurate mappings serve: the share of rows and contacts they served, and what fell back;
- cost: CPU time against plain ODE in one interleaved benchmark (lab/cost.py);
- the largest stable step (lab/probe.py);
and which policies failed (blew up or broke) on some run. The section ends with the lines of code to write for the
policy its first line recommends (code_policy, steadystep.report.snippets): the one with the same motion under every
profile, else the one most alike across profiles on the most scenes.

A winner is named only where its lead is larger than the measured spread of repeats: for the deviation and the
consistency, how much each moved when the random profiles were run again with the next seed
(aggregate.py); for the cost, the ranges over the benchmark's blocks. Otherwise the page says they tie.
Every piece of markup here is a markupsafe.Markup whose arguments are escaped as they are put in (Markup.format,
Markup.join): nothing is escaped by hand.
"""

from __future__ import annotations

import math
import statistics

from markupsafe import Markup

from steadystep.lab import runs
from steadystep.core._native import lib

# The mapping enum (stepping.h) by value; each mapping's one-line meaning (DESIGN.md, docs/exact-mappings.md).
MAPPINGS = {
    lib.SS_MAPPING_IMPLICIT_EULER: ("implicit Euler", "the article's erp = hk/(hk+c), cfm = 1/(hk+c) for each step "
                                    "h: ODE's step is then the implicit-Euler step of the spring-damper"),
    lib.SS_MAPPING_MATCHED: ("matched", "erp and cfm chosen so that a step of h decays and turns exactly as the "
                             "spring-damper does over h (exact at a constant step)"),
    lib.SS_MAPPING_EXACT: ("exact", "erp and cfm solved from the step before, so that a linear spring-damper's "
                           "samples equal the exact solution under any sequence of steps"),
}
# The ladder that separates the cut from the mapping: each policy differs from the one before in one thing.
CONTROL_LADDER = ("naive", "substeps-frozen", "implicit-euler", "matched", "exact")
# Consistency at or below this (relative to the amplitude) is rounding: the runs are the same motion.
IDENTICAL = 1e-9


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


def definitions(policies: list[str]) -> list[list[str]]:
    """Each policy's (name, cut, mapping), read from the library's own presets (runs.make_stepping)."""
    return [[policy, cut_text(s), mapping_text(s)] for policy in policies for s in [runs.make_stepping(policy)]]


def _first(scene: str) -> str:
    return runs.motion_quantities(scene)[0]


def _finite(value) -> bool:
    return value is not None and isinstance(value, (int, float)) and math.isfinite(value)


def link(anchor: str, text: str) -> Markup:
    return Markup("<a href='#{}'>{}</a>").format(anchor, text)


def bold(text: str) -> Markup:
    return Markup("<b>{}</b>").format(text)


def _x(value: float) -> str:
    return f"×{value:.3g}" if math.isfinite(value) else "∞"


def _and(items) -> Markup:
    return Markup(", ").join(items)


def leaders(values: dict[str, float], noise: dict[str, float] | None = None) -> list[str]:
    """The policies tied for the lowest value: the lowest, and every other whose value less its spread of repeats
    reaches the lowest's plus its own (lower is better; a spread not measured counts 0). One name: a winner."""
    finite = {p: v for p, v in values.items() if _finite(v)}
    if not finite:
        return []
    noise = {p: n if _finite(n) else 0.0 for p, n in (noise or {}).items()}
    best = min(finite, key=lambda p: (finite[p], p))
    reach = finite[best] + noise.get(best, 0.0)
    tied = [p for p in finite if p == best or finite[p] - noise.get(p, 0.0) <= reach]
    return sorted(tied, key=lambda p: (finite[p], p))


def _verdict(tied: list[str]) -> Markup:
    if len(tied) == 1:
        return bold(tied[0])
    return Markup("tie: {}").format(_and(bold(p) for p in tied))


def _per_scene(report, values: dict, noise: dict, zero: float = 0.0, exclude=()) -> dict[str, list[str]]:
    """scene -> the leaders on its first quantity (values, noise: scene -> policy -> quantity)."""
    out = {}
    for scene in report.scenes:
        if scene not in values:
            continue
        q = _first(scene)
        cells = {p: values[scene][p][q] for p in report.policies[scene] if p in values[scene] and p not in exclude}
        cells = {p: 0.0 if _finite(v) and v <= zero else v for p, v in cells.items()}
        spread = {p: noise.get(scene, {}).get(p, {}).get(q, 0.0) for p in cells}
        out[scene] = leaders(cells, spread)
    return out


def _grouped(by_scene: dict[str, list[str]]) -> Markup:
    """"p on a, b; tie (p, q) on c": each verdict with the scenes it holds for, linked to their sections."""
    groups: dict[tuple, list[str]] = {}
    for scene, tied in by_scene.items():
        if tied:
            groups.setdefault(tuple(tied), []).append(scene)
    parts = [Markup("{} on {}").format(_verdict(list(tied)), _and(link(s, s) for s in scenes))
             for tied, scenes in sorted(groups.items(), key=lambda item: (len(item[0]), -len(item[1])))]
    return Markup("; ").join(parts)


def same_everywhere(report) -> list[str]:
    """The policies whose motion is the same under every profile on every scene (consistency <= IDENTICAL)."""
    per_scene = {s: {p: report.consistency[s][p][_first(s)] for p in report.policies[s]}
                 for s in report.scenes if s in report.consistency}
    policies = list(dict.fromkeys(p for values in per_scene.values() for p in values))
    return [p for p in policies if per_scene and all(_finite(v.get(p)) and v[p] <= IDENTICAL
                                                     for v in per_scene.values())]


def _consistency(report) -> Markup | None:
    per_scene = {s: {p: report.consistency[s][p][_first(s)] for p in report.policies[s]}
                 for s in report.scenes if s in report.consistency}
    if not per_scene:
        return None
    same = same_everywhere(report)
    parts = []
    if same:
        parts.append(Markup("{}: the same motion under every frame-time profile on all {} scenes (consistency ≤ {}): "
                            "every physics step has the same length whatever the frames")
                     .format(Markup(" and ").join(bold(p) for p in same), len(per_scene), f"{IDENTICAL:g}"))
    moving = _per_scene(report, report.consistency, getattr(report, "repeat_consistency", {}), IDENTICAL, same)
    if any(moving.values()):
        lead = "among the policies whose steps follow the frames, the most alike across profiles: " if same else \
            "the most alike across profiles: "
        parts.append(Markup("{}{}").format(lead, _grouped(moving)))
    return Markup("; ").join(parts) + Markup(". ") + link("consistency", "consistency table")


def control_ladder(report) -> dict[str, list[tuple[str, float, float]]]:
    """scene -> [(policy, consistency, deviation) of its first quantity] along CONTROL_LADDER, for the policies
    the scene ran."""
    out = {}
    for scene in report.scenes:
        if scene not in report.consistency:
            continue
        q = _first(scene)
        ladder = [(p, report.consistency[scene][p][q], report.spreads[scene][p][q]) for p in CONTROL_LADDER
                  if p in report.consistency[scene]]
        if {"naive", "substeps-frozen", "implicit-euler"} <= {p for p, _, _ in ladder}:
            out[scene] = ladder
    return out


def _number(value) -> str:
    return "failed" if value is not None and math.isinf(value) else "-" if not _finite(value) else f"{value:.2g}"


def _cut_and_mapping(report) -> Markup | None:
    ladders = control_ladder(report)
    if not ladders:
        return None
    parts = []
    for scene, ladder in ladders.items():
        values = {p: c for p, c, _ in ladder}
        parts.append(Markup("{}: {}").format(link(scene, scene), Markup(" → ").join(
            f"{_number(values[p])}" for p in ("naive", "substeps-frozen", "implicit-euler"))))
    return (Markup("the consistency of each scene's first quantity from naive (one step a frame) to the control "
                   "substeps-frozen (substeps, the softness still frozen at the tuned step: what cutting the frame "
                   "gives) to implicit-euler (the same substeps, the softness mapped to each: what the mapping adds): ")
            + Markup("; ").join(parts) + Markup(". ") + link("control", "cut and mapping table"))


def _accuracy_exact(report) -> Markup | None:
    entries = [e for e in report.side_by_side if e["profile"] == "uniform:15:45" and _finite(e["rms_vs_exact"])]
    if not entries:
        return None
    entries.sort(key=lambda e: e["rms_vs_exact"])
    best = entries[0]
    others = _and(f"{e['policy']} {e['rms_vs_exact']:.2g}" for e in entries[1:])
    return Markup("{}: closest to the exact solution of the oscillator at 15-45 fps, RMS error {}·x0 (then {}); a "
                  "deterministic comparison with the exact solution, not a repeat. ").format(
        bold(best["policy"]), f"{best['rms_vs_exact']:.2g}", others) + link("exact", "oscillator table")


def _accuracy_reference(report) -> Markup | None:
    per_scene = _per_scene(report, report.spreads, getattr(report, "repeat_deviation", {}))
    if not any(per_scene.values()):
        return None
    return (Markup("the lowest deviation (RMS over profiles) of each scene's first quantity, ties within the spread "
                   "of repeats: ") + _grouped(per_scene) + Markup(". ") + link("deviation", "deviation table"))


ACCURATE = ("matched", "exact", "fixed-matched", "fixed-exact")


def served_shares(counts: dict[str, int]) -> tuple[float, float, float, int]:
    """(by the mapping, handed to matched, handed to implicit Euler) as shares of the total, and the total."""
    total = sum(counts.values())
    if not total:
        return math.nan, math.nan, math.nan, 0
    return (counts["by_mapping"] / total, counts["handed_to_matched"] / total,
            counts["handed_to_implicit_euler"] / total, total)


def percent(share: float) -> str:
    return "-" if not _finite(share) else f"{100 * share:.0f} %"


def _served(report) -> Markup | None:
    served = getattr(report, "served", {})
    parts = []
    for scene, by_policy in served.items():
        pieces = []
        for policy in (p for p in ("matched", "exact") if p in by_policy):
            rows, contacts = (served_shares(by_policy[policy][what]) for what in ("rows", "contacts"))
            said = [f"{percent(share[0])} of its {what}" for what, share in (("rows", rows), ("contacts", contacts))
                    if share[3]]
            if said:
                pieces.append(Markup("{} serves {}").format(policy, " and ".join(said)))
        if pieces:
            parts.append(Markup("{}: {}").format(link(scene, scene), _and(pieces)))
    if not parts:
        return None
    return (Markup("the share of row-steps and contacts each accurate mapping served itself (the rest fell back, "
                   "mostly to implicit Euler): ") + Markup("; ").join(parts) + Markup(". ")
            + link("served", "served table"))


def cost_leaders(costs) -> dict[str, list[str]]:
    """scene -> the policies (not naive) tied for the cheapest: the cheapest by median ratio, and every other
    whose range over the benchmark's blocks reaches into the cheapest's."""
    by_scene: dict[str, dict] = {}
    for c in costs:
        if c.policy != "naive" and _finite(c.ratio_median):
            by_scene.setdefault(c.scene, {})[c.policy] = c
    out = {}
    for scene, entries in by_scene.items():
        best = min(entries, key=lambda p: (entries[p].ratio_median, p))
        out[scene] = sorted((p for p, c in entries.items() if p == best or c.ratio_low <= entries[best].ratio_high),
                            key=lambda p: (entries[p].ratio_median, p))
    return out


def _cost(report) -> Markup | None:
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
    text = _and(f"{p} {_x(medians[p])}" for p in sorted(medians, key=medians.get))
    library = _and(f"{p} {_x(statistics.median(v))}" for p, v in overhead.items())
    return (Markup("the cheapest policy that cuts the frame (naive aside), per scene, a tie where the ranges over "
                   "the benchmark's blocks overlap: {}. Wall time per frame against a program's own loop (one "
                   "plain ODE step a frame) under {} frames, median over scenes: {}. That is the substeps (steps "
                   "per frame in the table): against plain ODE taking the same steps, the library itself costs {}. ")
            .format(_grouped(cost_leaders(report.costs)), report.costs[0].profile, text, library)
            + link("cost", "cost table"))


def _stable(report) -> Markup | None:
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
    text = Markup("{}: stable up to the longest steps, {} on the hardest scene ({}), {} as the geometric mean over "
                  "the {} probed scenes").format(Markup(" and ").join(bold(p) for p in best),
                                                 _ms(reference[worst_scene]), worst_scene, _ms(best_score[1]),
                                                 len(reference))
    shortfalls = []
    for policy, values in by_policy.items():
        short = [f"{scene} {_ms(v)} against {_ms(reference[scene])}" for scene, v in values.items()
                 if scene in reference and v < reference[scene]]
        if short and policy not in best:
            shortfalls.append(Markup("{} is shorter on {}").format(policy, ", ".join(short)))
    if shortfalls:
        text += Markup("; ") + Markup("; ").join(shortfalls)
    # Ranked on the hardest scene and the mean, the best may still be beaten on one scene: say where.
    beaten = []
    for scene, best_value in reference.items():
        further = [f"{p} {_ms(v[scene])}" for p, v in by_policy.items()
                   if p not in best and v.get(scene, 0) > best_value]
        if further:
            beaten.append(Markup("on {}, {} against {}").format(scene, ", ".join(further), _ms(best_value)))
    if beaten:
        text += Markup("; longer than the best elsewhere: ") + Markup("; ").join(beaten)
    not_probed = getattr(report, "not_probed", [])
    if not_probed:
        text += Markup("; not probed: {}").format(", ".join(not_probed))
    return text + Markup(". ") + link("stable", "largest stable step")


def _failures(report) -> Markup:
    failed: dict[str, list[str]] = {}
    for r in report.rows:
        if r.status != "ok":
            failed.setdefault(r.policy, []).append(f"{r.scene} {r.profile} ({r.status})")
    if not failed:
        return Markup("No run blew up or broke. ") + link("runs", "every run")
    items = Markup("; ").join(
        Markup("{}: {} run{} ({}{})").format(bold(p), len(v), "s" if len(v) > 1 else "", ", ".join(v[:3]),
                                           ", ..." if len(v) > 3 else "") for p, v in failed.items())
    return Markup("Failed (blew up or broke): {}. ").format(items) + link("runs", "every run")


def recommendation(report) -> list[tuple[str, Markup]]:
    """The opening section's lines: (need, text), each made from this run's numbers and linked to its evidence."""
    lines = [("Same motion at every frame rate", _consistency(report)),
             ("What cutting the frame gives, what the mapping adds", _cut_and_mapping(report)),
             ("Closest to the exact solution", _accuracy_exact(report)),
             ("Closest to the fine-step reference", _accuracy_reference(report)),
             ("Where the accurate mappings serve", _served(report)),
             ("Cheapest", _cost(report)),
             ("Largest stable step", _stable(report)),
             ("Avoid", _failures(report))]
    return [(need, text) for need, text in lines if text]


def code_policy(report) -> tuple[str, Markup] | None:
    """The policy whose code the opening section ends with, and why, from the first line's numbers: the first (in
    the library's order of presets) whose motion is the same under every profile on every scene; else the preset
    that is most alike across profiles (or tied for it) on the most scenes; None when neither is measured. Only the
    library's presets (stepping.h) have code: the lab's control substeps-frozen does not."""
    from steadystep.core.stepping import policy_names

    presets = policy_names()
    same = [p for p in presets if p in same_everywhere(report)]
    if same:
        return same[0], Markup("the same motion at every frame rate, as the first line says (") + link(
            "consistency", "consistency table") + Markup(")")
    per_scene = {s: values for s, values in _per_scene(report, report.consistency,
                                                        getattr(report, "repeat_consistency", {}), IDENTICAL).items()}
    counts = {p: sum(p in leaders for leaders in per_scene.values()) for p in presets}
    if not any(counts.values()):
        return None
    best = max(presets, key=lambda p: (counts[p], -presets.index(p)))
    return best, Markup("the most alike across frame rates on {} of the {} scenes, as the first line says (").format(
        counts[best], len(per_scene)) + link("consistency", "consistency table") + Markup(")")


def per_scene(report) -> list[dict]:
    """One entry per scene for the table "which policy for which kind of scene": the scene, its kind (the
    library's description), and the verdicts for consistency (among the policies whose steps follow the frames),
    deviation and cost, each a winner or a tie."""
    consistent = _per_scene(report, report.consistency, getattr(report, "repeat_consistency", {}), IDENTICAL,
                            same_everywhere(report))
    accurate = _per_scene(report, report.spreads, getattr(report, "repeat_deviation", {}))
    cheap = cost_leaders(report.costs)
    return [{"scene": s, "kind": runs.scene_info(s).description, "consistency": consistent.get(s, []),
             "deviation": accurate.get(s, []), "cost": cheap.get(s, [])} for s in report.scenes]


def verdict(tied: list[str]) -> Markup:
    """A winner in bold, or "tie: ..." (the table cells)."""
    return _verdict(tied) if tied else Markup("-")

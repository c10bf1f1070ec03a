"""report.html: the comparison's page, built with Jinja2 with autoescape on (every value is escaped unless it is a
markupsafe.Markup, which only report/recommendation.py, report/animation.py and the cells below make, their arguments
escaped as they go in). The templates are in report/templates.py."""

from __future__ import annotations

import math
import platform
import time
from pathlib import Path

import numpy as np

from markupsafe import Markup

from steadystep.report import animation, figures, recommendation as page, snippets
from steadystep.report.cells import bad, cell, embed, embed_png, number, status_cell  # noqa: F401
from steadystep.lab import cost, runs
from steadystep.report.export import swept_axes
from steadystep.report.model import Report
from steadystep.report.tasks import NOT_PROBED
from steadystep.report.templates import ENVIRONMENT
from steadystep.report.validate import GRID_AXES


# Enum-valued settings by field name, shown by their names (the C integers meant nothing on a page).
_SETTING_ENUMS = {"cut": "FrameCut", "mapping": "Mapping", "solver": "Solver"}


def machine_line(report) -> str:
    """The cores and the load beside the timings: "2 cores (2 usable), load 3.1 at the start, 3.4 before the cost
    benchmark, 2.9 after it (1-minute averages)"; what was not recorded is left out."""
    machine = getattr(report, "machine", None) or {}
    cores = f"{machine['cores']:.0f} cores ({machine.get('usable_cores', machine['cores']):.0f} usable)" \
        if machine.get("cores") else "an unknown number of cores"
    loads = [f"{machine[key]:.1f} {when}" for key, when in (("load_at_start", "at the start"),
                                                            ("load_before_cost", "before the cost benchmark"),
                                                            ("load_after_cost", "after it"))
             if machine.get(key) is not None]
    return cores + (f", load {', '.join(loads)} (1-minute averages)" if loads else ", load not recorded")


def readable_settings(settings: dict | None) -> str:
    """Settings as a person reads them: "name = value" by field, enums by name in lower case with dashes
    (cut = substeps, solver = quick), seconds with their unit, nested dicts in parentheses; "-" for none."""
    from steadystep.core import enums

    def shown(name: str, value) -> str:
        if isinstance(value, dict):
            return f"{name} ({readable_settings(value)})"
        if name in _SETTING_ENUMS and isinstance(value, int):
            try:
                value = getattr(enums, _SETTING_ENUMS[name])(value).name.lower().replace("_", "-")
            except ValueError:
                pass
        elif isinstance(value, float):
            value = f"{value:g} s" if name.endswith("_s") else f"{value:g}"
        return f"{name} = {value}"

    return ", ".join(shown(name, value) for name, value in (settings or {}).items()) or "-"


def policy_cell(policy: str) -> Markup:
    return Markup('<span class="dot" style="background:{}"></span>{}').format(figures.policy_color(policy), policy)


def _all_policies(report: Report) -> list[str]:
    return list(dict.fromkeys(p for s in report.scenes for p in report.policies[s]))


def by_scene(report: Report, values: dict, noise: dict, zero: float = 0.0) -> dict:
    """A scene x policy table of values[scene][policy][first motion quantity], the leaders of a row (the lowest,
    and those tied with it within the spread of repeats) in bold, the spread beside each value."""
    policies = _all_policies(report)
    rows = []
    for scene in report.scenes:
        if scene not in values:
            continue
        quantity = runs.motion_quantities(scene)[0]
        cells = {p: values[scene][p][quantity] for p in report.policies[scene] if p in values[scene]}
        # At or below zero the numbers are rounding: shown as 0, all of them the best.
        cells = {p: 0.0 if v is not None and math.isfinite(v) and v <= zero else v for p, v in cells.items()}
        spread = {p: noise.get(scene, {}).get(p, {}).get(quantity, math.nan) for p in cells}
        leaders = page.leaders(cells, spread)
        row = [page.link(scene, scene), quantity]
        for p in policies:
            text = number(cells.get(p))
            if p in cells and math.isfinite(spread.get(p, math.nan)) and spread[p] > 0:
                text = f"{text} ± {number(spread[p], 2)}"
            row.append(page.bold(text) if p in leaders else text)
        rows.append(row)
    return {"header": ["scene", "quantity"] + [policy_cell(p) for p in policies], "rows": rows}


def control_table(report: Report) -> dict:
    ladders = page.control_ladder(report)
    policies = [p for p in page.CONTROL_LADDER if any(p == q for ladder in ladders.values() for q, _, _ in ladder)]
    rows = []
    for scene, ladder in ladders.items():
        values = {p: (c, d) for p, c, d in ladder}
        rows.append([page.link(scene, scene), runs.motion_quantities(scene)[0]]
                    + [f"{number(values[p][0])} / {number(values[p][1])}" if p in values else "-" for p in policies])
    return {"header": ["scene", "quantity"] + [policy_cell(p) for p in policies], "rows": rows}


def served_table(report: Report) -> dict:
    rows = []
    for scene, by_policy in report.served.items():
        for policy in (p for p in page.ACCURATE if p in by_policy):
            if not any(sum(by_policy[policy][what].values()) for what in ("rows", "contacts")):
                continue  # nothing bound and nothing softened through the stepper: nothing to serve
            row = [page.link(scene, scene), policy_cell(policy)]
            for what in ("rows", "contacts"):
                mapped, matched, implicit, total = page.served_shares(by_policy[policy][what])
                row += [str(total)] + ([page.percent(v) for v in (mapped, matched, implicit)] if total else
                                       ["-", "-", "-"])
            rows.append(row)
    header = ["scene", "policy"] + [f"{what} {column}" for what in ("row-steps", "contacts")
                                    for column in ("counted", "served by the mapping", "handed to matched",
                                                   "handed to implicit Euler")]
    return {"header": header, "rows": rows}


def _blocks(costs) -> str:
    """How many blocks the benchmark measured: "7", or "3 to 7" when some pairs stopped after a rotation
    (cost.TIGHT_RANGE)."""
    counts = sorted({c.repeats for c in costs if c.status == "ok"}) or [0]
    return f"{counts[0]}" if len(counts) == 1 else f"{counts[0]} to {counts[-1]}"


NOT_ALIKE = "not like with like"


def _ratio_cells(ok: bool, median: float, low: float, high: float, blocks: int, measured: int,
                 digits: int = 3) -> list:
    """A ratio's median and range over the blocks it counts (lab/cost.py: those whose two copies had as many bodies
    awake before and after); "not like with like" where no block did, the count where only some did."""
    if not ok:
        return ["-", "-"]
    if blocks == 0 or not math.isfinite(median):
        return [Markup("<span title='{}'>{}</span>").format(
            "one copy fell asleep (auto-disable) and the other did not, in every block", NOT_ALIKE), "-"]
    spread = f"{number(low, digits)} – {number(high, digits)}"
    return [f"×{number(median, digits)}", spread + (f" ({blocks} of {measured} blocks)" if blocks < measured else "")]


def cost_table(report: Report) -> dict:
    rows = []
    for c in report.costs:
        ok = c.status == "ok"
        rows.append([c.scene, policy_cell(c.policy), str(c.repeats) if ok else "-", number(c.steps_per_frame),
                     number(c.us_per_frame) if ok else bad(c.status)]
                    + _ratio_cells(ok, c.ratio_median, c.ratio_low, c.ratio_high, c.ratio_blocks, c.repeats)
                    + _ratio_cells(ok, c.overhead_median, c.overhead_low, c.overhead_high, c.overhead_blocks,
                                   c.repeats, 4))
    return {"header": ["scene", "policy", "blocks", "steps / frame", "CPU µs / frame",
                       "per frame / program's own (median)", "range over blocks",
                       "library: / plain ODE at the same steps (median)", "range over blocks"],
            "rows": rows}


def stable_table(report: Report) -> dict:
    policies = _all_policies(report)
    rows = []
    for scene, results in report.probes.items():
        by_policy = {}
        for r in results:
            by_policy.setdefault(r.policy, r)  # a study's grid: its first point
        cells = [scene]
        for p in policies:
            r = by_policy.get(p)
            if r is None:
                cells.append("-")
            elif not math.isfinite(r.unstable_s):
                cells.append(f"≥ {number(1000 * r.stable_s, 4)}")
            else:
                cells.append(Markup("<span title='{}'>{}</span>").format(r.reason or "",
                                                                         number(1000 * r.stable_s, 4)))
        rows.append(cells)
    return {"header": ["scene"] + [policy_cell(p) for p in policies], "rows": rows}


def side_by_side_table(report: Report) -> dict:
    rows = []
    for e in report.side_by_side:
        status = e["status"]
        rows.append([e["profile"], policy_cell(e["policy"]), cell(e["rms_vs_exact"], status),
                     number(e["decay_rate_per_s"], 4), number(e["true_decay_rate_per_s"], 4),
                     number(e["angular_frequency_rad_s"], 5), number(e["true_angular_frequency_rad_s"], 5),
                     status_cell(status)])
    return {"header": ["profile", "policy", "RMS vs exact / x0", "fitted decay (1/s)", "true decay (1/s)",
                       "fitted ω (rad/s)", "true ω (rad/s)", "status"], "rows": rows}


def scene_section(report: Report, scene: str) -> dict:
    quantities = runs.motion_quantities(scene)
    info = runs.scene_info(scene)
    units = dict(zip(info.quantities, info.units))
    swept = swept_axes(report)
    header = (["profile", "policy"] + [f"{a} ({GRID_AXES[a]})" for a in swept]
              + [f"deviation of {q}" for q in quantities]
              + (["RMS vs exact / x0"] if scene == "oscillator" else [])
              + ["steps / frame", "rows served by implicit Euler", "contacts served by implicit Euler", "status"])
    rows = []
    for r in (r for r in report.rows if r.scene == scene):
        fallback = r.policy in page.ACCURATE
        rows.append([r.profile, policy_cell(r.policy)] + [number(r.grid[a], 6) for a in swept]
                    + [cell(r.deviations[q], r.status) for q in quantities]
                    + ([cell(r.rms_vs_exact, r.status)] if scene == "oscillator" else [])
                    + [number(r.steps_per_frame), str(r.rows_handed_to_implicit_euler) if fallback else "-",
                       str(r.contacts_handed_to_implicit_euler) if fallback else "-", status_cell(r.status)])
    return {"scene": scene, "description": info.description, "table": {"header": header, "rows": rows},
            "units": ", ".join(f"{q} in {units[q]}" for q in quantities),
            "images": [embed(p) for p in report.figures.get(scene, []) if p.suffix == ".png"]}


def code_to_write(report: Report) -> dict | None:
    """The end of the opening section: the policy its first line recommends, why, and the C and Python snippets."""
    chosen = page.code_policy(report)
    if chosen is None:
        return None
    policy, why = chosen
    return {"policy": policy, "why": why, "summary": snippets.summary(policy),
            "snippets": snippets.for_policy(policy)}


def answer(report: Report) -> dict | None:
    """The page's first sentence and picture: for these scenes, what changes with the frame rate under each policy
    (the policies whose motion is the same at every frame rate, or the most alike), the recommended policy (the one
    the code is written for) and its cost in one number: the median over the scenes of its CPU time against the
    program's plain loop (one step a frame), with the cores and the load it was measured under; the picture
    (answer.py): per scene and policy, each profile's deviation from the fine-step reference and the
    consistency, the recommended policy in bold."""
    chosen = page.code_policy(report)
    if chosen is None:
        return None
    policy = chosen[0]
    same = page.same_everywhere(report)
    if same:
        what = (f"only {', '.join(same)} gave the same motion at every frame rate; under every other policy the "
                "motion changed with the frame rate")
    else:
        what = "under every policy the motion changed with the frame rate"
    ratios = [c.ratio_median for c in report.costs if c.policy == policy and c.status == "ok" and c.ratio_median > 0]
    machine = report.machine
    load = f", load {machine['load_before_cost']:.1f}" if machine.get("load_before_cost") is not None else ""
    cores = f"; {machine['cores']:.0f} cores{load}" if machine.get("cores") else ""
    costs = (f"; it costs about {float(np.median(ratios)):.1f} times the program's plain loop (one step a frame, "
             f"CPU time: median over {len(ratios)} scene{'s' if len(ratios) != 1 else ''}{cores})") if ratios else ""
    figure = None
    if report.rows:
        from steadystep.report import answer as report_answer

        figure = embed_png(report_answer.png(report, policy, page.IDENTICAL), "answer-figure",
                           "per scene and policy, each frame-time profile's deviation from the fine-step reference")
    return {"sentence": f"For these scenes ({', '.join(report.scenes)}), {what}. Use {policy}{costs}.",
            "figure": figure}


def as_html(report: Report, command: str, article_paths: list[Path]) -> str:
    """The whole page."""
    pngs = [p for p in article_paths if p.suffix == ".png"]
    return ENVIRONMENT.get_template("report.html").render(
        report=report, command=command,
        recommendation=page.recommendation(report), code=code_to_write(report), answer=answer(report),
        per_scene=[{**entry, "consistency": page.verdict(entry["consistency"]),
                    "deviation": page.verdict(entry["deviation"]), "cost": page.verdict(entry["cost"])}
                   for entry in page.per_scene(report)],
        policies=page.definitions(runs.policy_names()),
        animation=animation.section(report.animation) if report.animation else None,
        consistency=by_scene(report, report.consistency, report.repeat_consistency, page.IDENTICAL),
        deviation=by_scene(report, report.spreads, report.repeat_deviation),
        control=control_table(report), served=served_table(report) if report.served else None,
        identical=f"{page.IDENTICAL:g}", repeat_profiles=report.repeat_profiles, repeat_seed=report.seed + 1,
        side_by_side=side_by_side_table(report) if report.side_by_side else None,
        cost=cost_table(report) if report.costs else None,
        cost_profile=report.costs[0].profile if report.costs else "-",
        cost_repeats=_blocks(report.costs), cost_tight=f"{100 * cost.TIGHT_RANGE:g} %",
        stable=stable_table(report) if report.probes else None,
        not_probed=[(scene, NOT_PROBED.get(scene, "")) for scene in report.not_probed],
        article=embed(pngs[0]) if pngs else None,
        scenes=[scene_section(report, s) for s in report.scenes],
        parameters=[[s, readable_settings(p)] for s, p in report.params.items()],
        stepping_defaults=readable_settings(runs.default_stepping()),
        reference_stepping=readable_settings(runs.reference_stepping()),
        reference_profile=runs.REFERENCE_PROFILE, node=platform.node(), machine=platform.machine(),
        made_at=time.strftime("%Y-%m-%d %H:%M:%S %Z"), phases=report.phases_s, machine_line=machine_line(report))

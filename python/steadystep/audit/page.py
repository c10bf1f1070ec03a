"""The audit's page (audit.html): the recommendation first, each claim linked to its table, then what it is about,
each chosen quantity under the program's own stepping and under the recommended policy across the audited frame
rates (the article's figure, for the user's program), then the tables and figures the claims rest on. Figures drawn
with report/figures.py's colours and style.

The page is the template audit.html (audit/templates.py) in the report's Jinja2 environment, autoescape on: every
value is escaped unless it is a markupsafe.Markup, made only here (a variant's dot, a failure in red, a small note)
with its arguments escaped as they go in; the tables are the report's table macro over {header, rows}.

The figures are units of work of their own (figure_units, draw_png: PNG bytes), so that the audit draws them in its
executor's workers after the runs (audit.audit(draw=True): Audit.figures) and this process needs no matplotlib;
whatever is not drawn there is drawn here, by the same function."""

from __future__ import annotations

import dataclasses
import io
import math
import platform
import time
from pathlib import Path

import numpy as np
from markupsafe import Markup

from steadystep.audit.claims import recommended
from steadystep.audit.run import OWN, SERVED_COLUMNS, TIME_COLUMN
from steadystep.audit.templates import ENVIRONMENT
from steadystep.report import palette, snippets
from steadystep.report.cells import bad, embed, number

OWN_COLOR = "#000000"
PROFILE_COLORS = ("#1f5fbf", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#17becf")
FIGURE_QUANTITIES = 4  # the deciding quantities drawn across frame rates, at most


def _color(variant: str) -> str:
    return OWN_COLOR if variant == OWN else palette.policy_color(variant)


def _number(value, digits: int = 3):
    """The report's number, a failure (an infinite value) in red."""
    if isinstance(value, float) and math.isinf(value):
        return bad("failed")
    return number(value, digits)


def _small(text: str) -> Markup:
    return Markup("<span class=small>{}</span>").format(text)


def _label(variant: str) -> str:
    return "own stepping" if variant == OWN else variant


def _variant(result, variant: str) -> Markup:
    role = result.roles.get(variant, "")
    mark = Markup(" {}").format(_small(f"({role})")) if role in ("control", "diagnosis") else ""
    return Markup('<span class="dot" style="background:{}"></span>{}{}').format(_color(variant), _label(variant), mark)


def _table(header: list, rows: list[list], anchor: str) -> dict:
    """A table for the report's table macro: cells are text (escaped there) or Markup."""
    return {"header": header, "rows": rows, "anchor": anchor}


def _quantity_header(result, q: str):
    if q in result.deciding:
        return q
    return Markup("{} {}").format(q, _small("(error-like: does not decide alone)"))


def _values_table(result, table: dict, errors: dict, anchor: str) -> dict:
    """variant x quantity with the standard error over runs, and the largest over the deciding quantities; the
    smallest of each column in bold."""
    header = ["variant"] + [_quantity_header(result, q) for q in result.quantities] + ["largest (deciding)"]
    best = {}
    for q in result.quantities:
        finite = [table[v][q] for v in result.variants if math.isfinite(table[v][q])]
        best[q] = min(finite) if finite else None
    rows = []
    for v in result.variants:
        cells = [_variant(result, v)]
        for q in result.quantities:
            text = _number(table[v][q], 3)
            if math.isfinite(table[v][q]) and errors[v][q] > 0:
                text = Markup("{} ± {}").format(text, _number(errors[v][q], 2))
            cells.append(Markup("<b>{}</b>").format(text) if table[v][q] == best[q] else text)
        deciding = [(table[v][q], q) for q in result.deciding if not math.isnan(table[v][q])]
        value, q = max(deciding) if deciding else (math.nan, "")
        cells.append(Markup("{} {}").format(_number(value, 3), _small(q)))
        rows.append(cells)
    return _table(header, rows, anchor)


def _whole_deviation_table(result) -> dict:
    rows = [[_variant(result, v)] + [_number(result.deviation["whole"][v][q], 3) for q in result.quantities]
            for v in result.variants]
    return _table(["variant"] + list(result.quantities), rows, "deviation-whole")


def _runs_table(result) -> dict:
    """Every run; the steps that made contacts but softened none when a run made any (the unsoftened claim)."""
    unsoftened = any(r.get("unsoftened_contact_steps") for r in result.runs)
    rows = []
    for r in result.runs:
        count = r.get("unsoftened_contact_steps")
        rows.append([_variant(result, r["variant"]), r["profile"], str(r["seed"]), str(r["frames"]),
                     _number(r["simulated_s"], 4), _number(r["steps_per_frame"]), r["compared_at"],
                     _number(r["cpu_s"] * 1000, 3)] + ([str(count) if count is not None else "-"] if unsoftened else [])
                    + ["ok" if r["status"] == "ok" else bad(r["status"])])
    return _table(["variant", "profile", "seed", "frames", "simulated (s)", "steps / frame", "compared at",
                   "CPU (ms)"] + (["steps with contacts, none softened"] if unsoftened else []) + ["status"], rows,
                  "runs")


def _cost_table(result) -> dict:
    cost = result.cost
    own = cost.get("per_simulated_s", {}).get(OWN)
    rows = []
    for v in result.variants:
        steps = [r["steps_per_frame"] for r in result.runs if r["variant"] == v and r["steps_per_frame"] is not None]
        value = cost.get("per_simulated_s", {}).get(v)
        noise = cost.get("noise", {}).get(v)
        per_second = _number(value, 4)
        if value is not None and noise:
            per_second = Markup("{} ± {}").format(per_second, _number(noise, 2))
        rows.append([_variant(result, v), _number(float(np.median(steps))) if steps else "-", per_second,
                     _number(value / own, 3) if value is not None and own else "-"])
    unit = cost.get("unit") or "not measured"
    return _table(["variant", "steps / frame (median over runs)", unit, "/ own stepping"], rows, "cost")


def _served_table(result) -> dict:
    columns = [c for c in SERVED_COLUMNS if any(c in s for s in result.served.values())]
    rows = [[_variant(result, v)] + [str(result.served[v].get(c, "-")) for c in columns] for v in result.variants
            if v in result.served]
    return _table(["variant"] + [c.replace("_", " ") for c in columns], rows, "served")


def _reference(result) -> dict:
    """The reference's table and the sentence under it."""
    r = result.reference
    rows = [[_quantity_header(result, q), result.units[q], _number(result.scales[q], 4),
             _number(r["largest_moving_difference"][q], 3), _number(r["difference_in_window"][q], 3),
             _number(result.repeat["difference"][q], 3)] for q in result.quantities]
    table = _table(["quantity", "unit", f"scale ({result.scale_source} range)",
                    f"largest RMS difference of the check over {r['window_s']:.3g} s / scale",
                    "RMS difference while held / scale (the reference's uncertainty)",
                    "a repeated run's difference / scale"], rows, "reference")
    steps = (f"Mean step: the reference {number(1000 * r['reference_step_s'] if r['reference_step_s'] else None)} "
             f"ms, its check {number(1000 * r['check_step_s'] if r['check_step_s'] else None)} ms "
             f"({'finer' if r['check_finer'] else 'not finer'}). Parted at: "
             f"{'never' if r['parted_at'] is None else number(r['parted_at']) + ' s'}. Physical: "
             f"{'yes' if r['sane'] else 'no'}. Usable for deviation: {'yes' if r['usable'] else 'no'}.")
    return {"table": table, "steps": steps}


def _diagnosis_table(result) -> dict | None:
    """None when there is no diagnosis claim (the page says why)."""
    claim = next((c for c in result.claims if c["kind"] == "diagnosis"), None)
    if claim is None:
        return None
    rows = [[s["step"], Markup("{} → {}").format(_variant(result, s["from"]), _variant(result, s["to"])),
             _number(s["from_value"]), _number(s["to_value"]), _number(s["noise"]), f"{s['share_removed']:.0%}",
             s["verdict"]] for s in claim["steps"]]
    return _table(["what changes", "from → to", "largest spread before", "after", "noise", "share removed",
                   "verdict"], rows, "diagnosis")


def _code(result) -> dict | None:
    """The recommendation's end: the lines of code to write for the policy it recommends, the program's language
    first; None when it recommends none."""
    policy = recommended(result)
    if policy is None:
        return None
    summary = snippets.summary(policy)
    return {"policy": policy, "summary": summary[0].upper() + summary[1:],
            "snippets": snippets.for_policy(policy, result.language)}


def _shown_pair(result) -> tuple[str, str]:
    """The two variants the page draws across frame rates: own stepping (or naive, or the first variant) and the
    recommended policy (or the least spread)."""
    left = OWN if OWN in result.variants else ("naive" if "naive" in result.variants else result.variants[0])
    right = recommended(result) or next((c["variant"] for c in result.claims if c["kind"] == "least_spread"),
                                              result.variants[-1])
    return left, right


def _draw_across(result, quantity: str):
    """One quantity under the program's own stepping and under the recommended policy, each in every audited
    profile run, with the reference dashed: how much each depends on the frame rate."""
    from matplotlib.figure import Figure

    left, right = _shown_pair(result)
    figure = Figure(figsize=(11, 3.4))
    axes = figure.subplots(1, 2, sharey=True)
    reference = result.trajectories["reference"]
    for ax, variant in zip(axes, (left, right)):
        for i, (profile, seed) in enumerate(result.runs_per_variant):
            run = result.trajectories[(variant, profile, seed)]
            ax.plot(run[TIME_COLUMN], run[quantity], color=PROFILE_COLORS[i % len(PROFILE_COLORS)], lw=1.0,
                    label=f"{profile} seed {seed}")
        ax.plot(reference[TIME_COLUMN], reference[quantity], color=palette.REFERENCE_COLOR, ls="--", lw=1.0,
                label=f"reference ({result.reference['reference_fps']} fps)")
        _mark_parting(ax, result)
        spread = result.spread[variant][quantity]
        ax.set_title(f"{_label(variant)}: spread {number(spread)} of the scale")
        ax.set_xlabel("t (s)")
    axes[0].set_ylabel(quantity)
    axes[1].legend(loc="best", fontsize=7)
    figure.suptitle(f"{result.program}: {quantity} at every audited frame rate", fontsize=10)
    figure.tight_layout()
    return figure


def _draw_reference(result):
    from matplotlib.figure import Figure

    figure = Figure(figsize=(11, 2.8))
    ax = figure.add_subplot()
    r = result.reference
    for q, values in r["_moving"].items():
        ax.plot(r["_t"], np.maximum(values, 1e-7), lw=1.2, label=q)  # a log axis: exact agreement drawn at 1e-7
    ax.axhline(r["tolerance"], color="#b00", ls="--", lw=1, label=f"tolerance {r['tolerance']:.0%} of the scale")
    _mark_parting(ax, result)
    ax.set_yscale("log")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("RMS difference / scale")
    ax.set_title(f"The reference against its check ({r['reference_fps']} and {r['check_fps']} fps), RMS over "
                 f"{r['window_s']:.3g} s")
    ax.legend(loc="best")
    figure.tight_layout()
    return figure


def _mark_parting(ax, result) -> None:
    parted_at = result.reference["parted_at"]
    if parted_at is not None:
        ax.axvspan(parted_at, result.duration_s, color="#f3d6d6", alpha=0.6, label="reference not held")


def figure_units(result) -> list[dict]:
    """The page's figures as units of work for draw_png, in the page's order: each deciding quantity across frame
    rates (at most FIGURE_QUANTITIES), then the reference's check. Each holds the result with only the trajectories
    the figures draw (the two variants shown and the reference), plain data a worker can be sent."""
    left, right = _shown_pair(result)
    drawn = {key: columns for key, columns in result.trajectories.items()
             if key == "reference" or (isinstance(key, tuple) and key[0] in (left, right))}
    slim = dataclasses.replace(result, trajectories=drawn, runs=[], spread_runs={}, deviation_runs={}, figures={})
    units = [dict(stem=f"audit_{i}_{q}", result=slim, quantity=q)
             for i, q in enumerate(result.deciding[:FIGURE_QUANTITIES])]
    return units + [dict(stem="audit_reference", result=slim, quantity=None)]


def draw_png(stem: str, result, quantity: str | None) -> bytes:
    """One figure of the page (a unit of figure_units) as the bytes of its PNG file: quantity across frame rates,
    or the reference's check when quantity is None."""
    import matplotlib

    from steadystep.report import figures

    with matplotlib.rc_context(figures.STYLE):
        figure = _draw_reference(result) if quantity is None else _draw_across(result, quantity)
        buffer = io.BytesIO()
        figure.savefig(buffer, format="png", dpi=150)  # as files.save_figure writes a figure
    return buffer.getvalue()


def draw(result, out_dir: Path) -> list[Path]:
    """The figures, as PNG beside the page (figure_units): those the audit drew already (result.figures, by stem)
    written as they are, the others drawn here."""
    from steadystep.files import write_output_bytes

    drawn = getattr(result, "figures", None) or {}
    paths = []
    for unit in figure_units(result):
        data = drawn.get(unit["stem"])
        paths.append(write_output_bytes(Path(out_dir) / f"{unit['stem']}.png", data if data else draw_png(**unit)))
    return paths


def page(result, out_dir: Path, command: str) -> str:
    """The whole page, its figures written beside it in out_dir."""
    paths = draw(result, Path(out_dir))
    left, right = _shown_pair(result)
    not_measured = "; ".join(f"{v}: {why}" for v, why in result.not_measured.items())
    return ENVIRONMENT.get_template("audit.html").render(
        result=result, command=command, code=_code(result),
        runs_text=", ".join(f"{p} seed {s}" for p, s in result.runs_per_variant),
        variants=", ".join(_label(v) for v in result.variants), shown=(_label(left), _label(right)),
        across=[embed(p) for p in paths[:-1]], reference_figure=embed(paths[-1]),
        spread=_values_table(result, result.spread, result.spread_error, "spread"),
        deviation=_values_table(result, result.deviation["window"], result.deviation_error, "deviation"),
        deviation_whole=_whole_deviation_table(result), diagnosis=_diagnosis_table(result),
        reference=_reference(result), cost=_cost_table(result),
        served=_served_table(result) if result.served else None,
        not_measured=f"Not measured: {not_measured}" if not_measured else None, runs=_runs_table(result),
        node=platform.node(), made_at=time.strftime("%Y-%m-%d %H:%M:%S %Z"))

"""The audit's page (audit.html): the recommendation first, each claim linked to its table, then what it is about,
each chosen quantity under the program's own stepping and under the recommended policy across the audited frame
rates (the article's figure, for the user's program), then the tables and figures the claims rest on. Figures drawn
with report/figures.py's colours and style; every text escaped.

The figures are units of work of their own (figure_units, draw_png: PNG bytes), so that the audit draws them in its
executor's workers after the runs (audit.audit(draw=True): Audit.figures) and this process needs no matplotlib;
whatever is not drawn there is drawn here, by the same function."""

from __future__ import annotations

import base64
import dataclasses
import html
import io
import math
import platform
import time
from pathlib import Path

import numpy as np

from steadystep.report import palette
from steadystep.audit.run import OWN, SERVED_COLUMNS, TIME_COLUMN

OWN_COLOR = "#000000"
PROFILE_COLORS = ("#1f5fbf", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#17becf")
FIGURE_QUANTITIES = 4  # the deciding quantities drawn across frame rates, at most


def _color(variant: str) -> str:
    return OWN_COLOR if variant == OWN else palette.policy_color(variant)


def _number(value, digits: int = 3) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "-"
    if isinstance(value, float) and math.isinf(value):
        return "<span class=bad>failed</span>"
    return f"{value:.{digits}g}"


def _label(variant: str) -> str:
    return "own stepping" if variant == OWN else variant


def _variant(result, variant: str) -> str:
    role = result.roles.get(variant, "")
    mark = {"control": " <span class=small>(control)</span>",
            "diagnosis": " <span class=small>(diagnosis)</span>"}.get(role, "")
    return (f'<span class="dot" style="background:{_color(variant)}"></span>{html.escape(_label(variant))}{mark}')


def _table(header: list[str], rows: list[list[str]], anchor: str) -> str:
    head = "".join(f"<th>{h}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{cell}</td>" for cell in row) + "</tr>" for row in rows)
    return f"<table id='{anchor}'><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def _quantity_header(result, q: str) -> str:
    mark = "" if q in result.deciding else " <span class=small>(error-like: does not decide alone)</span>"
    return html.escape(q) + mark


def _values_table(result, table: dict, errors: dict, anchor: str) -> str:
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
                text += f" ± {_number(errors[v][q], 2)}"
            cells.append(f"<b>{text}</b>" if table[v][q] == best[q] else text)
        deciding = [(table[v][q], q) for q in result.deciding if not math.isnan(table[v][q])]
        value, q = max(deciding) if deciding else (math.nan, "")
        cells.append(f"{_number(value, 3)} <span class=small>{html.escape(q)}</span>")
        rows.append(cells)
    return _table(header, rows, anchor)


def _whole_deviation_table(result) -> str:
    header = ["variant"] + [html.escape(q) for q in result.quantities]
    rows = [[_variant(result, v)] + [_number(result.deviation["whole"][v][q], 3) for q in result.quantities]
            for v in result.variants]
    return _table(header, rows, "deviation-whole")


def _runs_table(result) -> str:
    """Every run; the steps that made contacts but softened none when a run made any (the unsoftened claim)."""
    unsoftened = any(r.get("unsoftened_contact_steps") for r in result.runs)
    rows = []
    for r in result.runs:
        status = "ok" if r["status"] == "ok" else f"<span class=bad>{html.escape(r['status'])}</span>"
        count = r.get("unsoftened_contact_steps")
        rows.append([_variant(result, r["variant"]), html.escape(r["profile"]), str(r["seed"]), str(r["frames"]),
                     _number(r["simulated_s"], 4), _number(r["steps_per_frame"]), html.escape(r["compared_at"]),
                     _number(r["cpu_s"] * 1000, 3)] + ([str(count) if count is not None else "-"] if unsoftened else [])
                    + [status])
    return _table(["variant", "profile", "seed", "frames", "simulated (s)", "steps / frame", "compared at",
                   "CPU (ms)"] + (["steps with contacts, none softened"] if unsoftened else []) + ["status"], rows,
                  "runs")


def _cost_table(result) -> str:
    cost = result.cost
    own = cost.get("per_simulated_s", {}).get(OWN)
    rows = []
    for v in result.variants:
        steps = [r["steps_per_frame"] for r in result.runs if r["variant"] == v and r["steps_per_frame"] is not None]
        value = cost.get("per_simulated_s", {}).get(v)
        noise = cost.get("noise", {}).get(v)
        rows.append([_variant(result, v), _number(float(np.median(steps))) if steps else "-",
                     _number(value, 4) + (f" ± {_number(noise, 2)}" if value is not None and noise else ""),
                     _number(value / own, 3) if value is not None and own else "-"])
    unit = cost.get("unit") or "not measured"
    return _table(["variant", "steps / frame (median over runs)", html.escape(unit), "/ own stepping"], rows, "cost")


def _served_table(result) -> str:
    columns = [c for c in SERVED_COLUMNS if any(c in s for s in result.served.values())]
    rows = [[_variant(result, v)] + [str(result.served[v].get(c, "-")) for c in columns] for v in result.variants
            if v in result.served]
    return _table(["variant"] + [html.escape(c.replace("_", " ")) for c in columns], rows, "served")


def _reference_table(result) -> str:
    r = result.reference
    rows = [[_quantity_header(result, q), html.escape(result.units[q]), _number(result.scales[q], 4),
             _number(r["largest_moving_difference"][q], 3), _number(r["difference_in_window"][q], 3),
             _number(result.repeat["difference"][q], 3)] for q in result.quantities]
    table = _table(["quantity", "unit", f"scale ({html.escape(result.scale_source)} range)",
                    f"largest RMS difference of the check over {r['window_s']:.3g} s / scale",
                    "RMS difference while held / scale (the reference's uncertainty)",
                    "a repeated run's difference / scale"], rows, "reference")
    steps = (f"Mean step: the reference {_number(1000 * r['reference_step_s'] if r['reference_step_s'] else None)} "
             f"ms, its check {_number(1000 * r['check_step_s'] if r['check_step_s'] else None)} ms "
             f"({'finer' if r['check_finer'] else 'not finer'}). Parted at: "
             f"{'never' if r['parted_at'] is None else _number(r['parted_at']) + ' s'}. Physical: "
             f"{'yes' if r['sane'] else 'no'}. Usable for deviation: {'yes' if r['usable'] else 'no'}.")
    return table + f"<p class=small>{html.escape(steps)}</p>"


def _diagnosis_table(result) -> str:
    claim = next((c for c in result.claims if c["kind"] == "diagnosis"), None)
    if claim is None:
        return ("<p id='diagnosis' class=small>No diagnosis: it needs the program's own stepping (or naive) with a "
                "spread above 0.</p>")
    rows = [[html.escape(s["step"]), _variant(result, s["from"]) + " → " + _variant(result, s["to"]),
             _number(s["from_value"]), _number(s["to_value"]), _number(s["noise"]),
             f"{s['share_removed']:.0%}", html.escape(s["verdict"])] for s in claim["steps"]]
    return _table(["what changes", "from → to", "largest spread before", "after", "noise", "share removed",
                   "verdict"], rows, "diagnosis")


def _code(result) -> str:
    """The recommendation's end: the lines of code to write for the policy it recommends, the program's language
    first; "" when it recommends none."""
    from steadystep.audit import comparison as audit  # recommended()
    from steadystep.report import snippets

    policy = audit.recommended(result)
    if policy is None:
        return ""
    blocks = "".join(f"<p class=small>{html.escape(s.language)}:</p><pre class=code><code>{html.escape(s.text)}"
                     "</code></pre>" for s in snippets.for_policy(policy, result.language))
    return (f"<h3 id='code'>The code to write for {html.escape(policy)}</h3>"
            f"<p>{html.escape(snippets.summary(policy)[0].upper() + snippets.summary(policy)[1:])}.</p>{blocks}")


def _embed(path: Path) -> str:
    data = base64.b64encode(Path(path).read_bytes()).decode()
    return f'<img src="data:image/png;base64,{data}" alt="{html.escape(Path(path).name)}">'


def _shown_pair(result) -> tuple[str, str]:
    """The two variants the page draws across frame rates: own stepping (or naive, or the first variant) and the
    recommended policy (or the least spread)."""
    from steadystep.audit import comparison as audit  # recommended()

    left = OWN if OWN in result.variants else ("naive" if "naive" in result.variants else result.variants[0])
    right = audit.recommended(result) or next((c["variant"] for c in result.claims if c["kind"] == "least_spread"),
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
        ax.set_title(f"{_label(variant)}: spread {_number(spread)} of the scale")
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
    paths = draw(result, Path(out_dir))
    across, reference_figure = paths[:-1], paths[-1]
    claims = "".join(f"<li>{html.escape(c['text'])} <a href='#{c['table']}'>({c['table']} table)</a></li>"
                     for c in result.claims)
    runs_text = ", ".join(f"{p} seed {s}" for p, s in result.runs_per_variant)
    left, right = _shown_pair(result)
    usable = result.reference["usable"]
    parts = [
        f"<h1>steadystep audit: {html.escape(result.program)}</h1>",
        f"<p>The program ran {result.duration_s:g} s under {html.escape(runs_text)}, as each of "
        f"{html.escape(', '.join(_label(v) for v in result.variants))}"
        + (f" (own stepping: {html.escape(result.own)})" if result.own else "")
        + ", each run a process of its own, against a fine-step reference checked at a finer step "
        "(docs/audit.md).</p>",
        "<section id='recommendation'><h2>Recommendation for this program</h2>"
        "<p class=small>Every line is computed from the tables below (metrics.json holds them and these claims) "
        "and links to its table. A value is better than another only beyond the noise of their difference.</p>"
        f"<ul class='answers'>{claims}</ul>{_code(result)}</section>",
        f"<h2>{html.escape(_label(left))} and {html.escape(_label(right))} at every audited frame rate</h2>",
        "<p class=small>Each deciding quantity in every profile run: the closer the curves of one panel, the less "
        "that stepping depends on the frame rate.</p>",
        *[_embed(p) for p in across],
        "<h2>Spread across frame rates (whole run)</h2>", _values_table(result, result.spread, result.spread_error,
                                                                        "spread"),
        f"<p class=small>Spread: each run after the first ({html.escape(result.runs_per_variant[0][0])}) against "
        "the first of the same variant, at the simulated times the two share when they share most of them (runs "
        "identical there score exactly 0), else interpolated onto the first's times; RMS over time, then over runs, "
        "divided by the quantity's scale; ± its standard error over the runs. Over the whole run, whatever the "
        "reference does. Bold: the smallest of a column.</p>",
        "<h2>Deviation from the fine-step reference</h2>",
        _values_table(result, result.deviation["window"], result.deviation_error, "deviation"),
        "<p class=small>" + ("Deviation: every run against the reference interpolated at the run's own times, "
                             "while the reference holds; RMS over time, then over runs, divided by the scale."
                             if usable else "Not claimed: the reference is not usable (see below); shown for "
                             "completeness.") + " Over the whole run:</p>",
        _whole_deviation_table(result),
        "<h2>Where the dependence comes from</h2>", _diagnosis_table(result),
        "<h2>The reference, checked</h2>", _reference_table(result), _embed(reference_figure),
        "<h2>Steps per frame and cost</h2>", _cost_table(result),
        "<p class=small>Instructions: counted by valgrind over the whole process (start-up included, the same for "
        "every variant). CPU time: the whole process of an executable, the stepping loop of a Python program.</p>"]
    if result.served:
        parts += ["<h2>What each mapping served</h2>", _served_table(result),
                  "<p class=small>Row-steps (every bound row counted once per physics step) and contacts, summed "
                  "over the variant's runs, from the program's optional columns.</p>"]
    if result.not_measured:
        parts += ["<p class=small>" + html.escape("Not measured: " + "; ".join(
            f"{v}: {why}" for v, why in result.not_measured.items())) + "</p>"]
    parts += ["<h2>Every run</h2>", _runs_table(result),
              "<h2>Regenerate</h2>", f"<pre>{html.escape(command)}</pre>",
              f"<p class=small>Made in {result.elapsed_s:.1f} s on {html.escape(platform.node())}, "
              f"{time.strftime('%Y-%m-%d %H:%M:%S %Z')}"
              + (f"; {result.reused_runs} finished runs kept from an interrupted audit" if result.reused_runs else "")
              + ".</p>"]
    return _PAGE.format(title=html.escape(f"steadystep audit: {result.program}"), body="\n".join(parts))


_PAGE = """<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>{title}</title>
<style>
body {{ font-family: system-ui, sans-serif; max-width: 1400px; margin: 2em auto; padding: 0 1em; color: #222; }}
table {{ border-collapse: collapse; margin: 0.5em 0 0.5em; font-size: 0.9em; }}
th, td {{ border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: right; }}
th {{ background: #f3f3f3; }} td:first-child {{ text-align: left; }}
img {{ max-width: 100%; display: block; margin: 0.5em 0 1.5em; }}
.dot {{ display: inline-block; width: 0.7em; height: 0.7em; border-radius: 50%; margin-right: 0.4em; }}
.bad {{ color: #b00; font-weight: bold; }}
#recommendation {{ background: #f4f8ff; border: 1px solid #c9d8f0; padding: 0.3em 1em 1em; }}
.answers li {{ margin: 0.35em 0; }}
pre {{ background: #f6f6f6; padding: 0.6em; white-space: pre-wrap; }}
pre.code {{ white-space: pre; overflow-x: auto; }}
.small {{ color: #666; font-size: 0.85em; margin-bottom: 1.5em; }}
</style></head><body>
{body}
</body></html>
"""

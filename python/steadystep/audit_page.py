"""The audit's page (audit.html): the recommendation first, each claim linked to its table, then the tables and
figures it rests on. The same look as the report's page; figures drawn with figures.py's colours and style."""

from __future__ import annotations

import base64
import html
import math
import platform
import time
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from steadystep import figures
from steadystep.audit_run import OWN, SERVED_COLUMNS, TIME_COLUMN

OWN_COLOR = "#000000"


def _color(variant: str) -> str:
    return OWN_COLOR if variant == OWN else figures.policy_color(variant)


def _number(value, digits: int = 3) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "-"
    if isinstance(value, float) and math.isinf(value):
        return "<span class=bad>failed</span>"
    return f"{value:.{digits}g}"


def _variant(variant: str) -> str:
    label = "own stepping" if variant == OWN else variant
    return f'<span class="dot" style="background:{_color(variant)}"></span>{html.escape(label)}'


def _table(header: list[str], rows: list[list[str]], anchor: str) -> str:
    head = "".join(f"<th>{h}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{cell}</td>" for cell in row) + "</tr>" for row in rows)
    return f"<table id='{anchor}'><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def _by_quantity(result, table: dict, anchor: str) -> str:
    """variant x quantity, over the window and the whole run; the smallest of a column (in the window) in bold."""
    header = ["variant"] + [f"{html.escape(q)} (window)" for q in result.quantities] + \
             [f"{html.escape(q)} (whole run)" for q in result.quantities]
    best = {}
    for q in result.quantities:
        finite = [table["window"][v][q] for v in result.variants if math.isfinite(table["window"][v][q])]
        best[q] = min(finite) if finite else None
    rows = []
    for v in result.variants:
        cells = [_variant(v)]
        for q in result.quantities:
            text = _number(table["window"][v][q], 4)
            cells.append(f"<b>{text}</b>" if table["window"][v][q] == best[q] else text)
        cells += [_number(table["whole"][v][q], 4) for q in result.quantities]
        rows.append(cells)
    return _table(header, rows, anchor)


def _runs_table(result) -> str:
    rows = []
    for r in result.runs:
        status = "ok" if r["status"] == "ok" else f"<span class=bad>{html.escape(r['status'])}</span>"
        rows.append([_variant(r["variant"]), html.escape(r["profile"]), str(r["seed"]), str(r["frames"]),
                     _number(r["simulated_s"], 4), _number(r["steps_per_frame"]), _number(r["cpu_s"] * 1000, 3),
                     _number(r["cpu_ms_per_simulated_s"]), status])
    return _table(["variant", "profile", "seed", "frames", "simulated (s)", "steps / frame", "CPU (ms)",
                   "CPU ms / simulated s", "status"], rows, "runs")


def _cost_table(result) -> str:
    own = result.cost.get(OWN)
    rows = []
    for v in result.variants:
        steps = [r["steps_per_frame"] for r in result.runs if r["variant"] == v and r["steps_per_frame"] is not None]
        cost = result.cost[v]
        rows.append([_variant(v), _number(float(np.median(steps))) if steps else "-", _number(cost),
                     _number(cost / own) if cost is not None and own else "-"])
    return _table(["variant", "steps / frame (median over runs)", "CPU ms / simulated s (median over runs)",
                   "/ own stepping"], rows, "cost")


def _served_table(result) -> str:
    columns = [c for c in SERVED_COLUMNS if any(c in s for s in result.served.values())]
    rows = [[_variant(v)] + [str(result.served[v].get(c, "-")) for c in columns] for v in result.variants
            if v in result.served]
    return _table(["variant"] + [html.escape(c.replace("_", " ")) for c in columns], rows, "served")


def _reference_table(result) -> str:
    r = result.reference
    rows = [[html.escape(q), _number(result.amplitudes[q], 4), _number(r["largest_moving_difference"][q], 3),
             _number(r["difference_in_window"][q], 3)] for q in result.quantities]
    return _table(["quantity", "range A of the reference", f"largest RMS difference over {r['window_s']:.3g} s / A",
                   "RMS difference in the window / A"], rows, "reference")


def _code(result) -> str:
    """The recommendation's end: the lines of code to write for the policy it recommends, the program's language
    first; "" when it recommends none."""
    from steadystep import audit, snippets

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


def _draw_quantity(result, quantity: str) -> Figure:
    figure = Figure(figsize=(11, 3.6))
    ax = figure.add_subplot()
    t = result.trajectories
    first = result.runs_per_variant[0]
    for variant in result.variants:
        run = t[variant]
        ax.plot(run[TIME_COLUMN], run[quantity], color=_color(variant), lw=1.1,
                label=f"{'own stepping' if variant == OWN else variant} ({first[0]})")
    for name, style in (("reference", "--"), ("check", ":")):
        ax.plot(t[name][TIME_COLUMN], t[name][quantity], color=figures.REFERENCE_COLOR, ls=style, lw=1.3,
                label=f"{name} ({result.reference['reference_fps' if name == 'reference' else 'check_fps']} fps)")
    _mark_window(ax, result)
    ax.set_xlabel("t (s)")
    ax.set_ylabel(quantity)
    ax.set_title(f"{result.program}: {quantity}, every variant under {first[0]} against the reference")
    ax.legend(ncol=3, loc="best")
    figure.tight_layout()
    return figure


def _draw_reference(result) -> Figure:
    figure = Figure(figsize=(11, 2.8))
    ax = figure.add_subplot()
    r = result.reference
    for q, values in r["_moving"].items():
        ax.plot(r["_t"], np.maximum(values, 1e-7), lw=1.2, label=q)  # a log axis: exact agreement drawn at 1e-7
    ax.axhline(r["tolerance"], color="#b00", ls="--", lw=1, label=f"tolerance {r['tolerance']:.0%} of A")
    _mark_window(ax, result)
    ax.set_yscale("log")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("RMS difference / A")
    ax.set_title(f"The reference against its check ({r['reference_fps']} and {r['check_fps']} fps), RMS over "
                 f"{r['window_s']:.3g} s")
    ax.legend(loc="best")
    figure.tight_layout()
    return figure


def _mark_window(ax, result) -> None:
    for i, (start, end) in enumerate(result.reference["not_held"]):
        ax.axvspan(start, end, color="#f3d6d6", alpha=0.6, label="reference does not hold" if i == 0 else None)


def draw(result, out_dir: Path) -> list[Path]:
    """The figures, as PNG beside the page: one per quantity, and the reference's check."""
    import matplotlib

    paths = []
    with matplotlib.rc_context(figures.STYLE):
        for i, q in enumerate(result.quantities):
            paths += figures.save(_draw_quantity(result, q), out_dir, f"audit_{i}_{q}", formats=("png",))
        paths += figures.save(_draw_reference(result), out_dir, "audit_reference", formats=("png",))
    return paths


def page(result, out_dir: Path, command: str) -> str:
    paths = draw(result, Path(out_dir))
    claims = "".join(f"<li>{html.escape(c['text'])} <a href='#{c['table']}'>({c['table']} table)</a></li>"
                     for c in result.claims)
    first = result.runs_per_variant[0]
    runs_text = ", ".join(f"{p} seed {s}" for p, s in result.runs_per_variant)
    parts = [
        f"<h1>steadystep audit: {html.escape(result.program)}</h1>",
        f"<p>The program ran {result.duration_s:g} s under {html.escape(runs_text)}, as each of "
        f"{html.escape(', '.join('own stepping' if v == OWN else v for v in result.variants))}"
        + (f" (own stepping: {html.escape(result.own)})" if result.own else "")
        + ", against a fine-step reference checked at a finer step (docs/audit.md).</p>",
        "<section id='recommendation'><h2>Recommendation for this program</h2>"
        "<p class=small>Every line is computed from the tables below (metrics.json holds them and these claims) "
        "and links to its table.</p>"
        f"<ul class='answers'>{claims}</ul>{_code(result)}</section>",
        "<h2>Spread across frame rates</h2>", _by_quantity(result, result.spread, "spread"),
        f"<p class=small>Spread: each run after the first ({html.escape(first[0])} seed {first[1]}) against the "
        "first of the same variant on the first's times, RMS over runs and time, divided by the reference's range A "
        "(max − min). Window: the times where the reference holds (below). Bold: the smallest of a column; failed: a "
        "run of that variant failed.</p>",
        "<h2>Deviation from the fine-step reference</h2>", _by_quantity(result, result.deviation, "deviation"),
        "<p class=small>Deviation: every run of the variant against the reference on the reference's times, RMS "
        "over runs and time, divided by A.</p>",
        "<h2>The reference, checked</h2>", _reference_table(result),
        "<p class=small>The reference (implicit-euler, one step per frame of "
        f"1/{result.reference['reference_fps']} s) against the same at 1/{result.reference['check_fps']} s: the "
        "RMS of their difference over a moving window, divided by A. Where it exceeds the tolerance, the two "
        "fine-step runs part, and so would any two runs: the window ends there.</p>",
        "<h2>Steps per frame and cost</h2>", _cost_table(result),
        "<p class=small>Steps per frame from the program's steps column (- when it prints none). CPU time: the "
        "whole process of an executable (start-up and CSV included), the stepping loop of a Python program.</p>"]
    if result.served:
        parts += ["<h2>What each mapping served</h2>", _served_table(result),
                  "<p class=small>Row-steps (every bound row counted once per physics step) and contacts, summed "
                  "over the variant's runs, from the program's optional columns.</p>"]
    parts += ["<h2>Every run</h2>", _runs_table(result), "<h2>Figures</h2>"]
    parts += [_embed(p) for p in paths]
    parts += ["<h2>Regenerate</h2>", f"<pre>{html.escape(command)}</pre>",
              f"<p class=small>Made in {result.elapsed_s:.1f} s on {html.escape(platform.node())}, "
              f"{time.strftime('%Y-%m-%d %H:%M:%S %Z')}.</p>"]
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

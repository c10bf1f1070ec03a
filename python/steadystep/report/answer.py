"""The report's first picture (issue 28): for the report's scenes, what changes with the frame rate under each
policy. One panel a scene; in it, for each policy, one dot per frame-time profile at that run's deviation from the
fine-step reference (RMS of the scene's first quantity, over the motion's amplitude), a line from the lowest to the
highest: the longer the line, the more the motion changes with the frame rate; a single dot, the same motion under
every profile. Above each policy its consistency (lab/consistency.py: 0 when the runs are the same motion). The
recommended policy's name is bold. A failed run (blew up, broke) has no deviation: it is marked ✕ at the panel's top.

Drawn with matplotlib's Figure (no pyplot, no global state), in the process that writes the page, from the report's
numbers alone: nothing is run again.
"""

from __future__ import annotations

import io
import math

import matplotlib
from matplotlib.figure import Figure

from steadystep.lab import runs
from steadystep.report.figures import policy_color

# Deviations below this are drawn at it (a log axis has no 0): far below any deviation a run of these scenes has.
FLOOR = 1e-9
MARKERS = "osD^vP*Xh<>"
STYLE = {"figure.dpi": 100, "axes.grid": True, "grid.alpha": 0.3, "axes.spines.top": False,
         "axes.spines.right": False, "font.size": 10, "legend.fontsize": 9}


def _short(value: float) -> str:
    if not math.isfinite(value):
        return "failed" if math.isinf(value) else "-"
    return "0" if value <= FLOOR else f"{value:.1g}"


def draw(report, recommended: str | None, identical: float) -> Figure:
    """The picture as a Figure: one panel per scene (at most four a row), the policies along x."""
    scenes = [s for s in report.scenes if any(r.scene == s for r in report.rows)]
    columns = min(4, max(1, len(scenes)))
    rows_of_panels = max(1, math.ceil(len(scenes) / columns))
    profiles = list(report.profiles)
    with matplotlib.rc_context(STYLE):
        figure = Figure(figsize=(12.5, 0.6 + 2.6 * rows_of_panels), layout="constrained")
        axes = figure.subplots(rows_of_panels, columns, squeeze=False).ravel()
        for ax in axes[len(scenes):]:
            ax.set_visible(False)
        for ax, scene in zip(axes, scenes):
            quantity = runs.motion_quantities(scene)[0]
            policies = list(report.policies[scene])
            found = {(r.profile, r.policy): (r.deviations.get(quantity, math.nan), r.status)
                     for r in report.rows if r.scene == scene}
            finite = [v for v, status in found.values() if status == "ok" and math.isfinite(v)]
            top = max([FLOOR * 10] + finite) * 6
            for x, policy in enumerate(policies):
                values = [found.get((p, policy), (math.nan, "ok")) for p in profiles]
                drawn = [max(v, FLOOR) for v, status in values if status == "ok" and math.isfinite(v)]
                color = policy_color(policy)
                if drawn:
                    ax.plot([x, x], [min(drawn), max(drawn)], color=color, linewidth=3, alpha=0.5,
                            solid_capstyle="round")
                for i, (value, status) in enumerate(values):
                    if status == "ok" and math.isfinite(value):
                        ax.plot([x], [max(value, FLOOR)], linestyle="none", marker=MARKERS[i % len(MARKERS)],
                                color=color, markeredgecolor="black", markeredgewidth=0.5, markersize=6)
                failed = sum(status != "ok" or math.isinf(value) for value, status in values)
                if failed:
                    ax.text(x, top / 2.2, f"✕ {failed} failed", ha="center", va="center", color="#b00000",
                            fontsize=8)
                consistency = report.consistency.get(scene, {}).get(policy, {}).get(quantity, math.nan)
                if math.isfinite(consistency) and consistency <= identical:
                    consistency = 0.0
                ax.text(x, top, _short(consistency), ha="center", va="bottom", fontsize=8,
                        fontweight="bold" if policy == recommended else "normal")
            ax.set_yscale("log")
            ax.set_ylim(bottom=FLOOR / 2 if any(v <= FLOOR for v in finite) else None, top=top * 3)
            ax.set_xticks(range(len(policies)))
            ax.set_xticklabels(policies, rotation=30, ha="right", fontsize=9)
            for label in ax.get_xticklabels():
                if label.get_text() == recommended:
                    label.set_fontweight("bold")
            ax.set_xlim(-0.6, len(policies) - 0.4)
            ax.set_title(f"{scene}: {quantity}", loc="left", fontsize=10)
        if len(scenes):
            axes[0].set_ylabel("deviation from the reference\n(RMS / amplitude)")
        handles = [matplotlib.lines.Line2D([], [], linestyle="none", marker=MARKERS[i % len(MARKERS)],
                                           color="#999", markeredgecolor="black", markeredgewidth=0.5)
                   for i in range(len(profiles))]
        figure.legend(handles, profiles, loc="outside upper right", ncols=len(profiles), frameon=False,
                      title="one dot per frame-time profile; number above: consistency (0: the same motion at every "
                            "frame rate)", title_fontsize=9)
    return figure


def png(report, recommended: str | None, identical: float) -> bytes:
    """The picture as PNG bytes, to embed in the page."""
    buffer = io.BytesIO()
    draw(report, recommended, identical).savefig(buffer, format="png")
    return buffer.getvalue()

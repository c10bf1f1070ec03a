"""Figures with matplotlib: the article's figure and the per-scene comparison plots.

Figures are made with matplotlib's Figure class and written to files, never shown: no backend is chosen, pyplot is
not used, and the style applies only while a figure is drawn (rc_context), so neither importing this module nor
drawing changes matplotlib's global state.

One colour per policy everywhere, and the article's own colours for its figure (exact solution blue, fixed 30 fps
red, variable 15-45 fps green). The reference run and the exact solution are drawn in black / blue, dashed.
"""

from __future__ import annotations

import functools
from pathlib import Path

import matplotlib
import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from steadystep.lab import article, runs
from steadystep.core._native import SteadystepError, number, printable
from steadystep.core.enums import Status
from steadystep.lab.limits import MIN_MEASURED_DURATION_S
from steadystep.lab.profiles import seed_value
from steadystep.files import save_figure
from steadystep.lab.profiles import frame_times
from steadystep.report.palette import (EXACT_COLOR, FIXED_30_COLOR, POLICY_COLORS, REFERENCE_COLOR, # noqa: F401
                                       VARIABLE_COLOR, policy_color)

STYLE = {
    "figure.dpi": 100, "axes.grid": True, "grid.alpha": 0.3, "axes.spines.top": False,
    "axes.spines.right": False, "font.size": 10, "legend.fontsize": 9, "legend.framealpha": 0.9,
}


def _styled(draw):
    """draw with STYLE in force while it runs (matplotlib's rc_context: nothing global is left changed)."""
    @functools.wraps(draw)
    def styled(*args, **kwargs):
        with matplotlib.rc_context(STYLE):
            return draw(*args, **kwargs)
    return styled


def _label(text: str) -> str:
    """User text (a profile spec, a trace file's name) as matplotlib draws it literally: no lone surrogates from
    bytes that were not UTF-8 (its fonts refuse them) and no $ that would start mathtext."""
    return printable(text).replace("$", r"\$")


def save(figure, out_dir: Path, stem: str, formats=("png", "svg")) -> list[Path]:
    """Saves the figure as out_dir/stem.png and .svg (each written whole). A Figure made without pyplot needs no
    closing: it is freed with its last reference."""
    out_dir = Path(out_dir)
    return [save_figure(figure, out_dir / f"{stem}.{suffix}") for suffix in formats]


@_styled
def article_figure(out_dir: Path, duration_s: float = 5.0, seed: int = 1) -> list[Path]:
    """The article's figure, twice: from its equations 4 and 5, and from real ODE with the article's method.

    Both panels use the oscillator scene's spring (its defaults: the article's kind of spring) released at rest from
    x0. Panel 2 runs ODE with policy implicit-euler and max_step_s = 1/15 s, so that every frame is one step, as in the
    equations. The variable frames come from the C profile uniform:15:45 with the given seed (in [0, 2^64)).
    duration_s (s) is at least MIN_MEASURED_DURATION_S (0.1 s) and within the bound of lab/limits.py for 15-45 fps
    frames (about 22000 s). Raises SteadystepError naming the value, before anything is drawn.
    """
    duration_s, seed = number("duration_s", duration_s, "s"), seed_value(seed)
    if not duration_s >= MIN_MEASURED_DURATION_S:
        raise SteadystepError(Status.OUT_OF_RANGE, f"duration_s = {duration_s:g} s: the figure needs at least "
                              f"{MIN_MEASURED_DURATION_S:g} s")
    one_step_per_frame = {"max_step_s": 1.0 / 15.0}
    for profile in ("fixed:30", "uniform:15:45"):
        runs.check_run_size(profile, duration_s, seed, runs.make_stepping("implicit-euler", **one_step_per_frame))
    params = runs.default_params("oscillator")
    osc = article.Oscillator(params["mass"], params["spring"]["stiffness"], params["spring"]["damping"])
    x0 = params["x0"]
    fine_t = np.linspace(0.0, duration_s, 2001)
    exact_x, _ = article.exact(osc, x0, 0.0, fine_t)

    fixed_frames = np.full(int(round(duration_s * 30)), 1.0 / 30)
    variable_frames = frame_times("uniform:15:45", int(duration_s * 45) + 2, seed)
    variable_frames = variable_frames[: int(np.searchsorted(np.cumsum(variable_frames), duration_s)) + 1]

    figure = Figure(figsize=(12, 7.2), constrained_layout=True)
    axes = figure.subplots(2, 1, sharex=True)
    top, bottom = axes
    for ax in axes:
        ax.plot(fine_t, exact_x, color=EXACT_COLOR, lw=2.0, label="exact solution")
        ax.axhline(0.0, color="#999999", lw=0.6)
        ax.set_ylabel("extension x (m)")

    t, x, _ = article.integrate(osc, x0, 0.0, fixed_frames)
    top.plot(t, x, color=FIXED_30_COLOR, lw=1.4, marker="o", ms=2.2, label="fixed step, Δt = 1/30 s\n(30 fps)")
    t, x, _ = article.integrate(osc, x0, 0.0, variable_frames)
    top.plot(t, x, color=VARIABLE_COLOR, lw=1.4, marker="o", ms=2.2,
             label="variable step,\n1/45 ≤ Δt ≤ 1/15 s\n(15-45 fps, uniform)")
    # Equations 4-5 are an explicit step: its determinant 1 - c h/m + k h²/2m exceeds 1 for h > 2c/k, where each
    # step adds energy. Said in the title, because with a stiff spring the 15 fps frames are past that bound.
    unstable_above_s = 2.0 * osc.damping / osc.stiffness if osc.stiffness > 0 else float("inf")
    top.set_title("The article's approximation (equations 4 and 5); it gains energy for steps "
                  f"Δt > 2c/k = {1000 * unstable_above_s:.0f} ms", loc="left")

    for profile, color, label in (("fixed:30", FIXED_30_COLOR, "fixed 30 fps"),
                                  ("uniform:15:45", VARIABLE_COLOR, "variable 15-45 fps, uniform")):
        result = runs.run("oscillator", profile, "implicit-euler", duration_s, seed=seed, stepping=one_step_per_frame)
        t = np.concatenate(([0.0], result.times))
        x = np.concatenate(([x0], result.quantities["x"]))
        bottom.plot(t, x, color=color, lw=1.4, marker="o", ms=2.2, label=f"ODE,\n{label}")
    bottom.set_title("Real ODE 0.16 with the article's method (erp = hk/(hk+c), cfm = 1/(hk+c) every step)",
                     loc="left")
    bottom.set_xlabel("time t (s)")
    for ax in axes:
        ax.set_xlim(0.0, duration_s)
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0))
    figure.suptitle(f"Spring-damper m = {osc.mass:g} kg, k = {osc.stiffness:g} N/m, c = {osc.damping:g} N·s/m, "
                    f"released at rest from x0 = {x0:g} m", fontsize=11)
    return save(figure, out_dir, "article_figure")


# Profiles told apart by line style and marker, policies by panel and colour.
PROFILE_STYLES = (("-", "o"), ("--", "s"), (":", "^"), ("-.", "D"), ((0, (5, 1, 1, 1)), "v"), ((0, (1, 3)), "P"))
MARKS_PER_CURVE = 12


def profile_style(index: int) -> tuple:
    return PROFILE_STYLES[index % len(PROFILE_STYLES)]


def _off_scale(t: np.ndarray, y: np.ndarray, low: float, high: float):
    """The first sample outside [low, high] (or not finite) as (t, edge value, 'above' or 'below'), else None."""
    outside = ~np.isfinite(y) | (y < low) | (y > high)
    if not np.any(outside):
        return None
    i = int(np.argmax(outside))
    above = not np.isfinite(y[i]) or y[i] > high
    return float(t[i]), high if above else low, "above" if above else "below"


def _draw_run(ax, t, y, color, style, low, high, failed: bool) -> dict:
    """One run's curve, clipped to the axes; marks where it leaves them (triangle at the edge) and where a failed
    run ends (a cross). Returns which marks were drawn."""
    drawn = {"off": False, "failed": False}
    linestyle, marker = style
    shown = np.clip(np.where(np.isfinite(y), y, np.nan), low, high)
    ax.plot(t, shown, color=color, ls=linestyle, lw=1.2, marker=marker, ms=3.5,
            markevery=max(1, len(t) // MARKS_PER_CURVE))
    exit_point = _off_scale(t, y, low, high)
    if exit_point is not None:
        when, edge, side = exit_point
        ax.plot([when], [edge], marker="^" if side == "above" else "v", ms=9, color=color, mec="black", mew=0.8,
                ls="none", zorder=5, clip_on=False)
        drawn["off"] = True
    if failed and len(t):
        finite = np.isfinite(y)
        last = int(np.nonzero(finite)[0][-1]) if np.any(finite) else 0
        ax.plot([t[last]], [float(np.clip(y[last], low, high)) if finite[last] else high], marker="X", ms=10,
                color=color, mec="black", mew=0.9, ls="none", zorder=6, clip_on=False)
        drawn["failed"] = True
    return drawn


def scene_figure(scene: str, quantity: str, unit: str, reference, results, out_dir: Path,
                 exact_curve=None) -> list[Path]:
    """draw_scene_figure saved as out_dir/scene_<scene>_<quantity>.png and .svg."""
    figure = draw_scene_figure(scene, quantity, unit, reference, results, exact_curve)
    return save(figure, out_dir, f"scene_{scene}_{quantity}".replace(" ", "_"))


@_styled
def draw_scene_figure(scene: str, quantity: str, unit: str, reference, results, exact_curve=None) -> Figure:
    """Small multiples: one panel per policy, the quantity over time under every profile (line style and marker per
    profile, the policy's colour), over the reference (and the exact solution). Runs that leave the shared axes are
    marked where they leave (a triangle on the edge), failed runs where they end (a cross).

    results: {(profile, policy): RunResult}; reference: RunResult; exact_curve: (t, y) or None.
    """
    profiles = list(dict.fromkeys(profile for profile, _ in results))
    policies = list(dict.fromkeys(policy for _, policy in results))
    columns = min(4, len(policies))
    rows = (len(policies) + columns - 1) // columns
    figure = Figure(figsize=(4.2 * columns, 2.8 * rows + 1.0), constrained_layout=True)
    axes = figure.subplots(rows, columns, squeeze=False, sharex=True, sharey=True)
    low, high = _limits(reference.quantities[quantity],
                        [r.quantities[quantity] for r in results.values() if r.step_count])
    marks = {"off": False, "failed": False}
    for index, policy in enumerate(policies):
        ax = axes[index // columns][index % columns]
        if exact_curve is not None:
            ax.plot(*exact_curve, color=EXACT_COLOR, lw=3.0, alpha=0.35)
        ax.plot(reference.times, reference.quantities[quantity], color=REFERENCE_COLOR, lw=1.0, ls=(0, (2, 2)),
                alpha=0.8)
        failures, drawn_profiles = {}, 0
        for j, profile in enumerate(profiles):
            result = results.get((profile, policy))
            if result is None or result.step_count == 0:
                continue
            drawn = _draw_run(ax, result.times, result.quantities[quantity], policy_color(policy), profile_style(j),
                              low, high, result.status != "ok")
            marks = {k: marks[k] or drawn[k] for k in marks}
            drawn_profiles += 1
            if result.status != "ok":
                failures.setdefault(result.status, []).append(_label(profile))
        ax.set_title(policy + failure_note(failures, drawn_profiles), loc="left", fontsize=10,
                     color=policy_color(policy) if not failures else "#b00000")
        ax.set_ylim(low, high)
        if index % columns == 0:
            ax.set_ylabel(f"{quantity} ({unit})" if unit else quantity)
        if index // columns == rows - 1 or index + columns >= len(policies):
            ax.set_xlabel("time (s)")
            ax.tick_params(labelbottom=True)
    for index in range(len(policies), rows * columns):
        axes[index // columns][index % columns].set_visible(False)
    # The legend says what is drawn and nothing else.
    handles = [Line2D([], [], color=REFERENCE_COLOR, lw=1.0, ls=(0, (2, 2)), label="reference (1/1000 s)")]
    if exact_curve is not None:
        handles.append(Line2D([], [], color=EXACT_COLOR, lw=3.0, alpha=0.35, label="exact solution"))
    for j, profile in enumerate(profiles):
        linestyle, marker = profile_style(j)
        handles.append(Line2D([], [], color="#555555", ls=linestyle, marker=marker, ms=4, label=_label(profile)))
    if marks["off"]:
        handles.append(Line2D([], [], color="#555555", marker="^", mec="black", ls="none", ms=8,
                              label="leaves the axes here"))
    if marks["failed"]:
        handles.append(Line2D([], [], color="#555555", marker="X", mec="black", ls="none", ms=9,
                              label="run failed here (blew up / broke)"))
    figure.legend(handles=handles, loc="outside lower center", ncol=min(5, len(handles)))
    figure.suptitle(f"{scene}: {quantity}, one panel per policy (colour), one line style per frame-time profile",
                    fontsize=11)
    return figure


def _limits(reference: np.ndarray, others: list[np.ndarray]) -> tuple[float, float]:
    """The y range: every curve's, but at most the reference's range widened by its span on each side, so that a
    run gone wild does not flatten every other curve (where one leaves this range, it is marked)."""
    finite = reference[np.isfinite(reference)]
    low, high = (float(finite.min()), float(finite.max())) if len(finite) else (-1.0, 1.0)
    span = high - low if high > low else max(abs(high), 1e-3)
    values = np.concatenate([finite] + [v[np.isfinite(v)] for v in others])
    low = max(float(values.min()), low - span)
    high = min(float(values.max()), high + span)
    margin = 0.08 * (high - low)
    return low - margin, high + margin


HATCHES = ("", "//", "..", "\\\\", "oo", "--", "++")


def deviation_figure(scene: str, quantity: str, deviations: dict, out_dir: Path,
                     statuses: dict | None = None) -> list[Path]:
    """draw_deviation_figure saved as out_dir/deviation_<scene>.png and .svg."""
    return save(draw_deviation_figure(scene, quantity, deviations, statuses), out_dir, f"deviation_{scene}")


def failure_note(failures: dict[str, list[str]], drawn: int, width: int = 44) -> str:
    """What a panel's title adds for its failed runs, kept within the panel (a list of every profile ran into the
    next panel's title): "\nbroken under every profile", or by status, "\nbroken: fixed:30, hitch:60:30:0.1",
    wrapped at width characters; "" when none failed."""
    import textwrap

    if not failures:
        return ""
    if len(failures) == 1 and len(next(iter(failures.values()))) == drawn > 1:
        return f"\n{next(iter(failures))} under every profile"
    text = "; ".join(f"{status}: {', '.join(labels)}" for status, labels in failures.items())
    return "\n" + textwrap.fill(text, width)


@_styled
def draw_deviation_figure(scene: str, quantity: str, deviations: dict, statuses: dict | None = None) -> Figure:
    """Grouped bars: the deviation per profile (groups) and policy (colour and hatch), on a log scale.

    deviations: {(profile, policy): value}; statuses: {(profile, policy): status}. A failed run (inf, or a status
    other than "ok") has no deviation to draw: no bar, but a red ✕ and its status at the foot of its place (a bar
    at some height would read as a value); the title mentions failures only when there are some."""
    statuses = statuses or {}
    profiles = list(dict.fromkeys(profile for profile, _ in deviations))
    policies = list(dict.fromkeys(policy for _, policy in deviations))
    finite = [v for k, v in deviations.items() if np.isfinite(v) and v > 0 and statuses.get(k, "ok") == "ok"]
    top = max(finite) * 3 if finite else 1.0
    bottom = min(finite) / 3 if finite else 1e-6
    figure = Figure(figsize=(min(16.0, max(9.0, 0.3 * len(profiles) * max(1, len(policies)) + 2.5)), 4.4),
                    constrained_layout=True)
    ax = figure.subplots()
    width = 0.8 / max(1, len(policies))
    any_failed = False
    for j, policy in enumerate(policies):
        positions, heights, failed = [], [], []
        for i, profile in enumerate(profiles):
            value = deviations.get((profile, policy))
            if value is None:
                continue
            bad = not np.isfinite(value) or statuses.get((profile, policy), "ok") != "ok"
            positions.append(i + (j - (len(policies) - 1) / 2) * width)
            heights.append(bottom if bad else max(value, bottom))  # the axis' foot: nothing shows of a failed run
            failed.append(statuses.get((profile, policy), "blew up") if bad and value is not None else None)
        bars = ax.bar(positions, heights, width, color=policy_color(policy), hatch=HATCHES[j % len(HATCHES)],
                      edgecolor="white", linewidth=0.4, label=policy)
        for bar, status in zip(bars, failed):
            if status:
                any_failed = True
                ax.text(bar.get_x() + bar.get_width() / 2, bottom * 1.15, f"✕ {status}", ha="center", va="bottom",
                        rotation=90, fontsize=7, color="#b00000")
    ax.set_yscale("log")
    ax.set_ylim(bottom, top * 2.0)
    ax.set_xticks(range(len(profiles)), [_label(profile) for profile in profiles])
    ax.set_ylabel("RMS deviation / amplitude")
    ax.set_title(f"{scene}: deviation of {quantity} from the reference run, by profile and policy"
                 + (" (✕: the run failed, no deviation)" if any_failed else ""), loc="left", fontsize=10)
    figure.legend(*ax.get_legend_handles_labels(), ncol=min(7, len(policies)), loc="outside lower center",
                  fontsize=8)
    return figure

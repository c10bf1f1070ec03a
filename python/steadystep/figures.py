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

from steadystep import article, runs
from steadystep._native import SteadystepError, number, printable
from steadystep.limits import MIN_MEASURED_DURATION_S
from steadystep.profiles import seed_value
from steadystep.files import save_figure
from steadystep.profiles import frame_times

POLICY_COLORS = {
    "naive": "#e6550d",    # orange
    "implicit-euler": "#756bb1",   # purple
    "matched": "#8c6d31",  # brown
    "exact": "#17becf",    # cyan
    "fixed": "#636363",    # grey
}
REFERENCE_COLOR = "#000000"
EXACT_COLOR = "#1f5fbf"      # the article's blue
FIXED_30_COLOR = "#d62728"   # the article's red
VARIABLE_COLOR = "#2ca02c"   # the article's green

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


def policy_color(policy: str) -> str:
    return POLICY_COLORS.get(policy, "#333333")


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
    duration_s (s) is at least MIN_MEASURED_DURATION_S (0.1 s) and within the bound of limits.py for 15-45 fps
    frames (about 22000 s). Raises SteadystepError naming the value, before anything is drawn.
    """
    duration_s, seed = number("duration_s", duration_s, "s"), seed_value(seed)
    if not duration_s >= MIN_MEASURED_DURATION_S:
        raise SteadystepError("out of range", f"duration_s = {duration_s:g} s: the figure needs at least "
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


@_styled
def scene_figure(scene: str, quantity: str, unit: str, reference, results, out_dir: Path,
                 exact_curve=None) -> list[Path]:
    """One panel per profile: the quantity over time for each policy, over the reference (and exact solution).

    results: {(profile, policy): RunResult}; reference: RunResult; exact_curve: (t, y) or None.
    """
    profiles = list(dict.fromkeys(profile for profile, _ in results))
    policies = list(dict.fromkeys(policy for _, policy in results))
    columns = min(3, len(profiles))
    rows = (len(profiles) + columns - 1) // columns
    figure = Figure(figsize=(4.6 * columns, 3.1 * rows + 0.8), constrained_layout=True)
    axes = figure.subplots(rows, columns, squeeze=False, sharex=True, sharey=True)
    low, high = _limits(reference.quantities[quantity],
                        [r.quantities[quantity] for r in results.values() if r.step_count])
    for index, profile in enumerate(profiles):
        ax = axes[index // columns][index % columns]
        if exact_curve is not None:
            ax.plot(*exact_curve, color=EXACT_COLOR, lw=2.4, alpha=0.6, label="exact solution")
        ax.plot(reference.times, reference.quantities[quantity], color=REFERENCE_COLOR, lw=1.0, ls="--",
                label="reference (1/1000 s)")
        for policy in policies:
            result = results.get((profile, policy))
            if result is None or result.step_count == 0:
                continue
            label = policy + (" (blew up)" if result.blew_up else " (broken)" if result.broken else "")
            # The article's method drawn on top: it is what the figure is about.
            on_top = policy == "implicit-euler"
            ax.plot(result.times, result.quantities[quantity], color=policy_color(policy), lw=1.5 if on_top else 1.1,
                    zorder=3 if on_top else 2, label=label)
        ax.set_title(_label(profile), loc="left", fontsize=10)
        ax.set_ylim(low, high)
        if index % columns == 0:
            ax.set_ylabel(f"{quantity} ({unit})" if unit else quantity)
        if index // columns == rows - 1 or index + columns >= len(profiles):
            ax.set_xlabel("time (s)")
            ax.tick_params(labelbottom=True)
    for index in range(len(profiles), rows * columns):
        axes[index // columns][index % columns].set_visible(False)
    handles, labels = axes[0][0].get_legend_handles_labels()
    seen = dict(zip(labels, handles))
    for ax in axes.flat:
        for handle, label in zip(*ax.get_legend_handles_labels()):
            seen.setdefault(label, handle)
    figure.legend(seen.values(), seen.keys(), loc="outside lower center", ncol=min(7, len(seen)))
    figure.suptitle(f"{scene}: {quantity} under each frame-time profile", fontsize=11)
    return save(figure, out_dir, f"scene_{scene}_{quantity}".replace(" ", "_"))


def _limits(reference: np.ndarray, others: list[np.ndarray]) -> tuple[float, float]:
    """The y range: every curve's, but at most the reference's range widened by its span on each side, so that a
    run gone wild does not flatten every other curve."""
    finite = reference[np.isfinite(reference)]
    low, high = (float(finite.min()), float(finite.max())) if len(finite) else (-1.0, 1.0)
    span = high - low if high > low else max(abs(high), 1e-3)
    values = np.concatenate([finite] + [v[np.isfinite(v)] for v in others])
    low = max(float(values.min()), low - span)
    high = min(float(values.max()), high + span)
    margin = 0.08 * (high - low)
    return low - margin, high + margin


@_styled
def deviation_figure(scene: str, quantity: str, deviations: dict, out_dir: Path) -> list[Path]:
    """Grouped bars: the deviation per profile (groups) and policy (colours), on a log scale.

    deviations: {(profile, policy): value}; inf (a blow-up) is drawn as a hatched bar at the top."""
    profiles = list(dict.fromkeys(profile for profile, _ in deviations))
    policies = list(dict.fromkeys(policy for _, policy in deviations))
    finite = [v for v in deviations.values() if np.isfinite(v) and v > 0]
    top = max(finite) * 3 if finite else 1.0
    bottom = min(finite) / 3 if finite else 1e-6
    figure = Figure(figsize=(max(6.0, 1.3 * len(profiles) * max(1, len(policies)) / 2.5 + 2), 3.8),
                    constrained_layout=True)
    ax = figure.subplots()
    width = 0.8 / max(1, len(policies))
    for j, policy in enumerate(policies):
        positions, heights, hatched = [], [], []
        for i, profile in enumerate(profiles):
            value = deviations.get((profile, policy))
            if value is None:
                continue
            positions.append(i + (j - (len(policies) - 1) / 2) * width)
            heights.append(value if np.isfinite(value) else top)
            hatched.append(not np.isfinite(value))
        bars = ax.bar(positions, heights, width, color=policy_color(policy), label=policy)
        for bar, blown in zip(bars, hatched):
            if blown:
                bar.set_hatch("xx")
                bar.set_edgecolor("white")
    ax.set_yscale("log")
    ax.set_ylim(bottom, top * 1.5)
    ax.set_xticks(range(len(profiles)), [_label(profile) for profile in profiles])
    ax.set_ylabel("RMS deviation / amplitude")
    ax.set_title(f"{scene}: deviation of {quantity} from the reference run, by profile and policy"
                 " (hatched: blew up)", loc="left", fontsize=10)
    ax.legend(ncol=len(policies), loc="upper left", fontsize=8)
    return save(figure, out_dir, f"deviation_{scene}")

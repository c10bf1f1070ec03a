"""Something to watch: the chain swinging under naive, implicit-euler and fixed at 15-45 fps, beside the fine-step
reference, as an animation inside report.html.

The runs are driven frame by frame (runs.Scene) under the profile's frame times; after every frame the chain's
drawing is recorded with the scene's time, as a program would draw it: on the poses the stepper gives to draw
(ssScene_InterpolatedPoints, from ssStepper_InterpolatedPose: the pivot and the far end of each link). Under fixed
those are blended between the last two physics steps at the frame's interpolation factor, so fixed moves smoothly
one step behind; under the other policies they are ODE's own. The page plays
them back on one clock: each panel shows the last frame its run rendered at or before that time, as a player of
that frame rate would see it. The page is self-contained: an inline SVG and an inline script with the
trajectories as JSON; nothing is fetched.

The script writes the frame it shows into the page (data-frame, data-time-s on the <figure>), so that a test in a
headless browser can see it move.
"""

from __future__ import annotations

import html
import json

import numpy as np

from steadystep import runs
from steadystep.profiles import frames_within

SCENE = "chain"
PROFILE = "uniform:15:45"
POLICIES = ("naive", "implicit-euler", "fixed")
REFERENCE_FRAME_S = runs.REFERENCE_STEP_S
# The reference is recorded at this rate (its 1000 frames a second would only make the page heavier).
REFERENCE_RECORD_HZ = 60.0
PLAYBACK_HZ = 60.0


def _record(policy: str, frames: list[float], stepping: dict | None, params: dict | None,
            every_s: float = 0.0) -> dict:
    """Plays frames through a Scene; returns {"policy", "t": [...], "points": [[[x, z], ...], ...], "status"}."""
    scene = runs.Scene(SCENE, policy, params=params, stepping=stepping)
    times, points, status = [0.0], [scene.points(interpolated=True)[:, [0, 2]].round(4).tolist()], "ok"
    next_record_s = every_s
    try:
        for frame_s in frames:
            try:
                scene.frame(frame_s)
            except runs.SteadystepError as error:
                status = error.status
                break
            now = scene.time_s
            if every_s and now + 1e-12 < next_record_s:
                continue
            next_record_s += every_s
            times.append(round(now, 6))
            points.append(scene.points(interpolated=True)[:, [0, 2]].round(4).tolist())
    finally:
        scene.close()
    return {"policy": policy, "t": times, "points": points, "status": status}


def record(duration_s: float = 5.0, seed: int = 1, params: dict | None = None) -> dict:
    """The chain under POLICIES at 15-45 fps and the reference (1 ms steps), for duration_s (s)."""
    frames = list(frames_within(PROFILE, duration_s, seed))
    reference_frames = [REFERENCE_FRAME_S] * int(round(duration_s / REFERENCE_FRAME_S))
    panels = [_record("implicit-euler", reference_frames, runs.reference_stepping(), params,
                      1.0 / REFERENCE_RECORD_HZ)]
    panels[0]["policy"] = "reference (1 ms steps)"
    for policy in POLICIES:
        panels.append(_record(policy, frames, None, params))
    everything = np.array([p for panel in panels for frame in panel["points"] for p in frame])
    finite = everything[np.all(np.isfinite(everything), axis=1)]
    low, high = finite.min(axis=0), finite.max(axis=0)
    return {"scene": SCENE, "profile": PROFILE, "seed": seed, "duration_s": duration_s, "panels": panels,
            "bounds": [float(low[0]), float(low[1]), float(high[0]), float(high[1])]}


def section(data: dict) -> str:
    """The HTML of the animation: an SVG with one panel per run and the script that plays them."""
    panels = data["panels"]
    width, height, pad = 300, 300, 14
    low_x, low_z, high_x, high_z = data["bounds"]
    span = max(high_x - low_x, high_z - low_z, 1e-3)
    scale = (width - 2 * pad) / span
    svg_panels = []
    for i, panel in enumerate(panels):
        x0 = i * (width + 10)
        status = "" if panel["status"] == "ok" else f" ({panel['status']})"
        svg_panels.append(
            f"<g transform='translate({x0},0)'><rect width='{width}' height='{height + 24}' fill='#fafafa' "
            f"stroke='#ccc'/><text x='8' y='{height + 17}' font-size='13'>{html.escape(panel['policy'] + status)}"
            f"</text>" + ("" if i == 0 else f"<polyline class='ghost' data-panel='{i}' fill='none' stroke='#bbb' "
                                       f"stroke-width='4' stroke-linejoin='round' points=''/>")
            + f"<polyline class='chain' data-panel='{i}' fill='none' stroke='#333' stroke-width='4' "
            f"stroke-linejoin='round' points=''/><circle class='tip' data-panel='{i}' r='5' fill='#d62728'/></g>")
    total_width = len(panels) * (width + 10)
    script = _SCRIPT.replace("__DATA__", json.dumps(data, separators=(",", ":"), allow_nan=False))
    script = script.replace("__SCALE__", repr(scale)).replace("__PAD__", str(pad))
    script = script.replace("__LOWX__", repr(low_x)).replace("__HIGHZ__", repr(high_z))
    script = script.replace("__HZ__", repr(PLAYBACK_HZ))
    return (f"<figure id='animation-player' data-frame='0' data-time-s='0'>"
            f"<svg id='animation-svg' width='{total_width}' height='{height + 26}' "
            f"viewBox='0 0 {total_width} {height + 26}' role='img' aria-label='the chain swinging'>"
            + "".join(svg_panels) + "</svg>"
            f"<figcaption><button id='animation-toggle' type='button'>pause</button> "
            f"t = <span id='animation-time'>0.00</span> s of {data['duration_s']:g} s (looping). Each panel shows the "
            f"last frame its run rendered: the reference every 1/60 s of its 1 ms steps, naive and implicit-euler "
            f"at their {html.escape(data['profile'])} frames (profile seed {data['seed']}); in grey behind them, "
            f"the reference at the same time.</figcaption>"
            f"</figure><script>{script}</script>")


# Plays on a counter of ticks (not the wall clock), so that a headless browser's virtual time drives it too.
_SCRIPT = """
(function () {
  const data = __DATA__;
  const scale = __SCALE__, pad = __PAD__, lowX = __LOWX__, highZ = __HIGHZ__, hz = __HZ__;
  const figure = document.getElementById('animation-player');
  const lines = figure.querySelectorAll('polyline.chain');
  const tips = figure.querySelectorAll('circle.tip');
  const ghosts = figure.querySelectorAll('polyline.ghost');
  const clock = document.getElementById('animation-time');
  let tick = 0, playing = true;
  function shown(times, t) {
    let lo = 0, hi = times.length - 1;
    while (lo < hi) { const mid = (lo + hi + 1) >> 1; if (times[mid] <= t) lo = mid; else hi = mid - 1; }
    return lo;
  }
  function place(pts) {
    return pts.map(function (p) { return [pad + (p[0] - lowX) * scale, pad + (highZ - p[1]) * scale]; });
  }
  function text(xy) {
    return xy.map(function (p) { return p[0].toFixed(1) + ',' + p[1].toFixed(1); }).join(' ');
  }
  function draw() {
    const t = (tick / hz) % data.duration_s;
    const reference = data.panels[0];
    const ghost = text(place(reference.points[shown(reference.t, t)]));
    ghosts.forEach(function (line) { line.setAttribute('points', ghost); });
    data.panels.forEach(function (panel, i) {
      const xy = place(panel.points[shown(panel.t, t)]);
      lines[i].setAttribute('points', text(xy));
      const tip = xy[xy.length - 1];
      tips[i].setAttribute('cx', tip[0].toFixed(1));
      tips[i].setAttribute('cy', tip[1].toFixed(1));
    });
    figure.setAttribute('data-frame', String(tick));
    figure.setAttribute('data-time-s', t.toFixed(3));
    clock.textContent = t.toFixed(2);
  }
  document.getElementById('animation-toggle').addEventListener('click', function () {
    playing = !playing;
    this.textContent = playing ? 'pause' : 'play';
  });
  draw();
  setInterval(function () { if (playing) { tick += 1; draw(); } }, 1000 / hz);
})();
"""

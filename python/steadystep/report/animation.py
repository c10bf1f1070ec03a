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

import numpy as np
from markupsafe import Markup

from steadystep.lab import runs
from steadystep.lab.profiles import frames_within

SCENE = "chain"
PROFILE = "uniform:15:45"
POLICIES = ("naive", "implicit-euler", "fixed")
REFERENCE_FRAME_S = runs.REFERENCE_STEP_S
# The reference is recorded at this rate (its 1000 frames a second would only make the page heavier).
REFERENCE_RECORD_HZ = 60.0
PLAYBACK_HZ = 60.0


def _record(policy: str, frames: list[float], stepping: dict | None, params: dict | None,
            every_s: float = 0.0) -> dict:
    """Plays frames through a Scene; returns {"policy", "t": [...], "points": [[[x, z], ...], ...], "status",
    "broken_s"}: status "broken" from the first frame after which the scene left its sanity bounds (broken_s, the
    scene's time then; the drawing goes on, physically wrong, and the panel says so), or a blow-up status."""
    scene = runs.Scene(SCENE, policy, params=params, stepping=stepping)
    times, points, status = [0.0], [scene.points(interpolated=True)[:, [0, 2]].round(4).tolist()], "ok"
    broken_s = None
    next_record_s = every_s
    try:
        for frame_s in frames:
            try:
                scene.frame(frame_s)
            except runs.SteadystepError as error:
                status = error.status
                break
            now = scene.time_s
            if broken_s is None and scene.broken is not None:
                status, broken_s = runs.BROKEN, round(now, 6)
            if every_s and now + 1e-12 < next_record_s:
                continue
            next_record_s += every_s
            times.append(round(now, 6))
            points.append(scene.points(interpolated=True)[:, [0, 2]].round(4).tolist())
    finally:
        scene.close()
    return {"policy": policy, "t": times, "points": points, "status": status, "broken_s": broken_s}


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


def _status_label(panel: dict) -> str:
    """What a panel's title adds when its run did not stay physical: ", broken at 1.23 s" (it left the scene's
    sanity bounds then: what follows is drawn, and wrong) or the blow-up status; nothing for a run that stayed ok."""
    if panel["status"] == "ok":
        return ""
    if panel.get("broken_s") is not None:
        return f", broken at {panel['broken_s']:.2f} s"
    return f" ({panel['status']})"


def section(data: dict) -> Markup:
    """The HTML of the animation: an SVG with one panel per run and the script that plays them
    (templates.py: animation.html)."""
    from steadystep.report.templates import ENVIRONMENT

    width, height, pad = 300, 300, 14
    low_x, low_z, high_x, high_z = data["bounds"]
    span = max(high_x - low_x, high_z - low_z, 1e-3)
    panels = [{"title": panel["policy"] + _status_label(panel), "failed": panel["status"] != "ok"}
              for panel in data["panels"]]
    return Markup(ENVIRONMENT.get_template("animation.html").render(
        panels=panels, width=width, height=height, total_width=len(panels) * (width + 10), data=data,
        scale=(width - 2 * pad) / span, pad=pad, low_x=low_x, high_z=high_z, hz=PLAYBACK_HZ,
        duration_s=data["duration_s"], profile=data["profile"], seed=data["seed"], policies=list(POLICIES)))

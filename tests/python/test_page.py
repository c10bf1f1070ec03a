"""The report's page in a real browser (Debian's headless Chromium), and its recommendation against its own numbers.

The page is made once for the module from a small comparison (the chain and the stack, two profiles, four policies
with the control substeps-frozen, 1 s, through the local pool), written with report.write, and opened as a file: the
animation must render and move, every link of the recommendation must land on something, and the recommendation
must name what metrics.json, read independently here, says is best, and say they tie where the lead is within the
measured spread of repeats.
"""

from __future__ import annotations

import dataclasses
import html
import json
import math
import os
import re
import shutil
import statistics
import subprocess

import numpy as np
import pytest

from steadystep import report

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
needs_chromium = pytest.mark.skipif(CHROMIUM is None and not os.environ.get("CI"),
                                    reason="chromium not found on PATH: install Debian's chromium (sudo apt-get install "
                                           "chromium; scripts/deps.sh does it; required in CI)")


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    out = tmp_path_factory.mktemp("page")
    made = report.compare(["chain", "stack"], ["fixed:30", "uniform:15:45"],
                          ["naive", "substeps-frozen", "implicit-euler", "matched"], duration_s=1.0, seed=2,
                          progress=False, figure_dir=out, executor="local")
    path = report.write(made, out, "steadystep compare --scenes chain stack <b>&")
    return path, json.loads((out / "metrics.json").read_text())


def _chromium(*args: str, tmp_path) -> subprocess.CompletedProcess:
    assert CHROMIUM is not None, ("chromium not found on PATH: install Debian's chromium (sudo apt-get install "
                                  "chromium; scripts/deps.sh does it)")
    command = [CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
               f"--user-data-dir={tmp_path / 'profile'}", *args]
    return subprocess.run(command, capture_output=True, text=True, timeout=180)


def _section(page: str, need: str) -> str:
    match = re.search(r"<li><b>" + re.escape(need) + r":</b>(.*?)</li>", page, re.S)
    assert match, need
    return match.group(1)


def test_every_link_lands_and_nothing_is_fetched(written):
    page = written[0].read_text()
    targets = set(re.findall(r"href='#([^']+)'", page))
    assert {"consistency", "deviation", "cost", "stable", "runs"} <= targets
    ids = set(re.findall(r"id='([^']+)'", page)) | set(re.findall(r'id="([^"]+)"', page))
    assert targets <= ids, targets - ids
    assert not re.search(r"""(src|href)=["']?(https?:)?//""", page), "the page must be self-contained"


def _leaders(values: dict, spread: dict) -> list[str]:
    """Written again from the rule the page states: the lowest, and every policy whose value less its spread of
    repeats reaches the lowest's value plus its spread."""
    values = {p: v for p, v in values.items() if v is not None}
    best = min(values, key=lambda p: (values[p], p))
    return sorted((p for p in values if values[p] - (spread.get(p) or 0) <= values[best] + (spread.get(best) or 0)),
                  key=lambda p: (values[p], p))


def _verdict_cell(page: str, scene: str, column: int) -> str:
    row = re.search(r"<tr><td><a href='#" + scene + r"'>" + scene + r"</a></td>(.*?)</tr>", page, re.S)
    assert row, scene
    return re.findall(r"<td>(.*?)</td>", row.group(1), re.S)[column]


def test_a_winner_is_named_only_beyond_the_spread_of_repeats(written):
    page, metrics = written[0].read_text(), written[1]
    assert metrics["repeat"]["profiles"] == ["uniform:15:45"] and metrics["repeat"]["seed"] == 3
    for scene, quantity in (("chain", "end x"), ("stack", "top x")):
        deviation = {p: v[quantity] for p, v in metrics["spread"][scene].items()}
        spread = {p: v[quantity] for p, v in metrics["repeat"]["deviation"][scene].items()}
        tied = _leaders(deviation, spread)
        cell = _verdict_cell(page, scene, 2)
        assert cell.startswith("tie: ") == (len(tied) > 1), (scene, cell, tied)
        assert re.findall(r"<b>([^<]+)</b>", cell) == tied
        # The spread is a real repeat: the uniform profile's runs under the next seed moved the deviation.
        assert any(v and v > 0 for v in spread.values())


def test_the_served_shares_are_the_runs_counters(written):
    page, metrics = written[0].read_text(), written[1]
    for scene in ("chain", "stack"):
        for what in ("rows", "contacts"):
            summed = {}
            for row in metrics["rows"]:
                if row["scene"] == scene and row["policy"] == "matched":
                    for kind, n in row[f"{what}_served"].items():
                        summed[kind] = summed.get(kind, 0) + n
            assert metrics["served"][scene]["matched"][what] == summed
    stack = metrics["served"]["stack"]["matched"]["contacts"]
    assert sum(stack.values()) > 0  # the stack softens its contacts with ssStepper_SoftenContact
    share = 100 * stack["by_mapping"] / sum(stack.values())
    assert f"matched serves" in _section(page, "Where the accurate mappings serve")
    assert f"{share:.0f} % of its contacts" in _section(page, "Where the accurate mappings serve")


def test_the_control_separates_the_cut_from_the_mapping(written):
    page, metrics = written[0].read_text(), written[1]
    text = _section(page, "What cutting the frame gives, what the mapping adds")
    c = {p: v["top x"] for p, v in metrics["consistency"]["stack"].items()}
    numbers = " → ".join("failed" if c[p] is None else f"{c[p]:.2g}" for p in ("naive", "substeps-frozen",
                                                                                 "implicit-euler"))
    assert numbers in text


def test_markup_is_escaped_unless_marked(written):
    page = written[0].read_text()
    assert "--scenes chain stack &lt;b&gt;&amp;" in page and "stack <b>&" not in page
    from steadystep.report import recommendation as page_module, html as report_html

    assert page_module.bold("<i>") == "<b>&lt;i&gt;</b>"
    assert report_html.policy_cell("a<b").endswith("a&lt;b")


def test_the_recommendation_names_the_best_by_the_numbers_on_the_page(written):
    page, metrics = written[0].read_text(), written[1]
    consistency = metrics["consistency"]["chain"]
    values = {p: v["end x"] for p, v in consistency.items()}
    best = min(values, key=lambda p: math.inf if values[p] is None else values[p])
    assert f"<b>{best}</b>" in _section(page, "Same motion at every frame rate")
    deviation = {p: v["end x"] for p, v in metrics["spread"]["chain"].items() if v["end x"] is not None}
    assert f"<b>{min(deviation, key=deviation.get)}</b>" in _section(page, "Closest to the fine-step reference")
    ratios = {}
    for entry in metrics["cost"]["runs"]:
        if entry["ratio_median"] is None:  # no block compared like with like (a copy asleep): no ratio, said so
            assert entry["status"] != "ok" or entry["ratio_blocks"] == 0
            continue
        ratios.setdefault(entry["policy"], []).append(entry["ratio_median"])
    if any(e["status"] == "ok" and e["ratio_blocks"] == 0 for e in metrics["cost"]["runs"]):
        assert "not like with like" in page[page.index("id='cost'"):]
    cheapest_text = _section(page, "Cheapest")
    for policy, values in ratios.items():
        assert html.escape(policy) + f" ×{statistics.median(values):.3g}" in cheapest_text
    stable: dict[str, dict[str, float]] = {}
    for scene, entries in metrics["largest_stable_step"].items():
        for e in entries:
            stable.setdefault(e["policy"], {})[scene] = e["stable_s"]
    score = {p: (min(v.values()), statistics.geometric_mean(v.values())) for p, v in stable.items()}
    best = max(score.values())
    stable_text = _section(page, "Largest stable step")
    assert f"{1000 * best[0]:.3g} ms" in stable_text
    for policy in stable:
        assert (f"<b>{policy}</b>" in stable_text) == (score[policy] == best)


def _first_screen(page: str) -> str:
    section = page[page.index("<section id='recommendation'>"):]
    return section[:section.index("</section>")]


def test_the_first_screen_ends_with_the_code_for_the_policy_it_recommends(written):
    """Read from metrics.json by the page's stated rule: no preset is the same under every profile here (no fixed
    policy ran), so the code is for the preset most alike across profiles on the most scenes (ties within the spread
    of repeats count for each), the library's order breaking a tie. The lab's control substeps-frozen has no code."""
    import steadystep as ss
    from steadystep.report import snippets

    page, metrics = written[0].read_text(), written[1]
    presets = ss.policy_names()
    counts = dict.fromkeys(presets, 0)
    for scene, quantity in (("chain", "end x"), ("stack", "top x")):
        values = {p: v[quantity] for p, v in metrics["consistency"][scene].items()}
        assert not any(v is not None and v <= 1e-9 for v in values.values())  # none the same everywhere
        spread = {p: v[quantity] for p, v in metrics["repeat"]["consistency"][scene].items()}
        for policy in _leaders(values, spread):
            if policy in counts:
                counts[policy] += 1
    policy = max(presets, key=lambda p: (counts[p], -presets.index(p)))
    assert counts[policy] > 0 and policy != "substeps-frozen"
    screen = _first_screen(page)
    assert f"<h3 id='code'>The code to write for {policy}</h3>" in screen
    assert f"the most alike across frame rates on {counts[policy]} of the 2 scenes" in screen
    assert screen.index("id='policies'") < screen.index("<h3 id='code'>")
    blocks = re.findall(r"<pre class=code><code>(.*?)</code></pre>", screen, re.S)
    assert [html.unescape(b) for b in blocks] == [s.text for s in snippets.for_policy(policy)]  # C, then Python
    assert screen.rstrip().endswith(f"<code>{blocks[-1]}</code></pre>")  # the code ends the first screen


def test_code_for_fixed_when_it_is_the_same_motion_everywhere():
    from steadystep.report import recommendation as page_module, html as report_html, snippets
    from steadystep.report.model import Report

    made = Report(scenes=["chain", "stack"], profiles=["fixed:30", "uniform:15:45"],
                  policies={"chain": ["implicit-euler", "fixed-exact", "fixed"], "stack": ["implicit-euler", "fixed",
                                                                                            "fixed-exact"]},
                  duration_s=1.0, seed=1,
                  consistency={"chain": {"implicit-euler": {"end x": 0.01}, "fixed": {"end x": 0.0},
                                         "fixed-exact": {"end x": 1e-12}},
                               "stack": {"implicit-euler": {"top x": 0.02}, "fixed": {"top x": 0.0},
                                         "fixed-exact": {"top x": 0.0}}})
    policy, why = page_module.code_policy(made)
    assert policy == "fixed" and "the same motion at every frame rate" in why  # the library's order: fixed first
    code = report_html.code_to_write(made)
    assert code["snippets"] == snippets.for_policy("fixed")
    assert "before_step" in code["summary"] and "interpolated poses" in code["summary"]
    # No preset the same everywhere: the most alike on the most scenes, a tie (one scene each) to the library's
    # order, in which implicit-euler comes before the fixed ones.
    made.consistency["stack"]["fixed"]["top x"] = made.consistency["stack"]["fixed-exact"]["top x"] = 0.03
    policy, why = page_module.code_policy(made)
    assert policy == "implicit-euler" and "on 1 of the 2 scenes" in why
    made.consistency["chain"]["fixed-exact"]["end x"] = 0.5  # on the chain, fixed alone leads now
    made.consistency["stack"]["fixed"]["top x"] = 0.02  # and ties implicit-euler on the stack
    policy, why = page_module.code_policy(made)
    assert policy == "fixed" and "on 2 of the 2 scenes" in why


def test_the_csv_columns_have_no_spaces(written):
    header = (written[0].parent / "metrics.csv").read_text().splitlines()[0].split(",")
    assert header == list(report.CSV_COLUMNS) and not any(" " in name for name in header)


@needs_chromium
def test_the_animation_renders_and_moves(written, tmp_path):
    url = written[0].resolve().as_uri()
    dom = _chromium("--virtual-time-budget=2000", "--dump-dom", url, tmp_path=tmp_path).stdout
    frame = re.search(r'id="animation-player" data-frame="(\d+)"', dom)
    assert frame and int(frame.group(1)) >= 30, dom[:300]
    lines = re.findall(r'<polyline class="chain" data-panel="\d" [^>]*points="([^"]*)"', dom)
    from steadystep.report import animation

    # The reference and each policy, fixed among them (drawn from the interpolated poses): pivot + 8 links.
    assert "fixed" in animation.POLICIES
    assert len(lines) == 1 + len(animation.POLICIES) and all(len(p.split()) == 9 for p in lines), lines

    import matplotlib.image

    shots = []
    for budget in (300, 1500):
        shot = tmp_path / f"shot_{budget}.png"
        _chromium(f"--virtual-time-budget={budget}", f"--screenshot={shot}", "--window-size=1400,3600", url,
                  tmp_path=tmp_path)
        shots.append(matplotlib.image.imread(shot))
    assert shots[0].shape == shots[1].shape  # the whole page: the answer's picture comes before the animation
    changed = np.any(np.abs(shots[0] - shots[1]) > 0.05, axis=-1)
    rows = np.nonzero(changed.any(axis=1))[0]
    assert changed.sum() > 200, changed.sum()
    # Only the animation moves: the changed pixels lie in one band of the page, not all over it.
    assert rows.max() - rows.min() < 500, (rows.min(), rows.max())


def _legend(figure) -> list[str]:
    return [text.get_text() for legend in figure.legends for text in legend.get_texts()]


def test_a_run_that_leaves_the_axes_is_marked_and_the_legend_says_only_what_is_drawn():
    from steadystep.report import figures
    from steadystep.lab import runs

    reference = runs.reference_run("chain", 3.0)
    results = {(profile, policy): runs.run("chain", profile, policy, 3.0)
               for profile in ("fixed:2", "fixed:30") for policy in ("naive", "implicit-euler")}
    # Naive under 2 s frames breaks the chain on its first step, where its run ends; stepped on frame by frame, the
    # torn chain's end falls tens of metres, far below the reference's range.
    torn = runs.Scene("chain", "naive")
    times, ends = [], {"end x": [], "end z": []}
    for _ in range(2):
        torn.frame(2.0)
        times.append(torn.time_s)
        for name, value in torn.sample().items():
            ends[name].append(value)
    assert torn.broken and min(ends["end z"]) < -10
    results[("fixed:2", "naive")] = dataclasses.replace(
        results[("fixed:2", "naive")], times=np.array(times), quantities={k: np.array(v) for k, v in ends.items()})
    figure = figures.draw_scene_figure("chain", "end z", "m", reference, results)
    labels = _legend(figure)
    assert "leaves the axes here" in labels and "fixed:2" in labels and "fixed:30" in labels
    assert "exact solution" not in labels
    if all(r.status == "ok" for r in results.values()):
        assert not any("failed" in label for label in labels)
    calm = {key: value for key, value in results.items() if key[0] == "fixed:30"}
    assert "leaves the axes here" not in _legend(figures.draw_scene_figure("chain", "end z", "m", reference, calm))
    bars = figures.draw_deviation_figure("chain", "end z", {("fixed:30", "naive"): 0.1,
                                                            ("fixed:30", "implicit-euler"): 0.01})
    assert "✕" not in bars.axes[0].get_title(loc="left") and "hatched" not in bars.axes[0].get_title(loc="left")
    failed = figures.draw_deviation_figure("chain", "end z", {("fixed:30", "naive"): math.inf,
                                                              ("fixed:30", "implicit-euler"): 0.01},
                                           {("fixed:30", "naive"): "blow-up", ("fixed:30", "implicit-euler"): "ok"})
    assert "the run failed" in failed.axes[0].get_title(loc="left")
    # A failed run has no deviation: no bar at some height (it read as a value), but its status at the axis' foot.
    foot = failed.axes[0].get_ylim()[0]
    assert max(bar.get_y() + bar.get_height() for bar in failed.axes[0].patches[:1]) <= foot * 1.0001
    assert [text.get_text() for text in failed.axes[0].texts] == ["✕ blow-up"]
    assert all(bar.get_alpha() in (None, 1) for bar in failed.axes[0].patches)  # nothing faded


def test_parameters_read_as_names_not_json_with_enum_integers():
    from steadystep.lab import runs
    from steadystep.report.html import readable_settings

    text = readable_settings(runs.reference_stepping())
    assert "cut = substeps" in text and "solver = quick" in text and "mapping = implicit-euler" in text
    assert "max_step_s = 0.001 s" in text and "{" not in text and '"' not in text
    assert readable_settings({"body_count": 150}) == "body_count = 150" and readable_settings(None) == "-"


def test_the_stable_step_line_says_where_the_best_is_beaten():
    """Ranked on the hardest scene and the geometric mean, the best policy may still be beaten on one scene."""
    import types

    from steadystep.report import recommendation as page
    from steadystep.lab import probe

    # Both tie on the hardest scene (drop); matched has the larger geometric mean, naive goes further on the chain.
    stable = {"buggy": {"naive": 0.080, "matched": 0.103}, "chain": {"naive": 0.0271, "matched": 0.0265},
              "drop": {"naive": 0.0214, "matched": 0.0214}}
    report_like = types.SimpleNamespace(probes={
        scene: [probe.ProbeResult(scene, policy, value, 2 * value, 1, "") for policy, value in values.items()]
        for scene, values in stable.items()})
    text = re.sub("<[^>]+>", "", page._stable(report_like))
    assert text.startswith("matched:")
    assert "naive is shorter on buggy 80 ms against 103 ms" in text
    assert "on chain, naive 27.1 ms against 26.5 ms" in text


def test_a_broken_run_in_the_animation_says_so_in_its_panel():
    """The naive chain leaves its sanity bounds at 15-45 fps: its panel is labelled broken, with the time, in red
    (it was animated with no label before)."""
    from steadystep.report import animation

    data = animation.record(duration_s=1.0, seed=1)
    naive = next(panel for panel in data["panels"] if panel["policy"] == "naive")
    assert naive["status"] == "broken" and 0 < naive["broken_s"] <= 1.0
    html = str(animation.section(data))
    assert re.search(r"fill='#b00000' font-weight='bold'>naive, broken at \d\.\d\d s</text>", html)
    assert ">fixed</text>" in html and ">implicit-euler</text>" in html  # the runs that stayed ok: plain titles


def test_the_failures_in_a_panels_title_stay_within_the_panel():
    """Every profile's failure was listed on one line and ran into the next panel's title (the chain's naive
    panel): now one status for all reads "broken under every profile", and any list is wrapped to the panel."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from steadystep.report import figures
    from steadystep.lab import runs

    profiles = ["fixed:30", "uniform:15:45", "jitter:30:3", "hitch:60:30:0.1", "vsync:60:30"]
    reference = runs.reference_run("chain", 3.0)
    results = {(profile, policy): runs.run("chain", profile, policy, 3.0)
               for profile in profiles for policy in ("naive", "implicit-euler", "fixed")}
    assert all(results[profile, "naive"].status == "broken" for profile in profiles)
    figure = figures.draw_scene_figure("chain", "end z", "m", reference, results)
    FigureCanvasAgg(figure).draw()
    renderer = figure.canvas.get_renderer()
    titles = [ax._left_title for ax in figure.axes if ax.get_visible()]  # set_title(loc="left")
    boxes = [title.get_window_extent(renderer) for title in titles if title.get_text()]
    assert titles[0].get_text() == "naive\nbroken under every profile"
    for one, other in zip(boxes, boxes[1:]):
        assert not one.overlaps(other), (one, other)
    assert figures.failure_note({"broken": ["fixed:30"], "blow-up": ["hitch:60:30:0.1"]}, 5) == \
        "\nbroken: fixed:30; blow-up: hitch:60:30:0.1"
    assert all(len(line) <= 44 for line in figures.failure_note({"broken": profiles * 3}, 20).splitlines())


def _measured(page: Path, tmp_path) -> dict:
    """The page laid out by Chromium at 1400 px wide: its height, and where the answer and its picture end
    (a copy of the page with a script that writes them into the DOM once it has loaded)."""
    copy = page.with_name("measured.html")
    copy.write_text(page.read_text().replace("</body>", """<script>
window.addEventListener('load', function () {
  const bottom = (id) => { const e = document.getElementById(id); return e ? e.getBoundingClientRect().bottom : -1; };
  document.body.setAttribute('data-height', document.documentElement.scrollHeight);
  document.body.setAttribute('data-answer-bottom', bottom('answer'));
  document.body.setAttribute('data-figure-bottom', bottom('answer-figure'));
});
</script></body>"""))
    dom = _chromium("--virtual-time-budget=1000", "--window-size=1400,900", "--dump-dom", copy.resolve().as_uri(),
                    tmp_path=tmp_path).stdout
    found = re.search(r'<body data-height="([\d.]+)" data-answer-bottom="([-\d.]+)" data-figure-bottom="([-\d.]+)"',
                      dom)
    assert found, dom[:500]
    return {"height": float(found.group(1)), "answer": float(found.group(2)), "figure": float(found.group(3))}


@needs_chromium
def test_the_first_screen_answers_in_one_sentence_and_a_picture(written, tmp_path):
    """Issue 28: at 1400 px wide the first 900 pixels hold the recommendation sentence and a figure, the details
    are collapsed below, and the page is under 15,000 pixels tall."""
    page = written[0].read_text()
    sentence = re.search(r"<p id='answer'><b>(.*?)</b></p>", page, re.S)
    text = html.unescape(sentence.group(1)) if sentence else ""
    assert "For these scenes (chain, stack)" in text and " Use " in text, text
    assert re.search(r"it costs about [\d.]+ times the program's plain loop .*2 cores, load [\d.]+\)\.$", text), text
    measured = _measured(written[0], tmp_path)
    assert 0 < measured["answer"] <= 900 and 0 < measured["figure"] <= 900, measured
    assert measured["height"] < 15000, measured
    assert "<details id='measured'>" in page and "<details id='parameters'>" in page
    # The picture is what changes with the frame rate under each policy (report/answer.py), not one scene's chart; the
    # reasons and the code are collapsed below it, one line of summary.
    assert 'id="answer-figure"' in page and "each frame-time profile&#39;s deviation" in page
    assert page.index("<details id='why'>") < page.index("<section id='recommendation'>")


def test_the_first_picture_shows_every_policys_runs_and_consistency():
    """The answer's picture from the report's own numbers: one panel a scene, one tick a policy, one dot a profile's
    run that did not fail, and the consistency above each policy, the recommended policy bold."""
    from steadystep.report import recommendation as page_module, answer as report_answer

    made = report.Report(scenes=["chain", "stack"], profiles=["fixed:30", "uniform:15:45"],
                         policies={"chain": ["naive", "fixed"], "stack": ["naive", "fixed"]}, duration_s=1.0, seed=1)
    deviation = {("chain", "fixed:30", "naive"): 0.2, ("chain", "uniform:15:45", "naive"): 0.5,
                 ("chain", "fixed:30", "fixed"): 0.01, ("chain", "uniform:15:45", "fixed"): 0.01,
                 ("stack", "fixed:30", "naive"): float("inf"), ("stack", "uniform:15:45", "naive"): 0.3,
                 ("stack", "fixed:30", "fixed"): 0.02, ("stack", "uniform:15:45", "fixed"): 0.02}
    for (scene, profile, policy), value in deviation.items():
        quantity = "end x" if scene == "chain" else "top x"
        made.rows.append(report.Row(scene, profile, policy, {quantity: value}, 1.0, 30.0, 1.0,
                             "ok" if value != float("inf") else "blow-up"))
    made.consistency = {"chain": {"naive": {"end x": 0.1}, "fixed": {"end x": 0.0}},
                        "stack": {"naive": {"top x": float("inf")}, "fixed": {"top x": 1e-12}}}
    figure = report_answer.draw(made, "fixed", page_module.IDENTICAL)
    panels = [ax for ax in figure.axes if ax.get_visible()]
    assert [ax.get_title(loc="left") for ax in panels] == ["chain: end x", "stack: top x"]
    for ax in panels:
        assert [t.get_text() for t in ax.get_xticklabels()] == ["naive", "fixed"]
        bold = [t.get_text() for t in ax.get_xticklabels() if t.get_fontweight() == "bold"]
        assert bold == ["fixed"]
    dots = {ax.get_title(loc="left"): sorted(round(float(line.get_ydata()[0]), 6) for line in ax.get_lines()
                                              if line.get_marker() not in (None, "None", ""))
            for ax in panels}
    assert dots == {"chain: end x": [0.01, 0.01, 0.2, 0.5], "stack: top x": [0.02, 0.02, 0.3]}
    texts = {ax.get_title(loc="left"): [t.get_text() for t in ax.texts] for ax in panels}
    assert texts["chain: end x"] == ["0.1", "0"]
    assert texts["stack: top x"] == ["✕ 1 failed", "failed", "0"]  # the blown-up run, and 1e-12 is the same motion
    assert report_answer.png(made, "fixed", page_module.IDENTICAL).startswith(b"\x89PNG")

"""The Jinja2 templates of report.html and the environment that renders them, autoescape on: every value is escaped
unless it is a markupsafe.Markup (made only by report/recommendation.py and report/html.py's cells, their arguments
escaped as they go in); the animation's data goes into its script through tojson (JSON escaped for HTML). Kept as
strings in a module, so that the installed package carries them as it carries its code."""

import jinja2

_TABLE = """
{% macro table(data, anchor=none) -%}
<table{% if anchor %} id='{{ anchor }}'{% endif %}><thead><tr>
{%- for h in data.header %}<th>{{ h }}</th>{% endfor %}</tr></thead><tbody>
{%- for row in data.rows %}<tr>{% for c in row %}<td>{{ c }}</td>{% endfor %}</tr>{% endfor -%}
</tbody></table>
{%- endmacro %}
"""

_REPORT = """{% from "table.html" import table %}
<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>steadystep report</title>
<style>
body { font-family: system-ui, sans-serif; max-width: 1400px; margin: 2em auto; padding: 0 1em; color: #222; }
table { border-collapse: collapse; margin: 0.5em 0 0.5em; font-size: 0.9em; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: right; }
th { background: #f3f3f3; } td:first-child, td:nth-child(2) { text-align: left; }
#policies td, #per-scene td, #policies th, #per-scene th { text-align: left; }
img { max-width: 100%; display: block; margin: 0.5em 0 1.5em; }
.dot { display: inline-block; width: 0.7em; height: 0.7em; border-radius: 50%; margin-right: 0.4em; }
.bad { color: #b00; font-weight: bold; }
#recommendation { background: #f4f8ff; border: 1px solid #c9d8f0; padding: 0.3em 1em 1em; }
.answers li { margin: 0.35em 0; }
pre { background: #f6f6f6; padding: 0.6em; } pre.code { overflow-x: auto; } .small { color: #666; font-size: 0.85em; margin-bottom: 1.5em; }
figure { margin: 0.5em 0 1.5em; } figcaption { max-width: 75em; }
details { margin: 0.6em 0; } summary { cursor: pointer; }
</style></head><body>
<h1>steadystep: which constraint-softness policy, under variable frame times</h1>
{% if answer %}<p id='answer'><b>{{ answer.sentence }}</b></p>
{% if answer.figure %}<figure id='answer-picture'>{{ answer.figure }}<figcaption class=small>Each dot is one
frame-time profile's run: its deviation from the fine-step reference (RMS of the scene's first quantity over the
motion's amplitude); the line joins one policy's profiles, so the longer it is, the more the motion changes with the
frame rate. The number above a policy is its consistency across the profiles (0: the same motion at every frame
rate); the recommended policy is bold.</figcaption></figure>{% endif %}
{% endif %}
<p class=small>Every run is real ODE 0.16 (libode from Debian) stepped by libsteadystep: each scene under each
frame-time profile ({{ report.profiles|join(", ") }}) and each policy, for {{ "%g"|format(report.duration_s) }} s,
against a reference run (the same scene at a fixed 1/1000 s step, the article's mapping).</p>
<details id='why'><summary><b>Why{% if code %}, and the code to write for {{ code.policy }}{% endif %}</b>: which
policy for which need, per scene, the policies defined</summary>
<section id='recommendation'><h2>Which policy for which need</h2>
<p class=small>Every line below is computed from this run's numbers, says for which scenes it holds, and links to the
table that shows it. A winner is named only where its lead is larger than the measured spread of repeats
({% if repeat_profiles %}the profiles a seed changes, {{ repeat_profiles|join(", ") }}, run again with seed
{{ repeat_seed }}{% else %}none measured: no profile here depends on the seed{% endif %}; for the cost, the ranges
over the benchmark's blocks); otherwise the line says they tie.</p>
<ul class='answers'>
{% for need, text in recommendation %}<li><b>{{ need }}:</b> {{ text }}</li>
{% endfor %}
</ul>
<h3>Per scene: which policy for which kind of program</h3>
<table id='per-scene'><thead><tr><th>scene</th><th>kind of program</th><th>most alike across frame rates (of those
whose steps follow the frames)</th><th>closest to the reference</th><th>cheapest</th></tr></thead><tbody>
{% for e in per_scene %}<tr><td><a href='#{{ e.scene }}'>{{ e.scene }}</a></td><td>{{ e.kind }}</td>
<td>{{ e.consistency }}</td><td>{{ e.deviation }}</td><td>{{ e.cost }}</td></tr>
{% endfor %}
</tbody></table>
<h3>The policies</h3>
<table id='policies'><thead><tr><th>policy</th><th>how a frame is cut</th><th>softness of each step</th></tr></thead>
<tbody>{% for name, cut, mapping in policies %}<tr><td><b>{{ name }}</b></td><td>{{ cut }}</td><td>{{ mapping }}</td></tr>
{% endfor %}</tbody></table>
{% if code %}
<h3 id='code'>The code to write for {{ code.policy }}</h3>
<p>For {{ code.why }}: {{ code.summary }}.</p>
{% for snippet in code.snippets %}<p class=small>{{ snippet.language }}:</p>
<pre class=code><code>{{ snippet.text }}</code></pre>
{% endfor %}
{% endif %}
</section>
</details>
{% if animation %}
<h2 id='animation'>Watch: the chain at 15-45 fps</h2>
{{ animation }}
{% endif %}
<details id='measured'><summary><b>Everything measured</b>: consistency, deviation, the control ladder, where the
mappings serve, cost, largest stable step, the article's figure, every scene and run</summary>
<h2>Frame-rate consistency</h2>
{{ table(consistency, "consistency") }}
<p class=small>Consistency: each run's followed quantity minus the mean over the profiles of the same policy, RMS over
profiles and time, divided by the reference's amplitude (max − min): 0 when the motion is the same at every frame
rate (shown 0 at or below {{ identical }}: rounding). ± the spread of repeats: how much it moved with the next seed.
Bold: the lowest of the row and those tied with it within their spreads; failed: a run of that policy blew up or
broke.</p>
<h2>Deviation from the fine-step reference</h2>
{{ table(deviation, "deviation") }}
<p class=small>RMS over the profiles of each run's deviation: RMS of the followed quantity minus the reference run,
divided by the reference's amplitude (max − min). ± and bold as above.</p>
{% if control.rows %}
<h2>What cutting the frame gives, what the mapping adds</h2>
{{ table(control, "control") }}
<p class=small>Consistency / deviation of each scene's first quantity (as in the two tables above) along the ladder
where each policy differs from the one before it in one thing: naive (one step of the whole frame, the softness
frozen at the tuned step), substeps-frozen (the control: the frame cut into substeps, the softness still frozen),
implicit-euler (the same substeps, the softness mapped to each step's length), matched and exact (the same substeps,
another mapping).</p>
{% endif %}
{% if served %}
<h2>Where the accurate mappings serve</h2>
{{ table(served, "served") }}
<p class=small>Summed over each scene's runs under every profile (the stepper's frame reports, ssServedCounts): every
bound joint row counted once per physics step, and every contact softened with ssStepper_SoftenContact. Served by the
mapping: matched or exact gave the row its softness; handed to matched: exact found no finite softness at that step
length; handed to implicit Euler: above the step's Nyquist frequency, undamped, no effective mass, a static load, or
no finite softness. They serve springs a program binds itself, free or with a declared load (the oscillator; the
buggy's suspension, its load declared); every adopted row and every contact of the programs measured is handed on.
Where the mapping serves nothing, the policy is implicit Euler at 1.035 times its instructions. Scenes with nothing
bound and no contact softened through the stepper are left out.</p>
{% endif %}
{% if side_by_side %}
<h2>Oscillator against the exact solution</h2>
{{ table(side_by_side, "exact") }}
{% endif %}
{% if cost %}
<h2>Cost against plain ODE</h2>
{{ table(cost, "cost") }}
<p class=small>One benchmark run of {{ "%.1f"|format(report.cost_wall_s) }} s, after every run and figure of this
study, on {{ machine_line }}: each policy and two plain ODE copies of the same scene take the same
{{ cost_profile }} frames in {{ cost_repeats }} blocks, the order of the three rotating; each ratio is taken per
block, its median and range shown (the blocks column: 3 where the first rotation's blocks already agreed within
{{ cost_tight }} in both ratios). The program's own: its per-step input (the stack's push, the piston's motor), collide,
one dWorldQuickStep of each whole frame, softness as tuned once (a program without the library). Plain ODE at the
same steps: the same input, one dWorldQuickStep per step the stepper takes, no library call in between; its ratio is
what the library itself costs. Times are the benchmark thread's CPU time (the timing loop runs in C,
ssScene_TimeFrames). A ratio counts only the blocks before and after which both of its copies had as many bodies
awake: a copy that fell asleep (auto-disable) steps for almost nothing, and against one that did not the ratio would
measure the sleep; "not like with like" where no block did. Where two policies' ranges overlap, the recommendation
calls them tied.</p>
{% endif %}
{% if stable %}
<h2>Largest stable step</h2>
{{ table(stable, "stable") }}
<p class=small>The longest step (ms) at which each scene stays stable: every frame one step of h (max_step_s =
fixed_step_s = h), 3 s; stable: no blow-up and every motion quantity within the reference's range widened by that
range on both sides. Bisection in log h between 1 and 250 ms (≥ 250: stable at the top). Hover a number for the first
failure above it.{% for scene, why in not_probed %} Not probed: {{ scene }}, {{ why }}.{% endfor %}</p>
{% endif %}
{% if article %}
<h2>The article's figure</h2>
<p>Top: the article's equations 4 and 5. Bottom: real ODE with the article's mapping, one step per frame (policy
implicit-euler, max_step_s = 1/15 s).</p>
{{ article }}
{% endif %}
<section id='runs'><h2>Every scene, every run</h2>
{% for s in scenes %}
<h3 id='{{ s.scene }}'>{{ s.scene }}</h3>
<p>{{ s.description }}</p>
{{ table(s.table, "runs-" ~ s.scene) }}
<p class=small>Rows (contacts) served by implicit Euler: of a matched or exact policy, the joint rows (contacts) that
the accurate mapping could not serve at that step (near-rigid rows above the step's Nyquist frequency, undamped
rows...), summed over the run's steps; - for policies that use implicit Euler throughout. Units: {{ s.units }}.</p>
{% for image in s.images %}{{ image }}
{% endfor %}
{% endfor %}
</section>
</details>
<details id='parameters'><summary><b>Parameters</b></summary>
<p>duration {{ "%g"|format(report.duration_s) }} s simulated per run, profile seed {{ report.seed }}, profiles
{{ report.profiles|join(", ") }}; stepping defaults: {{ stepping_defaults }} (policy set per run);
reference: {{ reference_stepping }}, under {{ reference_profile }}.</p>
{{ table({"header": ["scene", "parameters"], "rows": parameters}) }}
</details>
<h2>Regenerate</h2>
<pre>{{ command }}</pre>
<p class=small>Made in {{ "%.1f"|format(report.elapsed_s) }} s ({% for phase, seconds in phases.items() %}{{ phase }}
{{ "%.1f"|format(seconds) }} s{% if not loop.last %}, {% endif %}{% endfor %}) on {{ node }} ({{ machine }}; {{ machine_line }}),
{{ made_at }}.</p>
</body></html>
"""

_ANIMATION = """<figure id='animation-player' data-frame='0' data-time-s='0'>
<svg id='animation-svg' width='{{ total_width }}' height='{{ height + 26 }}' viewBox='0 0 {{ total_width }} {{ height + 26 }}'
 role='img' aria-label='the chain swinging'>
{% for panel in panels %}<g transform='translate({{ loop.index0 * (width + 10) }},0)'><rect width='{{ width }}'
 height='{{ height + 24 }}' fill='#fafafa' stroke='#ccc'/><text x='8' y='{{ height + 17 }}' font-size='13'{% if panel.failed %} fill='#b00000' font-weight='bold'{% endif %}>{{ panel.title }}</text>
{% if not loop.first %}<polyline class='ghost' data-panel='{{ loop.index0 }}' fill='none' stroke='#bbb' stroke-width='4'
 stroke-linejoin='round' points=''/>{% endif %}<polyline class='chain' data-panel='{{ loop.index0 }}' fill='none'
 stroke='#333' stroke-width='4' stroke-linejoin='round' points=''/><circle class='tip' data-panel='{{ loop.index0 }}'
 r='5' fill='#d62728'/></g>
{% endfor %}</svg>
<figcaption><button id='animation-toggle' type='button'>pause</button> t = <span id='animation-time'>0.00</span> s of
{{ "%g"|format(duration_s) }} s (looping). Each panel shows the last frame its run rendered, drawn as a program draws
it, on the poses the stepper gives to draw (ssStepper_InterpolatedPose): the reference every 1/60 s of its 1 ms
steps; {{ policies|join(", ") }} at their {{ profile }} frames (profile seed {{ seed }}), fixed blended between its
last two 1/60 s steps at each frame's interpolation factor (one step behind, and smooth), the others ODE's own poses;
in grey behind them, the reference at the same time.</figcaption>
</figure><script>
(function () {
  const data = {{ data|tojson }};
  const scale = {{ scale|tojson }}, pad = {{ pad|tojson }}, lowX = {{ low_x|tojson }}, highZ = {{ high_z|tojson }}, hz = {{ hz|tojson }};
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
</script>
"""

TEMPLATES = {"table.html": _TABLE, "report.html": _REPORT, "animation.html": _ANIMATION}


def environment(templates: dict[str, str]) -> jinja2.Environment:
    """The pages' environment over these templates: autoescape on, an undefined name an error rather than an empty
    string, block tags taking their line with them. The report's and the audit's pages (audit/templates.py)."""
    return jinja2.Environment(loader=jinja2.DictLoader(templates), autoescape=True, trim_blocks=True,
                              lstrip_blocks=True, undefined=jinja2.StrictUndefined)


ENVIRONMENT = environment(TEMPLATES)

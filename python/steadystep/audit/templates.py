"""The Jinja2 template of audit.html, in the report's environment (report/templates.py: autoescape on, the table
macro, the same settings), so that the two pages are made the one way. Kept as a string in a module, as the report's
are, so that the installed package carries it as it carries its code."""

from steadystep.report.templates import TEMPLATES, environment

_AUDIT = """{% from "table.html" import table %}
<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>steadystep audit: {{ result.program }}</title>
<style>
body { font-family: system-ui, sans-serif; max-width: 1400px; margin: 2em auto; padding: 0 1em; color: #222; }
table { border-collapse: collapse; margin: 0.5em 0 0.5em; font-size: 0.9em; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: right; }
th { background: #f3f3f3; } td:first-child { text-align: left; }
img { max-width: 100%; display: block; margin: 0.5em 0 1.5em; }
.dot { display: inline-block; width: 0.7em; height: 0.7em; border-radius: 50%; margin-right: 0.4em; }
.bad { color: #b00; font-weight: bold; }
#recommendation { background: #f4f8ff; border: 1px solid #c9d8f0; padding: 0.3em 1em 1em; }
.answers li { margin: 0.35em 0; }
pre { background: #f6f6f6; padding: 0.6em; white-space: pre-wrap; }
pre.code { white-space: pre; overflow-x: auto; }
.small { color: #666; font-size: 0.85em; margin-bottom: 1.5em; }
</style></head><body>
<h1>steadystep audit: {{ result.program }}</h1>
<p>The program ran {{ "%g"|format(result.duration_s) }} s under {{ runs_text }}, as each of {{ variants }}
{%- if result.own %} (own stepping: {{ result.own }}){% endif %}, each run a process of its own, against a fine-step
reference checked at a finer step (docs/audit.md).</p>
<section id='recommendation'><h2>Recommendation for this program</h2><p class=small>Every line is computed from the
tables below (metrics.json holds them and these claims) and links to its table. A value is better than another only
beyond the noise of their difference.</p><ul class='answers'>
{%- for claim in result.claims %}<li>{{ claim.text }} <a href='#{{ claim.table }}'>({{ claim.table }} table)</a></li>
{%- endfor %}</ul>
{%- if code %}<h3 id='code'>The code to write for {{ code.policy }}</h3><p>{{ code.summary }}.</p>
{%- for snippet in code.snippets %}<p class=small>{{ snippet.language }}:</p><pre class=code><code>{{ snippet.text }}
{#- #}</code></pre>{% endfor %}{% endif %}</section>
<h2>{{ shown[0] }} and {{ shown[1] }} at every audited frame rate</h2>
<p class=small>Each deciding quantity in every profile run: the closer the curves of one panel, the less that stepping
depends on the frame rate.</p>
{% for image in across %}{{ image }}
{% endfor %}
<h2>Spread across frame rates (whole run)</h2>
{{ table(spread, spread.anchor) }}
<p class=small>Spread: each run after the first ({{ result.runs_per_variant[0][0] }}) against the first of the same
variant, at the simulated times the two share when they share most of them (runs identical there score exactly 0),
else interpolated onto the first's times; RMS over time, then over runs, divided by the quantity's scale; ± its
standard error over the runs. Over the whole run, whatever the reference does. Bold: the smallest of a column.</p>
<h2>Deviation from the fine-step reference</h2>
{{ table(deviation, deviation.anchor) }}
<p class=small>{% if result.reference.usable %}Deviation: every run against the reference interpolated at the run's
own times, while the reference holds; RMS over time, then over runs, divided by the scale.{% else %}Not claimed: the
reference is not usable (see below); shown for completeness.{% endif %} Over the whole run:</p>
{{ table(deviation_whole, deviation_whole.anchor) }}
<h2>Where the dependence comes from</h2>
{% if diagnosis %}{{ table(diagnosis, diagnosis.anchor) }}
{% else %}<p id='diagnosis' class=small>No diagnosis: it needs the program's own stepping (or naive) with a spread
above 0.</p>
{% endif %}
<h2>The reference, checked</h2>
{{ table(reference.table, reference.table.anchor) }}<p class=small>{{ reference.steps }}</p>
{{ reference_figure }}
<h2>Steps per frame and cost</h2>
{{ table(cost, cost.anchor) }}
<p class=small>Instructions: counted by valgrind over the whole process (start-up included, the same for every
variant). CPU time: the whole process of an executable, the stepping loop of a Python program.</p>
{% if served %}<h2>What each mapping served</h2>
{{ table(served, served.anchor) }}
<p class=small>Row-steps (every bound row counted once per physics step) and contacts, summed over the variant's runs,
from the program's optional columns.</p>
{% endif %}
{% if not_measured %}<p class=small>{{ not_measured }}</p>
{% endif %}
<h2>Every run</h2>
{{ table(runs, runs.anchor) }}
<h2>Regenerate</h2>
<pre>{{ command }}</pre>
<p class=small>Made in {{ "%.1f"|format(result.elapsed_s) }} s on {{ node }}, {{ made_at }}
{%- if result.reused_runs %}; {{ result.reused_runs }} finished runs kept from an interrupted audit{% endif %}.</p>
</body></html>
"""

ENVIRONMENT = environment({"table.html": TEMPLATES["table.html"], "audit.html": _AUDIT})

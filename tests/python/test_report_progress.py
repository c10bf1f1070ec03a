"""Long work says where it is: off a terminal, `steadystep compare` writes a line per phase and at least one every
STEADYSTEP_PROGRESS_S seconds while it works, with an estimate (issue 28; scripts/report runs it this way)."""

import io
import os
import re
import subprocess
import sys
import time
from pathlib import Path

from steadystep.report import progress as report_progress

REPO = Path(__file__).resolve().parents[2]
STEADYSTEP = Path(sys.executable).with_name("steadystep")
LINE = re.compile(r"^steadystep (compare|report) \[[^\]]+\] "
                  r"(started(: \d+ \w+)?"
                  r"|\d+/\d+ \w+ \(\d+%\), [\w ]+ elapsed(, about [\w ]+ left|, estimate after the first unit)?"
                  r"(; last: .+)?"
                  r"|working, [\w ]+ elapsed"
                  r"|done:( \d+ \w+)? in [\w ]+)$")


def test_a_unit_longer_than_the_interval_still_shows_the_job_alive():
    out = io.StringIO()
    bar = report_progress.Lines(3, "steadystep compare [runs]", "unit", stream=out, every_s=0.1)
    bar.update()
    bar.set_postfix_str("oscillator fixed:30 naive")
    time.sleep(0.45)  # one long unit: the ticker repeats the state
    bar.update(2)
    bar.close()
    lines = out.getvalue().splitlines()
    assert lines[0] == "steadystep compare [runs] started: 3 units"
    assert lines[-1] == "steadystep compare [runs] done: 3 units in 0 s"
    assert all(LINE.match(line) for line in lines), lines
    ticks = [line for line in lines if line.startswith("steadystep compare [runs] 1/3 units (33%)")]
    assert len(ticks) >= 2 and all("left; last: oscillator fixed:30 naive" in line for line in ticks), lines


def test_durations_read_as_a_person_says_them():
    assert [report_progress.duration(s) for s in (0.4, 42, 185, 3725)] == ["0 s", "42 s", "3 min 05 s", "1 h 02 min"]


def test_compare_off_a_terminal_writes_a_line_at_least_every_interval(tmp_path):
    """A tiny study, its stderr a pipe: every line in the documented format, no silence longer than the interval
    plus what happens between two phases, every phase named, and the article's figure drawn once, by compare."""
    env = {**os.environ, "STEADYSTEP_PROGRESS_S": "0.5"}
    started = time.monotonic()
    process = subprocess.Popen([str(STEADYSTEP), "compare", "--out", str(tmp_path / "out"), "--scenes", "oscillator",
                                "--profiles", "fixed:30", "--duration", "0.5", "--executor", "serial"],
                               stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=env)
    arrivals = []
    for line in process.stderr:
        arrivals.append((time.monotonic(), line.rstrip("\n")))
    assert process.wait(timeout=120) == 0
    lines = [line for _, line in arrivals]
    assert lines and all(LINE.match(line) for line in lines), [line for line in lines if not LINE.match(line)]
    gaps = [b - a for (a, _), (b, _) in zip(arrivals, arrivals[1:])]
    assert max(gaps) < 3.0, (max(gaps), lines)
    assert arrivals[0][0] - started < 10  # the first line once the package is imported
    assert lines[0] == "steadystep compare [runs] started: 44 units"  # the runs, then their figures: one bar
    for phase in ("figures", "cost against plain ODE", "article's figure", "page"):
        assert any(line.startswith(f"steadystep compare [{phase}] done") for line in lines), (phase, lines)
    assert any(", about " in line and " left" in line for line in lines)
    assert (tmp_path / "out" / "article_figure.png").exists()


def test_scripts_report_draws_the_article_figure_once_and_ticks_through_the_build():
    text = (REPO / "scripts" / "report").read_text()
    assert "steadystep\" figure" not in text  # compare draws it; drawing it first too was twice
    assert "still working" in text and "STEADYSTEP_PROGRESS_S" in text


def test_cores_and_load_are_recorded_beside_the_timings(tmp_path):
    """The cost benchmark's paragraph and the page's foot say on how many cores and under what load they were
    timed; metrics.json carries the numbers (docs/metrics.md, machine)."""
    import json

    out = tmp_path / "out"
    done = subprocess.run([str(STEADYSTEP), "compare", "--out", str(out), "--scenes", "oscillator", "--profiles",
                           "fixed:30", "--duration", "0.2", "--executor", "serial"], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr
    machine = json.loads((out / "metrics.json").read_text())["machine"]
    assert machine["cores"] == os.cpu_count() and 1 <= machine["usable_cores"] <= machine["cores"]
    assert all(machine[key] >= 0 for key in ("load_at_start", "load_before_cost", "load_after_cost"))
    page = (out / "report.html").read_text()
    assert page.count(f"{machine['cores']} cores ({machine['usable_cores']} usable), load ") == 2  # cost, foot
    assert "alone on the machine" not in page


def test_scripts_report_says_where_the_environment_and_build_are(tmp_path):
    """scripts/report in a copy of the tree whose deps.sh takes a while and whose steadystep only records its
    arguments: off a terminal it writes the environment phase's start, a line every STEADYSTEP_PROGRESS_S while
    deps.sh works, its end, then runs compare once (the article's figure with it) into its own report/."""
    (tmp_path / "scripts").mkdir()
    (tmp_path / "scripts" / "report").write_text((REPO / "scripts" / "report").read_text())
    (tmp_path / "scripts" / "deps.sh").write_text("sleep 1.2\n")
    (tmp_path / ".venv" / "bin").mkdir(parents=True)
    fake = tmp_path / ".venv" / "bin" / "steadystep"
    fake.write_text(f"#!/bin/sh\necho \"$@\" >> {tmp_path / 'calls'}\n")
    fake.chmod(0o755)
    done = subprocess.run(["bash", str(tmp_path / "scripts" / "report"), "--scenes", "chain"], capture_output=True,
                          text=True, timeout=60, env={**os.environ, "STEADYSTEP_PROGRESS_S": "0.3"})
    assert done.returncode == 0, done.stderr
    lines = done.stderr.splitlines()
    assert lines[0].startswith("steadystep report [environment, build] started")
    assert sum("[environment, build] still working" in line for line in lines) >= 2, lines
    assert lines[-1].startswith("steadystep report [environment, build] done in")
    assert (tmp_path / "calls").read_text().splitlines() == [f"compare --force --out {tmp_path / 'report'} --scenes chain"]

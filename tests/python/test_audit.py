"""`steadystep audit` end to end on real programs: the three example programs (each against its own stepping), the
chaotic pendulum that takes part through the lab's audit_flags.h, and a Python program. Short runs, two profiles.

Each page's recommendation is checked claim by claim against its own metrics.json by an independent reader
(audit_claims_check.py), and the audit's numbers for an example equal those recomputed here from the programs' own
CSV with the definitions of docs/audit.md."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from markupsafe import escape  # as the page escapes its text (Jinja2, autoescape)

import audit_claims_check
from steadystep.report import snippets

ROOT = Path(__file__).resolve().parents[2]
BUILD = ROOT / "build"
SCRIPT = Path(sys.executable).parent / "steadystep"
COMMAND = [str(SCRIPT)] if SCRIPT.exists() else [sys.executable, "-m", "steadystep.cli"]
SHORT = ["--duration", "2", "--profiles", "fixed:60", "uniform:15:45", "--seeds", "1", "2", "--cost", "time"]
EXAMPLES = {"vehicle": ["height_m", "pitch_rad"], "chain": ["end_x_m", "end_z_m"],
            "stack": ["top_z_m", "ground_force_N"]}

pytestmark = pytest.mark.skipif(not (BUILD / "steadystep_example_chain_steadystep").exists(),
                                reason="needs the example programs built in build/")


def steadystep(*args):
    return subprocess.run([*COMMAND, *map(str, args)], capture_output=True, text=True, timeout=300)


def audited(out: Path, *args) -> dict:
    done = steadystep("audit", *args, "--out", out, *SHORT)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines()[0] == str(out / "audit.html")
    for name in ("audit.html", "metrics.json", "metrics.csv"):
        assert (out / name).stat().st_size > 0
    return json.loads((out / "metrics.json").read_text())


@pytest.fixture(scope="module")
def examples(tmp_path_factory) -> dict:
    out = {}
    for program in EXAMPLES:
        directory = tmp_path_factory.mktemp(program)
        out[program] = (directory, audited(directory, BUILD / f"steadystep_example_{program}_steadystep",
                                           "--own", BUILD / f"steadystep_example_{program}_ode"))
    return out


@pytest.mark.parametrize("program", EXAMPLES)
def test_example_page_agrees_with_its_tables(examples, program):
    directory, metrics = examples[program]
    assert metrics["quantities"] == EXAMPLES[program]
    assert metrics["variants"][0] == "own" and "implicit-euler" in metrics["variants"]
    kinds = audit_claims_check.check(metrics)
    assert {"least_spread", "cheapest", "recommend", "diagnosis"} <= set(kinds)
    assert ("least_deviation" in kinds) == metrics["reference_check"]["usable"]
    page = (directory / "audit.html").read_text()
    for claim in metrics["claims"]:  # each claim on the page, linked to a table that is there
        assert f"href='#{claim['table']}'" in page and f"id='{claim['table']}'" in page
    # The recommendation ends with the lines of code for the policy it names, C (the program's language) first.
    policy, = (c["variant"] for c in metrics["claims"] if c["kind"] == "recommend")
    c, python = snippets.for_policy(policy)
    section = page[page.index("<section id='recommendation'>"):]
    section = section[:section.index("</section>")]
    assert section.index(f"<h3 id='code'>The code to write for {policy}</h3>") > section.index("</ul>")
    assert section.index(escape(c.text)) < section.index(escape(python.text))
    assert section.endswith(f"<code>{escape(python.text)}</code></pre>")
    # The adopted programs move alike at every frame rate; their own stepping does not (docs/examples.md).
    spread = metrics["spread"]
    assert max(spread["implicit-euler"].values()) < max(spread["own"].values())
    # The examples take no diagnosis flag: the page says the diagnosis variants were not measured, and why.
    assert set(metrics["not_measured"]) == {"half-step", "more-iterations"}
    assert "does not take --max-step-scale" in page


def _csv(program: str, variant: str, profile: str, seed: int) -> dict:
    command = ([str(BUILD / f"steadystep_example_{program}_ode")] if variant == "own" else
               [str(BUILD / f"steadystep_example_{program}_steadystep"), "--policy", variant])
    if variant == "reference":
        command = [str(BUILD / f"steadystep_example_{program}_steadystep"), "--policy", "implicit-euler",
                   "--max-step", "0.001"]
    text = subprocess.run(command + ["--profile", profile, "--seed", str(seed), "--duration", "2"],
                          capture_output=True, text=True, check=True).stdout.split()
    table = np.array([[float(x) for x in line.split(",")] for line in text[1:]])
    return {name: table[:, i] for i, name in enumerate(text[0].split(","))}


def _last_at_each_time(columns: dict) -> dict:
    keep = np.append(columns["t_s"][1:] != columns["t_s"][:-1], True)
    return {name: values[keep] for name, values in columns.items()}


def test_numbers_recomputed_from_the_programs_csv(examples):
    """docs/audit.md's definitions, computed here from the programs' CSV: the same as the audit's. Scale: the range
    over the own stepping runs and the reference. Spread: each run against the first at the times they share when they
    share most of them, else interpolated onto the first's times. Deviation: the reference interpolated at each
    run's own times, while the reference holds."""
    _, metrics = examples["chain"]
    reference = _csv("chain", "reference", "fixed:1000", 1)
    runs = [(p["profile"], p["seed"]) for p in metrics["profile_runs"]]
    assert runs == [("fixed:60", 1), ("uniform:15:45", 1), ("uniform:15:45", 2)]
    csvs = {variant: [_last_at_each_time(_csv("chain", variant, profile, seed)) for profile, seed in runs]
            for variant in ("own", "implicit-euler", "fixed")}
    parted_at = metrics["reference_check"]["parted_at"]
    for q in EXAMPLES["chain"]:
        values = np.concatenate([run[q] for run in csvs["own"]] + [reference[q]])
        scale = float(values.max() - values.min())
        assert metrics["scales"][q] == pytest.approx(scale, rel=1e-15)
        for variant, made in csvs.items():
            differences = []
            for run in made[1:]:
                shared, in_run, in_first = np.intersect1d(run["t_s"], made[0]["t_s"], return_indices=True)
                if len(shared) >= 0.5 * min(len(run["t_s"]), len(made[0]["t_s"])):
                    d = run[q][in_run] - made[0][q][in_first]
                else:
                    d = np.interp(made[0]["t_s"], run["t_s"], run[q]) - made[0][q]
                differences.append(np.sqrt(np.mean(d ** 2)) / scale)
            spread = np.sqrt(np.mean(np.square(differences)))
            assert metrics["spread"][variant][q] == pytest.approx(spread, rel=1e-12, abs=1e-15)
            errors = []
            for run in made:
                inside = np.ones(len(run["t_s"]), bool) if parted_at is None else run["t_s"] < parted_at
                truth = np.interp(run["t_s"][inside], reference["t_s"], reference[q])
                errors.append(np.sqrt(np.mean((run[q][inside] - truth) ** 2)) / scale)
            deviation = np.sqrt(np.mean(np.square(errors)))
            assert metrics["deviation"]["window"][variant][q] == pytest.approx(deviation, rel=1e-12, abs=1e-15)
    # fixed: the runs end frames on the same steps, compared at the times they share
    assert {r["compared_at"] for r in metrics["runs"] if r["variant"] == "fixed"} == {"baseline", "shared"}


def test_chaos_limits_the_claims_to_where_the_reference_holds(tmp_path):
    """The double pendulum parts from itself at a finer step after a few seconds: the audit says where, and every
    claim is measured up to there."""
    pendulum = BUILD / "steadystep_example_audit_pendulum"
    done = steadystep("audit", pendulum, "--own", pendulum, "--out", tmp_path, "--duration", "8", "--profiles",
                      "fixed:60", "uniform:15:45", "--seeds", "1", "--policies", "implicit-euler", "exact", "fixed",
                      "--cost", "none")
    assert done.returncode == 0, done.stderr
    metrics = json.loads((tmp_path / "metrics.json").read_text())
    check = metrics["reference_check"]
    assert not check["holds_whole_run"] and 1.0 < check["parted_at"] < 6.0, check  # parted after a few seconds
    assert check["held_s"] == pytest.approx(check["parted_at"], abs=0.01)
    kinds = audit_claims_check.check(metrics)
    assert "recommend" in kinds and "served" in kinds
    # The window's numbers are not the whole run's: after the parting, every run wanders off.
    assert metrics["deviation"]["window"]["exact"]["tip_x_m"] < metrics["deviation"]["whole"]["exact"]["tip_x_m"]
    # exact hands the pendulum's near-rigid hinge rows to implicit Euler, every one of them: the same numbers.
    served = metrics["served"]["exact"]
    assert served["rows_handed_to_implicit_euler"] > 0
    assert metrics["spread"]["exact"] == metrics["spread"]["implicit-euler"]
    # fixed: the same motion at every frame rate, bit for bit at the times the runs share; recommended
    assert metrics["spread"]["fixed"] == {"tip_x_m": 0.0, "tip_z_m": 0.0}
    assert next(c for c in metrics["claims"] if c["kind"] == "recommend")["variant"] == "fixed"


def test_python_program(tmp_path):
    done = steadystep("audit", "--python", ROOT / "examples" / "audit_slider.py", "--out", tmp_path, "--duration",
                      "2", "--profiles", "fixed:60", "uniform:15:45", "--seeds", "1", "--policies",
                      "implicit-euler", "exact", "fixed", "--no-diagnosis")
    assert done.returncode == 0, done.stderr
    metrics = json.loads((tmp_path / "metrics.json").read_text())
    assert metrics["quantities"] == ["x_m", "v_m_per_s"] and metrics["variants"][0] == "own"  # its own_frame()
    policy, = (c["variant"] for c in metrics["claims"] if c["kind"] == "recommend")
    assert done.stdout.endswith(snippets.as_text(policy, "Python") + "\n")  # the code to write, Python first
    audit_claims_check.check(metrics)
    # The spring is linear with a known mass: exact follows it far closer than implicit Euler's damping does.
    deviation = metrics["deviation"]["window"]
    assert deviation["exact"]["x_m"] < 0.5 * deviation["implicit-euler"]["x_m"]
    # One step of at most 1/60 s per frame at 60 fps: the steps column the audit counted itself.
    steps = {(r["variant"], r["profile"]): r["steps_per_frame"] for r in metrics["runs"]}
    assert steps["exact", "fixed:60"] == 1.0 and steps["exact", "uniform:15:45"] > 1.0


def test_figures_drawn_in_the_pool_are_the_page_figures(tmp_path):
    """audit(draw=True) draws the page's figures in its executor's workers after the runs (so that the process that
    runs the audit need not): they are the very figures this process draws from the same result, and write() puts
    those it finds in the result beside the page instead of drawing them again."""
    from steadystep import audit
    from steadystep.audit import page as audit_page

    program = audit.Executable((str(BUILD / "steadystep_example_chain_steadystep"),),
                               own=(str(BUILD / "steadystep_example_chain_ode"),))
    result = audit.audit(program, ["fixed:60", "uniform:15:45"], [1], ["naive", "fixed"], 1.0, "local",
                         progress=False, cost="none", diagnosis=False, draw=True)
    units = audit_page.figure_units(result)
    assert list(result.figures) == [unit["stem"] for unit in units] == \
        [f"audit_{i}_{q}" for i, q in enumerate(result.deciding[:audit_page.FIGURE_QUANTITIES])] + ["audit_reference"]
    for unit in units:
        assert result.figures[unit["stem"]].startswith(b"\x89PNG")
        assert result.figures[unit["stem"]] == audit_page.draw_png(**unit)
    result.figures = {stem: b"drawn in the pool " + stem.encode() for stem in result.figures}
    audit.write(result, tmp_path, "steadystep audit (test)")
    for stem, data in result.figures.items():
        assert (tmp_path / f"{stem}.png").read_bytes() == data


def test_serial_and_pool_give_the_same_audit(tmp_path):
    """The same audit in this process and through the local pool: the same numbers, claims and figures; only the
    runs' times differ (each run is its own process wherever it is started)."""
    from steadystep import audit

    program = audit.Executable((str(BUILD / "steadystep_example_chain_steadystep"),),
                               own=(str(BUILD / "steadystep_example_chain_ode"),))
    results = {executor: audit.audit(program, ["fixed:60", "uniform:15:45"], [1, 2], ["naive", "fixed"], 1.0,
                                     executor, progress=False, cost="none", draw=True)
               for executor in ("serial", "local")}
    pages = {}
    for executor, result in results.items():
        data = audit.comparison.as_json(result, "steadystep audit (test)")
        for run in data["runs"]:
            del run["cpu_s"], run["wall_s"], run["cpu_ms_per_simulated_s"]
        del data["elapsed_s"]
        pages[executor] = data
    assert pages["serial"] == pages["local"]
    assert results["serial"].figures == results["local"].figures

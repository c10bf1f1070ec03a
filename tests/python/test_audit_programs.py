"""`steadystep audit` on programs of the kinds games are (tests/audit_programs: a box stack of unequal masses, a
ragdoll on boxes, a tilting maze with a clock of whole milliseconds, a buggy whose fine-step runs misbehave) and on
the project's own examples (the wrecking arm, the program that substeps itself), each built as a user's would be.

For each, the audit's recommendation is checked by separate runs (other frame-time profiles and seeds than the
audit's): the recommended policy's largest spread is within the noise of the smallest of the policies', and it is
no worse than the program's own stepping in any quantity beyond that noise, or the audit's page says where it is.
Every claim is also checked against the tables by an independent reader (audit_claims_check.py). The test programs
link the installed core alone (no lab) and take part through steadystep/audit/protocol.h: built here against an
install of build/ when the build has not made them."""

import json
import math
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from markupsafe import escape  # as the page escapes its text (Jinja2, autoescape)

import audit_claims_check

ROOT = Path(__file__).resolve().parents[2]
BUILD = ROOT / "build"
SCRIPT = Path(sys.executable).parent / "steadystep"
COMMAND = [str(SCRIPT)] if SCRIPT.exists() else [sys.executable, "-m", "steadystep.cli"]
PROGRAMS = ("box_stack", "ragdoll", "maze", "hopper", "box_stack_unsoftened")
AUDITED = ["--duration", "3", "--profiles", "fixed:60", "uniform:15:45", "--seeds", "1", "2"]
# The separate runs: other profiles and seeds than the audit's.
SEPARATE = [("fixed:45", 1), ("uniform:15:45", 7), ("uniform:20:50", 8)]
SEPARATE_POLICIES = ("naive", "implicit-euler", "exact", "fixed")

pytestmark = pytest.mark.skipif(not (BUILD / "CMakeCache.txt").exists(), reason="needs the C build in build/")


@pytest.fixture(scope="session")
def programs(tmp_path_factory) -> dict:
    """The test programs: the build's (tests/audit_programs/audit_programs.cmake), else built here against an install
    of the build (tests/audit_programs/CMakeLists.txt: find_package(steadystep), the core alone)."""
    if all((BUILD / f"steadystep_audit_{name}").exists() for name in PROGRAMS):
        return {name: BUILD / f"steadystep_audit_{name}" for name in PROGRAMS}
    work = tmp_path_factory.mktemp("audit_programs")
    prefix, build = work / "prefix", work / "build"
    for command in (["cmake", "--install", str(BUILD), "--prefix", str(prefix)],
                    ["cmake", "-S", str(ROOT / "tests" / "audit_programs"), "-B", str(build),
                     f"-DCMAKE_PREFIX_PATH={prefix}", "-DCMAKE_BUILD_TYPE=Release"],
                    ["cmake", "--build", str(build), "-j2"]):
        done = subprocess.run(command, capture_output=True, text=True, timeout=600)
        assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    made = {name: build / f"steadystep_audit_{name}" for name in PROGRAMS}
    for path in made.values():  # the core alone: no lab library
        assert "steadystep_lab" not in subprocess.run(["ldd", str(path)], capture_output=True, text=True).stdout
    return made


def audit(out: Path, program: Path, *args, own: Path | None = None) -> dict:
    """The audit of program (an executable with its own stepping in own, default itself; or a Python file)."""
    which = (["--python", str(program)] if program.suffix == ".py" else
             [str(program), "--own", str(own or program)])
    done = subprocess.run([*COMMAND, "audit", *which, "--out", str(out), *AUDITED, *map(str, args)],
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    metrics = json.loads((out / "metrics.json").read_text())
    audit_claims_check.check(metrics)
    page = (out / "audit.html").read_text()
    # what the audit is about first: own stepping and the recommended policy, each across the audited frame rates
    recommended = metrics_recommended(metrics)
    assert f"<h2>own stepping and {recommended} at every audited frame rate</h2>" in page
    assert page.count("<img ") == min(len(metrics["deciding"]), 4) + 1
    for claim in metrics["claims"]:  # each claim on the page, linked to a table that is there
        assert escape(claim["text"]) in page
        assert f"href='#{claim['table']}'" in page and f"id='{claim['table']}'" in page
    return metrics


def run_csv(program, variant: str, profile: str, seed: int, duration: float) -> dict:
    """One run's columns: program is an audit.run.Executable or PythonProgram, or a path (its own stepping itself)."""
    from steadystep.audit.run import Executable, run

    if isinstance(program, Path):
        program = Executable((str(program),), (str(program),))
    made = run(program, variant, profile, seed, duration)
    assert made.ok, made.status
    return made.columns


def _last_at_each_time(columns: dict) -> tuple[np.ndarray, dict]:
    t = columns["t_s"]
    keep = np.append(t[1:] != t[:-1], True)
    return t[keep], {q: v[keep] for q, v in columns.items()}


def difference(run: dict, base: dict, q: str) -> float:
    """RMS of run - base (docs/audit.md): at the times they share when they share most, else interpolated."""
    t_run, run = _last_at_each_time(run)
    t_base, base = _last_at_each_time(base)
    shared = sorted(set(t_run.tolist()) & set(t_base.tolist()))
    if len(shared) >= max(2, 0.5 * min(len(t_run), len(t_base))):
        index_run = {t: i for i, t in enumerate(t_run.tolist())}
        index_base = {t: i for i, t in enumerate(t_base.tolist())}
        a = np.array([run[q][index_run[t]] for t in shared])
        b = np.array([base[q][index_base[t]] for t in shared])
    else:
        a, b = np.interp(t_base, t_run, run[q]), base[q]
    return float(np.sqrt(np.mean((a - b) ** 2)))


def separately(program, metrics: dict) -> dict:
    """Each policy's (and own stepping's) spread per quantity, with its standard error, from SEPARATE runs."""
    out = {}
    for variant in ("own", *SEPARATE_POLICIES, metrics_recommended(metrics)):
        if variant in out:
            continue
        runs = [run_csv(program, variant, p, s, metrics["duration_s"]) for p, s in SEPARATE]
        out[variant] = {}
        for q in metrics["quantities"]:
            values = [difference(r, runs[0], q) / metrics["scales"][q] for r in runs[1:]]
            rms = math.sqrt(sum(v * v for v in values) / len(values))
            error = float(np.std(values, ddof=1)) / math.sqrt(len(values))
            out[variant][q] = (rms, error)
    return out


def metrics_recommended(metrics: dict) -> str:
    return next(c for c in metrics["claims"] if c["kind"] == "recommend")["variant"]


def check_by_separate_runs(program, metrics: dict) -> tuple[str, dict]:
    """The recommendation against separate runs: its largest spread (over the deciding quantities) within the noise
    of the smallest policy's, and no worse than own stepping beyond the noise in any quantity unless the page's
    recommendation says so."""
    recommended = metrics_recommended(metrics)
    spreads = separately(program, metrics)
    repeat = metrics["repeat"]["difference"]

    def largest(v):
        return max((spreads[v][q][0], spreads[v][q][1], q) for q in metrics["deciding"])

    rec, rec_error, rec_q = largest(recommended)
    for policy in SEPARATE_POLICIES:
        other, other_error, other_q = largest(policy)
        noise = 2 * math.hypot(rec_error, other_error) + 2 * max(repeat[rec_q], repeat[other_q])
        assert rec <= other + noise, (recommended, rec, policy, other, noise)
    claim = next(c for c in metrics["claims"] if c["kind"] == "recommend")
    said = {w["quantity"] for w in claim["worse_than_base"] if w["table"] == "spread"}
    for q in metrics["quantities"]:
        value, error = spreads[recommended][q]
        own, own_error = spreads["own"][q]
        noise = 2 * math.hypot(error, own_error) + 2 * repeat[q]
        assert value <= own + noise or q in said, (recommended, q, value, own, noise)
    return recommended, spreads


def test_box_stack(programs, tmp_path):
    """Unequal masses, QuickStep at 10 iterations, a push: fixed steps make it the same at every frame rate, bit for
    bit (its spread exactly 0); the separate runs agree."""
    metrics = audit(tmp_path, programs["box_stack"])
    assert metrics["spread"]["fixed"] == {q: 0.0 for q in metrics["quantities"]}
    if shutil.which("valgrind"):  # cost by instructions: a count repeats exactly, ties within its resolution only
        assert metrics["cost"]["method"] == "instructions" and metrics["cost"]["repeat_difference"] < 1e-3
        assert "cheapest" in [c["kind"] for c in metrics["claims"]]
    assert all(r["compared_at"] in ("shared", "baseline") for r in metrics["runs"] if r["variant"] == "fixed")
    # its near callback softens every contact: counted under every policy, and none left unsoftened
    assert all(r["unsoftened_contact_steps"] == 0 for r in metrics["runs"] if r["variant"] != "own")
    assert "unsoftened" not in [c["kind"] for c in metrics["claims"]]
    recommended, spreads = check_by_separate_runs(programs["box_stack"], metrics)
    assert recommended == "fixed" and all(v == (0.0, 0.0) for v in spreads["fixed"].values())
    # what the diagnosis says, in numbers the tables hold
    diagnosis = next(c for c in metrics["claims"] if c["kind"] == "diagnosis")
    assert [s["step"] for s in diagnosis["steps"]] == ["the cut", "the mapping", "the step length", "the solver",
                                                      "identical steps"]


def test_box_stack_that_forgets_to_soften_is_told(programs, tmp_path):
    """The same stack with a near callback that forgets ssStepper_SoftenContact: every step under a policy makes
    contacts and softens none; the audit says how many, names the call, and shows the count beside each run."""
    policies = ("implicit-euler", "fixed")
    metrics = audit(tmp_path, programs["box_stack_unsoftened"], "--cost", "none", "--no-diagnosis",
                    "--policies", *policies)
    claim = next(c for c in metrics["claims"] if c["kind"] == "unsoftened")
    assert set(claim["steps"]) == set(policies) and all(n > 0 for n in claim["steps"].values()), claim
    assert "ssStepper_SoftenContact" in claim["text"] and "near callback" in claim["text"]
    for run in metrics["runs"]:  # own stepping does not count (-1: the column left out); every policy run did
        count = run["unsoftened_contact_steps"]
        assert count is None if run["variant"] == "own" else count > 0, run
    assert "steps with contacts, none softened" in (tmp_path / "audit.html").read_text()


def test_ragdoll_claims_spread_where_the_reference_parts(programs, tmp_path):
    """A chaotic fall: the reference and its check part early, yet the spread across frame rates is claimed over the
    whole run, and deviation only before the parting."""
    metrics = audit(tmp_path, programs["ragdoll"], "--cost", "none", "--no-diagnosis")
    check = metrics["reference_check"]
    assert check["parted_at"] is not None and check["parted_at"] < 2.0, check
    kinds = [c["kind"] for c in metrics["claims"]]
    assert "least_spread" in kinds and "recommend" in kinds
    recommended, _ = check_by_separate_runs(programs["ragdoll"], metrics)
    assert recommended == "fixed"


def test_maze_names_the_clock_floor(programs, tmp_path):
    """A clock of whole milliseconds: the check at 4000 frames a second steps 1 ms, as the reference does. The audit
    says so, makes no claim about deviation, and still claims the spread."""
    metrics = audit(tmp_path, programs["maze"], "--cost", "none", "--no-diagnosis")
    check = metrics["reference_check"]
    assert not check["check_finer"] and check["clock_floor_s"] == pytest.approx(0.001, rel=0.01), check
    reference_claim = metrics["claims"][0]
    assert "floor of about 1 ms" in reference_claim["text"] and "unchecked" in reference_claim["text"]
    assert "least_deviation" not in [c["kind"] for c in metrics["claims"]]
    check_by_separate_runs(programs["maze"], metrics)


def test_hopper_names_an_unphysical_reference(programs, tmp_path):
    """Per-step boosts sized for 60 fps throw the fine-step reference metres up: the audit names the reference
    unphysical (the quantity, how fast, how far), scales by the program's own runs, and claims no deviation."""
    metrics = audit(tmp_path, programs["hopper"], "--cost", "none", "--no-diagnosis")
    check = metrics["reference_check"]
    assert not check["sane"] and check["unphysical"][0]["quantity"] == "chassis_z_m", check
    assert check["unphysical"][0]["reached"] > 5.0
    assert "reference is unphysical" in metrics["claims"][0]["text"]
    assert metrics["scale_source"] == "the own stepping runs"
    assert "least_deviation" not in [c["kind"] for c in metrics["claims"]]
    check_by_separate_runs(programs["hopper"], metrics)


EXAMPLES = {  # the project's programs: (the program, its own stepping: None for the same, or a Python file)
    "wrecking_arm": ("steadystep_example_wrecking_arm", None),
    "substepping_program": ("steadystep_test_substepping_program", None),
    "audit_pendulum": ("steadystep_example_audit_pendulum", None),
    "chain": ("steadystep_example_chain_steadystep", "steadystep_example_chain_ode"),
    "audit_slider.py": (ROOT / "examples" / "audit_slider.py", None),
}


@pytest.mark.parametrize("example", EXAMPLES)
def test_project_examples(example, tmp_path):
    """The project's game-like example, its program that substeps itself (three dWorldStep a frame, naive its own
    stepping bit for bit), the chaotic pendulum, the chain against its plain-ODE twin, and the Python slider with its
    own_frame."""
    from steadystep.audit.run import Executable, PythonProgram

    name, own = EXAMPLES[example]
    if isinstance(name, Path):
        program, separate = name, PythonProgram(str(name))
    else:
        program, own = BUILD / name, (BUILD / own if own else BUILD / name)
        if not program.exists() or not own.exists():
            pytest.skip(f"{program} not built")
        separate = Executable((str(program),), (str(own),))
    # A Python run is a slower process: half the time, the policies the separate runs hold it against.
    shorter = ["--duration", "1.5", "--policies", *SEPARATE_POLICIES] if isinstance(name, Path) else []
    metrics = audit(tmp_path, program, "--cost", "none", "--no-diagnosis", *shorter,
                    own=None if isinstance(name, Path) else own)
    assert metrics["variants"][0] == "own"
    check_by_separate_runs(separate, metrics)
    if example == "substepping_program":
        assert metrics["spread"]["naive"] == metrics["spread"]["own"]

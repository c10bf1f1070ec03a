"""The Python audit protocol's per-step hook (docs/audit.md): PythonWorld.before_step(time_s, step_s) is called before
every physics step of every run, under every policy, with the step's simulated start time and length; inputs
computed there give the same motion at every frame rate under fixed; what it raises refuses the program by name.

The program is written here, small: a 1 kg body on a slider with a spring stop, pushed by a force that follows the
simulated time, and two followed quantities that report what the hook saw (the sum of the step lengths it was given
and how many calls), so that the audit's own columns can be held against them."""

import numpy as np
import pytest

from steadystep import audit
from steadystep.audit.run import STEP_COLUMN, TIME_COLUMN, BadProgram, run
from steadystep.core.stepping import policy_names

PROGRAM = '''
import ctypes
import math

import odepy

import steadystep as ss
from steadystep.audit import PythonWorld


def build_world():
    world = odepy.dWorldCreate()
    odepy.dWorldSetGravity(world, 0.0, 0.0, 0.0)
    body = odepy.dBodyCreate(world)
    mass = odepy.dMass()
    odepy.dMassSetBoxTotal(ctypes.byref(mass), 1.0, 0.1, 0.1, 0.1)
    odepy.dBodySetMass(body, ctypes.byref(mass))
    slider = odepy.dJointCreateSlider(world, 0)
    odepy.dJointAttach(slider, body, 0)
    odepy.dJointSetSliderAxis(slider, 1.0, 0.0, 0.0)
    odepy.dJointSetSliderParam(slider, odepy.dParamLoStop, 0.0)
    odepy.dJointSetSliderParam(slider, odepy.dParamHiStop, 0.0)
    odepy.dBodySetPosition(body, 0.5, 0.0, 0.0)
    registry = ss.Registry(world)
    registry.bind_joint(slider, ss.JointParam.STOP, 1, ss.Spring(stiffness=40.0, damping=1.0))
    seen = {"sum_s": 0.0, "calls": 0, "next_s": 0.0}

    def before_step(time_s, step_s):
        assert time_s == seen["next_s"], (time_s, seen["next_s"])  # each step starts where the last one ended
        seen["sum_s"] += step_s
        seen["calls"] += 1
        seen["next_s"] = time_s + step_s
        odepy.dBodyAddForce(body, FORCE(time_s), 0.0, 0.0)

    def close():
        registry.close()
        odepy.dWorldDestroy(world)

    return PythonWorld(world=world, registry=registry, before_step=before_step, close=close,
                       extra={"body": body, "seen": seen})


def FORCE(time_s):
    return 2.0 * math.sin(2 * math.pi * time_s / 0.7) + 0.5


def read_quantities(world):
    seen = world.extra["seen"]
    return {"x_m": odepy.dBodyGetPosition(world.extra["body"])[0], "seen_s": seen["sum_s"],
            "calls_count": float(seen["calls"])}
'''


@pytest.fixture(scope="module")
def program(tmp_path_factory):
    path = tmp_path_factory.mktemp("program") / "per_step.py"
    path.write_text(PROGRAM)
    return audit.PythonProgram(str(path))


@pytest.mark.parametrize("policy", policy_names())
def test_the_hook_runs_before_every_step_with_its_time_and_length(program, policy):
    for profile, seed in (("fixed:60", 1), ("uniform:15:45", 2)):
        made = run(program, policy, profile, seed, 1.0)
        assert made.ok, made.status
        columns = made.columns
        # the step lengths the hook was given add up to the audit's time column, to the bit, frame by frame
        assert np.array_equal(columns["seen_s"], columns[TIME_COLUMN]), policy
        assert np.array_equal(columns["calls_count"], np.cumsum(columns[STEP_COLUMN]))
        assert columns["calls_count"][-1] > 0


def test_per_step_inputs_give_the_same_motion_at_every_frame_rate_under_fixed(program):
    runs = [run(program, "fixed", profile, seed, 2.0).columns
            for profile, seed in (("fixed:60", 1), ("fixed:30", 1), ("fixed:144", 1), ("uniform:15:45", 1))]
    first = dict(zip(runs[0][TIME_COLUMN], runs[0]["x_m"]))
    for columns in runs[1:]:
        shared = [(t, x) for t, x in zip(columns[TIME_COLUMN], columns["x_m"]) if t in first]
        assert len(shared) >= 20
        assert all(x == first[t] for t, x in shared)  # the same bits where the runs end a frame on the same step
    assert np.ptp(runs[0]["x_m"]) > 0.1  # it moved


def test_a_hook_that_raises_refuses_the_program_by_name(tmp_path):
    path = tmp_path / "raises.py"
    path.write_text(PROGRAM.replace("seen[\"calls\"] += 1", "seen[\"calls\"] += 1\n        if seen[\"calls\"] == 5: "
                                    "raise RuntimeError(\"the fifth step\")"))
    with pytest.raises(BadProgram, match=r"raises.py \(fixed, fixed:60, seed 1\): before_step\(\) raised "
                                         r"RuntimeError: the fifth step"):
        run(audit.PythonProgram(str(path)), "fixed", "fixed:60", 1, 1.0)
    path.write_text(PROGRAM.replace("before_step=before_step,", "before_step=3,"))
    with pytest.raises(BadProgram, match=r"PythonWorld.before_step = 3: must be callable"):
        run(audit.PythonProgram(str(path)), "implicit-euler", "fixed:60", 1, 1.0)


def test_the_recommendation_ends_with_the_code_to_write(tmp_path):
    """The audit's page and its command line end their recommendation with the lines of code for the policy it
    recommends, the program's language (Python here) first."""
    from markupsafe import escape  # as the page escapes its text (Jinja2, autoescape)
    import json
    import subprocess
    import sys
    from pathlib import Path

    from steadystep.report import snippets

    script = Path(sys.executable).parent / "steadystep"
    command = [str(script)] if script.exists() else [sys.executable, "-m", "steadystep.cli"]
    program = tmp_path / "slider.py"  # following the body alone: the hook's counts differ with the step
    program.write_text(PROGRAM.replace('"seen_s": seen["sum_s"],\n            "calls_count": float(seen["calls"])',
                                       '"v_m_per_s": odepy.dBodyGetLinearVel(world.extra["body"])[0]'))
    out = tmp_path / "audit"
    done = subprocess.run([*command, "audit", "--python", program, "--out", out, "--duration", "1",
                           "--profiles", "fixed:60", "uniform:15:45", "--seeds", "1", "--policies", "implicit-euler",
                           "fixed", "--executor", "serial"], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["quantities"] == ["x_m", "v_m_per_s"]
    policy, = (c["variant"] for c in metrics["claims"] if c["kind"] == "recommend")
    code = snippets.as_text(policy, "Python")
    assert done.stdout.endswith(code + "\n")
    assert done.stdout.index("- For this program: ") < done.stdout.index(code)  # after the claims
    page = (out / "audit.html").read_text()
    section = page[page.index("<section id='recommendation'>"):]
    section = section[:section.index("</section>")]
    python, c = snippets.for_policy(policy, "Python")
    assert section.index(f"<h3 id='code'>The code to write for {policy}</h3>") > section.index("</ul>")
    assert section.index(escape(python.text)) < section.index(escape(c.text))
    assert section.endswith(f"<code>{escape(c.text)}</code></pre>")

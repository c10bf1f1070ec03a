"""The code the audit's recommendation and the report's first screen end with (steadystep.report.snippets) is real code:
each C snippet compiles as C and as C++ against the library's headers, each Python snippet runs on an odepy world, for
every policy of the library."""

import ctypes
import shutil
import subprocess
from pathlib import Path

import odepy
import pytest

import steadystep as ss
from steadystep.report import snippets

INCLUDE = Path(ss.__file__).parent / "core" / "_native" / "include"  # the headers the package was built from
COMPILER = {"c": shutil.which("cc"), "c++": shutil.which("c++")}

C_PROGRAM = """#include <steadystep/steadystep.h>
static dBodyID body;
{top}
int adopt_and_run(ssStepperDef def, double frame_s);
int adopt_and_run(ssStepperDef def, double frame_s) {{
  ssStepper* stepper = NULL;
  ssFrameReport report;
{once}
  for (int frame = 0; frame < 3; ++frame) {{
{frame}
  }}
  ssStepper_Destroy(stepper);
  return report.steps;
}}
"""


def _indent(code: str) -> str:
    return "\n".join("    " + line for line in code.splitlines())


@pytest.mark.parametrize("language", ["c", "c++"])
@pytest.mark.parametrize("policy", ss.policy_names())
def test_each_c_snippet_compiles(tmp_path, policy, language):
    if COMPILER[language] is None:
        pytest.skip(f"no {language} compiler")
    snippet, = (s for s in snippets.for_policy(policy) if s.language == "C")
    source = tmp_path / "snippet.c"
    source.write_text(C_PROGRAM.format(top=snippet.top, once=_indent(snippet.once), frame=_indent(snippet.frame)))
    flags = ["-fsyntax-only", "-Wall", "-Werror", "-Wno-unused-variable", "-Wno-unused-but-set-variable",
             "-Wno-unused-parameter", f"-I{INCLUDE}"]
    done = subprocess.run([COMPILER[language], *flags, "-x", language, str(source)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr + source.read_text()


@pytest.mark.parametrize("policy", ss.policy_names())
def test_each_python_snippet_runs_on_an_odepy_world(policy):
    snippet, = (s for s in snippets.for_policy(policy) if s.language == "Python")
    odepy.dInitODE2(0)
    world = odepy.dWorldCreate()
    odepy.dWorldSetGravity(world, 0.0, 0.0, -9.81)
    space = odepy.dSimpleSpaceCreate(0)
    contacts = odepy.dJointGroupCreate(0)
    body = odepy.dBodyCreate(world)
    mass = odepy.dMass()
    odepy.dMassSetSphereTotal(ctypes.byref(mass), 1.0, 0.1)
    odepy.dBodySetMass(body, ctypes.byref(mass))
    odepy.dGeomSetBody(odepy.dCreateSphere(space, 0.1), body)
    program = {"ss": ss, "world": world, "space": space, "contacts": contacts, "body": body,
               "collide": lambda stepper: None, "frame_s": 1 / 50}
    exec(snippet.top + "\n" + snippet.once, program)
    for _ in range(3):
        exec(snippet.frame, program)
    stepper = program["stepper"]
    assert stepper.stepping.policy == policy and stepper.known_body_count == 1
    assert odepy.dBodyGetPosition(body)[2] < 0.0  # it fell: the frames were stepped
    if snippets.is_fixed(policy):
        position, quaternion = program["position"], program["quaternion"]
        assert len(position) == 3 and len(quaternion) == 4 and position[2] > odepy.dBodyGetPosition(body)[2]
    stepper.close()
    odepy.dJointGroupDestroy(contacts)
    odepy.dSpaceDestroy(space)
    odepy.dWorldDestroy(world)


def test_fixed_moves_the_logic_to_before_step_and_draws_interpolated_poses():
    c, python = snippets.for_policy("fixed")
    assert "def.before_step = beforeStep" in c.text and "ssStepper_CurrentStep" in c.text
    assert "step.time_s" in c.text and "step.step_s" in c.text and "ssStepper_InterpolatedPose" in c.text
    assert "before_step=before_step" in python.text and "stepper.interpolated_pose(body)" in python.text
    for snippet in snippets.for_policy("implicit-euler"):
        assert "before_step" not in snippet.text and "nterpolated" not in snippet.text
        assert "the loop as it is" in snippet.text
    assert [s.language for s in snippets.for_policy("fixed", first="Python")] == ["Python", "C"]
    text = snippets.as_text("fixed")
    assert text.startswith("The code to write for fixed: ") and text.rstrip().endswith("not at ODE's pose")

"""Every code block of README.md and docs/*.md is fenced and compiled or run (issue 28), chosen by its language tag:

- c, cpp: the file's C blocks, in order, one translation unit behind stubs for what they take from the program
  around them (a world, a space, a car, a frame clock, a renderer), compiled as C and as C++ against the package's
  headers and ODE's, warnings as errors; a block tagged `c fragment` (statements from inside a function) is
  compiled as the body of a function of its own;
- python: run, on a small odepy world (or PyODE's, for a block that imports ode) with what the block names from
  the program around it (world, space, contacts, collide, frame_s); `python compile-only` (a block that needs a
  program or files of the reader's): compiled, and every steadystep function it calls exists and takes the
  arguments it is given;
- sh: each command checked without running it: `steadystep ...` parsed by the command line's own parser, `cmake`'s
  -D options declared in CMakeLists.txt, `scripts/...` present and executable, `build/steadystep_example_NAME` and
  `build/steadystep_test_NAME` with their sources, `.venv/bin/python FILE` with FILE present;
- diff: every line of the block is a line of the real `diff -u` of the two files it names, in order;
- text, output: not code (a diagram, a program's output), not checked.
A block with another tag, or none, fails: tag it, or teach this test to check it. An indented code block (four
spaces, or four beyond a list item's text) fails too: fence it, so that it has a tag.
"""

from __future__ import annotations

import ctypes
import re
import shlex
import shutil
import subprocess
from pathlib import Path

import pytest

import steadystep as ss

REPO = Path(__file__).resolve().parents[2]
INCLUDE = Path(ss.__file__).parent / "core" / "_native" / "include"  # the headers the package was built from
NOT_CODE = {"text", "output"}
CHECKED = {"c", "cpp", "python", "sh", "diff"}
VARIANTS = {"c fragment", "python compile-only"}  # checked as the module's docstring says


def documents() -> list[Path]:
    return [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]


def fenced_blocks(path: Path) -> list[tuple[int, str, str]]:
    """(line, language tag, text) of every fenced block (``` or ~~~) of a Markdown file; the tag is the info string's
    first word, with a second word that says how to check it kept after a space (`c fragment`)."""
    blocks, inside, start, tag, lines = [], None, 0, "", []
    for number, line in enumerate(path.read_text().splitlines(), 1):
        fence = re.match(r"^(\s*)(```+|~~~+)\s*([^\s`]*)[ \t]*([^\s`]*)", line)
        if inside is None and fence:
            tag = " ".join(word for word in (fence.group(3).lower(), fence.group(4).lower()) if word)
            inside, start, lines = fence.group(2), number, []
        elif inside is not None and line.strip().startswith(inside) and not line.strip().strip(inside[0]):
            blocks.append((start, tag, "\n".join(lines) + "\n"))
            inside = None
        elif inside is not None:
            lines.append(line)
    assert inside is None, f"{path.name}: a block opened at line {start} is never closed"
    return blocks


def all_blocks() -> list[tuple[Path, int, str, str]]:
    return [(path, line, tag, text) for path in documents() for line, tag, text in fenced_blocks(path)]


def _id(block) -> str:
    return f"{block[0].name}:{block[1]}:{block[2] or 'untagged'}"


def test_every_block_has_a_tag_this_test_checks():
    blocks = all_blocks()
    assert len(blocks) >= 30  # README's two C loops and its two commands, python.md's three, ...
    unknown = [_id(b) for b in blocks if b[2] not in CHECKED | NOT_CODE | VARIANTS]
    assert not unknown, f"blocks this test cannot check (tag them text or output if they are not code): {unknown}"


def indented_blocks(path: Path) -> list[int]:
    """The first line of every indented code block of a Markdown file (CommonMark: after a blank line, indented four
    spaces, or four beyond the text of the list item it is in), outside fenced blocks."""
    found, inside, blank, item = [], None, True, None  # item: the indent of the current list item's text
    for number, line in enumerate(path.read_text().splitlines(), 1):
        indent = len(line) - len(line.lstrip(" "))
        fence = re.match(r"^\s*(```+|~~~+)", line)
        if inside is not None:
            inside = None if line.strip().startswith(inside) and not line.strip().strip(inside[0]) else inside
            continue
        if not line.strip():
            blank = True
            continue
        marker = re.match(r"^(\s*)([-*+]|\d+[.)])\s+", line)
        if item is not None and indent < item and not marker and blank:
            item = None  # back at the text's left edge after a blank line: out of the list
        if blank and indent >= (item or 0) + 4:
            found.append(number)
            inside = None
        elif fence:
            inside = fence.group(1)
        elif marker and indent < (item or 0) + 4:
            item = len(marker.group(0))
        blank = False
    return found


@pytest.mark.parametrize("path", documents(), ids=lambda p: p.name)
def test_no_indented_code_blocks(path):
    """An indented block has no tag, so nothing here would check it: fence it with one."""
    assert not indented_blocks(path), f"{path.name}: indented code blocks at lines {indented_blocks(path)}"


def test_an_indented_block_is_found(tmp_path):
    page = tmp_path / "page.md"
    page.write_text("Text:\n\n    scripts/report\n\n- an item\n\n  its second paragraph\n\n      code in the item\n\n"
                    "```sh\n    scripts/test\n```\n")
    assert indented_blocks(page) == [3, 9]


# What a README-style C block takes from the program around it.
C_STUBS = """#include <math.h>
#include <stdio.h>
#include <ode/ode.h>
static dWorldID world;
static dSpaceID space;
static dJointGroupID contacts;
static dBodyID car;
static dJointID motor;
static double throttle = 1.0;
static double next_frame_seconds(void) { return 1.0 / 60; }
static void draw(const double position[3], const double quaternion[4]) { (void)position, (void)quaternion; }
static void restore_last_good_state(void) {}
"""
# What a `c fragment` block (statements from inside one of the program's functions) takes from around it: the names of
# examples/vehicle_steadystep.c it is added to (docs/examples.md).
FRAGMENT_STUBS = """#include <steadystep/steadystep.h>
enum { WHEEL_COUNT = 4 };
static ssRegistry* registry;
static dJointID hinges[WHEEL_COUNT];
static const double chassis_mass = 900.0;
"""


def _c_documents() -> list[Path]:
    return [path for path in documents() if any(tag in ("c", "cpp", "c fragment") for _, tag, _ in fenced_blocks(path))]


@pytest.mark.parametrize("language", ["c", "c++"])
@pytest.mark.parametrize("path", _c_documents(), ids=lambda p: p.name)
def test_c_blocks_compile(tmp_path, path, language):
    compiler = shutil.which("cc" if language == "c" else "c++")
    if compiler is None:
        pytest.skip(f"no {language} compiler")
    blocks = fenced_blocks(path)
    code = "".join(text for _, tag, text in blocks if tag in ("c", "cpp"))
    fragments = "".join(f"static void fragment_{line}(void) {{\n{text}}}\n" for line, tag, text in blocks
                        if tag == "c fragment")
    source = tmp_path / "blocks.c"
    source.write_text(C_STUBS + (FRAGMENT_STUBS if fragments else "") + code + fragments)
    ode = subprocess.run(["pkg-config", "--cflags", "ode"], capture_output=True, text=True).stdout.split()
    standard = "-std=c17" if language == "c" else "-std=c++17"
    flags = [standard, "-fsyntax-only", "-Wall", "-Wextra", "-Werror", "-Wno-unused-function",
             "-Wno-unused-variable", f"-I{INCLUDE}", *ode]
    done = subprocess.run([compiler, *flags, "-x", language, str(source)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr[:3000]


def _odepy_program() -> dict:
    import odepy

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
    return {"world": world, "space": space, "contacts": contacts, "body": body,
            "collide": lambda stepper: None, "frame_s": 1 / 60, "height": lambda: odepy.dBodyGetPosition(body)[2]}


def _pyode_program() -> dict:
    ode = pytest.importorskip("ode", reason="PyODE (Debian's python3-pyode) is not importable")
    world = ode.World()
    world.setGravity((0, 0, -9.81))
    space = ode.SimpleSpace()
    ode.GeomPlane(space, (0, 0, 1), 0)
    body = ode.Body(world)
    mass = ode.Mass()
    mass.setSphereTotal(1.0, 0.1)
    body.setMass(mass)
    body.setPosition((0, 0, 0.2))
    ode.GeomSphere(space, 0.1).setBody(body)
    return {"world": world, "space": space, "contactgroup": ode.JointGroup(), "body": body, "frame_s": 1 / 60,
            "height": lambda: body.getPosition()[2]}


PYTHON_BLOCKS = [b for b in all_blocks() if b[2] == "python"]


@pytest.mark.parametrize("block", PYTHON_BLOCKS, ids=_id)
def test_python_blocks_run(block):
    _, _, _, text = block
    program = _pyode_program() if re.search(r"^import ode\b", text, re.M) else _odepy_program()
    height = program["height"]
    start = height()
    exec(compile(text, _id(block), "exec"), program)
    stepper = program.get("stepper")
    if stepper is not None:  # it stepped a frame: the body fell
        assert height() < start
        stepper.close()


COMPILE_ONLY = [b for b in all_blocks() if b[2] == "python compile-only"]


@pytest.mark.parametrize("block", COMPILE_ONLY, ids=_id)
def test_python_compile_only_blocks_call_what_exists(block):
    """Compiled; every call of a steadystep module's function binds to its signature (placeholders for the values)."""
    import ast
    import importlib
    import inspect

    tree = ast.parse(block[3], _id(block))
    modules = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.split(".")[0] == "steadystep":
            for alias in node.names:
                modules[alias.asname or alias.name] = importlib.import_module(f"{node.module}.{alias.name}")
    calls = [node for node in ast.walk(tree) if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
             and isinstance(node.func.value, ast.Name) and node.func.value.id in modules]
    assert calls, f"{_id(block)}: calls nothing of steadystep"
    for call in calls:
        function = getattr(modules[call.func.value.id], call.func.attr, None)
        assert callable(function), f"{_id(block)}: {call.func.value.id}.{call.func.attr} does not exist"
        inspect.signature(function).bind(*call.args, **{k.arg: k.value for k in call.keywords})


def _check_command(words: list[str]) -> str | None:
    """Why a shell command of the docs would fail, or None."""
    while words and re.match(r"^[A-Z_]+=", words[0]):  # VARIABLE=value before the command
        words = words[1:]
    if not words:
        return None
    command, args = words[0], words[1:]
    if command.endswith("steadystep") and (command == "steadystep" or (REPO / command).parent.name == "bin"):
        from steadystep import cli

        try:
            cli.build_parser().parse_args(args)
        except SystemExit as done:  # --version and --help exit 0
            return f"steadystep's parser refuses {args}" if done.code else None
        return None
    if command == "cmake":
        declared = (REPO / "CMakeLists.txt").read_text()
        for arg in args:
            option = re.match(r"^-D([A-Za-z_]+)", arg)
            if option and not option.group(1).startswith("CMAKE_") and option.group(1) not in declared:
                return f"cmake option {option.group(1)} is not declared in CMakeLists.txt"
        return None
    built = re.match(r"^build/steadystep_(example|test)_(\w+)$", command)
    if built:
        source = (REPO / "examples" / f"{built.group(2)}.c" if built.group(1) == "example" else
                  REPO / "tests" / "c" / f"test_{built.group(2)}.cpp")
        return None if source.is_file() else f"{command}: no {source.relative_to(REPO)} it is built from"
    if command.endswith("bin/python"):
        return None if args and (REPO / args[0]).is_file() else f"{command} {args[:1]}: no such file in the repository"
    if command.startswith("scripts/"):
        script = REPO / command
        return None if script.is_file() and script.stat().st_mode & 0o111 else f"{command} is not an executable script"
    return f"no check for the command {command!r}"


SH_BLOCKS = [b for b in all_blocks() if b[2] == "sh"]


@pytest.mark.parametrize("block", SH_BLOCKS, ids=_id)
def test_shell_blocks_name_commands_and_options_that_exist(block):
    text = block[3]
    done = subprocess.run(["bash", "-n"], input=text, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    lines = [shlex.split(line, comments=True) for line in text.splitlines()]
    problems = [problem for words in lines if (problem := _check_command(words))]
    # A comment that shows another way ("# or: ...") is a command too.
    for line in text.splitlines():
        other = re.match(r"^\s*#\s*or:\s*(.*)$", line)
        if other and (problem := _check_command(shlex.split(other.group(1), comments=True))):
            problems.append(problem)
    assert not problems, problems


DIFF_BLOCKS = [b for b in all_blocks() if b[2] == "diff"]


@pytest.mark.parametrize("block", DIFF_BLOCKS, ids=_id)
def test_diff_blocks_are_the_real_diff(block):
    path, line, _, text = block
    before = path.read_text().splitlines()[:line - 1]
    named = [re.search(r"diff -u ([^\s`]+) ([^\s`]+)", b) for b in before]
    named = [m for m in named if m][-1:]
    assert named, f"{_id(block)}: say which files the diff is of (`diff -u A B` before the block)"
    old, new = named[0].groups()
    real = subprocess.run(["diff", "-u", old, new], capture_output=True, text=True, cwd=REPO).stdout.splitlines()
    shown = [l for l in text.splitlines() if not l.startswith("@@")]
    real_lines = [l for l in real if not l.startswith("@@")]
    at = 0
    for wanted in shown:
        while at < len(real_lines) and real_lines[at].rstrip() != wanted.rstrip():
            at += 1
        assert at < len(real_lines), f"{_id(block)}: not in the real `diff -u {old} {new}`, in order: {wanted!r}"
        at += 1

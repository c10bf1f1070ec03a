"""Hostile input through the real command: every subcommand's every numeric flag over a table of absurd values,
seeded random byte strings in every argument, and binary trace files. Whatever the input, the command ends with
exit code 0 (done), 1 (a blow-up) or 2 (refused, one line on stderr naming the value), never a traceback, and its
--json output parses as strict JSON (no NaN or Infinity).

The cases run in this process through steadystep.cli.main(argv), with pytest's capture as stdout and stderr: a
strict UTF-8 stream, as a terminal's is, so text that cannot be written fails here as it would there. A few run
as real processes with arguments that are not UTF-8 (test_non_utf8_argv_...); test_c_boundary_from_python.py
runs issue 8's examples that reach ODE, each in its own process.
"""

import json
import os
import random
import subprocess
import sys
from pathlib import Path

import pytest

from steadystep.cli import build_parser, main

SCRIPT = Path(sys.executable).parent / "steadystep"
COMMAND = [str(SCRIPT)] if SCRIPT.exists() else [sys.executable, "-m", "steadystep.cli"]

# Numbers a careless user or an attacker types. Each goes into every numeric flag of every subcommand.
HOSTILE_NUMBERS = [
    "nan", "-nan", "NaN", "inf", "-inf", "Infinity", "1e308", "-1e308", "1e309", "9" * 400, "-0", "-0.0", "0",
    "1e-320", "4.9e-324", "-1e-320", "-1", "1e9", "1e12", "", " ", "abc", "1e", "0x10", "1_0", "\udcff1", "1\x7f",
]
# Seeds are integers: the same table, plus the edges of uint64 and an integer too long to read.
HOSTILE_SEEDS = HOSTILE_NUMBERS + ["18446744073709551615", "18446744073709551616", "-18446744073709551615",
                                   "0b101", "1" * 5000]

# The names a refusal may give a flag's value by: the flag, or the library's name for it.
VALUE_NAMES = {"--dt": ["step_s"], "--max-step": ["max_step_s"], "--low": ["low_s"], "--high": ["high_s"],
               "--frequency": ["frequency_hz"], "--k": ["k ="], "--c": ["c ="]}
# figure and compare take about a second per accepted value (they draw figures): each flag's first accepted value
# runs in full, later ones that the parser accepts too are not run again.
SLOW = {"figure", "compare"}

# Every subcommand with cheap settings, and its numeric flags.
OUT = "{out}"
SUBCOMMANDS = {
    "figure": (["figure", "--out", OUT, "--duration", "0.2", "--seed", "1"], ["--duration", "--seed"]),
    "compare": (["compare", "--out", OUT, "--force", "--scenes", "oscillator", "--profiles", "fixed:30",
                 "--policies", "implicit-euler", "--duration", "0.2", "--seed", "1"], ["--duration", "--seed"]),
    "run": (["run", "oscillator", "--profile", "fixed:30", "--policy", "implicit-euler", "--duration", "0.2", "--json"],
            ["--duration", "--seed", "--max-step"]),
    "probe": (["probe", "oscillator", "--policies", "implicit-euler", "--duration", "0.2", "--low", "0.01", "--high", "0.1",
               "--json"], ["--duration", "--low", "--high"]),
    "convert k c": (["convert", "--k", "40", "--c", "1", "--dt", "0.02", "--mass", "1", "--json"],
                    ["--k", "--c", "--dt", "--mass"]),
    "convert erp cfm": (["convert", "--erp", "0.2", "--cfm", "1e-5", "--dt", "0.016667", "--json"],
                        ["--erp", "--cfm", "--dt"]),
    "convert frequency": (["convert", "--frequency", "2", "--damping-ratio", "0.3", "--mass", "1.5", "--dt", "0.01",
                           "--json"], ["--frequency", "--damping-ratio", "--mass", "--dt"]),
}


def _refuse_constant(name):
    raise ValueError(f"{name} is not strict JSON")


def run_cli(capsys, argv):
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


def check_outcome(argv, code, out, err):
    """The promise for any input: a known exit code, no traceback, one line for a refusal, strict JSON."""
    where = f"argv={argv!r} code={code} stderr={err!r}"
    assert code in (0, 1, 2), where
    assert "Traceback" not in err and "Traceback" not in out, where
    if code == 2:
        lines = err.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("steadystep"), where
        assert out == "", where
    if "--json" in argv and code in (0, 1):
        json.loads(out, parse_constant=_refuse_constant)


def with_value(argv, flag, value):
    """argv with flag's value replaced (or the flag added)."""
    argv = list(argv)
    if flag in argv:
        argv[argv.index(flag) + 1] = value
    else:
        argv += [flag, value]
    return argv


@pytest.mark.parametrize("subcommand", list(SUBCOMMANDS))
def test_every_numeric_flag_over_hostile_numbers(capsys, tmp_path, subcommand):
    base, flags = SUBCOMMANDS[subcommand]
    outcomes = {}
    for flag in flags:
        accepted = False
        for value in HOSTILE_SEEDS if flag == "--seed" else HOSTILE_NUMBERS:
            argv = [tmp_path.as_posix() if part == OUT else part for part in with_value(base, flag, value)]
            if accepted and subcommand in SLOW and parses(argv):
                continue
            code, out, err = run_cli(capsys, argv)
            check_outcome(argv, code, out, err)
            if code == 2:
                # The refusal names the value or the flag it came in.
                name = flag.lstrip("-")
                names = [flag, name, name.replace("-", "_"), repr(value), *VALUE_NAMES.get(flag, [])]
                assert any(n in err for n in names), (argv, err)
            accepted = accepted or code == 0
            outcomes[code] = outcomes.get(code, 0) + 1
    assert outcomes.get(2, 0) > 0  # the table is hostile enough to be refused somewhere


def parses(argv) -> bool:
    try:
        build_parser().parse_args(argv)
        return True
    except Exception:  # the parser's one-line refusal
        return False


def random_text(rng: random.Random) -> str:
    """A random argument as the OS hands it to Python: bytes decoded with surrogateescape. A mix of raw bytes,
    text that looks like a spec or a number, and bytes spliced into either."""
    kind = rng.randrange(4)
    if kind == 0:
        raw = bytes(rng.randrange(1, 256) for _ in range(rng.randrange(0, 40)))
    elif kind == 1:
        head = rng.choice(["fixed", "uniform", "jitter", "hitch", "vsync", "trace", "oscillator", "implicit-euler", "naive"])
        fields = [rng.choice(HOSTILE_NUMBERS + ["30", "60", "0.1", "1/60", "", "-"]) for _ in range(rng.randrange(4))]
        raw = ":".join([head, *fields]).encode("utf-8", "surrogateescape")
    elif kind == 2:
        raw = rng.choice(HOSTILE_NUMBERS).encode("utf-8", "surrogateescape") + bytes([rng.randrange(128, 256)])
    else:
        raw = "".join(rng.choice("0123456789.eE+-:_xXnaiNf ") for _ in range(rng.randrange(1, 20))).encode()
    return os.fsdecode(raw)


def test_random_byte_arguments_in_every_slot(capsys, tmp_path):
    rng = random.Random(8)
    slots = [
        lambda t: ["run", t, "--profile", "fixed:30", "--policy", "implicit-euler", "--duration", "0.2", "--json"],
        lambda t: ["run", "oscillator", "--profile", t, "--policy", "implicit-euler", "--duration", "0.2",
                   "--json"],
        lambda t: ["run", "chain", "--profile", "fixed:30", "--policy", t, "--duration", "0.2"],
        lambda t: ["run", "oscillator", "--profile", "fixed:30", "--policy", "naive", "--duration", t, "--json"],
        lambda t: ["run", "oscillator", "--profile", "fixed:30", "--policy", "implicit-euler", "--duration", "0.2",
                   "--max-step", t, "--json"],
        lambda t: ["probe", t, "--duration", "0.2", "--json"],
        lambda t: ["probe", "oscillator", "--policies", t, "--duration", "0.2"],
        lambda t: ["compare", "--out", str(tmp_path), "--force", "--scenes", t, "--profiles", "fixed:30",
                   "--policies", "implicit-euler", "--duration", "0.2"],
        lambda t: ["compare", "--out", str(tmp_path), "--force", "--scenes", "oscillator", "--profiles", "fixed:30", t,
                   "--duration", "0.2"],
        lambda t: ["compare", "--out", str(tmp_path), "--force", "--scenes", "oscillator", "--profiles", "fixed:30",
                   "--policies", t, "--duration", "0.2"],
        lambda t: ["convert", "--k", t, "--c", "1", "--dt", "0.02", "--json"],
        lambda t: ["convert", "--erp", "0.2", "--cfm", t, "--dt", "0.02", "--json"],
        lambda t: ["convert", "--frequency", t, "--damping-ratio", t, "--mass", "1", "--json"],
        lambda t: ["figure", "--duration", t, "--out", str(tmp_path / "figure")],
        lambda t: [t],
        lambda t: ["run", "oscillator", t],
    ]
    codes = []
    for case in range(300):
        argv = rng.choice(slots)(random_text(rng))
        code, out, err = run_cli(capsys, argv)
        check_outcome(argv, code, out, err)
        codes.append(code)
    assert codes.count(2) > 100


def test_nul_and_lone_surrogates_from_python_are_refused_by_name(capsys):
    for argv in (["run", "oscillator\0", "--profile", "fixed:30", "--policy", "implicit-euler"],
                 ["run", "oscillator", "--profile", "fixed:30\0garbage", "--policy", "implicit-euler"],
                 ["run", "oscillator", "--profile", "fixed:30", "--policy", "spring\ud800"],
                 ["probe", "\ud800"]):
        code, out, err = run_cli(capsys, argv)
        check_outcome(argv, code, out, err)
        assert code == 2 and ("NUL" in err or "surrogate" in err or "unknown" in err), err


def trace_files(directory: Path, rng: random.Random) -> list[str]:
    """Trace files a careless user passes: random binary, NULs, long lines, a directory, special files, a name that
    is not UTF-8 (holding a good trace, which must work)."""
    files = {
        "random.bin": bytes(rng.randrange(256) for _ in range(4096)),
        "nul_after_number.txt": b"0.5\0garbage\n",
        "nul_only.txt": b"\0" * 2048,
        "good_then_binary.txt": b"0.02\n0.03\n\xff\xfe\xfd\n",
        "latin1_comment.txt": b"# caf\xe9\n0.02\n",
        "long_last_line.txt": b"0." + b"0" * 500 + b"2",
        "very_long_line.txt": b"0.02" + b" " * 5000 + b"\n",
        "empty.txt": b"",
        "comments_only.txt": b"# nothing\n\n",
        "control.txt": b"0.02\n\x1b[31m\r\n",
        "huge_numbers.txt": b"1e308\n1e309\n",
        "many_lines.txt": b"0.02\n" * 20000,
        os.fsdecode(b"bad\xffname.txt"): b"0.02\n0.04\n",
    }
    for _ in range(20):
        files[f"random_{len(files)}.bin"] = bytes(rng.randrange(256) for _ in range(rng.randrange(1, 700)))
    for name, content in files.items():
        (directory / name).write_bytes(content)
    return [str(directory / name) for name in files] + [str(directory), "/dev/null", str(directory / "missing")]


def test_trace_files_of_any_bytes(capsys, tmp_path):
    rng = random.Random(80)
    codes = {}
    for path in trace_files(tmp_path, rng):
        for policy in ("implicit-euler", "naive"):
            argv = ["run", "oscillator", "--profile", f"trace:{path}", "--policy", policy, "--duration", "0.3",
                    "--json"]
            code, out, err = run_cli(capsys, argv)
            check_outcome(argv, code, out, err)
            codes[os.path.basename(path), policy] = code
    assert codes["bad\udcffname.txt", "implicit-euler"] == 0  # a good trace under a name that is not UTF-8 works
    assert codes["random.bin", "implicit-euler"] == 2 and codes["nul_only.txt", "naive"] == 2


def steadystep_bytes(*args: bytes):
    return subprocess.run([*map(os.fsencode, COMMAND), *args], capture_output=True, timeout=60)


def test_non_utf8_argv_through_the_real_command(tmp_path):
    (tmp_path / os.fsdecode(b"tr\xe9ce.txt")).write_bytes(b"0.02\n0.05\n")
    cases = [
        ([b"run", b"\xff\xfe", b"--profile", b"fixed:30", b"--policy", b"implicit-euler"], 2),
        ([b"run", b"oscillator", b"--profile", b"fixed:30", b"--policy", b"spr\xc3ing"], 2),
        ([b"run", b"oscillator", b"--profile", b"trace:/no/such/\xff", b"--policy", b"implicit-euler"], 2),
        ([b"convert", b"--k", b"4\xff0", b"--c", b"1", b"--dt", b"0.1"], 2),
        ([b"compare", b"--scenes", b"osc\x80", b"--out", os.fsencode(tmp_path / "report")], 2),
        ([b"run", b"oscillator", b"--profile", b"trace:" + os.fsencode(tmp_path) + b"/tr\xe9ce.txt", b"--policy",
          b"implicit-euler", b"--duration", b"0.5", b"--json"], 0),
    ]
    for args, expected in cases:
        result = steadystep_bytes(*args)
        assert result.returncode == expected, (args, result.stderr)
        assert b"Traceback" not in result.stderr
        if expected == 2:
            assert len(result.stderr.strip().splitlines()) == 1, (args, result.stderr)
            result.stderr.decode("utf-8")  # what the command writes is UTF-8, whatever it was given
        else:
            json.loads(result.stdout, parse_constant=_refuse_constant)
    assert not (tmp_path / "report").exists()

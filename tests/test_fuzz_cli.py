"""Random bytes, point tables and option values thrown at every command: exit 0, 1, 2 or 3, one line, no traceback.

Bounded so the suite stays fast: few examples, small inputs, a per-example deadline.  Commands that
need a serial port are run only with ``loop://``, and ``receive`` with waits of a fraction of a second;
``plot`` gets random bytes only (a picture per example would be slow).  Every command is covered:
``test_every_command_is_fuzzed`` fails when one is added without its entry here.
"""

from __future__ import annotations

import io
import tempfile
from pathlib import Path

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from lagsym.cli import main

SETTINGS = settings(max_examples=25, deadline=20_000, suppress_health_check=[HealthCheck.too_slow],
                    derandomize=True)
GOOD = '{"points": [[0, 0, 1], [0, 1, 2], [1, 0, 3], [1, 1, 4]]}'
PROGRAM = "%\nO1\nG0 X0 Y0 Z10\nG1 Z0 F100\nX1\nY1\nM30\n%\n"

# Each command with the numeric options it takes; values are drawn at random for them.
COMMANDS = {
    "equation": ["--digits", "--max-terms"],
    "curve": ["--digits"],
    "check": [],
    "probe": ["--tip-radius", "--top", "--bottom", "--clearance", "--overtravel", "--retract", "--feed", "--margin",
              "--program-number", "--degree", "--nodes", "--box"],
    "read-probe": ["--degree"],
    "fit": ["--degree", "--max-degree", "--threshold"],
    "piecewise": [],
    "sample": ["--nx", "--ny", "--step", "--x0", "--max-points"],
    "compare": ["--samples", "--degree", "--tolerance"],
    "toolpath": ["--scale", "--step", "--stepover", "--tool-diameter", "--feed", "--spindle", "--safe-z",
                 "--decimals", "--max-points"],
    "macro": ["--scale", "--step", "--stepover", "--tool-diameter", "--feed", "--safe-z", "--tolerance"],
    "verify": ["--scale", "--tool-diameter", "--cell", "--gouge-limit"],
    "simulate": ["--max-blocks", "--max-idle-blocks"],
    "export": ["--degree", "--base-z"],
    "rough": ["--stock-above", "--margin", "--stepdown", "--stepover", "--step", "--stock-to-leave",
              "--tool-diameter", "--scale", "--feed", "--spindle", "--safe-z", "--max-points", "--max-samples"],
    "job": ["--max-points", "--max-samples"],
    "send": ["--start-block", "--buffer-chars", "--memory-chars", "--overrun-chars", "--stall-timeout", "--leader",
             "--trailer"],
    "receive": ["--timeout", "--idle-timeout"],
    "dnc": [],
    "plot": [],
}
JOB = """points = "{points}"\nsafe_z = 20\n[stock]\ntop_above = 1\n[tools.t]\nnumber = 1\nshape = "flat"
diameter = 1\n[[operations]]\nkind = "rough"\ntool = "t"\nstepover = 0.5\n"""
NUMBERS = st.one_of(
    st.sampled_from(["nan", "inf", "-inf", "0", "-1", "1e308", "1e-308", "1e999999", "999999999999999999", "",
                     "\u0667", "1/0", "0x10", "1_000"]),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.integers(-10**20, 10**20).map(str),
)


def run(argv: list[str]) -> tuple[int, str]:
    out, err = io.StringIO(), io.StringIO()
    status = main(argv, out, err)
    return status, err.getvalue()


def assert_answered(status: int, err: str) -> None:
    assert status in (0, 1, 2, 3), (status, err)
    assert "Traceback" not in err and "internal error" not in err, err
    if status == 2:
        assert err.count("\n") == 1 and err.startswith("lagsym: error:"), err


def _args(cmd: str, files: dict[str, Path]) -> list[str]:
    if cmd == "verify":
        return [cmd, str(files["points"]), str(files["program"])]
    if cmd in ("simulate", "send"):
        return [cmd, str(files["program"])] + (["--port", "loop://", "--baud", "115200", "--quiet"] * (cmd == "send"))
    if cmd == "receive":  # nothing ever arrives on loop://: a short wait, then exit 3
        return [cmd, "--port", "loop://", "--timeout", "0.2", "--quiet"]
    if cmd == "job":
        return [cmd, str(files["job"])]
    if cmd == "dnc":
        return [cmd, "serve", str(files["job"]), "--check"]
    if cmd == "probe":
        return [cmd, "--box", "0,10,0,10", "--top", "5", "--bottom", "0", "--tip-radius", "1"]
    if cmd == "rough":
        return [cmd, str(files["points"]), "--stock-above", "1"]
    return [cmd, str(files["points"])]


def _files(d: str) -> dict[str, Path]:
    return {"points": Path(d) / "p.json", "program": Path(d) / "p.nc", "job": Path(d) / "job.toml"}


def test_every_command_is_fuzzed():
    from lagsym.cli import COMMANDS as ALL

    assert set(COMMANDS) == set(ALL)


@settings(SETTINGS, max_examples=40)
@given(cmd=st.sampled_from(sorted(COMMANDS)), data=st.binary(max_size=300))
def test_random_bytes_as_every_input(cmd, data):
    with tempfile.TemporaryDirectory() as d:
        files = _files(d)
        for p in files.values():
            p.write_bytes(data)
        assert_answered(*run(_args(cmd, files)))


_CELL = st.one_of(st.integers(-5, 5).map(str), st.sampled_from(["1.5", "1,5", "nan", "1e400", "x", "", "1/3", "-0"]))


@SETTINGS
@given(cmd=st.sampled_from(["equation", "check", "sample", "compare", "macro"]),
       rows=st.lists(st.lists(_CELL, min_size=2, max_size=4), min_size=1, max_size=10),
       sep=st.sampled_from([",", ";", "\t", " "]), end=st.sampled_from(["\n", "\r\n", "\r"]))
def test_random_point_tables(cmd, rows, sep, end):
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / "p.csv"
        p.write_text(end.join(sep.join(r) for r in rows) + end, newline="")
        assert_answered(*run([cmd, str(p)]))


# receive waits as long as its timeouts say: only values that are refused, or a fraction of a second
_WAITS = st.one_of(st.sampled_from(["nan", "inf", "-inf", "0", "-1", "1e308", "1e999999", "", "\u0667", "1/0"]),
                   st.floats(1e-3, 0.3).map(repr))


@settings(SETTINGS, max_examples=40)
@given(cmd=st.sampled_from(sorted(c for c in COMMANDS if COMMANDS[c])), data=st.data())
def test_random_option_values(cmd, data):
    option = data.draw(st.sampled_from(COMMANDS[cmd]))
    value = data.draw(_WAITS if cmd == "receive" else NUMBERS)
    with tempfile.TemporaryDirectory() as d:
        files = _files(d)
        files["points"].write_text(GOOD)
        files["program"].write_text(PROGRAM)
        files["job"].write_text(JOB.format(points=files["points"]))
        argv = _args(cmd, files) + [f"{option}={value}"]
        if cmd in ("toolpath", "macro") and option != "--safe-z":
            argv.append("--safe-z=100")
        assert_answered(*run(argv))


@settings(max_examples=10, deadline=20_000, derandomize=True)
@given(data=st.binary(max_size=200))
def test_send_to_a_loop_port(data):
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / "p.nc"
        p.write_bytes(data)
        assert_answered(*run(["send", str(p), "--port", "loop://"]))

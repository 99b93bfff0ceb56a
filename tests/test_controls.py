"""Controls as values: one registry, every table derived from it, and Haas as the control added by one value."""

from __future__ import annotations

import dataclasses
import importlib
import pkgutil
import re
from pathlib import Path

import pytest

import lagsym
from lagsym.controls import CONTROLS, control, names, work_offset
from lagsym.errors import InputError, ProgramError, ToolpathError
from lagsym.io import read_points
from lagsym.lagrange import lagrange_surface
from lagsym.machine import MachineSettings, Placement, RasterSpec, Tool
from lagsym.post.program import point_program, write_program
from lagsym.simulate import simulate
from lagsym.toolpath import plan_toolpath

from conftest import EXAMPLES
from gcheck import check_feeds, interpret

LANGUAGES = {c.macro.name for c in CONTROLS.values() if c.macro is not None}
PROFILES = {c.dnc_profile for c in CONTROLS.values() if c.dnc_profile is not None}
# What a table keyed by control names may be keyed by: all the controls, or those of one capability.
EXPECTED = {frozenset(names()), frozenset(names(point_lists=True)), frozenset(names(macros=True)),
            frozenset(names(point_lists=True, macros=True))}


def _modules():
    for info in pkgutil.walk_packages(lagsym.__path__, "lagsym."):
        if info.name.startswith(("lagsym.plot", "lagsym.dnc.port")) or info.name == "lagsym.__main__":
            continue
        yield importlib.import_module(info.name)


def _keyed_tables():
    """Every module-level dict, mapping or tuple of strings in lagsym that names a control."""
    known = set(CONTROLS)
    for module in _modules():
        for attr, value in vars(module).items():
            if attr.startswith("__"):
                continue
            keys = None
            if isinstance(value, dict) or type(value).__name__ == "mappingproxy":
                keys = set(value)
            elif isinstance(value, tuple) and value and all(isinstance(v, str) for v in value):
                keys = set(value)
            if keys and all(isinstance(k, str) for k in keys) and keys & known:
                yield f"{module.__name__}.{attr}", keys


def test_every_table_keyed_by_control_names_names_registered_controls_and_misses_none():
    tables = dict(_keyed_tables())
    assert "lagsym.machine.DIALECTS" in tables and "lagsym.simulate.reader.SIM_DIALECTS" in tables
    for where, keys in tables.items():
        if keys <= LANGUAGES or keys <= PROFILES | LANGUAGES:
            continue  # keyed by macro language (the writers and parsers) or by serial profile
        assert keys <= set(CONTROLS), f"{where} names {sorted(keys - set(CONTROLS))}, not registered controls"
        assert frozenset(keys) in EXPECTED, f"{where} ({sorted(keys)}) misses a control that has its capability"


def test_every_language_has_its_writer_and_parser_and_every_profile_its_line_settings():
    from lagsym.dnc import PROFILES as LINE_PROFILES
    from lagsym.macro.program import RENDERERS
    from lagsym.simulate.reader import PARSERS

    assert set(RENDERERS) == set(PARSERS) == LANGUAGES
    assert PROFILES <= set(LINE_PROFILES)


def test_no_control_is_compared_by_name_outside_the_registry():
    root = Path(lagsym.__file__).parent
    found = [f"{p.relative_to(root)}:{n}" for p in root.rglob("*.py") for n, line in enumerate(p.read_text().splitlines(), 1)
             if re.search(r"dialect\s*(==|!=|not in|in\s*\()", line)]
    assert not found


def test_controls_are_frozen_values():
    c = control("fanuc")
    with pytest.raises(dataclasses.FrozenInstanceError):
        c.max_block = 300
    with pytest.raises(TypeError):
        c.macro_variables["full"] = ((1, 2),)
    with pytest.raises(TypeError):
        CONTROLS["acme"] = c


def test_a_bad_name_or_word_names_the_choices():
    with pytest.raises(InputError, match="dialect 'sinumerik' is not one of fanuc, haas, linuxcnc, heidenhain, grbl"):
        control("sinumerik")
    with pytest.raises(InputError, match="'G54 M30' is not a work offset word of any control: fanuc G54 to G59"):
        work_offset("G54 M30")
    assert control(control("haas")) is CONTROLS["haas"]


@pytest.mark.parametrize("word, dialect, ok", [
    ("G154 P99", "haas", True), ("G129", "haas", True), ("G54.1 P5", "haas", False),
    ("G154 P5", "fanuc", False), ("G54.1 P48", "fanuc", True), ("G54.1 P49", "fanuc", False),
    ("G59.3", "linuxcnc", True), ("G59.1", "grbl", False),
])
@pytest.mark.slow
def test_each_control_reads_its_own_work_offsets(word, dialect, ok):
    s = MachineSettings(dialect=dialect, work_offset=word) if ok or re.fullmatch(
        "|".join(c.work_offsets for c in CONTROLS.values() if c.work_offsets), word) else None
    if s is None:
        with pytest.raises(InputError, match="not a work offset word of any control"):
            MachineSettings(dialect=dialect, work_offset=word)
        return
    assert control(dialect).reads_work_offset(word) is ok
    if ok:
        write_program(point_program(_path(), dataclasses.replace(s, safe_z_mm=90.0, mm_per_unit=20.0)))
    else:
        with pytest.raises(ProgramError, match=f"not one a {dialect} control has"):
            write_program(point_program(_path(), dataclasses.replace(s, safe_z_mm=90.0, mm_per_unit=20.0)))


def test_program_numbers_are_the_controls_own():
    assert MachineSettings(dialect="haas", program_number=12345).program_number == 12345
    with pytest.raises(ToolpathError, match="program number 12345 must be 1 to 9999 for a fanuc program"):
        MachineSettings(dialect="fanuc", program_number=12345)


_PATHS = {}


def _path():
    if not _PATHS:
        surf = lagrange_surface(read_points(EXAMPLES / "paper-example-4.json"))
        _PATHS["p"] = plan_toolpath(surf, Tool("ball", 6.0), RasterSpec("x", 4.0, 2.0), Placement(20.0))
    return _PATHS["p"]


def test_a_haas_point_list_is_read_by_rs274_and_moves_as_planned(rs274):
    s = MachineSettings(dialect="haas", mm_per_unit=20.0, safe_z_mm=90.0, program_number=12345, work_offset="G154 P7",
                        tool_number=150)
    text = write_program(point_program(_path(), s, title="haas part"))
    lines = text.splitlines()
    assert lines[:2] == ["%", "O12345 (HAAS PART)"] and lines[-3:] == ["M05", "M30", "%"]
    assert "G154 P7" in lines and "T150 M06" in lines and any(line.startswith("G00 G43 H150 ") for line in lines)
    # rs274 has no G154 and a tool table of its own: only those words are changed for it.
    feeds, _ = interpret(rs274, text.replace("G154 P7", "G54").replace("T150", "T1").replace("H150", "H1"))
    check_feeds(feeds, _path().points_mm, s)
    # The moves are a Fanuc program's: only the framing and the words asked for differ.
    fanuc = write_program(point_program(_path(), dataclasses.replace(s, dialect="fanuc", program_number=1234,
                                                                     work_offset="G54"), title="haas part"))
    moves = ("G0", "X", "Y", "Z")
    assert [x for x in lines if x.startswith(moves)] == [x for x in fanuc.splitlines() if x.startswith(moves)]


@pytest.mark.slow
def test_a_haas_macro_runs_in_the_simulator_at_haas_precision_as_the_fanuc_macro_does(run_cli, tmp_path):
    points = str(EXAMPLES / "paper-example-4.json")
    common = ["--scale", "20", "--tool-diameter", "4", "--stepover", "4", "--step", "2", "--safe-z", "100"]
    for d in ("haas", "fanuc"):
        status, _, err = run_cli("macro", points, *common, "--dialect", d, "-o", str(tmp_path / f"{d}.nc"))
        assert status == 0, err
    haas, fanuc = (tmp_path / "haas.nc").read_text(), (tmp_path / "fanuc.nc").read_text()
    assert haas.splitlines()[1].startswith("O01000 ") and fanuc.splitlines()[1].startswith("O1000 ")
    assert haas.splitlines()[2:] == fanuc.splitlines()[2:]
    a, b = simulate(haas, "haas"), simulate(fanuc, "fanuc")
    assert a.precision == 8 and a.dialect == "haas"
    assert a.moves == b.moves and len(a.moves) > 100


def test_the_simulator_keeps_to_the_haas_variables():
    program = "#700=1.\nG1 X#700 Y0. Z0. F100.\nM30\n"
    assert len(simulate(program, "fanuc").moves) == 1  # a Fanuc's #700 is a common variable
    with pytest.raises(lagsym.ControlAlarm, match="variable 700 is outside"):
        simulate(program, "haas")  # a Haas keeps #700-#799 for itself


@pytest.mark.slow
def test_haas_is_reachable_from_every_command(run_cli, tmp_path):
    points = str(EXAMPLES / "paper-example-4.json")
    rough = tmp_path / "rough.nc"
    status, _, err = run_cli("rough", points, "--scale", "20", "--tool-shape", "flat", "--tool-diameter", "10",
                             "--safe-z", "90", "--stock-above", "2", "--stepdown", "6", "--stepover", "8",
                             "--dialect", "haas", "--macro", "-o", str(rough))
    assert status == 0, err
    text = rough.read_text()
    assert "#800=" in text and "#927=" in text and "#928=" not in text  # the clearance tables in #800-#999
    assert len(simulate(text, "haas").moves) > 10
    job = tmp_path / "job.toml"
    job.write_text((EXAMPLES / "example-4-job.toml").read_text().replace('dialect = "linuxcnc"', 'dialect = "haas"')
                   .replace('"paper-example-4.json"', repr(points).replace("'", '"'))
                   .replace("stepover = 0.5", "stepover = 4").replace("stepover = 5", "stepover = 8"))
    status, _, err = run_cli("job", str(job), "-o", str(tmp_path / "job.nc"))
    assert status == 0, err
    assert (tmp_path / "job.nc").read_text().splitlines()[1].startswith("O01000")
    from lagsym.dnc import profile

    assert profile(control("haas").dnc_profile).line_ending == "crlf"
    status, out, _ = run_cli("send", "--help")
    assert status == 0 and "haas" in out


def test_the_docs_table_is_the_registry():
    text = (Path(__file__).parents[1] / "docs" / "controllers.md").read_text()
    rows = text.split("<!-- controls-table")[1].split("\n\n")[0].splitlines()[3:]
    seen = {}
    for row in rows:
        cells = [c.strip() for c in row.strip("|").split("|")]
        seen[cells[0].strip("`")] = cells[1:]
    assert list(seen) == list(CONTROLS)
    for name, c in CONTROLS.items():
        m = c.macro
        assert seen[name] == [str(c.max_block), str(c.axis_digits),
                              f"{c.tools or '-'} / {c.length_offsets or '-'}", c.work_offset_text,
                              f"{c.program_numbers[0]}-{c.program_numbers[1]}", m.name if m else "-",
                              str(m.default_precision) if m else "-",
                              f"`{c.dnc_profile}`" if c.dnc_profile else "-",
                              f"{c.probing.move}, {c.probing.output}" if c.probing else "-"], name

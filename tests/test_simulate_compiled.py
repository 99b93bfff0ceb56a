"""The compiled executor against the expressions' closures run block by block: the same values, to the digit.

The closures (``Expr.run``, built from the tree by
:func:`lagsym.simulate.expressions.closure`) do every operation through the
control's methods, one block after another; the executor runs Python code
generated from the same trees.  Every stored variable (its digits, exponent
and sign, ``str`` of the Decimal), every move and every alarm must agree.
"""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings, strategies as st

from lagsym.simulate import ControlAlarm, simulate
from lagsym.simulate.alarms import BlockAlarm
from lagsym.simulate.blocks import Assign, AssignNamed, IfThen, Words
from lagsym.simulate.compiler import compile_program
from lagsym.simulate.control import ControlState
from lagsym.simulate.executor import _labels, _match_loops, _run
from lagsym.simulate.reader import read_blocks
from lagsym.simulate.runaway import Runaway


def interpreted(text: str, dialect: str, precision: int):
    """Variables, moves or alarm of a straight program, each block's closures called in turn."""
    m = ControlState(dialect, precision)
    try:
        blocks = read_blocks(text, dialect)
    except ControlAlarm as e:
        return ("alarm", e.alarm, e.line)
    for b in blocks:
        try:
            if isinstance(b, IfThen):
                if b.cond(m):
                    m.set(b.then.target(m), b.then.value(m))
            elif isinstance(b, Assign):
                m.set(b.target(m), b.value(m))
            elif isinstance(b, AssignNamed):
                m.names[b.name] = m.ctx.plus(b.value(m))
            elif isinstance(b, Words):
                values = {letter: f(m) for letter, f in b.words}
                m.motion = "G1"
                m.feed = values.get("F", m.feed)  # before the move, as the control takes it
                m.move(b.line, values)
        except BlockAlarm as e:
            return ("alarm", e.alarm, b.line)
        except ArithmeticError:
            return ("alarm", "111", b.line)
    return _state(m)


def compiled(text: str, dialect: str, precision: int):
    """The same from the compiled segments."""
    m = ControlState(dialect, precision)
    try:
        blocks = _match_loops(read_blocks(text, dialect))
        table, where = compile_program(m, blocks, _labels(blocks))
        _run(table, where, blocks, m, Runaway(blocks=blocks))
    except ControlAlarm as e:
        return ("alarm", e.alarm, e.line)
    return _state(m)


def _state(m):
    moves = [(mv.line, mv.x, mv.y, mv.z, math.copysign(1, mv.x)) for mv in m.moves]
    return ({n: str(v) for n, v in m.vars.items()}, {k: str(v) for k, v in m.names.items()}, moves)


_LEAVES = ("0.", "1.", "2.5", "-3.", "0.1", "7.", "1.2345678", "123456.78", "1.23456789", "99999999.", ".00001")
_FUNCS = ("SQRT", "ABS", "FIX", "FUP", "ROUND", "SIN", "COS", "TAN", "ATAN", "ASIN", "LN", "EXP")


def _expressions(variables):
    leaf = st.sampled_from(_LEAVES) | st.sampled_from(variables)

    def extend(inner):
        binop = st.builds(lambda a, op, b: f"[{a}{op}{b}]", inner, st.sampled_from(["+", "-", "*", "/", " MOD "]),
                          inner)
        compare = st.builds(lambda a, op, b: f"[{a} {op} {b}]", inner,
                            st.sampled_from(["EQ", "NE", "LT", "LE", "GT", "GE", "AND", "OR", "XOR"]), inner)
        func = st.builds(lambda f, a: f"{f}[{a}]", st.sampled_from(_FUNCS), inner)
        atan2 = st.builds(lambda a, b: f"ATAN[{a}]/[{b}]", inner, inner)
        neg = st.builds(lambda a: f"-{a}", inner)
        return binop | compare | func | atan2 | neg

    return st.recursive(leaf, extend, max_leaves=5).filter(lambda e: e.count("[") <= 5)


_FANUC_VARS = ["#1", "#2", "#3", "#0", "#100", "#[#1]", "#[#1+99.]", "##1", "[#3*0.]"]  # the last: -0


@pytest.mark.slow
@settings(max_examples=300, deadline=None)
@given(st.lists(st.tuples(st.sampled_from(["#1", "#2", "#100", "#101", "#[#1]", "#1", "#100", "#34"]),
                          _expressions(_FANUC_VARS),
                          st.booleans(), _expressions(_FANUC_VARS)), min_size=1, max_size=6),
       st.sampled_from([8, 15]))
def test_fanuc_compiled_code_matches_the_closures(statements, precision):
    lines = ["#1=1.", "#2=[0.*-1.]", "#3=-2.5"]
    for target, value, conditional, cond in statements:
        lines.append(f"IF [{cond}] THEN {target}={value}" if conditional else f"{target}={value}")
    lines += [f"G1 X{statements[0][1]} Y#2 Z#100 F1.", "#5=[#1+#2]", "G1 X#5 Y[#2*-1.] Z#3"]
    text = "\n".join(lines) + "\n"
    assert compiled(text, "fanuc", precision) == interpreted(text, "fanuc", precision), text


@pytest.mark.slow
@settings(max_examples=150, deadline=None)
@given(st.lists(st.tuples(st.sampled_from(["#<a>", "#<b>", "#5", "#[#<a>]"]),
                          _expressions(["#<a>", "#<b>", "#<c>", "#5", "#[#5+1]"])), min_size=1, max_size=6))
def test_linuxcnc_compiled_code_matches_the_closures(statements):
    lines = ["#<a> = 2.", "#5 = [0. * -1.]"] + [f"{t} = {v}" for t, v in statements]
    lines += ["G1 X#<a> Y#5 Z[#<a> * 0.]", "#<b> = [#<a> + 1.]", "G1 X#<b> Y0 Z0"]
    text = "\n".join(lines) + "\n"
    assert compiled(text, "linuxcnc", 15) == interpreted(text, "linuxcnc", 15), text


@pytest.mark.parametrize("text, alarm, line", [
    ("#1=1.\n#2=[#1/[#1-1.]]\n", "112", 2),
    ("#1=2.\n#2=[1.+#[#1+500.]]\n#3=[#1/0.]\n", "112", 3),  # #502 is in range: only the division stops
    ("#1=2.\n#2=[1.+#[#1+300.]]\n", "115", 2),
    ("#1=1.\n#200=[#1/0.]\n", "112", 2),  # the value first, then the variable's range, as the control
    ("#1=1.\n#200=#1\n", "115", 2),
    ("#1=1.\nG1 X1.23456789 Y0. Z0.\n", "003", 2),
    ("#1=-1.\n#2=SQRT[#1]\n", "111", 2),
    ("#1=1.\nIF [#1 GT 0.] THEN #2=[1./[#1-1.]]\n", "112", 2),
])
def test_alarms_name_the_block_that_raised_them(text, alarm, line):
    with pytest.raises(ControlAlarm) as e:
        simulate(text + "M30\n", "fanuc", 8)
    assert (e.value.alarm, e.value.line) == (alarm, line)
    assert interpreted(text, "fanuc", 8) == ("alarm", alarm, line)


def test_a_negative_zero_keeps_its_sign_where_the_control_keeps_it():
    """Stored values are rounded by ``plus`` (-0 becomes 0); an axis word's value is not."""
    for text in ("#1=[0.*-1.]\nG1 X#1 Y[0.*-1.] Z0. F100.\nM30\n", "#1=-2.5\n#2=[#1*0.]\nG1 X#2 Y[#1*0.] Z0. F100.\nM30\n"):
        sim = simulate(text, "fanuc", 8)
        assert math.copysign(1, sim.moves[0].x) == 1 and math.copysign(1, sim.moves[0].y) == -1


@pytest.mark.parametrize("text", [
    "#1=1.\nIF [#1 GT 0.] THEN #100=2.\nIF [#1 LT 0.] THEN #101=3.\nG1 X#100 Y#101 Z0. F100.\n",  # only #100 is set
    "#1=1.\n#100=5.\nIF [#1 GT 0.] THEN #100=[#100+1.]\n#100=[#100*2.]\nG1 X#100 Y0. Z0. F100.\n",
    "#1=3.\n#[#1]=4.\n#2=[#3+#1]\nG1 X#2 Y#3 Z0. F100.\n",  # a computed number: no locals
])
def test_conditional_and_computed_assignments(text):
    assert compiled(text, "fanuc", 8) == interpreted(text, "fanuc", 8)
    assert compiled(text, "fanuc", 8)[0] == interpreted(text, "fanuc", 8)[0] != {}


def test_a_point_list_runs_as_one_call_with_the_modes_of_each_block():
    """Blocks of constant words: G90/G91, G0/G1, F, M30 stopping, counted block by block."""
    lines = ["G90 G0 X0. Y0. Z5.", "G1 Z0. F100."] + [f"X{k}. Y{2 * k}." for k in range(1, 250)]
    lines += ["G91 X1. Y-1.", "G0 Z10.", "M30", "G1 X99. Y99. Z99."]
    sim = simulate("\n".join(lines) + "\n", "fanuc", 8)
    assert sim.blocks == 254 and len(sim.moves) == 253  # the block after M30 never runs
    assert (sim.moves[251].x, sim.moves[251].y, sim.moves[251].z) == (250.0, 497.0, 0.0)  # G91: 249+1, 498-1
    assert sim.moves[-1].motion == "G0" and sim.moves[-1].z == 10.0 and sim.moves[-2].feed == 100.0
    assert [m.line for m in sim.moves[:3]] == [1, 2, 3]


def test_an_alarm_in_a_point_list_names_its_block():
    lines = [f"G1 X{k}. Y0. Z0. F100." for k in range(150)] + ["G2 X1. Y1."]
    with pytest.raises(ControlAlarm, match="alarm arc") as e:
        simulate("\n".join(lines) + "\n", "fanuc", 8)
    assert e.value.line == 151

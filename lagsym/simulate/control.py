"""The control's arithmetic and variables: a decimal context, variable ranges, rounding and modal state.

Every stored value and every operation's result is rounded to the chosen
number of significant digits (8 for a Fanuc 16/18-class control, 15 for
IEEE double), and every constant is rounded as it is read, as a control does.
"""

from __future__ import annotations

import math
from decimal import ROUND_CEILING, ROUND_DOWN, ROUND_FLOOR, ROUND_HALF_UP, ROUND_UP, Context, Decimal

from ..controls import Control, control
from .alarms import BlockAlarm, feed_zero
from .probing import ProbeCrash
from .result import SimMoves

__all__ = ["ControlState"]


class ControlState:
    """Variables, modal state and arithmetic of one run on a control (a :class:`~lagsym.controls.Control`).

    ``ranges`` are the variable numbers the program may use, by default the control's.
    """

    def __init__(self, dialect: str | Control, precision: int, ranges=None):
        c = control(dialect)
        if c.macro is None:
            raise ValueError(f"a {c.name} control has no macro language to simulate")
        self.dialect, self.language = c.name, c.macro
        self.precision, self.ranges = precision, c.variables if ranges is None else ranges
        self.ctx = Context(prec=precision, Emin=-99, Emax=99)
        self.vars: dict[int, Decimal] = {}
        self.constants: dict[str, Decimal] = {}
        self.names: dict[str, Decimal] = {}
        self.pos = [Decimal(0)] * 3
        self.motion = "G0"
        self.feed = Decimal(0)
        self.absolute = True
        self.moves = SimMoves()
        self.probing = c.probing
        self.target = None  # what a probing move touches (lagsym.simulate.probing), when the run has one
        self.probe_pending: float | None = None  # the probing move of the block being run
        self.probes = 0
        self.output: list[str] = []
        self.output_open = False

    def const(self, text: str) -> Decimal:
        value = self.constants.get(text)
        if value is None:
            if self.language.counts_digits:
                whole, _, frac = text.lstrip("+-").partition(".")
                digits = len(whole.lstrip("0")) + len(frac)
                if digits > self.precision:
                    raise BlockAlarm("003", f"{text} has {digits} digits, "
                                         f"more than the {self.precision} the control reads")
            value = self.constants[text] = self.ctx.create_decimal(text)
        return value

    def check(self, n: int) -> int:
        if self.probing is not None and n == self.probing.alarm_variable:
            raise BlockAlarm(str(n), f"the program raised its own alarm (#{n})")
        if not any(lo <= n <= hi for lo, hi in self.ranges):
            allowed = ", ".join(f"{lo}-{hi}" for lo, hi in self.ranges)
            raise BlockAlarm("115", f"variable {n} is outside the allowed ranges {allowed}")
        return n

    def index(self, value: Decimal) -> int:
        """A computed variable or sequence number, rounded to the nearest integer as the control does."""
        return int(value.to_integral_value(rounding=ROUND_HALF_UP))

    def get(self, n: int) -> Decimal:
        if n == 0 and self.language.vacant_zero:
            return Decimal(0)  # #0 is always vacant; vacant reads as 0 in arithmetic
        if self.probing is None or n not in self.probing.result_variables:
            self.check(n)
        return self.vars.get(n, Decimal(0))

    def set(self, n: int, value: Decimal) -> None:
        self.vars[self.check(n)] = self.ctx.plus(value)

    def named(self, name: str) -> Decimal:
        if name not in self.names:
            raise BlockAlarm("named", f"named parameter #<{name}> is used before it is set")
        return self.names[name]

    def divide(self, a: Decimal, b: Decimal) -> Decimal:
        if b == 0:
            raise BlockAlarm("112", "division by zero")
        return self.ctx.divide(a, b)

    def func(self, name: str, a: Decimal) -> Decimal:
        c = self.ctx
        if name == "SQRT":
            if a < 0:
                raise BlockAlarm("111", f"square root of {a}")
            return c.sqrt(a)
        if name == "ABS":
            return c.abs(a)
        if name == "FIX":  # Fanuc drops the fraction (toward zero); LinuxCNC rounds down
            return a.to_integral_value(rounding=ROUND_DOWN if self.language.fix_toward_zero else ROUND_FLOOR)
        if name == "FUP":  # Fanuc raises the magnitude (away from zero); LinuxCNC rounds up
            return a.to_integral_value(rounding=ROUND_UP if self.language.fix_toward_zero else ROUND_CEILING)
        if name == "ROUND":
            return a.to_integral_value(rounding=ROUND_HALF_UP)
        if name == "EXP":
            return c.exp(a)
        if name == "LN":
            if a <= 0:
                raise BlockAlarm("111", f"logarithm of {a}")
            return c.ln(a)
        x = float(a)
        try:
            value = {"SIN": lambda: math.sin(math.radians(x)), "COS": lambda: math.cos(math.radians(x)),
                     "TAN": lambda: math.tan(math.radians(x)), "ATAN": lambda: math.degrees(math.atan(x)),
                     "ASIN": lambda: math.degrees(math.asin(x)), "ACOS": lambda: math.degrees(math.acos(x))}[name]()
        except ValueError:
            raise BlockAlarm("111", f"{name} of {a}") from None
        return c.create_decimal(repr(value))

    def atan2(self, a: Decimal, b: Decimal) -> Decimal:
        return self.ctx.create_decimal(repr(math.degrees(math.atan2(float(a), float(b))) % 360.0))

    def move(self, line: int, words: dict[str, Decimal]) -> None:
        if self.probe_pending is not None:
            code, self.probe_pending = self.probe_pending, None
            self._probe(line, words, code)
            return
        for axis, letter in enumerate("XYZ"):
            if letter in words:
                v = words[letter]
                self.pos[axis] = v if self.absolute else self.ctx.add(self.pos[axis], v)
        if any(k in words for k in "XYZ"):
            if self.motion == "G1" and not self.feed > 0:
                raise feed_zero(self.feed)
            self.moves.append(line, self.motion == "G0", float(self.pos[0]), float(self.pos[1]),
                              float(self.pos[2]), float(self.feed))

    def same_state(self, other: tuple) -> bool:
        """Whether everything that decides what runs next is as in ``other`` (a :meth:`state`)."""
        return (self.pos == other[0] and self.vars == other[1] and self.names == other[2]
                and (self.motion, self.feed, self.absolute) == other[3])

    def state(self) -> tuple:
        """A copy of the variables, the position and the modes: with the block to run, all a run depends on."""
        return list(self.pos), dict(self.vars), dict(self.names), (self.motion, self.feed, self.absolute)

    # ------------------------------------------------------------------ probing and printed output

    def _probe(self, line: int, words: dict[str, Decimal], code: float) -> None:
        """A probing move (``G31``, ``G38.2``) toward the target: stop where the tip touches, note where."""
        name = f"G{code:g}"
        if self.target is None:
            raise BlockAlarm("not-run", f"{name} probes, which the simulator runs only against a given surface")
        if not any(k in words for k in "XYZ"):
            raise BlockAlarm("probe", f"{name} without an axis word")
        if self.feed <= 0:
            raise BlockAlarm("probe", f"{name} with no feed (F)")
        start = [float(p) for p in self.pos]
        end = list(self.pos)
        for axis, letter in enumerate("XYZ"):
            if letter in words:
                end[axis] = words[letter] if self.absolute else self.ctx.add(self.pos[axis], words[letter])
        try:
            touch = self.target.touch(start, [float(p) for p in end])
        except ProbeCrash as e:
            raise BlockAlarm("probe", str(e)) from None
        if touch is None:
            if self.probing.checks_contact:
                raise BlockAlarm("probe", f"{name} move finished without making contact")
            self.pos = end  # a skip move without the signal ends where it was sent
        else:
            self.pos = [self.ctx.create_decimal(repr(float(v))) for v in touch]
        for n, v in zip(self.probing.result_variables, self.pos):
            self.vars[n] = v
        if self.probing.checks_contact:
            self.vars[5070] = Decimal(int(touch is not None))  # LinuxCNC: 1 after a successful probe
        self.probes += 1
        self.moves.append(line, False, float(self.pos[0]), float(self.pos[1]), float(self.pos[2]), float(self.feed))

    def send(self, action: str, items: tuple = ()) -> None:
        """``POPEN``/``DPRNT``/``PCLOS`` or LinuxCNC's log: open the output, print one line, close it."""
        if action == "open":
            self.output_open = True
        elif action == "close":
            self.output_open = False
        elif not self.output_open:
            if self.language.name == "fanuc":
                raise BlockAlarm("dprnt", "DPRNT before POPEN: the port is not open")
            return  # LinuxCNC drops a (LOG,..) while no log file is open
        else:
            self.output.append("".join(self._printed(item) for item in items))

    def _printed(self, item) -> str:
        if item[0] == "text":
            return item[1]
        if item[0] == "param":
            return f"{float(self.get(item[1])):f}"  # LinuxCNC prints a parameter as %f
        _, n, digits, decimals = item
        v = self.get(n).quantize(Decimal(1).scaleb(-decimals), rounding=ROUND_HALF_UP)
        whole = len(str(abs(int(v))))
        if whole > digits:
            raise BlockAlarm("dprnt", f"#{n} = {v} has more than the {digits} digits before the point DPRNT prints")
        text = format(abs(v), "f")
        return ("-" if v < 0 else " ") + text  # the sign's place is a space for a positive value

"""A job file's lengths and feeds, read in the job's units unless they name their own, as millimetres.

A machinist with an inch control thinks in inches and inches a minute: in a
job with ``units = "inch"``, ``safe_z = 2`` is 2 inches and ``feed = 24`` is
24 inches a minute.  A value written as text with its unit (``"50 mm"``,
``"0.1 in"``, ``"600 mm/min"``, ``"24 in/min"``) is read in that unit in any
job.  Everything after this module reads millimetres; a converted value keeps
what the file said, so a message about it names that.
"""

from __future__ import annotations

import math
from fractions import Fraction

from ..errors import InputError
from ..machine import FEED_UNITS, LENGTH_UNITS, MM_PER, split_unit
from ..values import NotANumber, exact_number

__all__ = ["in_mm", "Given", "LENGTH_KEYS", "FEED_KEYS"]

# The keys read as lengths and as feeds, by table ("" is the top of the file).  A list is converted item by item.
LENGTH_KEYS = {"": ("safe_z", "origin"), "stock": ("top", "top_above", "margin", "block"),
               "tools": ("diameter", "corner_radius", "flute_length", "reach"),
               "operations": ("stepdown", "stepover", "step", "scallop", "tolerance", "stock_to_leave", "rest_above",
                              "max_engagement"),
               "probe": ("box", "top", "bottom", "tip_radius", "clearance", "overtravel")}
FEED_KEYS = {"": ("rapid",), "operations": ("feed", "plunge_feed"), "probe": ("feed",)}
_HUGE = 1e300  # beyond this a number is left as given, for the range check to refuse by its own figure


class Given(float):
    """A length or feed in mm that the job file gave in inches or with its unit: ``exact`` is its exact value in mm,
    and its repr is what the file said with the millimetres, as a message shows it: ``2 (50.8 mm)``."""

    def __new__(cls, exact: Fraction, text: str):
        self = super().__new__(cls, float(exact))
        self.exact, self.text = exact, text
        return self

    def __repr__(self) -> str:
        return f"{self.text} ({float(self):g} mm)"

    __str__ = __repr__


def in_mm(data: dict, source: str) -> dict:
    """``data`` (a parsed job file) with its lengths and feeds in mm; a new dict, ``data`` is left as it is.

    The keys and tables are checked afterwards: a value that is not a number is left for that check to name,
    except text, which must be a number and its unit.
    """
    if not isinstance(data, dict):
        return data
    units = data.get("units", "mm")
    factor = MM_PER.get(units, Fraction(1)) if isinstance(units, str) else Fraction(1)  # a bad units: refused later
    out = _table(data, "", "", factor, source)
    for name in ("stock", "probe"):
        if isinstance(data.get(name), dict):
            out[name] = _table(data[name], name, f"{name}.", factor, source)
    if isinstance(data.get("tools"), dict):
        out["tools"] = {k: _table(t, "tools", f"tools.{k}.", factor, source) if isinstance(t, dict) else t
                        for k, t in data["tools"].items()}
    if isinstance(data.get("operations"), list):
        out["operations"] = [_table(op, "operations", f"operations[{i}].", factor, source) if isinstance(op, dict)
                             else op for i, op in enumerate(data["operations"])]
    return out


def _table(table: dict, kind: str, where: str, factor: Fraction, source: str) -> dict:
    out = dict(table)
    for keys, units in ((LENGTH_KEYS.get(kind, ()), LENGTH_UNITS), (FEED_KEYS.get(kind, ()), FEED_UNITS)):
        for key in keys:
            if key not in out:
                continue
            value = out[key]
            if isinstance(value, list):
                out[key] = [_value(v, f"{where}{key}[{k}]", factor, units, source) for k, v in enumerate(value)]
            else:
                out[key] = _value(value, where + key, factor, units, source)
    return out


def _value(value, key: str, factor: Fraction, units: dict, source: str):
    if isinstance(value, str):
        number, named = split_unit(value, units)
        try:
            if named is None:
                raise NotANumber(value)
            exact = exact_number(number)
        except NotANumber:
            examples = "'2 in' or '50 mm'" if units is LENGTH_UNITS else "'24 in/min' or '600 mm/min'"
            raise InputError(f"{source}: {key} = {value!r} must be a number, in the job's units, or a number and "
                             f"its unit, such as {examples}") from None
        return Given(exact * named, repr(value))
    plain = isinstance(value, (int, float)) and not isinstance(value, bool)
    if factor == 1 or not plain or not math.isfinite(value) or abs(value) > _HUGE:
        return value
    return Given(Fraction(repr(value)) * factor if isinstance(value, float) else Fraction(value) * factor, repr(value))

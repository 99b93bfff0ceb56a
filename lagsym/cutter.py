"""Cutters: the one place that knows what a cutter's shape means.

A :class:`Cutter` is a frozen value: a shape name from :data:`SHAPES`, a
diameter and, for a bull nose, a corner radius.  The rest of lagsym asks the
cutter instead of comparing shape names: its radius and corner radius, which
are all drop-cutter (:mod:`lagsym.toolpath.dropcutter`) and the simulated cut
(:mod:`lagsym.verify.swept`) need, since a ball and a flat end are the two
limits of a bull nose (corner radius the radius, or 0); its profile; how a
program header names it; the cutter grown by the stock to leave; and whether
a parametric macro can drive it.

Adding a shape (a tapered ball, a chamfer) starts here: its entry in
:data:`SHAPES`, its parameters and their checks on :class:`Cutter`, its
profile in :func:`cutter_profile`.  The compiled and closed-form code takes
the radius and corner radius today, so a profile that is not a bull nose's
also needs its lowest point in drop-cutter's kernel
(:mod:`lagsym.toolpath.kernel`) and along a move (:mod:`lagsym.verify.swept`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import NamedTuple

import numpy as np

from .errors import InputError, ToolpathError
from .values import choice, finite, positive

__all__ = ["Cutter", "Tool", "Shape", "SHAPES", "TOOL_SHAPES", "cutter_profile", "corner_radius", "RAMP_DEG"]

RAMP_DEG = {True: 15.0, False: 3.0}
"""The steepest descent into material (degrees from the horizontal) a cutter is given when none is stated:
15 degrees for a centre-cutting end mill, 3 for one that does not cut at its centre (its uncut core meets a
post of material about its core's width times the slope, which a shallow ramp keeps thin)."""


class Shape(NamedTuple):
    """What a shape name means: how a program names it, and where its corner radius comes from.

    ``corner_share`` is the corner radius as a share of the cutter's radius
    (1: a ball, whose corner is its whole radius; 0: the sharp edge of a flat
    end), or None where the cutter is given a corner radius of its own.
    """

    title: str
    corner_share: float | None


SHAPES: Mapping[str, Shape] = MappingProxyType({
    "ball": Shape("BALL END", 1.0),
    "flat": Shape("FLAT END", 0.0),
    "bull": Shape("BULL NOSE", None),  # a bull-nose (corner-radius) end mill
})
"""Every cutter shape, by the name the command line and the job file use."""

TOOL_SHAPES = tuple(SHAPES)


@dataclass(frozen=True)
class Cutter:
    """A milling cutter: ``shape`` is ``"ball"``, ``"flat"`` or ``"bull"``, ``diameter_mm`` its diameter (0: a point).

    A bull-nose (``"bull"``) end mill has a flat end of diameter
    ``diameter_mm - 2 * corner_radius_mm`` rounded into its side by a torus of
    radius ``corner_radius_mm`` (more than 0, less than half the diameter).
    The ball and the flat end are its two limits (corner radius the radius, or
    0), so one profile, :meth:`profile_mm`, describes every cutter, and
    :attr:`radius_mm` and :attr:`corner_mm` are all the geometry drop-cutter
    and the simulated cut take.

    ``centre_cutting`` says whether the end cuts at its centre, and
    ``ramp_angle_deg`` (more than 0, at most 90 degrees from the horizontal)
    the steepest descent into material roughing may make with it;
    :attr:`max_ramp_deg` is that, or :data:`RAMP_DEG` where none is given.

    Examples
    --------
    >>> Cutter("bull", 10.0, corner_radius_mm=1.0).corner_mm
    1.0
    >>> Cutter("ball", 6.0).corner_mm, Cutter("flat", 6.0).corner_mm
    (3.0, 0.0)
    >>> Cutter("bull", 10.0)
    Traceback (most recent call last):
    ...
    lagsym.errors.InputError: a bull-nose cutter needs a corner radius (--corner-radius), more than 0 and less than half its diameter 10 mm
    """

    shape: str = "ball"
    diameter_mm: float = 6.0
    corner_radius_mm: float | None = None
    centre_cutting: bool = True
    ramp_angle_deg: float | None = None

    def __post_init__(self):
        kind = SHAPES[choice(self.shape, TOOL_SHAPES, "tool shape")]
        object.__setattr__(self, "diameter_mm", positive(self.diameter_mm, "tool diameter", allow_zero=True))
        if not isinstance(self.centre_cutting, bool):
            raise InputError(f"centre cutting {self.centre_cutting!r} must be true or false")
        if self.ramp_angle_deg is not None:
            a = finite(self.ramp_angle_deg, "ramp angle")
            if not 0.0 < a <= 90.0:
                raise InputError(f"ramp angle {a:g} degrees must be more than 0 and at most 90")
            if a == 90.0 and not self.centre_cutting:
                raise InputError("ramp angle 90 degrees is a plunge, which a cutter that does not cut at its "
                                 f"centre cannot make: give a shallower angle (default {RAMP_DEG[False]:g})")
            object.__setattr__(self, "ramp_angle_deg", a)
        r = self.corner_radius_mm
        if kind.corner_share is not None:
            if r is not None:
                raise InputError(f"a corner radius ({r!r} mm) is for a bull-nose cutter (tool shape bull), "
                                 f"not a {kind.title.lower()}")
            return
        half = self.diameter_mm / 2.0
        if r is None:
            raise InputError(f"a bull-nose cutter needs a corner radius (--corner-radius), more than 0 and less "
                             f"than half its diameter {self.diameter_mm:g} mm")
        r = finite(r, "corner radius")
        if not 0.0 < r < half:
            raise InputError(f"corner radius {r:g} mm must be more than 0 and less than half the tool diameter "
                             f"({half:g} mm); a corner radius of half the diameter is a ball end (tool shape ball)")
        object.__setattr__(self, "corner_radius_mm", r)

    @property
    def max_ramp_deg(self) -> float:
        """The steepest descent into material (degrees from the horizontal): the stated ramp angle, or :data:`RAMP_DEG`.

        Examples
        --------
        >>> Cutter("flat", 10.0).max_ramp_deg, Cutter("flat", 10.0, centre_cutting=False).max_ramp_deg
        (15.0, 3.0)
        >>> Cutter("flat", 10.0, ramp_angle_deg=90).max_ramp_deg
        90.0
        """
        return RAMP_DEG[self.centre_cutting] if self.ramp_angle_deg is None else float(self.ramp_angle_deg)

    @property
    def radius_mm(self) -> float:
        """Half the diameter."""
        return self.diameter_mm / 2.0

    @property
    def corner_mm(self) -> float:
        """The corner radius: the radius for a ball, 0 for a flat end."""
        share = SHAPES[self.shape].corner_share
        return float(self.corner_radius_mm) if share is None else self.radius_mm * share

    @property
    def is_ball(self) -> bool:
        """True for a ball end: its tip one radius below its centre, wherever the surface's normal points.

        Only a ball has a side step from a scallop height and a tip a macro
        can compute (one offset along the surface's normal).
        """
        return SHAPES[self.shape].corner_share == 1.0

    @property
    def curvature_per_mm(self) -> float:
        """The curvature of the lower surface at the tip: 1 / radius for a ball, 0 where the end is flat.

        Only for a cutter with a diameter.
        """
        return 1.0 / self.radius_mm if self.is_ball else 0.0

    def profile_mm(self, d2) -> np.ndarray:
        """Height of the cutter's lower surface above its tip at squared distance ``d2`` (mm²) from its axis.

        Within the radius only; the flat part is 0, the corner a quarter circle.

        Examples
        --------
        >>> Cutter("ball", 2.0).profile_mm(1.0).item(), Cutter("flat", 2.0).profile_mm(1.0).item()
        (1.0, 0.0)
        """
        return cutter_profile(d2, self.radius_mm, self.corner_mm)

    def grown_mm(self, stock_mm: float) -> tuple[float, float]:
        """Radius and corner radius (mm) of the cutter that rides ``stock_mm`` above the part wherever it touches.

        The cutter grown by the stock all round touches the part where the
        cutter touches the part grown by it: a ball or a bull nose grows in
        radius and corner radius alike.  A flat end keeps its sharp edge: it
        is lifted by the stock instead (its radius and corner stay).

        Examples
        --------
        >>> Cutter("ball", 6.0).grown_mm(0.5), Cutter("flat", 6.0).grown_mm(0.5)
        ((3.5, 3.5), (3.0, 0.0))
        """
        if SHAPES[self.shape].corner_share == 0.0:
            return self.radius_mm, 0.0
        return self.radius_mm + stock_mm, self.corner_mm + stock_mm

    @property
    def label(self) -> str:
        """How a program header names the tool: ``BALL END D6 MM``, ``BULL NOSE D10 R1 MM``."""
        kind = SHAPES[self.shape]
        corner = f" R{self.corner_mm:g}" if kind.corner_share is None else ""
        return f"{kind.title} D{self.diameter_mm:g}{corner} MM"

    @property
    def in_macro(self) -> bool:
        """True where a parametric macro can drive the cutter: a ball end, or any cutter of diameter 0.

        A ball's tip is one offset along the surface's normal, which the
        control computes; a diameter of 0 programs the surface itself.  Any
        other cutter rests on the highest point under its disc
        (:meth:`check_macro` says why it is refused).
        """
        return self.is_ball or self.diameter_mm == 0

    def check_macro(self) -> Cutter:
        """The cutter, refused if a parametric macro cannot drive it (see :attr:`in_macro`).

        A flat end of radius ``R`` rests on the highest point of the surface
        under its disc, ``max Z`` over the disc, which has no closed form; the
        height at the centre (what a zero diameter programs) lies below it
        wherever the surface slopes and the cutter would cut into the part
        (30.4 mm on paper example 1 at scale 10 with a 6 mm cutter).  A bull
        nose rests on such a point as well.

        Examples
        --------
        >>> Cutter("ball", 6.0).check_macro().in_macro
        True
        >>> Cutter("flat", 6.0).check_macro()
        Traceback (most recent call last):
        ...
        lagsym.errors.ToolpathError: a flat-end cutter (diameter 6 mm) rests on the highest point under its disc, \
which a macro cannot compute on the control: use the point-list toolpath (lagsym toolpath --tool-shape flat), \
which drops the cutter onto the exact surface, or a ball end (--tool-shape ball), or --tool-diameter 0 for the \
surface itself
        """
        if self.in_macro:
            return self
        what = SHAPES[self.shape].title.lower().replace(" ", "-")
        raise ToolpathError(
            f"a {what} cutter (diameter {self.diameter_mm:g} mm) rests on the highest point under its disc, "
            "which a macro cannot compute on the control: use the point-list toolpath "
            f"(lagsym toolpath --tool-shape {self.shape}), which drops the cutter onto the exact surface, "
            "or a ball end (--tool-shape ball), or --tool-diameter 0 for the surface itself")


Tool = Cutter
"""The name most callers know a :class:`Cutter` by."""


def corner_radius(shape: str | None, radius: float, corner: float | None = None) -> float:
    """The corner radius of a cutter of ``radius`` (any units), from its shape name or given.

    With a shape name, ``corner`` is given for a bull nose only (more than 0,
    less than ``radius``).  Without one, ``corner`` itself says the shape:
    ``radius`` (or not given) a ball, 0 a flat end, between them a bull nose.

    Examples
    --------
    >>> corner_radius("ball", 0.5), corner_radius("flat", 0.5), corner_radius(None, 0.5, 0.25)
    (0.5, 0.0, 0.25)
    """
    if shape is None:
        if corner is None:
            return radius
        c = finite(corner, "corner radius")
        if not 0.0 <= c <= radius:
            raise ToolpathError(f"corner radius {corner!r} must be 0 to the tool radius {radius:g}")
        return c
    share = SHAPES[choice(shape, TOOL_SHAPES, "tool shape")].corner_share
    if share is not None:
        if corner is not None:
            raise ToolpathError(f"a corner radius ({corner!r}) is for a bull-nose cutter, not a {shape} end")
        return radius * share
    if corner is None or not 0.0 < float(corner) < radius:
        raise ToolpathError(f"a bull-nose cutter of radius {radius:g} needs a corner radius more than 0 and less "
                            f"than {radius:g}, not {corner!r}")
    return float(corner)


def cutter_profile(d2, radius: float, corner: float) -> np.ndarray:
    """Height above the tip of a cutter of ``radius`` with a ``corner`` radius, at squared distance ``d2``.

    ``corner`` is ``radius`` for a ball and 0 for a flat end; any units, the
    same for all three.  ``d2`` beyond the radius is treated as on the rim.
    """
    d2 = np.asarray(d2, dtype=float)
    if corner <= 0.0:
        return np.zeros(d2.shape)
    flat = radius - corner
    if flat <= 0.0:
        return radius - np.sqrt(np.maximum(radius * radius - d2, 0.0))
    out = np.maximum(np.sqrt(np.maximum(d2, 0.0)) - flat, 0.0)
    return corner - np.sqrt(np.maximum(corner * corner - out * out, 0.0))

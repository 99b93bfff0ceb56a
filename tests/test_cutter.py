"""The cutter value: its shapes' profiles, what it tells the planner and the macros, its checks, immutability.

The profiles are checked against the cutter's geometry written here apart
from :func:`lagsym.cutter.cutter_profile`: a point of a ball's lower surface
lies on its sphere, a bull nose's on its flat or on the circle its corner
sweeps, a flat end's on its end face.
"""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import numpy as np
import pytest

import lagsym
from lagsym import machine
from lagsym.cutter import SHAPES, TOOL_SHAPES, Cutter, Tool, corner_radius, cutter_profile
from lagsym.errors import InputError, ToolpathError

CUTTERS = [Cutter("ball", 6.0), Cutter("flat", 6.0), Cutter("bull", 10.0, 1.0), Cutter("bull", 8.0, 3.5),
           Cutter("ball", 0.0), Cutter("flat", 0.0)]


def _distances(cutter, n=401):
    return np.linspace(0.0, cutter.radius_mm, n)


def test_a_ball_profile_lies_on_its_sphere():
    for d_mm in (6.0, 1.0, 25.4):
        c, d = Cutter("ball", d_mm), _distances(Cutter("ball", d_mm))
        r, p = c.radius_mm, c.profile_mm(d * d)
        # The centre is one radius above the tip: every point of the lower half is a radius from it.
        assert np.allclose(d**2 + (r - p) ** 2, r * r, rtol=0, atol=1e-12 * r * r)
        assert np.all((p >= 0) & (p <= r)) and np.all(np.diff(p) >= 0)


def test_a_flat_end_is_flat_to_its_rim():
    c = Cutter("flat", 6.0)
    assert np.all(c.profile_mm(_distances(c) ** 2) == 0.0)


@pytest.mark.parametrize("diameter, corner", [(10.0, 1.0), (8.0, 3.5), (6.0, 0.25)])
def test_a_bull_nose_profile_is_its_flat_then_its_corner_circle(diameter, corner):
    c = Cutter("bull", diameter, corner)
    d = _distances(c)
    p = c.profile_mm(d * d)
    flat = diameter / 2 - corner
    on_flat = d <= flat
    assert np.all(p[on_flat] == 0.0)
    # Beyond the flat, the corner: a circle of the corner radius centred one corner radius up, at the flat's edge.
    e = d[~on_flat] - flat
    assert np.allclose(e**2 + (corner - p[~on_flat]) ** 2, corner**2, rtol=0, atol=1e-12 * corner**2)
    assert np.all(p <= corner) and abs(p[-1] - corner) < 1e-12  # reaches the side at the rim


def test_the_ball_and_the_flat_end_are_the_limits_of_a_bull_nose():
    d2 = _distances(Cutter("ball", 6.0)) ** 2
    near_ball = Cutter("bull", 6.0, 3.0 * (1 - 1e-12)).profile_mm(d2)
    near_flat = Cutter("bull", 6.0, 1e-12).profile_mm(d2)
    assert np.max(np.abs(near_ball - Cutter("ball", 6.0).profile_mm(d2))) < 1e-5
    assert np.max(np.abs(near_flat - Cutter("flat", 6.0).profile_mm(d2))) < 1e-5


@pytest.mark.parametrize("cutter", CUTTERS, ids=lambda c: c.label)
def test_profile_is_the_generic_profile_of_radius_and_corner(cutter):
    d2 = _distances(cutter) ** 2
    assert np.array_equal(cutter.profile_mm(d2), cutter_profile(d2, cutter.radius_mm, cutter.corner_mm))


def test_corner_radius_of_each_shape():
    assert Cutter("ball", 6.0).corner_mm == 3.0
    assert Cutter("flat", 6.0).corner_mm == 0.0
    assert Cutter("bull", 10.0, 1.5).corner_mm == 1.5
    # Drop-cutter's reading of shape names in surface units gives the same.
    assert corner_radius("ball", 0.15) == 0.15 and corner_radius("flat", 0.15) == 0.0
    assert corner_radius("bull", 0.15, 0.05) == 0.05 and corner_radius(None, 0.15, 0.05) == 0.05
    assert corner_radius(None, 0.15) == 0.15


def test_labels_name_shape_and_size():
    assert [c.label for c in CUTTERS[:3]] == ["BALL END D6 MM", "FLAT END D6 MM", "BULL NOSE D10 R1 MM"]


def test_grown_by_the_stock():
    assert Cutter("ball", 6.0).grown_mm(0.5) == (3.5, 3.5)
    assert Cutter("bull", 10.0, 1.0).grown_mm(0.5) == (5.5, 1.5)
    assert Cutter("flat", 6.0).grown_mm(0.5) == (3.0, 0.0)  # lifted instead
    for c in CUTTERS:
        assert c.grown_mm(0.0) == (c.radius_mm, c.corner_mm)


def test_only_a_ball_has_a_curvature_at_its_tip():
    assert Cutter("ball", 4.0).curvature_per_mm == 0.5
    assert Cutter("flat", 4.0).curvature_per_mm == 0.0 and Cutter("bull", 4.0, 1.0).curvature_per_mm == 0.0


def test_a_macro_drives_a_ball_or_a_point_and_refuses_the_rest():
    assert [c.in_macro for c in CUTTERS] == [True, False, False, False, True, True]
    assert [c.is_ball for c in CUTTERS] == [True, False, False, False, True, False]
    for c in CUTTERS:
        if c.in_macro:
            assert c.check_macro() is c
    with pytest.raises(ToolpathError) as e:
        Cutter("flat", 6.0).check_macro()
    assert str(e.value) == (
        "a flat-end cutter (diameter 6 mm) rests on the highest point under its disc, which a macro cannot compute "
        "on the control: use the point-list toolpath (lagsym toolpath --tool-shape flat), which drops the cutter "
        "onto the exact surface, or a ball end (--tool-shape ball), or --tool-diameter 0 for the surface itself")
    with pytest.raises(ToolpathError, match=r"^a bull-nose cutter \(diameter 10 mm\).*--tool-shape bull\)"):
        Cutter("bull", 10.0, 1.0).check_macro()


def test_a_cutter_is_immutable_and_a_value():
    c = Cutter("bull", 10.0, 1.0)
    for name, value in (("shape", "ball"), ("diameter_mm", 1.0), ("corner_radius_mm", 2.0)):
        with pytest.raises(dataclasses.FrozenInstanceError):
            setattr(c, name, value)
    assert (c.shape, c.diameter_mm, c.corner_radius_mm) == ("bull", 10.0, 1.0)
    assert c == Cutter("bull", 10, 1) and hash(c) == hash(Cutter("bull", 10, 1)) and c != Cutter("bull", 10.0, 2.0)
    bigger = dataclasses.replace(c, diameter_mm=12.0)  # a new value, checked as any other
    assert bigger.label == "BULL NOSE D12 R1 MM" and c.diameter_mm == 10.0
    with pytest.raises(InputError, match="not a ball end"):
        dataclasses.replace(c, shape="ball")
    with pytest.raises(TypeError):
        SHAPES["cone"] = SHAPES["ball"]  # the table of shapes is read-only too
    with pytest.raises(AttributeError):
        SHAPES["ball"].corner_share = 0.5


@pytest.mark.parametrize("args, named", [
    (("cone", 6.0), "'cone'"),
    (("ball", -1.0), "-1"),
    (("ball", float("nan")), "nan"),
    (("flat", "six"), "'six'"),
    (("flat", 6.0, 1.25), "1.25"),
    (("bull", 10.0, 7.5), "7.5"),
    (("bull", 10.0, -0.5), "-0.5"),
    (("bull", 10.0, float("inf")), "inf"),
    (("bull", 12.5), "12.5"),
])
def test_bad_values_give_one_line_naming_the_value(args, named):
    with pytest.raises(InputError) as e:
        Cutter(*args)
    text = str(e.value)
    assert "\n" not in text and named in text, text


def test_a_bad_shape_names_the_valid_ones():
    with pytest.raises(InputError, match=r"^tool shape 'cone' is not one of ball, flat, bull$"):
        Cutter("cone")


@pytest.mark.parametrize("args, named", [
    (("bull", 0.3, 0.3), "0.3"),
    (("flat", 0.3, 0.1), "0.1"),
    ((None, 0.3, 0.45), "0.45"),
    ((None, 0.3, -0.1), "-0.1"),
])
def test_drop_cutter_shapes_in_surface_units_are_checked_too(args, named):
    with pytest.raises(ToolpathError) as e:
        corner_radius(*args)
    assert "\n" not in str(e.value) and named in str(e.value)


def test_the_names_callers_know_stay():
    assert Tool is Cutter and machine.Tool is Cutter and machine.Cutter is Cutter
    assert machine.TOOL_SHAPES == TOOL_SHAPES == ("ball", "flat", "bull") == tuple(SHAPES)
    assert machine.cutter_profile is cutter_profile
    assert Tool() == Cutter("ball", 6.0)


# A shape name compared or looked up outside the cutter: ``tool.shape == "ball"``, ``"bull" != shape``,
# ``shape in ("flat", "bull")``, ``{"ball": radius, ...}.get(shape)``.
_NAME = r"""["'](?:ball|flat|bull)["']"""
_COMPARED = re.compile(rf"(?:==|!=)\s*{_NAME}|{_NAME}\s*(?:==|!=)|\bin\s*[(\[{{]\s*{_NAME}|{{\s*{_NAME}\s*:")


def test_no_module_but_the_cutter_compares_shape_names():
    root = Path(lagsym.__file__).parent
    found = [f"{p.relative_to(root)}:{i}: {line.strip()}"
             for p in sorted(root.rglob("*.py")) if p.name != "cutter.py"
             for i, line in enumerate(p.read_text().splitlines(), 1) if _COMPARED.search(line)]
    assert not found, "\n".join(found)

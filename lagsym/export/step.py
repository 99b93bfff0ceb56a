"""STEP (ISO 10303-21, AP214) files of an exact patch: a face, or a solid down to a base plane.

The patch is a ``B_SPLINE_SURFACE_WITH_KNOTS`` bounded by its four boundary
curves (``B_SPLINE_CURVE_WITH_KNOTS``, the edge rows of the control net: a
boundary of a polynomial patch is a polynomial curve of the same degree).
Alone it is one ``ADVANCED_FACE`` in a ``SHELL_BASED_SURFACE_MODEL``; with a
base it is the top of a ``MANIFOLD_SOLID_BREP``: four planar sides, each
bounded by a boundary curve, two vertical lines and a line in the base, and
the planar base.  Every face is oriented with its normal outwards.

The file is written as text here rather than through a CAD kernel: the
format is plain, the kernel would be a large binary dependency for a small
writer, and the tests read every file back with OpenCascade, an independent
reader, which checks the writer better than writing and reading with the
same library would.
"""

from __future__ import annotations

import time
from fractions import Fraction
from typing import IO

from ..cad.patch import BSplinePatch
from ..cad.solid import check_base
from .cadtext import check_units, multiplicities, real

__all__ = ["write_step"]

SCHEMA = "AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }"


class _Data:
    """The DATA section: numbered instances, each added once."""

    def __init__(self):
        self.lines: list[str] = []

    def add(self, text: str) -> str:
        self.lines.append(f"#{len(self.lines) + 1}={text};")
        return f"#{len(self.lines)}"

    def point(self, p) -> str:
        return self.add(f"CARTESIAN_POINT('',({','.join(real(c) for c in p)}))")

    def direction(self, d) -> str:
        return self.add(f"DIRECTION('',({','.join(real(c) for c in d)}))")


def _refs(items) -> str:
    return "(" + ",".join(items) + ")"


def _units(data: _Data, units: str) -> str:
    """The representation context: lengths in ``units``, angles in radians, uncertainty 1e-7 mm."""
    mm = data.add("( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.) )")
    length = mm
    if units == "inch":
        exponents = data.add("DIMENSIONAL_EXPONENTS(1.,0.,0.,0.,0.,0.,0.)")
        measure = data.add(f"LENGTH_MEASURE_WITH_UNIT(LENGTH_MEASURE(25.4),{mm})")
        length = data.add(f"( CONVERSION_BASED_UNIT('INCH',{measure}) LENGTH_UNIT() NAMED_UNIT({exponents}) )")
    angle = data.add("( NAMED_UNIT(*) PLANE_ANGLE_UNIT() SI_UNIT($,.RADIAN.) )")
    solid = data.add("( NAMED_UNIT(*) SI_UNIT($,.STERADIAN.) SOLID_ANGLE_UNIT() )")
    accuracy = "1.E-07" if units == "mm" else "4.E-09"
    uncertainty = data.add(f"UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE({accuracy}),{length},"
                           f"'distance_accuracy_value','confusion accuracy')")
    return data.add(f"( GEOMETRIC_REPRESENTATION_CONTEXT(3) GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT(({uncertainty})) "
                    f"GLOBAL_UNIT_ASSIGNED_CONTEXT(({length},{angle},{solid})) REPRESENTATION_CONTEXT('','') )")


def _product(data: _Data, name: str) -> str:
    """The product structure a CAD system opens as a part; returns the product definition shape."""
    app = data.add("APPLICATION_CONTEXT('automotive design')")
    data.add(f"APPLICATION_PROTOCOL_DEFINITION('international standard','automotive_design',2000,{app})")
    pc = data.add(f"PRODUCT_CONTEXT('',{app},'mechanical')")
    product = data.add(f"PRODUCT('{name}','{name}','',({pc}))")
    data.add(f"PRODUCT_RELATED_PRODUCT_CATEGORY('part',$,({product}))")
    formation = data.add(f"PRODUCT_DEFINITION_FORMATION('','',{product})")
    pdc = data.add(f"PRODUCT_DEFINITION_CONTEXT('part definition',{app},'design')")
    definition = data.add(f"PRODUCT_DEFINITION('design','',{formation},{pdc})")
    return data.add(f"PRODUCT_DEFINITION_SHAPE('','',{definition})")


def _knots(knots) -> tuple[str, str]:
    values, counts = multiplicities(knots)
    return "(" + ",".join(str(c) for c in counts) + ")", "(" + ",".join(real(v) for v in values) + ")"


def _curve(data: _Data, degree: int, knots, points: list[str]) -> str:
    mults, values = _knots(knots)
    return data.add(f"B_SPLINE_CURVE_WITH_KNOTS('',{degree},{_refs(points)},.UNSPECIFIED.,.F.,.F.,"
                    f"{mults},{values},.UNSPECIFIED.)")


def _line(data: _Data, start: str, direction) -> str:
    vector = data.add(f"VECTOR('',{data.direction(direction)},1.)")
    return data.add(f"LINE('',{start},{vector})")


def _face(data: _Data, surface: str, edges: list[tuple[str, bool]]) -> str:
    oriented = [data.add(f"ORIENTED_EDGE('',*,*,{e},{'.T.' if forward else '.F.'})") for e, forward in edges]
    loop = data.add(f"EDGE_LOOP('',{_refs(oriented)})")
    bound = data.add(f"FACE_OUTER_BOUND('',{loop},.T.)")
    return data.add(f"ADVANCED_FACE('',({bound}),{surface},.T.)")


def _plane(data: _Data, origin, normal, ref) -> str:
    place = data.add(f"AXIS2_PLACEMENT_3D('',{data.point(origin)},{data.direction(normal)},{data.direction(ref)})")
    return data.add(f"PLANE('',{place})")


def _top(data: _Data, patch: BSplinePatch):
    """The patch, its corner vertices and its boundary edges (``"v0"`` etc. as in :meth:`BSplinePatch.boundary`)."""
    net = [[data.point(p) for p in row] for row in patch.control_points]
    mu, ku = _knots(patch.knots_u)
    mv, kv = _knots(patch.knots_v)
    rows = ",".join(_refs(r) for r in net)
    surface = data.add(f"B_SPLINE_SURFACE_WITH_KNOTS('',{patch.degree_u},{patch.degree_v},({rows}),"
                       f".UNSPECIFIED.,.F.,.F.,.F.,{mu},{mv},{ku},{kv},.UNSPECIFIED.)")
    corner = {(a, b): data.add(f"VERTEX_POINT('',{net[-1 if a else 0][-1 if b else 0]})") for a in (0, 1) for b in (0, 1)}
    ends = {"v0": ((0, 0), (1, 0)), "u1": ((1, 0), (1, 1)), "v1": ((0, 1), (1, 1)), "u0": ((0, 0), (0, 1))}
    points = {"v0": [r[0] for r in net], "v1": [r[-1] for r in net], "u0": net[0], "u1": net[-1]}
    edges = {}
    for side, (start, end) in ends.items():
        degree = patch.degree_u if side[0] == "v" else patch.degree_v
        knots = patch.knots_u if side[0] == "v" else patch.knots_v
        curve = _curve(data, degree, knots, points[side])
        edges[side] = data.add(f"EDGE_CURVE('',{corner[start]},{corner[end]},{curve},.T.)")
    return surface, corner, edges


def _solid_faces(data: _Data, patch: BSplinePatch, corner, top_edges, base_z: Fraction) -> list[str]:
    """The four sides and the base: faces of planes, normals outwards."""
    x0, x1, y0, y1 = patch.xy_box
    xy = {(0, 0): (x0, y0), (1, 0): (x1, y0), (0, 1): (x0, y1), (1, 1): (x1, y1)}
    base_pt = {k: data.point((*v, base_z)) for k, v in xy.items()}
    low = {k: data.add(f"VERTEX_POINT('',{p})") for k, p in base_pt.items()}
    up = {k: data.add(f"EDGE_CURVE('',{low[k]},{corner[k]},{_line(data, base_pt[k], (0, 0, 1))},.T.)") for k in xy}
    base = {}
    for side, start, end, direction in (("v0", (0, 0), (1, 0), (1, 0, 0)), ("u1", (1, 0), (1, 1), (0, 1, 0)),
                                        ("v1", (0, 1), (1, 1), (1, 0, 0)), ("u0", (0, 0), (0, 1), (0, 1, 0))):
        base[side] = data.add(f"EDGE_CURVE('',{low[start]},{low[end]},{_line(data, base_pt[start], direction)},.T.)")
    T, F = True, False
    faces = [
        _face(data, _plane(data, (x0, y0, base_z), (0, -1, 0), (1, 0, 0)),  # front, y = y0
              [(base["v0"], T), (up[(1, 0)], T), (top_edges["v0"], F), (up[(0, 0)], F)]),
        _face(data, _plane(data, (x1, y0, base_z), (1, 0, 0), (0, 1, 0)),  # right, x = x1
              [(base["u1"], T), (up[(1, 1)], T), (top_edges["u1"], F), (up[(1, 0)], F)]),
        _face(data, _plane(data, (x1, y1, base_z), (0, 1, 0), (-1, 0, 0)),  # back, y = y1
              [(base["v1"], F), (up[(0, 1)], T), (top_edges["v1"], T), (up[(1, 1)], F)]),
        _face(data, _plane(data, (x0, y1, base_z), (-1, 0, 0), (0, -1, 0)),  # left, x = x0
              [(base["u0"], F), (up[(0, 0)], T), (top_edges["u0"], T), (up[(0, 1)], F)]),
        _face(data, _plane(data, (x0, y0, base_z), (0, 0, -1), (1, 0, 0)),  # base, seen from below
              [(base["u0"], T), (base["v1"], T), (base["u1"], F), (base["v0"], F)]),
    ]
    return faces


def write_step(stream: IO[str], patch: BSplinePatch, *, base_z: Fraction | None = None, units: str = "mm",
               name: str = "surface", timestamp: str | None = None, source: str = "<surface>") -> None:
    """Write ``patch`` to ``stream`` as a STEP AP214 file: a face, or a solid down to ``base_z``.

    Parameters
    ----------
    stream : text stream
    patch : BSplinePatch
        The exact patch (:func:`lagsym.cad.cad_patch`); its coordinates are lengths in ``units``.
    base_z : Fraction, optional
        The height of the base plane for a solid; it must lie below the whole
        surface (:func:`lagsym.cad.check_base`), else an InputError naming ``source``.
    units : {"mm", "inch"}
        The length unit the file declares.
    name : str
        The product's name in the file.
    timestamp : str, optional
        ISO 8601 time for the header (default: now, UTC).
    source : str
        The points file, for messages.
    """
    from .. import __version__

    check_units(units)
    if base_z is not None:
        base_z = check_base(patch, base_z, source)
    name = "".join(c for c in name if c.isprintable() and c not in "'\\") or "surface"
    data = _Data()
    context = _units(data, units)
    shape = _product(data, name)
    surface, corner, edges = _top(data, patch)
    top = _face(data, surface, [(edges["v0"], True), (edges["u1"], True), (edges["v1"], False), (edges["u0"], False)])
    axes = data.add(f"AXIS2_PLACEMENT_3D('',{data.point((0, 0, 0))},{data.direction((0, 0, 1))},"
                    f"{data.direction((1, 0, 0))})")
    if base_z is None:
        shell = data.add(f"OPEN_SHELL('',({top}))")
        model = data.add(f"SHELL_BASED_SURFACE_MODEL('',({shell}))")
        rep = data.add(f"MANIFOLD_SURFACE_SHAPE_REPRESENTATION('{name}',({model},{axes}),{context})")
    else:
        faces = [top, *_solid_faces(data, patch, corner, edges, Fraction(base_z))]
        shell = data.add(f"CLOSED_SHELL('',{_refs(faces)})")
        brep = data.add(f"MANIFOLD_SOLID_BREP('{name}',{shell})")
        rep = data.add(f"ADVANCED_BREP_SHAPE_REPRESENTATION('{name}',({brep},{axes}),{context})")
    data.add(f"SHAPE_DEFINITION_REPRESENTATION({shape},{rep})")
    stamp = timestamp or time.strftime("%Y-%m-%dT%H:%M:%S", time.gmtime())
    kind = "solid" if base_z is not None else "surface"
    stream.write("ISO-10303-21;\nHEADER;\n"
                 f"FILE_DESCRIPTION(('{patch.name} {kind}, exact control points rounded once to doubles'),'2;1');\n"
                 f"FILE_NAME('{name}','{stamp}',(''),(''),'lagsym {__version__}','lagsym {__version__}','');\n"
                 f"FILE_SCHEMA(('{SCHEMA}'));\nENDSEC;\nDATA;\n")
    stream.write("\n".join(data.lines))
    stream.write("\nENDSEC;\nEND-ISO-10303-21;\n")

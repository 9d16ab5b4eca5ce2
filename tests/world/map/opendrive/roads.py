"""Small OpenDRIVE files written for tests: one road of given planView records and lanes."""

from __future__ import annotations

from pathlib import Path

from world.map.opendrive.geometry import PlanView
from world.map.opendrive.model import Arc, Geometry, Line, Shape, Spiral

ONE_LANE = ('<laneSection s="0"><center><lane id="0" type="none"/></center><right>'
            '<lane id="-1" type="driving"><width sOffset="0" a="3.5" b="0" c="0" d="0"/>'
            '</lane></right></laneSection>')


def shape_xml(shape: Shape) -> str:
    """The shape element of a line, arc or spiral record."""
    if isinstance(shape, Arc):
        return f'<arc curvature="{shape.curvature!r}"/>'
    if isinstance(shape, Spiral):
        return f'<spiral curvStart="{shape.curv_start!r}" curvEnd="{shape.curv_end!r}"/>'
    return "<line/>"


def geometry_xml(g: Geometry, shape: str | None = None) -> str:
    """One <geometry> (its shape element `shape`, else the record's own)."""
    return (f'<geometry s="{g.s!r}" x="{g.x!r}" y="{g.y!r}" hdg="{g.hdg!r}" '
            f'length="{g.length!r}">{shape or shape_xml(g.shape)}</geometry>')


def road_xml(geometries: str, length: float | str, lanes: str = ONE_LANE,
             road_id: str = "1") -> str:
    """A file of one road."""
    return (f'<OpenDRIVE><header revMajor="1" revMinor="6"/><road id="{road_id}" '
            f'length="{length}" junction="-1"><planView>{geometries}</planView>'
            f'<lanes>{lanes}</lanes></road></OpenDRIVE>')


def chained(shapes: list[Shape], length: float) -> list[Geometry]:
    """Records of `shapes`, each `length` [m] long, each starting exactly where the one
    before ends (its end evaluated on itself)."""
    out: list[Geometry] = []
    x = y = h = 0.0
    for k, shape in enumerate(shapes):
        g = Geometry(k * length, x, y, h, length, shape)
        out.append(g)
        ex, ey, eh = PlanView((g,)).record_ends()
        x, y, h = float(ex[0]), float(ey[0]), float(eh[0])
    return out


def winding(records: int, length: float, curvature: float) -> list[Geometry]:
    """`records` spirals of `length` [m] swinging between +-`curvature` [1/m] (the worst
    kind of record for the arc spline: its curvature changes everywhere)."""
    shapes: list[Shape] = [Spiral(curvature * (-1) ** k, curvature * (-1) ** (k + 1))
                           for k in range(records)]
    return chained(shapes, length)


def write(path: Path, text: str) -> Path:
    """`text` written to `path`."""
    path.write_text(text, encoding="utf-8")
    return path


def straight(length: float = 100.0) -> str:
    """One line record of `length` [m]."""
    return geometry_xml(Geometry(0.0, 0.0, 0.0, 0.0, length, Line()))


"""Reading a Trajectory element (or its CatalogReference) and its Shape: Polyline,
Clothoid, ClothoidSpline (1.3), Nurbs. Counts and lengths are bounded
(`limits.MAX_TRAJECTORY_POINTS`, `MAX_TRAJECTORY_LENGTH`, ...)."""

from __future__ import annotations

from collections.abc import Callable
from itertools import pairwise

from avsim.scenario.openscenario.attributes import unsupported
from avsim.scenario.openscenario.context import Context
from avsim.scenario.openscenario.limits import (
    MAX_CURVATURE,
    MAX_CURVATURE_RATE,
    MAX_NURBS_ORDER,
    MAX_TIME,
    MAX_TRAJECTORY_LENGTH,
    MAX_TRAJECTORY_POINTS,
)
from avsim.scenario.openscenario.parse_positions import parse_position
from avsim.scenario.openscenario.trajectories import (
    Clothoid,
    ClothoidSpline,
    ClothoidSplineSegment,
    ControlPoint,
    Nurbs,
    Polyline,
    Trajectory,
    TrajectoryShape,
    Vertex,
)
from avsim.scenario.openscenario.xmlread import Node


def _counted(node: Node, tag: str, least: int) -> list[Node]:
    items = node.all(tag)
    if len(items) < least:
        raise node.error(f"a {node.tag} needs at least {least} {tag} elements")
    if len(items) > MAX_TRAJECTORY_POINTS:
        raise node.error(f"must have <= {MAX_TRAJECTORY_POINTS} {tag} elements, "
                         f"got {len(items)}")
    return items


def _time(node: Node, ctx: Context, name: str) -> float | None:
    return ctx.attrs.opt_bounded(node, name, -MAX_TIME, MAX_TIME, "s")


def _polyline(node: Node, ctx: Context) -> TrajectoryShape:
    return Polyline(tuple(
        Vertex(_time(v, ctx, "time"), parse_position(v.need("Position"), ctx))
        for v in _counted(node, "Vertex", 2)))


def _length(node: Node, ctx: Context) -> float:
    length = ctx.attrs.bounded(node, "length", 0.0, MAX_TRAJECTORY_LENGTH, "m")
    if length <= 0.0:
        raise node.error(f"length: must be > 0, got {length:g}")
    return length


def _curvature(node: Node, ctx: Context, name: str) -> float:
    return ctx.attrs.bounded(node, name, -MAX_CURVATURE, MAX_CURVATURE, "1/m")


def _clothoid(node: Node, ctx: Context) -> TrajectoryShape:
    a = ctx.attrs
    rate_name = "curvaturePrime" if "curvaturePrime" in node.attrs else "curvatureDot"
    rate = a.opt_bounded(node, rate_name, -MAX_CURVATURE_RATE, MAX_CURVATURE_RATE, "1/m^2")
    position = node.child("Position")
    return Clothoid(
        curvature=_curvature(node, ctx, "curvature"),
        curvature_rate=rate or 0.0,
        length=_length(node, ctx),
        start_time=_time(node, ctx, "startTime"),
        stop_time=_time(node, ctx, "stopTime"),
        position=None if position is None else parse_position(position, ctx),
    )


def _spline_segment(node: Node, ctx: Context) -> ClothoidSplineSegment:
    a = ctx.attrs
    start = node.child("PositionStart")
    return ClothoidSplineSegment(
        curvature_start=_curvature(node, ctx, "curvatureStart"),
        curvature_end=_curvature(node, ctx, "curvatureEnd"),
        length=_length(node, ctx),
        h_offset=a.number_or(node, "hOffset", 0.0),
        time_start=_time(node, ctx, "timeStart"),
        position_start=None if start is None else parse_position(start, ctx),
    )


def _clothoid_spline(node: Node, ctx: Context) -> TrajectoryShape:
    segments = tuple(_spline_segment(s, ctx) for s in _counted(node, "ClothoidSplineSegment", 1))
    total = sum(s.length for s in segments)
    if total > MAX_TRAJECTORY_LENGTH:
        raise node.error(f"its segments' length must be <= {MAX_TRAJECTORY_LENGTH:g} m, "
                         f"got {total:g}")
    return ClothoidSpline(segments, _time(node, ctx, "timeEnd"))


def _nurbs(node: Node, ctx: Context) -> TrajectoryShape:
    a = ctx.attrs
    order = a.integer(node, "order")
    if not 2 <= order <= MAX_NURBS_ORDER:
        raise node.error(f"order: must be 2 to {MAX_NURBS_ORDER}, got {order}")
    points = []
    for p in _counted(node, "ControlPoint", order):
        weight = a.number_or(p, "weight", 1.0)
        if weight <= 0.0:
            raise p.error(f"weight: must be > 0, got {weight:g}")
        points.append(ControlPoint(_time(p, ctx, "time"), weight,
                                   parse_position(p.need("Position"), ctx)))
    knots = tuple(a.number(k, "value") for k in node.all("Knot"))
    if len(knots) != len(points) + order:
        raise node.error(f"needs {len(points) + order} Knot elements (control points + "
                         f"order), got {len(knots)}")
    if any(b < k for k, b in pairwise(knots)):
        raise node.error("its knot values must not decrease")
    if knots[order - 1] >= knots[len(points)]:
        raise node.error("its knot values span no curve (all equal where it is defined)")
    return Nurbs(order, tuple(points), knots)


_SHAPES: dict[str, Callable[[Node, Context], TrajectoryShape]] = {
    "Polyline": _polyline,
    "Clothoid": _clothoid,
    "ClothoidSpline": _clothoid_spline,
    "Nurbs": _nurbs,
}


def parse_trajectory(node: Node, ctx: Context) -> Trajectory:
    """A Trajectory element, or a CatalogReference to one."""
    if node.tag == "CatalogReference":
        entry = ctx.catalogs.resolve(node, ctx.attrs, ("Trajectory",))
        return parse_trajectory(entry.node, ctx.in_scope(entry.scope, entry.node))
    if node.tag != "Trajectory":
        raise unsupported(node)
    ctx = ctx.with_declarations(node)
    a = ctx.attrs
    shape = node.need("Shape").only_child()
    reader = _SHAPES.get(shape.tag)
    if reader is None:
        raise unsupported(shape)
    params = ctx.attrs.scope.values if node.child("ParameterDeclarations") is not None else {}
    return Trajectory(
        name=a.text(node, "name"),
        closed=a.boolean(node, "closed"),
        shape=reader(shape, ctx),
        parameters=dict(params),
    )


def parse_trajectory_ref(node: Node, ctx: Context) -> Trajectory:
    """The trajectory a TrajectoryRef holds (or, 1.0, the Trajectory / CatalogReference
    directly under `node`)."""
    holder = node.child("TrajectoryRef")
    if holder is not None:
        return parse_trajectory(holder.only_child(), ctx)
    found = node.child("Trajectory") or node.child("CatalogReference")
    if found is None:
        raise node.error("missing element TrajectoryRef")
    return parse_trajectory(found, ctx)


SHAPE_READERS = _SHAPES  # the trajectory Shape elements read (`coverage`)

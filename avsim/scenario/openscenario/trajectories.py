"""Trajectories (OpenSCENARIO's Trajectory and its Shape choice): a Polyline of vertices,
a Clothoid, a ClothoidSpline (1.3) of segments, a Nurbs of weighted control points.
Lengths in metres, curvatures in 1/m, curvature rates in 1/m², angles in radians, times in
seconds. `sampling` turns each into a dense timed polyline."""

from __future__ import annotations

from dataclasses import dataclass

from avsim.scenario.openscenario.positions import Position


@dataclass(frozen=True, slots=True)
class Vertex:
    time: float | None  # [s] when the vertex is reached, None when not timed
    position: Position


@dataclass(frozen=True, slots=True)
class Polyline:
    vertices: tuple[Vertex, ...]


@dataclass(frozen=True, slots=True)
class Clothoid:
    """A curve whose curvature changes linearly with arc length: k(l) = curvature +
    curvature_rate l, from `position` (None: the actor's pose when the action starts)."""

    curvature: float  # [1/m] at the start
    curvature_rate: float  # [1/m²] curvatureDot (1.0) / curvaturePrime (1.1+)
    length: float  # [m]
    start_time: float | None  # [s] at the start, None when not timed
    stop_time: float | None  # [s] at the end
    position: Position | None


@dataclass(frozen=True, slots=True)
class ClothoidSplineSegment:
    """One clothoid of a spline: its curvature moves linearly from start to end over its
    length; it starts where the previous one ends (or at `position_start`), turned by
    `h_offset`."""

    curvature_start: float  # [1/m]
    curvature_end: float  # [1/m]
    length: float  # [m]
    h_offset: float  # [rad] added to the heading at its start
    time_start: float | None  # [s]
    position_start: Position | None


@dataclass(frozen=True, slots=True)
class ClothoidSpline:
    segments: tuple[ClothoidSplineSegment, ...]
    time_end: float | None  # [s] at the end of the last segment


@dataclass(frozen=True, slots=True)
class ControlPoint:
    time: float | None  # [s]
    weight: float  # [-] > 0 (1 when not written)
    position: Position


@dataclass(frozen=True, slots=True)
class Nurbs:
    """A non-uniform rational B-spline of degree `order` - 1; `knots` has len(control
    points) + order non-decreasing values."""

    order: int
    control_points: tuple[ControlPoint, ...]
    knots: tuple[float, ...]


TrajectoryShape = Polyline | Clothoid | ClothoidSpline | Nurbs


@dataclass(frozen=True, slots=True)
class Trajectory:
    name: str
    closed: bool
    shape: TrajectoryShape
    parameters: dict[str, int | float | bool | str]  # its own ParameterDeclarations

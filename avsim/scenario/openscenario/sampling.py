"""A trajectory's shape as a dense polyline (map frame) with the time of each point.

- Polyline: its vertices as they are.
- Clothoid: heading h(l) = h0 + k l + k' l^2 / 2 along arc length l from its start pose,
  integrated (3-point Gauss-Legendre on sub-steps of `SAMPLE_STEP` / 4, exact to well under
  a millimetre at the bounded curvatures) and kept every `SAMPLE_STEP`; timed linearly in
  arc length from startTime to stopTime when both are given.
- ClothoidSpline: its segments end to end (curvature linear from start to end; each starts
  where the previous one ends, or at its own PositionStart, turned by hOffset); timed
  linearly in arc length within each segment when every segment has a timeStart and the
  spline a timeEnd.
- Nurbs: the rational B-spline of the control points' (x, y) with their weights
  (homogeneous coordinates, `scipy.interpolate.BSpline`, degree order - 1), over the knots'
  span where it is defined, at about `SAMPLE_STEP` along its control polygon (at least
  4 points per control point, at most `MAX_SAMPLES`); times, when every control point has
  one, follow the same rational basis.

A start pose is the first vertex's, the clothoid's Position, or (when not written) the
actor's pose when the action starts (`start`)."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import BSpline

from avsim.scenario.openscenario.positions import Position
from avsim.scenario.openscenario.resolve import Pose, PositionError
from avsim.scenario.openscenario.trajectories import (
    Clothoid,
    ClothoidSpline,
    Nurbs,
    Polyline,
    TrajectoryShape,
)

SAMPLE_STEP = 0.5  # [m] between the points of a sampled curve
MAX_SAMPLES = 50_000  # points of a sampled NURBS (a clothoid's are bounded by its length)
_SUB = 4  # integration sub-steps per sample step
_GAUSS = ((-math.sqrt(0.6), 5.0 / 18.0), (0.0, 8.0 / 18.0), (math.sqrt(0.6), 5.0 / 18.0))

Floats = NDArray[np.float64]
Place = Callable[[Position], Pose]


@dataclass(frozen=True)
class Sampled:
    """Points (x, y) [m], map frame, the heading [rad] at each (a polyline's: its
    vertices' own); `times` [s] (the file's, before any Timing) or None."""

    x: Floats
    y: Floats
    heading: Floats
    times: Floats | None

    @property
    def arc(self) -> Floats:
        """[m] the arc length at each point."""
        return _arc(self.x, self.y)

    def at(self, s: float, t: float) -> Pose:
        """The pose `s` [m] along the polyline and `t` [m] to its left, heading along it."""
        arc = self.arc
        if not -1e-6 <= s <= arc[-1] + 1e-6:
            raise PositionError(f"s = {s:g} m is off the trajectory (0 to {arc[-1]:g} m)")
        found = int(np.searchsorted(arc, s, side="right")) - 1
        i = min(max(found, 0), len(arc) - 2)
        span = arc[i + 1] - arc[i]
        u = 0.0 if span <= 0.0 else (s - arc[i]) / span
        heading = math.atan2(self.y[i + 1] - self.y[i], self.x[i + 1] - self.x[i])
        x = self.x[i] + u * (self.x[i + 1] - self.x[i]) - t * math.sin(heading)
        y = self.y[i] + u * (self.y[i + 1] - self.y[i]) + t * math.cos(heading)
        return Pose(float(x), float(y), heading)


def _arc(x: Floats, y: Floats) -> Floats:
    return np.concatenate(([0.0], np.cumsum(np.hypot(np.diff(x), np.diff(y)))))


def clothoid_points(start: Pose, k0: float, rate: float, length: float
                    ) -> tuple[Floats, Floats, Floats]:
    """(x, y, heading) every `SAMPLE_STEP` (and at the end) along a clothoid of curvature
    k0 + rate l over `length` [m] from `start`."""
    n = max(1, math.ceil(length / SAMPLE_STEP))
    fine = np.linspace(0.0, length, n * _SUB + 1)
    half = 0.5 * np.diff(fine)
    mid = fine[:-1] + half
    dx = np.zeros_like(mid)
    dy = np.zeros_like(mid)
    for xi, w in _GAUSS:
        lq = mid + xi * half
        hq = start.heading + k0 * lq + 0.5 * rate * lq * lq
        dx += w * np.cos(hq)
        dy += w * np.sin(hq)
    x = start.x + np.concatenate(([0.0], np.cumsum(dx * 2.0 * half)))
    y = start.y + np.concatenate(([0.0], np.cumsum(dy * 2.0 * half)))
    keep = np.arange(0, n * _SUB + 1, _SUB)
    lk = fine[keep]
    return x[keep], y[keep], start.heading + k0 * lk + 0.5 * rate * lk * lk


def _start(position: Position | None, place: Place, start: Pose | None) -> Pose:
    if position is not None:
        return place(position)
    if start is None:
        raise PositionError("a clothoid without a start position has no start here")
    return start


def _linear_times(t0: float | None, t1: float | None, arc: Floats) -> Floats | None:
    if t0 is None or t1 is None:
        return None
    total = arc[-1] if arc[-1] > 0.0 else 1.0
    return np.asarray(t0 + (t1 - t0) * arc / total, dtype=np.float64)


def _polyline(shape: Polyline, place: Place) -> Sampled:
    poses = [place(v.position) for v in shape.vertices]
    times = [v.time for v in shape.vertices]
    timed = None if any(t is None for t in times) else np.array(times, dtype=np.float64)
    return Sampled(np.array([p.x for p in poses]), np.array([p.y for p in poses]),
                   np.array([p.heading for p in poses]), timed)


def _clothoid(shape: Clothoid, place: Place, start: Pose | None) -> Sampled:
    x, y, h = clothoid_points(_start(shape.position, place, start), shape.curvature,
                              shape.curvature_rate, shape.length)
    return Sampled(x, y, h, _linear_times(shape.start_time, shape.stop_time, _arc(x, y)))


def _spline(shape: ClothoidSpline, place: Place, start: Pose | None) -> Sampled:
    xs: list[Floats] = []
    ys: list[Floats] = []
    hs: list[Floats] = []
    ts: list[Floats | None] = []
    segments = shape.segments
    ends = [s.time_start for s in segments[1:]] + [shape.time_end]
    pose = start
    for k, seg in enumerate(segments):
        origin = _start(seg.position_start, place, pose)
        origin = Pose(origin.x, origin.y, origin.heading + seg.h_offset)
        rate = (seg.curvature_end - seg.curvature_start) / seg.length
        x, y, h = clothoid_points(origin, seg.curvature_start, rate, seg.length)
        first = 0 if k == 0 else 1  # the joint once
        xs.append(x[first:])
        ys.append(y[first:])
        hs.append(h[first:])
        times = _linear_times(seg.time_start, ends[k], _arc(x, y))
        ts.append(None if times is None else times[first:])
        pose = Pose(float(x[-1]), float(y[-1]), float(h[-1]))
    timed = None if any(t is None for t in ts) else np.concatenate(
        [t for t in ts if t is not None])
    return Sampled(np.concatenate(xs), np.concatenate(ys), np.concatenate(hs), timed)


def _nurbs(shape: Nurbs, place: Place) -> Sampled:
    points = shape.control_points
    poses = [place(p.position) for p in points]
    w = np.array([p.weight for p in points])
    cx, cy = np.array([p.x for p in poses]), np.array([p.y for p in poses])
    times = [p.time for p in points]
    timed = not any(t is None for t in times)
    ct = np.array([t if t is not None else 0.0 for t in times])
    degree = shape.order - 1
    knots = np.array(shape.knots, dtype=np.float64)
    polygon = float(np.sum(np.hypot(np.diff(cx), np.diff(cy))))
    n = int(min(MAX_SAMPLES, max(4 * len(points), math.ceil(polygon / SAMPLE_STEP) + 1)))
    u = np.linspace(knots[degree], knots[len(points)], n)
    coefficients = np.stack([w * cx, w * cy, w * ct, w], axis=1)
    values = BSpline(knots, coefficients, degree, extrapolate=False)(u)
    values[-1] = BSpline(knots, coefficients, degree)(knots[len(points)] - 1e-12)
    denominator = values[:, 3]
    x, y = values[:, 0] / denominator, values[:, 1] / denominator
    heading = np.arctan2(np.gradient(y), np.gradient(x))
    return Sampled(x, y, heading, values[:, 2] / denominator if timed else None)


def sample(shape: TrajectoryShape, place: Place, start: Pose | None = None) -> Sampled:
    """The shape as a dense polyline (module doc); `place` resolves a position, `start` is
    the actor's pose (None: none is known, e.g. for a TrajectoryPosition)."""
    if isinstance(shape, Polyline):
        return _polyline(shape, place)
    if isinstance(shape, Clothoid):
        return _clothoid(shape, place, start)
    if isinstance(shape, ClothoidSpline):
        return _spline(shape, place, start)
    return _nurbs(shape, place)

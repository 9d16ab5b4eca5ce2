"""The lane-change path: a Hermite cubic from the lateral offset and heading (ICCAS Fig. 4b).

Frame: the Frenet frame of the TARGET lane. ``s`` [m] is the station along the route's
reference line, ``r`` [m] the lateral offset from the target lane's centre, left +.

The car starts at station ``s0``, offset ``r0``, with heading error ``psi0`` (its heading
minus the lane heading at ``s0``, wrapped to (-pi, pi], left +) and speed ``v``. Over
``L`` metres the path's offset is the cubic Hermite

    r(u) = h00(u) r0 + h10(u) L m0,    u = (s - s0) / L in [0, 1],
    h00 = 2u^3 - 3u^2 + 1,  h10 = u^3 - 2u^2 + u,

with start value ``r0``, start slope ``dr/ds = m0 = tan(psi0)``, end value 0 and end slope 0
(the h01 and h11 terms vanish). Before ``s0`` the path is the straight extension
``r0 + m0 (s - s0)``; after ``s0 + L`` it is the target lane's centre, ``r = 0``.

Length and duration: ``L = max(v T, min_length)``; the floor keeps the path drivable at low
speed, where it then takes ``L / v`` > T seconds. The cubic's ``r''(s)`` is linear in u, so
its peak is at an end, in closed form (``dr = -r0`` the lateral distance to cover):

    r''(s0)     = (6 dr - 4 L m0) / L^2,    r''(s0 + L) = (-6 dr + 2 L m0) / L^2,
    a_peak      = v^2 max(|6 dr - 4 L m0|, |6 dr - 2 L m0|) / L^2.

From parallel (m0 = 0) and above the floor, ``a_peak = 6 |dr| / T^2``. The duration T is
the smallest on a grid (step ``T_STEP``) from ``t_min`` whose ``a_peak`` <= ``a_lat_design``.
Lateral acceleration wins over duration: the grid goes on past the nominal longest change
``t_max`` up to the hard cap ``t_cap``, and if even that fails, T = ``t_cap`` and the peak
exceeds the design value (check `peak_lateral_accel`). The curvature of the path steps by
``r''`` at both ends of the cubic (a cubic Hermite has no end-curvature conditions).

Small-offset approximation: station metres are taken as path metres, and the scale
``(1 - k r)`` of curves offset from the lane's centre is ignored: the heading is
``lane heading + atan(r')`` and the curvature ``lane curvature + r'' / (1 + r'^2)^1.5``
(exact on straights; on a curve of radius R the errors are of order r / R).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from planner.messages import ReferencePath
from planner.route import path_stations
from world.frames import wrap_angle
from world.hdmap import FloatArray, Lane, RoadMap

T_STEP = 0.05  # [s] grid of the duration search


@dataclass(frozen=True, slots=True)
class LaneChangeParams:
    a_lat_design: float = 0.85  # [m/s^2] peak lateral acceleration of the planned path
    #   (below the acceptance: room for the controller's tracking)
    t_min: float = 3.0  # [s] shortest lane change
    t_max: float = 5.0  # [s] nominal longest lane change; the search goes past it if needed
    t_cap: float = 8.0  # [s] hard cap when the acceleration needs more than t_max
    min_length: float = 15.0  # [m] shortest path, for low speeds

    def __post_init__(self) -> None:
        if not 0.0 < self.t_min <= self.t_max <= self.t_cap:
            raise ValueError("need 0 < t_min <= t_max <= t_cap")
        if self.a_lat_design <= 0.0 or self.min_length <= 0.0:
            raise ValueError("a_lat_design and min_length must be > 0")


def path_length(speed: float, duration: float, params: LaneChangeParams) -> float:
    """[m] the path length ``max(v T, min_length)``."""
    return max(speed * duration, params.min_length)


def peak_lateral_accel(dr: float, slope: float, speed: float, length: float) -> float:
    """[m/s^2] ``v^2 max |r''(s)|`` of the cubic covering ``dr`` [m] (target minus start
    offset, left +) over ``length`` [m] from start slope ``slope`` (dr/ds) to parallel."""
    start = 6.0 * dr - 4.0 * length * slope
    end = 6.0 * dr - 2.0 * length * slope
    return speed * speed * max(abs(start), abs(end)) / (length * length)


def plan_duration(dr: float, slope: float, speed: float, params: LaneChangeParams) -> float:
    """[s] the smallest T on the ``T_STEP`` grid from ``t_min`` whose path keeps
    `peak_lateral_accel` <= ``a_lat_design``, searched up to ``t_cap`` (beyond ``t_max`` when
    needed); ``t_cap`` if none does."""
    if speed < 0.0:
        raise ValueError("speed must be >= 0")
    n = math.floor((params.t_cap - params.t_min) / T_STEP + 1e-9)
    for k in range(n + 1):
        duration = round(params.t_min + k * T_STEP, 9)
        length = path_length(speed, duration, params)
        if peak_lateral_accel(dr, slope, speed, length) <= params.a_lat_design:
            return duration
    return params.t_cap


@dataclass(frozen=True, slots=True)
class LaneChangePath:
    """One planned lane change, in the target lane's Frenet frame (module docstring)."""

    s0: float  # [m] station of the start
    length: float  # [m] station length L of the cubic
    r0: float  # [m] start offset from the target lane's centre, left +
    m0: float  # [-] start slope dr/ds, tan of the heading error
    duration: float  # [s] planned duration T (the drive takes length / speed)
    target_index: int  # the target lane's index (`RoadMap.lane`)

    @property
    def end(self) -> float:
        """[m] station where the path reaches the target lane's centre."""
        return self.s0 + self.length

    def _u(self, s: ArrayLike) -> FloatArray:
        return np.clip((np.asarray(s, dtype=np.float64) - self.s0) / self.length, 0.0, 1.0)

    def _before(self, s: ArrayLike) -> FloatArray:
        """[m] station distance before the start, 0 from the start on (<= 0)."""
        return np.minimum(np.asarray(s, dtype=np.float64) - self.s0, 0.0)

    def offset_at(self, s: ArrayLike) -> FloatArray:
        """[m] r(s), the path's offset from the target lane's centre at stations s."""
        u = self._u(s)
        h00 = (2.0 * u - 3.0) * u * u + 1.0
        h10 = ((u - 2.0) * u + 1.0) * u
        return h00 * self.r0 + h10 * self.length * self.m0 + self.m0 * self._before(s)

    def slope_at(self, s: ArrayLike) -> FloatArray:
        """[-] dr/ds at stations s."""
        u = self._u(s)
        d00 = 6.0 * u * (u - 1.0)
        d10 = (3.0 * u - 4.0) * u + 1.0
        slope = d00 * self.r0 / self.length + d10 * self.m0
        return np.where(self._before(s) < 0.0, self.m0, slope)

    def second_derivative_at(self, s: ArrayLike) -> FloatArray:
        """[1/m] d2r/ds2 at stations s (0 outside the cubic; it steps at both ends)."""
        s_arr = np.asarray(s, dtype=np.float64)
        u = self._u(s_arr)
        dd00 = 12.0 * u - 6.0
        dd10 = 6.0 * u - 4.0
        inside = (s_arr >= self.s0) & (s_arr <= self.end)
        value = (dd00 * self.r0 + dd10 * self.length * self.m0) / (self.length * self.length)
        return np.where(inside, value, 0.0)

    def peak_lateral_accel(self, speed: float) -> float:
        """[m/s^2] ``v^2 max |r''|`` at ``speed`` [m/s]."""
        return peak_lateral_accel(-self.r0, self.m0, speed, self.length)

    def progress(self, s: float) -> float:
        """[-] the fraction of the path's length behind station s, in [0, 1]."""
        return float(self._u(s))

    def done(self, s: float, r: float | None = None, tolerance: float = 0.5) -> bool:
        """Whether the change is over: station s at or past the end and, if the car's own
        offset ``r`` [m] from the target lane's centre is given, ``|r| <= tolerance`` [m]."""
        return s >= self.end and (r is None or abs(r) <= tolerance)

    def reference_path(
        self, lane: Lane, s: float, behind: float, ahead: float, spacing: float,
        route_length: float,
    ) -> ReferencePath:
        """The path on the target ``lane`` from ``s - behind`` to ``s + ahead``, every
        ``spacing`` [m] of station (`planner.route.path_stations`, clamped to the route's
        [0, ``route_length``]). Headings and curvatures: module docstring."""
        if lane.index != self.target_index:
            raise ValueError(f"lane {lane.index} is not the target lane {self.target_index}")
        stations = path_stations(s, behind, ahead, spacing, route_length)
        r = self.offset_at(stations)
        slope = self.slope_at(stations)
        xy = np.asarray(lane.position(stations, r), dtype=np.float64).reshape(-1, 2)
        heading = np.asarray(lane.heading_at(stations), dtype=np.float64) + np.arctan(slope)
        curvature = np.asarray(lane.curvature_at(stations), dtype=np.float64) + (
            self.second_derivative_at(stations) / (1.0 + slope * slope) ** 1.5)
        return ReferencePath(xy=xy, heading=heading, curvature=curvature)


def heading_error(lane: Lane, x: float, y: float, heading: float,
                  near: float | None = None) -> tuple[float, float, float]:
    """(s0 [m], r0 [m], psi0 [rad]) of a car at (``x``, ``y``) [m] heading ``heading``
    [rad] in ``lane``'s Frenet frame: its station, its offset from the lane's centre and its
    heading minus the lane's, wrapped to (-pi, pi]. ``near`` [m] is the car's station (the
    localiser's, `RoadMap.local_coordinates` with its hint): on a bend that turns back on
    itself the nearest point of the whole route may lie on its other pass, where the lane
    heads the other way (a heading error near pi)."""
    xy = np.array([x, y], dtype=np.float64)
    s_arr, r_arr = (lane.local_coordinates(xy) if near is None
                    else lane.local_coordinates(xy, near))
    s0, r0 = float(s_arr), float(r_arr)
    return s0, r0, wrap_angle(heading - float(lane.heading_at(s0)))


def can_start(lane: Lane, x: float, y: float, heading: float,
              near: float | None = None) -> bool:
    """Whether `start_lane_change` plans a path into ``lane`` from this pose: the car heads
    less than 90 degrees off the lane (a car that has spun cannot change lanes; it holds
    its lane)."""
    return abs(heading_error(lane, x, y, heading, near)[2]) < 0.5 * math.pi


@dataclass(frozen=True, slots=True)
class RoutePose:
    """A car's pose on the route, from one projection (`route_pose`) that serves every lane:
    the lanes share the route's reference line, so its station and its heading error (the
    car's heading minus the reference line's tangent, which `Lane.heading_at` is for every
    lane) are the same for each; only the offset from a lane's centre differs
    (`in_lane`). The projection's inputs are kept so that a caller can tell whether it is
    the pose it wants (`is_for`)."""

    x: float  # [m] map frame, the car's centre
    y: float  # [m]
    heading: float  # [rad] map frame
    near: float | None  # [m] the projection's hint (`RoadMap.local_coordinates`)
    station: FloatArray  # [m] 0-d: the car's station along the reference line
    offset: FloatArray  # [m] 0-d: its offset from the reference line, left +
    heading_error: float  # [rad] heading minus the route's tangent there, in (-pi, pi]

    def is_for(self, x: float, y: float, heading: float, near: float | None) -> bool:
        """Whether this is the pose of a car at (`x`, `y`) [m] heading `heading` [rad],
        projected with the hint `near` [m]."""
        return (self.x, self.y, self.heading, self.near) == (x, y, heading, near)

    def in_lane(self, lane: Lane) -> tuple[float, float, float]:
        """(s0 [m], r0 [m], psi0 [rad]) in `lane`'s Frenet frame, as `heading_error`."""
        r = self.offset - lane.offset_at(self.station)
        return float(self.station), float(np.asarray(r)), self.heading_error

    @property
    def can_start(self) -> bool:
        """`can_start` for any lane: the car heads less than 90 degrees off the route."""
        return abs(self.heading_error) < 0.5 * math.pi


def route_pose(road: RoadMap, x: float, y: float, heading: float,
               near: float | None = None) -> RoutePose:
    """The car's `RoutePose` (the projection `heading_error` makes, for every lane at once)."""
    xy = np.array([x, y], dtype=np.float64)
    s_arr, d_arr = (road.local_coordinates(xy) if near is None
                    else road.local_coordinates(xy, near))
    psi = wrap_angle(heading - float(road.heading_at(float(s_arr))))
    return RoutePose(x, y, heading, near, s_arr, d_arr, psi)


def start_lane_change(
    lane: Lane, target_index: int, x: float, y: float, heading: float, speed: float,
    params: LaneChangeParams, near: float | None = None,
) -> LaneChangePath:
    """Plan a change into the target ``lane`` (index ``target_index``) for a car at
    (``x``, ``y``) [m] with ``heading`` [rad] and ``speed`` [m/s] >= 0, its station near
    ``near`` [m] when given (`heading_error`).

    Raises ValueError if ``lane`` is not lane ``target_index`` or the car heads 90 degrees
    or more off the lane (no cubic in s starts there: check `can_start` first).
    """
    if lane.index != target_index:
        raise ValueError(f"lane {lane.index} is not the target lane {target_index}")
    return _path_from(target_index, *heading_error(lane, x, y, heading, near), speed, params)


def start_lane_change_at(lane: Lane, target_index: int, pose: RoutePose, speed: float,
                         params: LaneChangeParams) -> LaneChangePath:
    """`start_lane_change` from the car's `RoutePose` (the same path, the projection made
    once for every lane the car may plan into)."""
    if lane.index != target_index:
        raise ValueError(f"lane {lane.index} is not the target lane {target_index}")
    return _path_from(target_index, *pose.in_lane(lane), speed, params)


def _path_from(target_index: int, s0: float, r0: float, psi0: float, speed: float,
               params: LaneChangeParams) -> LaneChangePath:
    """The path from station `s0` [m], offset `r0` [m] and heading error `psi0` [rad] in
    the target lane's frame at `speed` [m/s] (`start_lane_change`)."""
    if abs(psi0) >= 0.5 * math.pi:
        raise ValueError(f"heading error {psi0:.3f} rad: the car does not head along the lane")
    m0 = math.tan(psi0)
    duration = plan_duration(-r0, m0, speed, params)
    return LaneChangePath(
        s0=s0, length=path_length(speed, duration, params), r0=r0, m0=m0,
        duration=duration, target_index=target_index)

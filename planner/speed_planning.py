"""Target speed for lane keeping: set speed, vehicle limit, posted limits and curves.

Along one lane of the map (parameters `SpeedPlanningParams`; speeds [m/s], distances [m]),
the target is the minimum of

* the driver's set speed, the vehicle's maximum speed and the sight speed (the fastest
  speed whose following gap and stop the forward sensing covers: `planner.fsm.acc.sight_speed`,
  given by the planner),
* the posted limit in force at the FRONT BUMPER, less ``limit_margin``,
* the curvature speed ``sqrt(a_lat_max / |kappa|)`` of the lane between the car's centre and
  its front axle,
* the crossing speed ``crossing_speed`` while the front bumper is within ``crossing_sight``
  of a marked crossing it has not reached: a pedestrian who steps out is tracked from about
  that range, and from this speed the car still stops before the crossing within ISO 15622's
  comfort (about 2.5 m/s^2 with the ramp-in; `planner.acc_control`), where at the posted
  40 km/h of a town it would need 5 m/s^2. Where a pedestrian waits at the
  crossing (`target`'s ``waiting``: `planner.events.EventMonitor.waiting`) the lower
  ``crossing_speed_waiting``: the track of a walker who steps off the kerb shows the walk
  about 0.9 s late (its velocity lags), 7.5 m of the approach at 30 km/h, after which a
  stop before the crossing may need 4 m/s^2; from 20 km/h it needs about 1.5 m/s^2;
* for every constraint ahead, the speed from which the car can reach it by braking at
  ``a_comf``: ``sqrt(v_c^2 + 2 a_comf max(d - brake_margin, 0))``. Constraints ahead are the
  speed-limit postings beyond the front bumper (``v_c`` = limit less ``limit_margin``, ``d``
  from the front bumper, so the limit already holds when the bumper reaches the sign), the
  crossings (``v_c`` = crossing_speed or crossing_speed_waiting, ``d`` from the front
  bumper to ``crossing_sight`` before the crossing) and the curvature-speed samples beyond
  the front axle (``d`` from the front axle).

``brake_margin`` makes the braking curve reach ``v_c`` that many metres before the
constraint: room for the speed loop's lag behind a falling target. ``limit_margin`` keeps
the target just under a posted limit, so that the speed loop's ripple about its target
stays within the speed-limit rule's small tolerance above the limit. The feed-forward
acceleration is -a_comf while a braking curve binds (beyond ``brake_margin``), else 0.

Distances along the lane are metres of the lane's centre line: a station step ``ds`` on a
lane offset from the reference line is ``(1 - k_ref * offset) ds = ds / (1 + kappa * offset)``
metres long (``kappa`` the lane's own curvature).

The map's constraints are static, so `SpeedPlanner` samples the lane once, on a grid fixed
to the map (every ``sample_spacing`` metres plus every piece start, where curvature and lane
offset step): curvature speed ``v_j`` and lane distance ``D_j`` from the route's start. The
braking curves of all curve samples beyond the brake margin reduce to one lookup: with
``d_j = D_j - D_axle``,

    min_j sqrt(v_j^2 + 2 a (d_j - m)) = sqrt(min_j (v_j^2 + 2 a D_j) - 2 a (D_axle + m)),

and the suffix minimum of ``v_j^2 + 2 a D_j`` (with its nearest arg-min) is precomputed. A
tick costs a few bisections, whatever the horizon: there is no horizon to choose, and a
constraint too far away to bind simply never does.
"""

from __future__ import annotations

import bisect
import enum
import math
from collections.abc import Collection
from dataclasses import dataclass

import numpy as np

from planner.limits import A_COMF
from world.frames import VehicleInfo, kph
from world.hdmap import Crosswalk, FloatArray, IntArray, Lane, RoadMap


class Binding(enum.Enum):
    """Which constraint sets the target speed."""

    SET_SPEED = "set_speed"  # the driver's set speed
    MAX_SPEED = "max_speed"  # the vehicle's maximum speed
    SIGHT = "sight"  # the fastest speed the forward sensing range covers
    LIMIT = "limit"  # the posted limit in force at the front bumper
    LIMIT_AHEAD = "limit_ahead"  # braking towards a lower posting ahead
    CURVE = "curve"  # the curvature speed between the car's centre and front axle
    CURVE_AHEAD = "curve_ahead"  # braking towards a curve ahead
    CROSSING = "crossing"  # the crossing speed near a marked crossing, or braking towards it


_AHEAD = (Binding.LIMIT_AHEAD, Binding.CURVE_AHEAD, Binding.CROSSING)


@dataclass(frozen=True, slots=True)
class SpeedPlanningParams:
    a_comf: float = A_COMF  # [m/s^2] comfortable deceleration towards constraints ahead
    a_lat_max: float = 3.0  # [m/s^2] lateral acceleration allowed in curves
    limit_margin: float = kph(0.3)  # [m/s] target below a posted limit: room for ripple
    brake_margin: float = 3.0  # [m] the braking curve reaches v_c this far before d = 0
    sample_spacing: float = 0.5  # [m] station step of the curvature samples (map-fixed grid)
    min_curvature: float = 1e-6  # [1/m] below this |kappa| the lane is straight (no limit)
    crossing_speed: float = kph(30.0)  # [m/s] near a marked crossing (module doc)
    crossing_sight: float = 20.0  # [m] ... within this of it (a pedestrian's tracking range)
    crossing_speed_waiting: float = kph(20.0)  # [m/s] ... where a pedestrian waits at it
    #   (module doc): a step-out seen 0.9 s late 17.6 m before the crossing leaves 12.6 m,
    #   a stop from 5.6 m/s in 11.6 m (after ``crossing_stop``) at 1.3 m/s^2


@dataclass(frozen=True, slots=True)
class SpeedTarget:
    speed: float  # [m/s] target speed now, >= 0
    accel: float  # [m/s^2] feed-forward: -a_comf while a braking curve binds, else 0
    limit_at_front: float  # [m/s] posted limit in force at the front bumper
    binding: Binding  # the constraint that sets `speed`
    distance: float  # [m] along the lane to the binding constraint (0 for those in force)


def braking_speed(v_c: FloatArray, d: FloatArray, params: SpeedPlanningParams) -> FloatArray:
    """[m/s] the highest speed now from which braking at ``a_comf`` reaches speed ``v_c``
    [m/s] ``brake_margin`` before the constraint at distance ``d`` [m]; shapes broadcast."""
    room = np.maximum(d - params.brake_margin, 0.0)
    out: FloatArray = np.sqrt(np.square(v_c) + 2.0 * params.a_comf * room)
    return out


def curve_speed(curvature: FloatArray, params: SpeedPlanningParams) -> FloatArray:
    """[m/s] ``sqrt(a_lat_max / |kappa|)`` per sample, +inf where the lane is straight."""
    k = np.abs(curvature)
    safe = np.maximum(k, params.min_curvature)
    out: FloatArray = np.where(k >= params.min_curvature, np.sqrt(params.a_lat_max / safe), np.inf)
    return out


def _lane_metric(lane: Lane, s: FloatArray) -> FloatArray:
    """[m/m] lane centre length per station metre: 1 / (1 + kappa_lane * offset)."""
    kappa = np.asarray(lane.curvature_at(s), dtype=np.float64)
    offset = np.asarray(lane.offset_at(s), dtype=np.float64)
    out: FloatArray = 1.0 / (1.0 + kappa * offset)
    return out


def _suffix_argmin(values: FloatArray) -> IntArray:
    """Per index i, the index of the least value in ``values[i:]``; ties to the nearest."""
    n = len(values)
    rev = values[::-1]
    running = np.minimum.accumulate(rev)
    attained = np.where(rev == running, np.arange(n), 0)  # reversed index where a min is set
    latest = np.maximum.accumulate(attained)  # in reversed order: the last (nearest) one
    out: IntArray = (n - 1 - latest)[::-1]
    return out


class SpeedPlanner:
    """The target speed along one lane of a map (see the module doc for the rule)."""

    def __init__(self, road: RoadMap, lane: Lane, params: SpeedPlanningParams,
                 vehicle: VehicleInfo) -> None:
        self.road, self.lane, self.params, self.vehicle = road, lane, params, vehicle
        spacing = params.sample_spacing
        grid = spacing * np.arange(math.floor(road.length / spacing) + 1, dtype=np.float64)
        starts = np.array([p.s0 for p in road.pieces], dtype=np.float64)
        stations = np.unique(np.concatenate((grid, starts[starts < road.length],
                                             [road.length])))
        # the metric is constant between piece starts, which are samples: left-point rule
        metric = _lane_metric(lane, stations)
        distance = np.concatenate(([0.0], np.cumsum(metric[:-1] * np.diff(stations))))
        v_curve = curve_speed(np.asarray(lane.curvature_at(stations), np.float64), params)
        key = np.square(v_curve) + 2.0 * params.a_comf * distance  # +inf on straights
        self._stations: list[float] = stations.tolist()
        self._metric: list[float] = metric.tolist()
        self._distance: list[float] = distance.tolist()
        self._v_curve = v_curve
        self._key: list[float] = key.tolist()
        self._best_ahead: list[int] = _suffix_argmin(key).tolist()
        self._post_s = [p.s for p in road.speed_limits]
        self._post_v = [p.limit for p in road.speed_limits]
        self._crossings = sorted(f.s for f in road.features if isinstance(f, Crosswalk))

    # -- lane geometry on the grid --------------------------------------------------------------

    def _index(self, s: float) -> int:
        """The last sample at or before station ``s`` (clamped to the grid)."""
        i = bisect.bisect_right(self._stations, s) - 1
        return min(max(i, 0), len(self._stations) - 1)

    def _distance_at(self, s: float) -> float:
        """[m] lane distance from the route's start to station ``s`` (exact: linear between
        samples)."""
        i = self._index(s)
        return self._distance[i] + self._metric[i] * (s - self._stations[i])

    def _station_ahead(self, s: float, metres: float) -> float:
        """[m] station ``metres`` [m] ahead of station ``s`` along the lane (local metric)."""
        return s + metres / self._metric[self._index(s)]

    def front_station(self, s: float) -> float:
        """[m] the station of the front bumper of a car whose centre is at station ``s``
        [m]: where the posted limit in force is read (`target`)."""
        return self._station_ahead(s, self.vehicle.front_overhang)

    # -- the target -----------------------------------------------------------------------------

    def target(self, s: float, *, set_speed: float, max_speed: float,
               sight_speed: float = math.inf,
               waiting: Collection[float] = ()) -> SpeedTarget:
        """The target speed for a car whose centre is at station ``s`` [m] of the lane.

        ``set_speed``, ``max_speed`` and ``sight_speed`` [m/s]; ``waiting`` the stations [m]
        of the marked crossings where a pedestrian waits (their speed is
        ``crossing_speed_waiting``). Ties go to the first of: set speed, max speed, sight,
        limit, curve now, curve ahead, limit ahead.
        """
        p = self.params
        s_front = self.front_station(s)
        s_axle = self._station_ahead(s, self.vehicle.front_axle)
        limit_at_front = float(self.road.speed_limit_at(s_front))
        candidates = [
            (set_speed, Binding.SET_SPEED, 0.0),
            (max_speed, Binding.MAX_SPEED, 0.0),
            (sight_speed, Binding.SIGHT, 0.0),
            (limit_at_front - p.limit_margin, Binding.LIMIT, 0.0),
            *self._curve_constraints(s, s_axle),
            *self._limit_constraints(s_front),
            *self._crossing_constraints(s_front, waiting),
        ]
        v, binding, d = min(candidates, key=lambda c: c[0])  # the first of equal minima
        braking = binding in _AHEAD and d > p.brake_margin
        return SpeedTarget(
            speed=max(v, 0.0),
            accel=-p.a_comf if braking else 0.0,
            limit_at_front=limit_at_front,
            binding=binding,
            distance=d,
        )

    def _curve_constraints(self, s: float, s_axle: float) -> list[tuple[float, Binding, float]]:
        """(speed, binding, distance) of the curve now, within the brake margin ahead of the
        front axle, and beyond it (the suffix minimum)."""
        p, st = self.params, self._stations
        i_now, i_axle = self._index(s), self._index(s_axle)
        out = [(float(self._v_curve[i_now:i_axle + 1].min()), Binding.CURVE, 0.0)]
        d_axle = self._distance_at(s_axle)
        i_margin = bisect.bisect_right(self._distance, d_axle + p.brake_margin) - 1
        first_ahead = bisect.bisect_right(st, s_axle)
        if first_ahead <= i_margin:  # samples ahead but within the margin: v_c itself
            near = self._v_curve[first_ahead:i_margin + 1]
            j = first_ahead + int(np.argmin(near))
            out.append((float(near.min()), Binding.CURVE_AHEAD, self._distance[j] - d_axle))
        beyond = max(i_margin + 1, first_ahead)
        if beyond < len(st):
            j = self._best_ahead[beyond]
            room = self._key[j] - 2.0 * p.a_comf * (d_axle + p.brake_margin)
            if math.isfinite(room):
                out.append((math.sqrt(room), Binding.CURVE_AHEAD, self._distance[j] - d_axle))
        return out

    def _limit_constraints(self, s_front: float) -> list[tuple[float, Binding, float]]:
        """(speed, binding, distance) per posting beyond the front bumper, up to the route's
        end; a higher posting never binds (its braking speed exceeds the limit in force)."""
        p = self.params
        d_front = self._distance_at(s_front)
        out = []
        for s_p, v_p in zip(self._post_s, self._post_v, strict=True):
            if s_front < s_p <= self.road.length:
                d = self._distance_at(s_p) - d_front
                v = math.sqrt((v_p - p.limit_margin) ** 2
                              + 2.0 * p.a_comf * max(d - p.brake_margin, 0.0))
                out.append((v, Binding.LIMIT_AHEAD, d))
        return out

    def _crossing_constraints(self, s_front: float, waiting: Collection[float],
                              ) -> list[tuple[float, Binding, float]]:
        """(speed, binding, distance) per marked crossing the front bumper has not reached:
        the crossing speed (``crossing_speed_waiting`` at those in `waiting`) within
        crossing_sight of it, the braking curve to it beyond."""
        p = self.params
        d_front = self._distance_at(s_front)
        out = []
        for s_c in self._crossings:
            if s_front < s_c <= self.road.length:
                d = max(self._distance_at(s_c) - d_front - p.crossing_sight, 0.0)
                v_c = p.crossing_speed_waiting if s_c in waiting else p.crossing_speed
                v = math.sqrt(v_c**2 + 2.0 * p.a_comf
                              * max(d - p.brake_margin, 0.0))
                out.append((v, Binding.CROSSING, d))
        return out

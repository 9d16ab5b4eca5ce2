"""Target speed for lane keeping: set speed, vehicle limit, posted limits and curves.

The target is the minimum of

* the driver's set speed and the vehicle's maximum speed,
* the posted limit in force at the FRONT BUMPER, less ``limit_margin``,
* the curvature speed ``sqrt(a_lat_max / |kappa|)`` of the lane between the car's centre and
  its front axle,
* for every constraint ahead, the speed from which the car can reach it by braking at
  ``a_comf``: ``sqrt(v_c^2 + 2 a_comf max(d - brake_margin, 0))``. Constraints ahead are the
  speed-limit postings beyond the front bumper (``v_c`` = limit less ``limit_margin``, ``d``
  from the front bumper, so the limit already holds when the bumper reaches the sign) and the
  curvature-speed samples beyond the front axle (``d`` from the front axle).

``brake_margin`` makes the braking curve reach ``v_c`` that many metres before the
constraint, room for the speed loop's lag behind a falling target.

``limit_margin`` (0.3 km/h) keeps the target just under a posted limit. The speed loop
holds its target with a small ripple, and the speed_limit rule tolerates +1 km/h over the
limit: aiming 0.3 km/h below gives the ripple 1.3 km/h of room above the target (instead of
1 km/h) for a loss of only 0.3 km/h of progress.

Distances along the lane are metres of the lane's centre line: a station step ``ds`` on a
lane offset from the reference line is ``(1 - k_ref * offset) ds = ds / (1 + kappa * offset)``
metres long (``kappa`` the lane's own curvature). The work is vectorised over the samples
(about 1 000 - 2 000 per call at highway speeds), as it runs every planner tick (40 Hz).
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

import numpy as np

from world.hdmap import FloatArray, Lane, RoadMap

KPH = 1.0 / 3.6  # [m/s per km/h]

# Stations sampled ahead per metre of horizon: the lane may be shorter than the reference
# line (the inside lane of a curve), so sample a little further in stations.
STATION_SPAN_FACTOR = 1.25  # [-]


class Binding(enum.Enum):
    """Which constraint sets the target speed."""

    SET_SPEED = "set_speed"  # the driver's set speed
    MAX_SPEED = "max_speed"  # the vehicle's maximum speed
    LIMIT = "limit"  # the posted limit in force at the front bumper
    LIMIT_AHEAD = "limit_ahead"  # braking towards a lower posting ahead
    CURVE = "curve"  # the curvature speed between the car's centre and front axle
    CURVE_AHEAD = "curve_ahead"  # braking towards a curve ahead


_AHEAD = (Binding.LIMIT_AHEAD, Binding.CURVE_AHEAD)
_KINDS = tuple(Binding)
_CODE = {b: i for i, b in enumerate(_KINDS)}


@dataclass(frozen=True, slots=True)
class SpeedPlanningParams:
    a_comf: float = 1.5  # [m/s^2] comfortable deceleration towards constraints ahead
    a_lat_max: float = 3.0  # [m/s^2] lateral acceleration allowed in curves
    limit_margin: float = 0.3 * KPH  # [m/s] target below a posted limit (see module doc)
    brake_margin: float = 3.0  # [m] the braking curve reaches v_c this far before d = 0
    horizon_extra: float = 20.0  # [m] look-ahead beyond the stopping distance from max speed
    sample_spacing: float = 0.5  # [m] station step of the curvature samples (map-fixed grid)
    front_overhang: float = 2.4  # [m] car centre -> front bumper
    front_axle: float = 1.35  # [m] car centre -> front axle
    min_curvature: float = 1e-6  # [1/m] below this |kappa| the lane is straight (no limit)


@dataclass(frozen=True, slots=True)
class SpeedTarget:
    speed: float  # [m/s] target speed now, >= 0
    accel: float  # [m/s^2] feed-forward: -a_comf while a braking curve binds, else 0
    limit_at_front: float  # [m/s] posted limit in force at the front bumper
    binding: Binding  # the constraint that sets `speed`
    distance: float  # [m] along the lane to the binding constraint (0 for those in force)


def horizon(max_speed: float, params: SpeedPlanningParams) -> float:
    """[m] look-ahead: the stopping distance from ``max_speed`` at ``a_comf``, plus extra."""
    return max_speed**2 / (2.0 * params.a_comf) + params.horizon_extra


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


@dataclass(frozen=True, slots=True)
class _Samples:
    """Stations ahead of the car and the lane distance to each, from the car's centre."""

    stations: FloatArray  # [m] (N,) from the car's centre station, clamped to the route
    distance: FloatArray  # [m] (N,) along the lane centre from the first sample

    def distance_at(self, s: FloatArray) -> FloatArray:
        """[m] lane distance from the first sample to stations ``s`` [m], shape of ``s``."""
        out: FloatArray = np.asarray(np.interp(s, self.stations, self.distance))
        return out


def _sample_ahead(
    road: RoadMap, lane: Lane, s: float, s_axle: float, span: float, spacing: float
) -> _Samples:
    """Stations from ``s`` to ``s + span`` [m]: a grid fixed on the map (multiples of
    ``spacing``, so a constraint's samples do not slide with the car from tick to tick), the
    start of every map piece (where curvature and lane offsets step, so an arc's start is
    exact) and the car's own ``s`` and front axle ``s_axle``; clamped to the route."""
    first, last = math.ceil(s / spacing), math.floor((s + span) / spacing)
    grid = spacing * np.arange(first, last + 1, dtype=np.float64)
    starts = np.array([p.s0 for p in road.pieces], dtype=np.float64)
    starts = starts[(starts > s) & (starts < s + span)]
    stations = np.unique(np.clip(np.concatenate(([s, s_axle], grid, starts)), 0.0, road.length))
    # the lane's metric is constant between pieces starts, and those are samples: the
    # left-point rule is exact
    steps = _lane_metric(lane, stations[:-1]) * np.diff(stations)
    return _Samples(stations, np.concatenate(([0.0], np.cumsum(steps))))


def _lane_metric(lane: Lane, s: FloatArray) -> FloatArray:
    """[m/m] lane centre length per station metre: 1 / (1 + kappa_lane * offset)."""
    kappa = np.asarray(lane.curvature_at(s), dtype=np.float64)
    offset = np.asarray(lane.offset_at(s), dtype=np.float64)
    out: FloatArray = 1.0 / (1.0 + kappa * offset)
    return out


def _station_ahead(lane: Lane, s: float, metres: float) -> float:
    """[m] station ``metres`` [m] ahead of station ``s`` along the lane (local metric)."""
    return s + metres / float(_lane_metric(lane, np.array([s]))[0])


def speed_target(
    road: RoadMap,
    lane: Lane,
    s: float,
    *,
    set_speed: float,
    max_speed: float,
    params: SpeedPlanningParams,
) -> SpeedTarget:
    """The target speed for a car whose centre is at station ``s`` [m] of ``lane``.

    ``set_speed`` and ``max_speed`` [m/s]. Postings come from ``road.speed_limits``, curves
    from ``lane.curvature_at``; everything beyond ``road.length`` is ignored. Ties go to the
    first of: set speed, max speed, limit, curve now, curve ahead, limit ahead.
    """
    s_front = _station_ahead(lane, s, params.front_overhang)
    s_axle = _station_ahead(lane, s, params.front_axle)
    span = STATION_SPAN_FACTOR * (params.front_overhang + horizon(max_speed, params))
    samples = _sample_ahead(road, lane, s, s_axle, span, params.sample_spacing)
    limit_at_front = float(np.asarray(road.speed_limit_at(s_front)))

    fixed_v = np.array([set_speed, max_speed, limit_at_front - params.limit_margin])
    fixed_k = np.array([_CODE[Binding.SET_SPEED], _CODE[Binding.MAX_SPEED], _CODE[Binding.LIMIT]])

    curve_v, curve_d, curve_k = _curve_constraints(lane, samples, s_axle, params)
    limit_v, limit_d, limit_k = _limit_constraints(road, samples, s_front, params)

    v = np.concatenate((fixed_v, curve_v, limit_v))
    d = np.concatenate((np.zeros(3), curve_d, limit_d))
    k = np.concatenate((fixed_k, curve_k, limit_k))
    i = int(np.argmin(v))
    binding = _KINDS[int(k[i])]
    braking = binding in _AHEAD and d[i] > params.brake_margin
    return SpeedTarget(
        speed=max(float(v[i]), 0.0),
        accel=-params.a_comf if braking else 0.0,
        limit_at_front=limit_at_front,
        binding=binding,
        distance=float(d[i]),
    )


def _curve_constraints(
    lane: Lane, samples: _Samples, s_axle: float, params: SpeedPlanningParams
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """(allowed speed [m/s], distance [m], binding code) per curvature sample.

    Samples up to the front axle are in force now (CURVE, d = 0); beyond it they are
    CURVE_AHEAD at their lane distance from the front axle.
    """
    kappa = np.asarray(lane.curvature_at(samples.stations), dtype=np.float64)
    v_c = curve_speed(kappa, params)
    d = np.maximum(samples.distance - samples.distance_at(np.array(s_axle)), 0.0)
    now = samples.stations <= s_axle
    code = np.where(now, _CODE[Binding.CURVE], _CODE[Binding.CURVE_AHEAD])
    return braking_speed(v_c, d, params), d, code


def _limit_constraints(
    road: RoadMap, samples: _Samples, s_front: float, params: SpeedPlanningParams
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """(allowed speed [m/s], distance [m], binding code) per posting ahead of the bumper.

    Only postings beyond the front bumper and within the sampled stations count; higher
    postings never bind (their braking speed exceeds the limit in force) and cost nothing.
    """
    post_s = np.array([p.s for p in road.speed_limits], dtype=np.float64)
    post_v = np.array([p.limit for p in road.speed_limits], dtype=np.float64)
    ahead = (post_s > s_front) & (post_s <= samples.stations[-1])
    d = samples.distance_at(post_s[ahead]) - samples.distance_at(np.array(s_front))
    v = braking_speed(post_v[ahead] - params.limit_margin, d, params)
    return v, d, np.full(d.shape, _CODE[Binding.LIMIT_AHEAD])

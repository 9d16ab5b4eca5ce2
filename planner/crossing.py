"""Vehicles whose motion crosses the car's path through a town junction.

Whatever the junction's control and the car's manoeuvre, a vehicle track in or near the
junction's box (its centre within ``near`` of the box, map frame) that moves (faster than
``moving``) across the car's path is watched: its prediction at constant speed and turn
rate (the rate its velocity's heading turned at between the track's last two states,
`TurnRates`; straight when not known), sampled every ``step`` for t in [0, ``horizon``]
[s], is checked
against the car's path ahead (the route's line from the front bumper to ``beyond`` past the
junction's exit, sampled every ``path_step``). A predicted position within ``clearance``
of a path point (the two half widths and a margin), where the track's heading crosses the
path's at more than ``across`` (the sine of the angle: not a vehicle ahead going the car's
way nor an oncoming one passing in its own lane), is a *conflict* at that point's station,
if the car can be there before the track has gone by: its front, from its speed ``v`` and
accelerating at ``pull_away``, reaches the point no later than the last predicted time
the track's centre is there plus ``step`` and ``after`` (the time a car's length takes to
clear it, and a margin: a post-encroachment time).

The nearest conflict ahead is where the car must not go (`crossing_stop`): it stops at its
stop line when its front is before it and it can stop there at ``line_decel``, else
``standoff`` short of the conflict point (the ACC's stop law brakes as hard as that takes).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from planner.limits import A_COMF, A_FIRM
from world.hdmap import Junction, RoadMap

FloatArray = NDArray[np.float64]


@dataclass(frozen=True, slots=True)
class CrossingParams:
    horizon: float = 4.0  # [s] a track's constant-velocity prediction looked at this far
    step: float = 0.1  # [s] ... sampled this often
    near: float = 6.0  # [m] a track's centre this near the box (or in it) is watched
    moving: float = 0.5  # [m/s] slower than this, a track is not moving
    clearance: float = 2.3  # [m] a predicted centre this near the path's line: a conflict
    #   (two half widths of ~0.95 m and 0.4 m of margin)
    across: float = 0.34  # [-] sin of the least angle between the track's heading and the
    #   path's (20 deg): crossing, not going along or against it
    path_step: float = 0.5  # [m] the car's path is sampled this often
    beyond: float = 5.0  # [m] the path looked at reaches this past the junction's exit
    pull_away: float = A_COMF  # [m/s^2] the car's acceleration towards the conflict point
    line_decel: float = A_FIRM  # [m/s^2] it stops at its line if it can at this
    standoff: float = 3.0  # [m] else its front stops this short of the conflict point
    after: float = 1.5  # [s] the track is taken to hold a conflict point this long after
    #   its predicted centre has left it (post-encroachment time)


def crossing_stop(road: RoadMap, j: Junction, front: float, v: float, xy: FloatArray,
                  vel: FloatArray, p: CrossingParams, offset: float = 0.0,
                  rate: FloatArray | None = None) -> float | None:
    """[m] from the front bumper (station `front`, speed `v` [m/s]) to where the car must
    stand for a vehicle crossing its path at junction `j` (module doc), or None; `xy` (N, 2)
    [m] and `vel` (N, 2) [m/s] the vehicle tracks' centres and velocities (map frame);
    `offset` [m] the kept lane's centre from the route's line (left +)."""
    s = conflict_station(road, j, front, v, xy, vel, p, offset, rate)
    if s is None:
        return None
    room = j.s_stop - front
    if room >= 0.0 and v * v <= 2.0 * p.line_decel * room:
        return room
    return max(s - front - p.standoff, 0.0)


def conflict_station(road: RoadMap, j: Junction, front: float, v: float, xy: FloatArray,
                     vel: FloatArray, p: CrossingParams, offset: float = 0.0,
                     rate: FloatArray | None = None) -> float | None:
    """[m] the station of the nearest conflict on the car's path ahead of `front` at `j`
    (module doc), or None; `rate` (N,) [rad/s] the tracks' turn rates (None: straight)."""
    if rate is None:
        rate = np.zeros(len(xy))
    watched = _watched(j, xy, vel, p)
    end = j.s_exit + p.beyond
    if not watched.any() or front >= end:
        return None
    stations = np.arange(front, end, p.path_step)
    px, py, heading = road.line.pose(stations, np.full_like(stations, offset))
    path = np.column_stack([px, py])  # (M, 2)
    times = np.arange(0.0, p.horizon + 0.5 * p.step, p.step)  # (K,)
    best: float | None = None
    for x0, v0, w in zip(xy[watched], vel[watched], rate[watched], strict=True):
        s = _first_conflict(path, heading, stations, front, v, x0, v0, float(w), times, p)
        if s is not None and (best is None or s < best):
            best = s
    return best


def _watched(j: Junction, xy: FloatArray, vel: FloatArray, p: CrossingParams,
             ) -> NDArray[np.bool_]:
    """(N,) the tracks in or within `near` of `j`'s box that move."""
    if len(xy) == 0:
        return np.zeros(0, dtype=bool)
    reach = j.half_width + p.near
    inside = (np.abs(xy[:, 0] - j.x) <= reach) & (np.abs(xy[:, 1] - j.y) <= reach)
    out: NDArray[np.bool_] = inside & (np.hypot(vel[:, 0], vel[:, 1]) > p.moving)
    return out


def _first_conflict(path: FloatArray, heading: FloatArray, stations: FloatArray,
                    front: float, v: float, x0: FloatArray, v0: FloatArray, rate: float,
                    times: FloatArray, p: CrossingParams) -> float | None:
    """[m] the nearest station of the path (`path` (M, 2) at `stations`, `heading` [rad])
    the track at `x0` moving at `v0` and turning at `rate` [rad/s] crosses in time for the
    car to meet it, or None."""
    predicted, h = predict(x0, v0, rate, times)  # (K, 2), (K,)
    d2 = ((predicted[:, None, :] - path[None, :, :]) ** 2).sum(axis=2)  # (K, M)
    close = d2 < p.clearance ** 2
    if not close.any():
        return None
    sine = np.abs(np.sin(h[:, None] - heading[None, :]))  # (K, M)
    close &= sine > p.across
    for m in np.flatnonzero(close.any(axis=0)):  # path points, nearest first
        gone = float(times[np.flatnonzero(close[:, m])[-1]]) + p.step + p.after  # [s]
        if _reach_time(float(stations[m]) - front, v, p.pull_away) <= gone:
            return float(stations[m])
    return None


def predict(x0: FloatArray, v0: FloatArray, rate: float,
            times: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Positions [m] (K, 2) and headings [rad] (K,) at `times` [s] of a vehicle at `x0`
    with velocity `v0` [m/s] turning at `rate` [rad/s] at constant speed."""
    speed = math.hypot(float(v0[0]), float(v0[1]))
    h0 = math.atan2(float(v0[1]), float(v0[0]))
    h = h0 + rate * times
    if abs(rate) < 1e-3:
        return x0[None, :] + times[:, None] * v0[None, :], h
    r = speed / rate
    x = x0[0] + r * (np.sin(h) - math.sin(h0))
    y = x0[1] - r * (np.cos(h) - math.cos(h0))
    return np.column_stack([x, y]), h


class TurnRates:
    """[rad/s] each track's turn rate: its velocity's heading change between two of its
    states (the tracker's own times: a state seen again between scans changes nothing)."""

    def __init__(self, moving: float) -> None:
        self.moving = moving  # [m/s] slower than this, a heading is not trusted
        # track id -> ([s] state time, [rad] heading, [rad/s] rate)
        self._last: dict[int, tuple[float, float, float]] = {}

    def update(self, times: list[float], ids: list[int], vel: FloatArray) -> FloatArray:
        """(N,) the turn rates of the tracks `ids` with velocities `vel` (N, 2) at their
        state `times` [s]."""
        rates = np.zeros(len(ids))
        seen: dict[int, tuple[float, float, float]] = {}
        for i, (t, tid, (vx, vy)) in enumerate(zip(times, ids, vel.tolist(), strict=True)):
            if math.hypot(vx, vy) <= self.moving:
                continue
            h = math.atan2(vy, vx)
            last = self._last.get(tid)
            if last is not None and t <= last[0]:
                seen[tid] = last
            else:
                rate = 0.0 if last is None else \
                    math.remainder(h - last[1], 2.0 * math.pi) / (t - last[0])
                seen[tid] = (t, h, rate)
            rates[i] = seen[tid][2]
        self._last = seen
        return rates


def _reach_time(distance: float, v: float, a: float) -> float:
    """[s] to cover `distance` [m] from speed v [m/s] accelerating at a [m/s^2]."""
    return (-v + math.sqrt(v * v + 2.0 * a * max(distance, 0.0))) / a

"""Criteria: objects that watch ground truth and give a verdict with a value, threshold and unit.

Each criterion sees a `TruthSample` at the criteria rate (and `no_collision` sees every
contact onset) and keeps what it needs; `result()` returns a `CriterionResult`. The run's
verdict is the conjunction. Definitions follow SCENARIO_FORMAT.md (default criteria) and
the ICCAS normal-driving rule (tyres must not leave the lane).
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from planner.acc import r157_min_gap
from world.actors import ActorPoses
from world.hdmap import RoadMap
from world.spec import ActorType, Crosswalk, SpeedBump, StopSign, TrafficLight

KPH = 1 / 3.6  # [m/s] per km/h
SPEED_TOLERANCE_KPH = 1.0  # [km/h] the speed_limit rule's tolerance
LINE_HALF_WIDTH = 0.075  # [m] half a painted lane line: a tyre touching paint is out
DECEL_WINDOW = 0.2  # [s] moving average of the max_decel criterion


@dataclass(frozen=True, slots=True, eq=False)
class TruthSample:
    """What the criteria see at one instant (all ground truth)."""

    t: float  # [s]
    speed: float  # [m/s] ego forward speed
    station: float  # [m] ego centre station on the route
    front_station: float  # [m] front bumper station
    tyres: NDArray[np.float64]  # [m] (4, 2) tyre patch centres, map frame
    tyre_stations: NDArray[np.float64]  # [m] (4,) their stations
    tyre_offsets: NDArray[np.float64]  # [m] (4,) their offsets from the reference line, left +
    touching: frozenset[int]  # body ids in contact with the ego (ground excluded)
    offset: float = 0.0  # [m] ego centre offset from the reference line, left +
    actors: ActorPoses | None = None  # every NPC now (for gap criteria)
    lane: int = 0  # the lane the stack keeps, or moves into (its plan's command)
    origin_lane: int = 0  # the lane a commanded lane change leaves (== lane otherwise)
    turning: bool = False  # the stack's motion FSM is in a commanded turn (a town junction)
    lateral_accel: float = 0.0  # [m/s^2] speed * yaw rate, left +
    road_curvature: float = 0.0  # [1/m] the route's curvature at the ego's station
    flat: bool = False  # a flat tyre event has happened to the ego
    rear_station: float | None = None  # [m] rear bumper station; None: as far behind the
    #   centre as the front bumper is ahead of it (the body is centred on the car's centre)
    axle_stations: tuple[float, float] | None = None  # [m] (front, rear) axle stations;
    #   None: the centre station plus / less the criterion's axle distances


@dataclass(frozen=True, slots=True)
class CriterionResult:
    name: str
    passed: bool
    value: float
    threshold: float
    unit: str
    first_failure: float | None = None  # [s] sim time it first failed, if it did
    note: str | None = None  # why it failed when the value does not say (nothing happened)

    def as_json(self) -> dict[str, object]:
        out: dict[str, object] = {
            "name": self.name, "passed": self.passed, "value": _round(self.value),
            "threshold": _round(self.threshold), "unit": self.unit,
        }
        if self.first_failure is not None:
            out["first_failure"] = round(self.first_failure, 3)
        if self.note is not None:
            out["note"] = self.note
        return out


def _round(x: float) -> float:
    return round(x, 4) if math.isfinite(x) else x


class Criterion:
    """Base of the criteria: a name, a unit, `update` per sample and a `result`."""

    name = ""
    unit = ""

    def __init__(self) -> None:
        self.first_failure: float | None = None

    def update(self, sample: TruthSample) -> None:
        raise NotImplementedError

    def result(self) -> CriterionResult:
        raise NotImplementedError

    def _fail(self, t: float) -> None:
        if self.first_failure is None:
            self.first_failure = t


class NoCollision(Criterion):
    """The ego touches no actor, building or roadside object: counts contact onsets."""

    name, unit = "no_collision", "contacts"

    def __init__(self, names: dict[int, str]) -> None:
        super().__init__()
        self.names = names  # body id -> what it is (for the event log)
        self.count = 0
        self._touching: frozenset[int] = frozenset()
        self.events: list[tuple[float, str]] = []

    def update(self, sample: TruthSample) -> None:
        for body in sorted(sample.touching - self._touching):
            self.count += 1
            self.events.append((sample.t, self.names.get(body, f"body {body}")))
            self._fail(sample.t)
        self._touching = sample.touching

    def result(self) -> CriterionResult:
        note = "; ".join(f"{what} at {t:.2f} s" for t, what in self.events[:5])
        return CriterionResult(self.name, self.count == 0, self.count, 0, self.unit,
                               self.first_failure, note=note)


class TyresInLane(Criterion):
    """Every tyre stays inside the ego's lane markings: value = least margin [m] of a tyre's
    outer edge to the inner edge of the painted line (negative: on or over the paint).

    The lane is the one the stack keeps. During a commanded lane change (the plan's lane
    differs from its origin lane) the tyres may be anywhere inside the two lanes' outer
    lines; once the change ends, inside the target lane. During a commanded turn through a
    town junction (no lines there) they are not judged; once it ends, inside the lane the
    turn leads into."""

    name, unit = "tyres_in_lane", "m"

    def __init__(self, road: RoadMap, tyre_half_width: float) -> None:
        super().__init__()
        self.road = road
        self.tyre_half_width = tyre_half_width
        self.margin = math.inf

    def update(self, sample: TruthSample) -> None:
        if sample.turning:
            return
        margin = float(np.min(lane_margins(self.road, sample, sample.lane, sample.origin_lane)))
        margin -= self.tyre_half_width
        self.margin = min(self.margin, margin)
        if margin < 0:
            self._fail(sample.t)

    def result(self) -> CriterionResult:
        return CriterionResult(self.name, self.margin >= 0, self.margin, 0.0, self.unit,
                               self.first_failure)


def lane_margins(road: RoadMap, sample: TruthSample, a: int, b: int) -> NDArray[np.float64]:
    """[m] (4,) each tyre patch centre's distance inside the inner edges of the outer lines
    of lanes a..b (one lane when a == b); negative outside."""
    s = sample.tyre_stations
    lo, hi = road.lane(min(a, b)), road.lane(max(a, b))
    c_lo, c_hi = np.asarray(lo.offset_at(s)), np.asarray(hi.offset_at(s))
    centre = 0.5 * (c_lo + c_hi)
    half = 0.5 * (c_hi - c_lo) + np.asarray(lo.width_at(s)) / 2 - LINE_HALF_WIDTH
    return np.asarray(half - np.abs(sample.tyre_offsets - centre), dtype=np.float64)


class SpeedLimit(Criterion):
    """Speed never exceeds the posted limit at the front bumper by more than 1 km/h:
    value = the largest excess [km/h]."""

    name, unit = "speed_limit", "km/h"

    def __init__(self, road: RoadMap) -> None:
        super().__init__()
        self.road = road
        self.excess = -math.inf

    def update(self, sample: TruthSample) -> None:
        limit = float(self.road.speed_limit_at(sample.front_station))
        excess = (sample.speed - limit) / KPH
        self.excess = max(self.excess, excess)
        if excess > SPEED_TOLERANCE_KPH:
            self._fail(sample.t)

    def result(self) -> CriterionResult:
        return CriterionResult(self.name, self.excess <= SPEED_TOLERANCE_KPH, self.excess,
                               SPEED_TOLERANCE_KPH, self.unit, self.first_failure)


class Completes(Criterion):
    """The ego's centre reaches `reach_s` before the end, or it stops (below 0.1 m/s for
    `STOPPED_FOR`) after a flat tyre, a stop the scenario expects: value = farthest
    station [m] (the note says when the flat tyre's stop completed it)."""

    name, unit = "completes", "m"
    STOPPED, STOPPED_FOR = 0.1, 2.0  # [m/s], [s]

    def __init__(self, reach_s: float) -> None:
        super().__init__()
        self.reach_s = reach_s
        self.farthest = -math.inf
        self.stopped_flat = False
        self._since: float | None = None

    def update(self, sample: TruthSample) -> None:
        self.farthest = max(self.farthest, sample.station)
        if not sample.flat or sample.speed >= self.STOPPED:
            self._since = None
            return
        self._since = sample.t if self._since is None else self._since
        self.stopped_flat |= sample.t - self._since >= self.STOPPED_FOR

    @property
    def done(self) -> bool:
        return self.farthest >= self.reach_s or self.stopped_flat

    def result(self) -> CriterionResult:
        note = "stopped after a flat tyre" if self.stopped_flat else None
        return CriterionResult(self.name, self.done, self.farthest, self.reach_s, self.unit,
                               note=note)


class MaxDecel(Criterion):
    """The ego's deceleration (0.2 s moving average) never exceeds the threshold [m/s^2]."""

    name, unit = "max_decel", "m/s^2"

    def __init__(self, threshold: float, rate: float) -> None:
        super().__init__()
        self.threshold = threshold
        self._speeds: deque[float] = deque(maxlen=max(2, round(DECEL_WINDOW * rate) + 1))
        self._window = (self._speeds.maxlen or 2) - 1
        self._rate = rate
        self.peak = 0.0

    def update(self, sample: TruthSample) -> None:
        self._speeds.append(sample.speed)
        if len(self._speeds) == self._speeds.maxlen:
            decel = (self._speeds[0] - self._speeds[-1]) * self._rate / self._window
            self.peak = max(self.peak, decel)
            if decel > self.threshold:
                self._fail(sample.t)

    def result(self) -> CriterionResult:
        return CriterionResult(self.name, self.peak <= self.threshold, self.peak,
                               self.threshold, self.unit, self.first_failure)


class MinGap(Criterion):
    """The bumper gap to the vehicle ahead in the ego's lane is never below the threshold
    (UN R157's d_min(v), or a fixed number of metres) while the ego moves faster than 2 m/s,
    except for `grace` seconds after that vehicle entered the lane ahead (a cut-in) and while
    it brakes harder than 3 m/s^2. Value: the smallest gap [m] checked; its threshold at that
    moment is reported with it (the least margin decides)."""

    name, unit = "min_gap", "m"
    MIN_SPEED = 2.0  # [m/s]
    HARD_BRAKE = 3.0  # [m/s^2]

    def __init__(self, threshold: float | str, road: RoadMap, ego_length: float,
                 grace: float = 10.0) -> None:
        super().__init__()
        self.fixed = None if threshold == "r157" else float(threshold)
        self.road = road
        self.ego_length = ego_length
        self.grace = grace
        self.entered: dict[str, float] = {}  # actor id -> time it entered the lane ahead
        self._started = False
        self.margin = math.inf
        self.gap = math.inf  # [m] at the least margin
        self.threshold = math.nan if self.fixed is None else self.fixed

    def update(self, sample: TruthSample) -> None:
        ahead = vehicles_ahead(sample, self.road, self.ego_length)
        for name in list(self.entered):
            if name not in ahead:
                del self.entered[name]
        for name in ahead:  # a vehicle ahead from the start has not cut in: no grace
            self.entered.setdefault(name, sample.t if self._started else -math.inf)
        self._started = True
        if not ahead or sample.speed <= self.MIN_SPEED:
            return
        name, gap, accel = min(ahead.values(), key=lambda a: a[1])
        if sample.t - self.entered[name] < self.grace or accel < -self.HARD_BRAKE:
            return
        d_min = self.fixed if self.fixed is not None else r157_min_gap(sample.speed)
        if gap - d_min < self.margin:
            self.margin, self.gap, self.threshold = gap - d_min, gap, d_min
        if gap < d_min:
            self._fail(sample.t)

    def result(self) -> CriterionResult:
        return CriterionResult(self.name, self.first_failure is None, self.gap,
                               self.threshold, self.unit, self.first_failure)


def vehicles_ahead(sample: TruthSample, road: RoadMap,
                   ego_length: float) -> dict[str, tuple[str, float, float]]:
    """Actor id -> (id, bumper gap [m], acceleration [m/s^2]) of the vehicles whose centre
    is in the ego's lane band (half a lane width either side of the ego's centre) ahead."""
    a = sample.actors
    if a is None or not len(a.ids):
        return {}
    width = float(road.lane(0).width_at(sample.station))
    lateral = np.abs(a.offsets - sample.offset) < 0.5 * width
    gap = a.stations - sample.station - (2.0 * a.half_sizes[:, 0] + ego_length) / 2
    out = {}
    for i in np.flatnonzero(lateral & (a.stations > sample.station)):
        if a.kinds[i].value in VEHICLES:
            out[a.ids[i]] = (a.ids[i], float(gap[i]), float(a.accels[i]))
    return out


VEHICLES = frozenset({"car", "truck"})


class LaneChangeDuration(Criterion):
    """Each commanded lane change takes at most `threshold` seconds from the first tyre
    leaving the origin lane's markings to all tyres inside the target lane's. Value: the
    longest [s] (one still unfinished at the end counts to the end); fails if no lane change
    was made (the scenario asks for one)."""

    name, unit = "lane_change_duration", "s"

    def __init__(self, road: RoadMap, tyre_half_width: float, threshold: float) -> None:
        super().__init__()
        self.road, self.tyre_half_width, self.threshold = road, tyre_half_width, threshold
        self.durations: list[float] = []
        self._command: tuple[int, int] | None = None  # (origin, lane) at the last sample
        self._change: tuple[int, int] | None = None  # (origin, target) being watched
        self._left: float | None = None  # [s] a tyre left the origin lane
        self._t = 0.0

    def update(self, sample: TruthSample) -> None:
        self._t = sample.t
        command = (sample.origin_lane, sample.lane)
        if sample.lane != sample.origin_lane and command != self._command:
            self._change, self._left = command, None  # a new command (once per change)
        self._command = command
        if self._change is None:
            return
        origin, target = self._change
        w = self.tyre_half_width
        if self._left is None:
            if np.min(lane_margins(self.road, sample, origin, origin)) < w:
                self._left = sample.t
            return
        if sample.t - self._left > self.threshold:
            self._fail(sample.t)
        if np.min(lane_margins(self.road, sample, target, target)) >= w:
            self.durations.append(sample.t - self._left)
            self._change = self._left = None

    def result(self) -> CriterionResult:
        durations = self.durations + ([self._t - self._left] if self._left is not None else [])
        value = max(durations, default=0.0)
        return CriterionResult(self.name, bool(durations) and value <= self.threshold,
                               value, self.threshold, self.unit, self.first_failure,
                               None if durations else "no lane change was made")


class LaneChangeLateralAccel(Criterion):
    """During each commanded lane change and 1 s after, the lateral acceleration the change
    adds (speed * yaw rate less speed^2 * the road's curvature, 0.2 s moving average) stays
    within `threshold`. Value: its peak [m/s^2]; fails if no lane change was made."""

    name, unit = "lane_change_lateral_accel", "m/s^2"
    AFTER = 1.0  # [s]

    def __init__(self, threshold: float, rate: float) -> None:
        super().__init__()
        self.threshold = threshold
        self.window: deque[float] = deque(maxlen=max(1, round(DECEL_WINDOW * rate)))
        self.peak = 0.0
        self.changes = 0
        self._until = -math.inf
        self._changing = False

    def update(self, sample: TruthSample) -> None:
        self.window.append(sample.lateral_accel - sample.speed**2 * sample.road_curvature)
        changing = sample.lane != sample.origin_lane
        if changing and not self._changing:
            self.changes += 1
        self._changing = changing
        if changing:
            self._until = sample.t + self.AFTER
        if sample.t <= self._until and len(self.window) == self.window.maxlen:
            a = abs(sum(self.window) / len(self.window))
            self.peak = max(self.peak, a)
            if a > self.threshold:
                self._fail(sample.t)

    def result(self) -> CriterionResult:
        return CriterionResult(self.name, self.changes > 0 and self.peak <= self.threshold,
                               self.peak, self.threshold, self.unit, self.first_failure,
                               None if self.changes else "no lane change was made")


class StandstillGap(Criterion):
    """Each time the ego stands (below 0.1 m/s for 1 s) behind a vehicle in its lane within
    `reach` metres, the bumper gap is within [low, high]. Value: the standstill gap farthest
    from the band's middle [m], against the bound on its side; fails if it never stood."""

    name, unit = "standstill_gap", "m"
    STOPPED, HOLD, REACH = 0.1, 1.0, 15.0  # [m/s], [s], [m]

    def __init__(self, low: float, high: float, road: RoadMap, ego_length: float) -> None:
        super().__init__()
        self.low, self.high, self.road, self.ego_length = low, high, road, ego_length
        self.gaps: list[float] = []
        self._since: float | None = None

    def update(self, sample: TruthSample) -> None:
        if sample.speed >= self.STOPPED:
            self._since = None
            return
        self._since = sample.t if self._since is None else self._since
        ahead = vehicles_ahead(sample, self.road, self.ego_length)
        gap = min((g for _, g, _ in ahead.values()), default=math.inf)
        if sample.t - self._since < self.HOLD or gap > self.REACH:
            return
        self.gaps.append(gap)
        if not self.low <= gap <= self.high:
            self._fail(sample.t)

    def result(self) -> CriterionResult:
        if not self.gaps:
            return CriterionResult(self.name, False, 0.0, self.low, self.unit, None,
                                   "the ego never stood behind a vehicle")
        mid = 0.5 * (self.low + self.high)
        worst = max(self.gaps, key=lambda g: abs(g - mid))
        bound = self.low if worst < mid else self.high
        return CriterionResult(self.name, self.first_failure is None, worst, bound, self.unit,
                               self.first_failure)


class TimeToResume(Criterion):
    """Once the lane ahead clears (no vehicle in it within 3 s at the wanted speed + 10 m
    that is slower than that speed) while the ego is slower than the wanted speed (the set
    speed, or the posted limit where lower) less 1 km/h, the ego is back at it within
    `threshold` seconds. Value: the longest such wait [s] (one still open at the end counts
    to the end); fails if the lane never cleared with the ego slowed."""

    name, unit = "time_to_resume", "s"

    def __init__(self, threshold: float, set_speed: float, road: RoadMap,
                 ego_length: float) -> None:
        super().__init__()
        self.threshold, self.set_speed, self.road = threshold, set_speed, road
        self.ego_length = ego_length
        self.waits: list[float] = []
        self._clear_at: float | None = None
        self._was_blocked = False
        self._t = 0.0

    def update(self, sample: TruthSample) -> None:
        self._t = sample.t
        want = min(self.set_speed, float(self.road.speed_limit_at(sample.front_station)))
        slow = sample.speed < want - SPEED_TOLERANCE_KPH * KPH
        a = sample.actors
        reach = 3.0 * want + 10.0
        blocking = a is not None and any(
            g <= reach and a.speeds[a.ids.index(name)] < want - SPEED_TOLERANCE_KPH * KPH
            for name, g, _ in vehicles_ahead(sample, self.road, self.ego_length).values())
        if self._clear_at is not None and (not slow or blocking):
            self._close(sample.t)
        if self._clear_at is None and slow and not blocking and self._was_blocked:
            self._clear_at = sample.t
        self._was_blocked = blocking

    def _close(self, t: float) -> None:
        assert self._clear_at is not None
        self.waits.append(t - self._clear_at)
        if self.waits[-1] > self.threshold:
            self._fail(t)
        self._clear_at = None

    def result(self) -> CriterionResult:
        waits = self.waits + ([self._t - self._clear_at] if self._clear_at is not None else [])
        if not waits:
            return CriterionResult(self.name, False, 0.0, self.threshold, self.unit, None,
                                   "the lane ahead never cleared with the ego slowed")
        value = max(waits)
        return CriterionResult(self.name, value <= self.threshold, value, self.threshold,
                               self.unit, self.first_failure)


class StopSigns(Criterion):
    """At each stop line (a `stop_sign` feature's station s) the ego stands, speed below
    0.1 m/s, for at least 1 s with its front bumper 0 to 4 m before the line (s - 4 <= front
    bumper station <= s) before the front bumper is ever over it (> s).

    Value: the shortest standstill [s] over the lines judged, each line's being its longest
    unbroken standstill in that zone before the bumper went over (0 if none). A line is
    judged once the bumper has gone over it or stood for 1 s; a line the run ends before
    (neither) is not, nor one the bumper was already over at the first sample. Fails at the
    first line the bumper goes over without the 1 s stop. No line judged (none on the map):
    value 0, passed."""

    name, unit = "stop_signs", "s"
    STOPPED, HOLD, ZONE = 0.1, 1.0, 4.0  # [m/s], [s], [m]

    def __init__(self, road: RoadMap) -> None:
        super().__init__()
        self.lines = [f.s for f in road.features if isinstance(f, StopSign)]
        self.longest = [0.0] * len(self.lines)  # [s] per line
        self.judged = [False] * len(self.lines)
        self._watched: list[bool] | None = None  # per line: before it at the first sample
        self._since: list[float | None] = [None] * len(self.lines)
        self._over = [False] * len(self.lines)  # the bumper has gone over the line

    def update(self, sample: TruthSample) -> None:
        front = sample.front_station
        if self._watched is None:
            self._watched = [front <= s for s in self.lines]
        for i, s in enumerate(self.lines):
            if not self._watched[i] or self._over[i]:
                continue
            if front > s:
                self._over[i] = self.judged[i] = True
                if self.longest[i] < self.HOLD:  # over it without the stop
                    self._fail(sample.t)
            elif sample.speed < self.STOPPED and front >= s - self.ZONE:
                since = self._since[i]
                if since is None:
                    since = self._since[i] = sample.t
                self.longest[i] = max(self.longest[i], sample.t - since)
                self.judged[i] = self.judged[i] or self.longest[i] >= self.HOLD
            else:
                self._since[i] = None

    def result(self) -> CriterionResult:
        judged = [d for d, j in zip(self.longest, self.judged, strict=True) if j]
        return CriterionResult(self.name, self.first_failure is None, min(judged, default=0.0),
                               self.HOLD, self.unit, self.first_failure)


class RedLights(Criterion):
    """The ego does not enter a junction on red: when its front bumper goes over a traffic
    light's stop line (a `traffic_light` feature's station s), the light is not red.

    Value: the least margin [s] to red over the lines crossed: at each crossing, the time
    left until the light turns red, or minus the time it has been red (fails). No line
    crossed: value +inf, passed."""

    name, unit = "red_lights", "s"

    def __init__(self, road: RoadMap) -> None:
        super().__init__()
        self.lights = [f for f in road.features if isinstance(f, TrafficLight)]
        self.margin = math.inf
        self._front: float | None = None  # [m] the front bumper's station at the last sample

    def update(self, sample: TruthSample) -> None:
        front, before = sample.front_station, self._front
        self._front = front
        if before is None:
            return
        for light in self.lights:
            if before <= light.s < front:
                margin = _margin_to_red(light, sample.t)
                self.margin = min(self.margin, margin)
                if margin < 0.0:
                    self._fail(sample.t)

    def result(self) -> CriterionResult:
        return CriterionResult(self.name, self.first_failure is None, self.margin, 0.0,
                               self.unit, self.first_failure)


def _margin_to_red(light: TrafficLight, t: float) -> float:
    """[s] until `light` turns red at time t, or minus how long it has been red."""
    into = (t + light.phase) % light.cycle
    red_at = light.green + light.yellow
    return red_at - into


class Crosswalks(Criterion):
    """No part of the ego is on a crosswalk while a pedestrian is on it within the ego's
    lane or within 1 m of that lane.

    A crosswalk (a `crosswalk` feature) covers stations [s, s + width] across the paved road.
    The ego covers stations [rear bumper, front bumper]. A pedestrian (an actor of type
    pedestrian) is on it when its footprint (its centre +- the larger of its half length and
    half width, along and across) overlaps the crosswalk, and in the ego's lane when that
    footprint also overlaps, across, the ego's lane widened by 1 m on each side: the lanes
    (of the ego's direction) its tyres are in, at the crosswalk's station. Value: the
    deepest overlap [m] of the ego's stations with a crosswalk while a pedestrian was on it
    in the ego's lane (negative: the ego stayed that far off it); 0 if that never happened
    (or the map has no crosswalk)."""

    name, unit = "crosswalks", "m"
    LANE_MARGIN = 1.0  # [m]

    def __init__(self, road: RoadMap) -> None:
        super().__init__()
        self.road = road
        self.crosswalks = [(f.s, f.s + f.width) for f in road.features
                           if isinstance(f, Crosswalk)]
        self.worst: float | None = None

    @property
    def needs_actors(self) -> bool:
        """Whether it reads the actors (only when the map has a crosswalk)."""
        return bool(self.crosswalks)

    def update(self, sample: TruthSample) -> None:
        a = sample.actors
        if not self.crosswalks or a is None or not len(a.ids):
            return
        walkers = np.array([k is ActorType.PEDESTRIAN for k in a.kinds])
        if not walkers.any():
            return
        reach = np.max(a.half_sizes[:, :2], axis=1)
        rear = (sample.rear_station if sample.rear_station is not None
                else 2.0 * sample.station - sample.front_station)
        for c0, c1 in self.crosswalks:
            right, left = (float(x) for x in self.road.paved_edges(c0))
            lo, hi = self._ego_lanes(sample, c0)
            lo, hi = max(lo - self.LANE_MARGIN, right), min(hi + self.LANE_MARGIN, left)
            on = (walkers & (a.stations + reach >= c0) & (a.stations - reach <= c1)
                  & (a.offsets + reach >= lo) & (a.offsets - reach <= hi))
            if not on.any():
                continue
            overlap = min(sample.front_station, c1) - max(rear, c0)
            self.worst = overlap if self.worst is None else max(self.worst, overlap)
            if overlap > 0.0:
                self._fail(sample.t)

    def _ego_lanes(self, sample: TruthSample, s: float) -> tuple[float, float]:
        """([m] right, [m] left) offsets of the band of ego-direction lanes the tyres are
        in, at station s (a tyre off the lanes counts in the nearest lane)."""
        c = self.road.cross_section_at(s)
        w = c.lane_width
        index = np.clip(np.floor((sample.tyre_offsets + 0.5 * w) / w), 0, c.lanes - 1)
        lo = self.road.lane(int(index.min())).offset_at(s)
        hi = self.road.lane(int(index.max())).offset_at(s)
        return float(lo) - 0.5 * w, float(hi) + 0.5 * w

    def result(self) -> CriterionResult:
        value = 0.0 if self.worst is None else self.worst
        return CriterionResult(self.name, self.first_failure is None, value, 0.0, self.unit,
                               self.first_failure)


class SpeedBumps(Criterion):
    """The ego's speed is at most the bump's pass speed + 1 km/h while either axle is within
    1 m of a speed bump (a `speed_bump` feature centred on station s: axle station in
    [s - length / 2 - 1, s + length / 2 + 1]).

    Value: the largest excess [km/h] of the speed over the bump's pass speed at those
    moments (negative: slower); 0 if an axle never came near a bump (or the map has none)."""

    name, unit = "speed_bumps", "km/h"
    NEAR = 1.0  # [m]

    def __init__(self, road: RoadMap, front_axle: float, rear_axle: float) -> None:
        """`front_axle`, `rear_axle`: [m] from the car's centre, both positive (used when
        a sample does not give the axle stations)."""
        super().__init__()
        self.front_axle, self.rear_axle = front_axle, rear_axle
        self.bumps = [(f.s - 0.5 * f.length - self.NEAR, f.s + 0.5 * f.length + self.NEAR,
                       f.pass_speed) for f in road.features if isinstance(f, SpeedBump)]
        self.worst: float | None = None

    def update(self, sample: TruthSample) -> None:
        axles = sample.axle_stations or (sample.station + self.front_axle,
                                         sample.station - self.rear_axle)
        for lo, hi, pass_speed in self.bumps:
            if not any(lo <= x <= hi for x in axles):
                continue
            excess = (sample.speed - pass_speed) / KPH
            self.worst = excess if self.worst is None else max(self.worst, excess)
            if excess > SPEED_TOLERANCE_KPH:
                self._fail(sample.t)

    def result(self) -> CriterionResult:
        value = 0.0 if self.worst is None else self.worst
        return CriterionResult(self.name, self.first_failure is None, value,
                               SPEED_TOLERANCE_KPH, self.unit, self.first_failure)


@dataclass
class CriteriaSet:
    """All criteria of a run; `verdict` is their conjunction."""

    items: list[Criterion] = field(default_factory=list)

    def update(self, sample: TruthSample) -> None:
        for c in self.items:
            c.update(sample)

    def results(self) -> list[CriterionResult]:
        return [c.result() for c in self.items]

    @property
    def passed(self) -> bool:
        return all(r.passed for r in self.results())

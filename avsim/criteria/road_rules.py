"""Road rules at the map's features: stop lines (`stop_signs`), traffic lights
(`red_lights`), crosswalks (`crosswalks`), speed bumps (`speed_bumps`). They always apply;
a map without the feature gives them nothing to watch."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from avsim.criteria.base import (
    SPEED_TOLERANCE_KPH,
    Criterion,
    CriterionResult,
    Need,
    TruthSample,
)
from avsim.criteria.declaration import Declaration
from avsim.criteria.wording import beside, signed
from world.frames import to_kph
from world.hdmap import Crosswalk, RoadMap, SpeedBump, StopSign
from world.spec import ActorType, TrafficLightSpec


class StopSigns(Criterion):
    """At each stop line (a `stop_sign` feature's station s) the ego stands, speed below
    `STOPPED`, for at least `HOLD` with its front bumper at most `ZONE` before the line
    (s - ZONE <= front bumper station <= s) before the front bumper is ever over it (> s).

    Value: the shortest standstill [s] over the lines judged, each line's being its longest
    unbroken standstill in that zone before the bumper went over (0 if none). A line is
    judged once the bumper has gone over it or stood for `HOLD`; a line the run ends before
    (neither) is not, nor one the bumper was already over at the first sample. An
    infraction at each line the bumper goes over without the stop. No line judged: not
    applicable."""

    name, unit = "stop_signs", "s"
    STOPPED, HOLD, ZONE = 0.1, 1.0, 4.0  # [m/s], [s], [m]

    def __init__(self, road: RoadMap) -> None:
        super().__init__()
        self.lines = [f.s for f in road.features if isinstance(f, StopSign)]
        self.longest = [0.0] * len(self.lines)  # [s] per line
        self.judged = [False] * len(self.lines)  # per line: gone over, or stood HOLD
        self._watched: list[bool] | None = None  # per line: before it at the first sample
        self._since: list[float | None] = [None] * len(self.lines)  # [s] standing since
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
                    shown = beside(self.longest[i], self.HOLD)
                    self._infraction(sample, f"over the stop line at s = {s:.0f} m after a "
                                             f"{shown} s stop ({self.HOLD:g} s needed)")
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
        if not judged:
            return CriterionResult.not_applicable(
                self.name, self.HOLD, self.unit, "the ego met no stop line" if self.lines
                else "no stop line on the route")
        return CriterionResult(self.name, self.first_failure is None, min(judged),
                               self.HOLD, self.unit, self.first_failure)


class RedLights(Criterion):
    """The ego does not enter a junction on red: when its front bumper goes over a traffic
    light's stop line (a `traffic_light` feature's station s), the light is not red.

    Value: the least margin [s] to red over the lines crossed: at each crossing, the time
    left until the light turns red, or minus the time it has been red (fails). No line
    crossed: not applicable. The lights' signal plans are the world's (the truth), not the
    stack's map, which has none."""

    name, unit = "red_lights", "s"

    def __init__(self, lights: Sequence[TrafficLightSpec]) -> None:
        super().__init__()
        self.lights = list(lights)
        self.margin = math.inf  # [s] the least margin to red at a crossing so far
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
                    self._infraction(sample, f"entered the junction at s = {light.s:.0f} m "
                                             f"with a margin of {signed(margin)} s to red "
                                             f"(negative: into red)")

    def result(self) -> CriterionResult:
        if math.isinf(self.margin):
            return CriterionResult.not_applicable(
                self.name, 0.0, self.unit, "the ego crossed no traffic light's stop line"
                if self.lights else "no traffic light on the route")
        return CriterionResult(self.name, self.first_failure is None, self.margin, 0.0,
                               self.unit, self.first_failure)


def _margin_to_red(light: TrafficLightSpec, t: float) -> float:
    """[s] until `light` turns red at time t, or minus how long it has been red."""
    into = (t + light.phase) % light.cycle
    red_at = light.green + light.yellow
    return red_at - into


class Crosswalks(Criterion):
    """No part of the ego is on a crosswalk while a pedestrian is on it within the ego's
    lane or within `LANE_MARGIN` of that lane.

    A crosswalk (a `crosswalk` feature) covers stations [s, s + width] across the paved road.
    The ego covers stations [rear bumper, front bumper]. A pedestrian (an actor of type
    pedestrian) is on it when its footprint (its centre +- the larger of its half length and
    half width, along and across) overlaps the crosswalk, and in the ego's lane when that
    footprint also overlaps, across, the ego's lane widened by `LANE_MARGIN` on each side
    (within the paved road): the lanes (of the ego's direction) its tyres are in, at the
    crosswalk's station. Value: the
    deepest overlap [m] of the ego's stations with a crosswalk while a pedestrian was on it
    in the ego's lane (negative: the ego stayed that far off it). Not applicable when no
    pedestrian was ever on a crosswalk in the ego's lane."""

    name, unit = "crosswalks", "m"
    LANE_MARGIN = 1.0  # [m] the ego's lane band widened by this each side

    def __init__(self, road: RoadMap) -> None:
        super().__init__()
        self.road = road
        self.crosswalks = [(f.s, f.s + f.width) for f in road.features
                           if isinstance(f, Crosswalk)]
        self.worst: float | None = None  # [m] the deepest overlap so far
        self.idle = not self.crosswalks  # no crosswalk: no pedestrians to watch

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
                self._fail(sample, f"{beside(overlap, 0.0)} m onto the crosswalk at s = {c0:.0f} m "
                                   f"with a pedestrian on it")

    def _ego_lanes(self, sample: TruthSample, s: float) -> tuple[float, float]:
        """([m] right, [m] left) offsets of the band of ego-direction lanes the tyres are
        in, at station s (a tyre off the lanes counts in the nearest lane)."""
        c = self.road.cross_section_at(s)
        if c.profile is not None:  # the lanes' edges where they lie at s
            edges = self.road.lane_boundaries(s)[1:c.lanes + 2]
            index = np.clip(np.searchsorted(edges, sample.tyre_offsets, side="right") - 1,
                            0, c.lanes - 1)
            return float(edges[index.min()]), float(edges[index.max() + 1])
        w = c.lane_width
        index = np.clip(np.floor((sample.tyre_offsets + 0.5 * w) / w), 0, c.lanes - 1)
        lo = self.road.lane(int(index.min())).offset_at(s)
        hi = self.road.lane(int(index.max())).offset_at(s)
        return float(lo) - 0.5 * w, float(hi) + 0.5 * w

    def result(self) -> CriterionResult:
        if self.worst is None:
            return CriterionResult.not_applicable(
                self.name, 0.0, self.unit, "no pedestrian was on a crosswalk in the ego's "
                "lane" if self.crosswalks else "no crosswalk on the route")
        return CriterionResult(self.name, self.first_failure is None, self.worst, 0.0,
                               self.unit, self.first_failure)


class SpeedBumps(Criterion):
    """The ego's speed is at most the bump's pass speed + `SPEED_TOLERANCE_KPH` while either
    axle is within `NEAR` of a speed bump (a `speed_bump` feature centred on station s: axle
    station in [s - length / 2 - NEAR, s + length / 2 + NEAR]).

    Value: the largest excess [km/h] of the speed over the bump's pass speed at those
    moments (negative: slower). Not applicable when no axle came near a bump."""

    name, unit = "speed_bumps", "km/h"
    NEAR = 1.0  # [m] an axle this close to a bump's ends is on it

    def __init__(self, road: RoadMap, front_axle: float, rear_axle: float) -> None:
        """`front_axle`, `rear_axle`: [m] from the car's centre, both positive (used when
        a sample does not give the axle stations)."""
        super().__init__()
        self.front_axle, self.rear_axle = front_axle, rear_axle
        self.bumps = [(f.s - 0.5 * f.length - self.NEAR, f.s + 0.5 * f.length + self.NEAR,
                       f.pass_speed) for f in road.features if isinstance(f, SpeedBump)]
        self.worst: float | None = None  # [km/h] the largest excess so far

    def update(self, sample: TruthSample) -> None:
        axles = sample.axle_stations or (sample.station + self.front_axle,
                                         sample.station - self.rear_axle)
        for lo, hi, pass_speed in self.bumps:
            if not any(lo <= x <= hi for x in axles):
                continue
            excess = to_kph(sample.speed - pass_speed)
            self.worst = excess if self.worst is None else max(self.worst, excess)
            if excess > SPEED_TOLERANCE_KPH:
                self._fail(sample, f"speed {to_kph(sample.speed):.1f} km/h over the bump "
                                   f"{to_kph(pass_speed):.0f} km/h by "
                                   f"{beside(excess, SPEED_TOLERANCE_KPH)} km/h")

    def result(self) -> CriterionResult:
        if self.worst is None:
            return CriterionResult.not_applicable(
                self.name, SPEED_TOLERANCE_KPH, self.unit, "no axle came near a speed bump"
                if self.bumps else "no speed bump on the route")
        return CriterionResult(self.name, self.first_failure is None, self.worst,
                               SPEED_TOLERANCE_KPH, self.unit, self.first_failure)


STOP_SIGNS: Declaration[None] = Declaration(
    build=lambda _, run: [StopSigns(run.road)], needs=frozenset({Need.MAP}), always=True)

RED_LIGHTS: Declaration[None] = Declaration(
    build=lambda _, run: [RedLights(run.signals)], needs=frozenset({Need.SIGNALS}), always=True)

CROSSWALKS: Declaration[None] = Declaration(
    build=lambda _, run: [Crosswalks(run.road)], needs=frozenset({Need.MAP, Need.ACTORS}),
    always=True)

SPEED_BUMPS: Declaration[None] = Declaration(
    build=lambda _, run: [SpeedBumps(run.road, run.car.front_axle, run.car.rear_axle)],
    needs=frozenset({Need.MAP, Need.CAR}), always=True)

"""Lane criteria: the tyres stay inside the lane markings (`tyres_in_lane`, always); lane
changes are quick and gentle (`lane_change_duration` and `lane_change_lateral_accel`, when
the scenario sets `lane_change`)."""

from __future__ import annotations

import math
from collections import deque

import numpy as np
from numpy.typing import NDArray
from pydantic import Field

from avsim.criteria.base import (
    DECEL_WINDOW,
    Criterion,
    CriterionResult,
    Need,
    TruthSample,
)
from avsim.criteria.declaration import Declaration, RunInputs
from avsim.scenario.fields import FormatModel, PosFloat
from world.hdmap import RoadMap

LINE_HALF_WIDTH = 0.075  # [m] half a painted lane line: a tyre touching paint is out


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
        self.tyre_half_width = tyre_half_width  # [m]
        self.margin = math.inf  # [m] the least margin so far

    def update(self, sample: TruthSample) -> None:
        if sample.turning:
            return
        margin = float(np.min(lane_margins(self.road, sample, sample.lane, sample.origin_lane)))
        margin -= self.tyre_half_width
        self.margin = min(self.margin, margin)
        if margin < 0:
            self._fail(sample, f"a tyre {-margin:.2f} m past the inner edge of the line (lane "
                               f"{sample.lane})")

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


class LaneChangeDuration(Criterion):
    """Each commanded lane change takes at most `threshold` seconds from the first tyre
    leaving the origin lane's markings to all tyres inside the target lane's. Value: the
    longest [s] (one still unfinished at the end counts to the end); fails if no lane change
    was made (the scenario asks for one)."""

    name, unit = "lane_change_duration", "s"

    def __init__(self, road: RoadMap, tyre_half_width: float, threshold: float) -> None:
        super().__init__()
        self.road, self.tyre_half_width, self.threshold = road, tyre_half_width, threshold
        self.durations: list[float] = []  # [s] every finished lane change
        self._command: tuple[int, int] | None = None  # (origin, lane) at the last sample
        self._change: tuple[int, int] | None = None  # (origin, target) being watched
        self._left: float | None = None  # [s] a tyre left the origin lane
        self._t = 0.0  # [s] the last sample's time

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
            self._fail(sample, f"the lane change from lane {origin} to {target} takes over "
                               f"{self.threshold:g} s")
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
    """During each commanded lane change and `AFTER` it, the lateral acceleration the change
    adds (speed * yaw rate less speed^2 * the road's curvature, moving average over
    `DECEL_WINDOW`) stays within `threshold`. Value: its peak [m/s^2]; fails if no lane
    change was made."""

    name, unit = "lane_change_lateral_accel", "m/s^2"
    AFTER = 1.0  # [s] judged this long after a change ends

    def __init__(self, threshold: float, rate: float) -> None:
        super().__init__()
        self.threshold = threshold
        self.window: deque[float] = deque(maxlen=max(1, round(DECEL_WINDOW * rate)))
        self.peak = 0.0  # [m/s^2] the largest averaged magnitude judged
        self.changes = 0  # commanded lane changes so far
        self._until = -math.inf  # [s] judged up to this time
        self._changing = False  # a change was commanded at the last sample

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
                self._fail(sample, f"lane change lateral acceleration {a:.2f} m/s^2 over "
                                   f"{self.threshold:g} m/s^2")

    def result(self) -> CriterionResult:
        return CriterionResult(self.name, self.changes > 0 and self.peak <= self.threshold,
                               self.peak, self.threshold, self.unit, self.first_failure,
                               None if self.changes else "no lane change was made")


class LaneChangeSetting(FormatModel):
    """Bounds on every commanded lane change; at least one must happen."""

    max_duration: PosFloat = Field(
        default=5.0,
        description="[s] from the first tyre leaving the origin lane to all tyres inside the "
        "target lane, > 0. Default 5.",
    )
    max_lateral_accel: PosFloat = Field(
        default=1.0,
        description="[m/s^2] the lateral acceleration the change adds (0.2 s average), > 0. "
        "Default 1.",
    )


def _lane_change(setting: LaneChangeSetting, run: RunInputs) -> list[Criterion]:
    """The two criteria of a `lane_change` setting."""
    return [LaneChangeDuration(run.road, run.car.tyre_width / 2, setting.max_duration),
            LaneChangeLateralAccel(setting.max_lateral_accel, run.rate)]


TYRES_IN_LANE: Declaration[None] = Declaration(
    build=lambda _, run: [TyresInLane(run.road, run.car.tyre_width / 2)],
    needs=frozenset({Need.MAP, Need.CAR}), always=True)

LANE_CHANGE: Declaration[LaneChangeSetting] = Declaration(
    build=_lane_change, needs=frozenset({Need.MAP, Need.CAR, Need.RATE}), key="lane_change",
    setting=LaneChangeSetting,
    doc="`{max_duration, max_lateral_accel}`: bounds on each lane change; at least one must "
    "happen. Default: off.", example={"max_duration": 5.0, "max_lateral_accel": 1.0})

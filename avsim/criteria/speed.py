"""Speed criteria: the posted limit (`speed_limit`, always) and the deceleration
(`max_decel`, when the scenario sets it; the contact impulse left out,
`avsim.criteria.impulse`)."""

from __future__ import annotations

import math
from collections import deque

from avsim.criteria.base import (
    DECEL_WINDOW,
    SPEED_TOLERANCE_KPH,
    Criterion,
    CriterionResult,
    Need,
    TruthSample,
)
from avsim.criteria.declaration import Declaration
from avsim.criteria.impulse import ImpulseSpans
from avsim.criteria.wording import beside
from avsim.scenario.fields import PosFloat
from world.frames import to_kph
from world.hdmap import RoadMap


class SpeedLimit(Criterion):
    """Speed never exceeds the posted limit at the front bumper's station by more than
    `SPEED_TOLERANCE_KPH`: value = the largest excess [km/h] of the speed over the limit
    (negative: it stayed that far under it)."""

    name, unit = "speed_limit", "km/h"

    def __init__(self, road: RoadMap) -> None:
        super().__init__()
        self.road = road
        self.excess = -math.inf  # [km/h] the largest speed over the limit so far

    def update(self, sample: TruthSample) -> None:
        limit = float(self.road.speed_limit_at(sample.front_station))
        excess = to_kph(sample.speed - limit)
        self.excess = max(self.excess, excess)
        if excess > SPEED_TOLERANCE_KPH:
            shown = beside(excess, SPEED_TOLERANCE_KPH)
            self._fail(sample, f"speed {to_kph(sample.speed):.1f} km/h over the limit "
                               f"{to_kph(limit):.0f} km/h by {shown} km/h")

    def result(self) -> CriterionResult:
        if math.isinf(self.excess):
            return CriterionResult.not_applicable(self.name, SPEED_TOLERANCE_KPH, self.unit,
                                                  "the run had no sample")
        return CriterionResult(self.name, self.excess <= SPEED_TOLERANCE_KPH, self.excess,
                               SPEED_TOLERANCE_KPH, self.unit, self.first_failure)


class MaxDecel(Criterion):
    """The ego's deceleration over `DECEL_WINDOW` never exceeds the threshold [m/s^2]:
    with N = round(DECEL_WINDOW rate) (at least 1) and the last N + 1 speeds v,
    decel = (v_0 - v_N) rate / N, judged once N + 1 samples are in; value = its peak. A
    window that meets a contact's impulse (`avsim.criteria.impulse`) is left out: a
    collision's momentum, not the brakes, changes the speed then (the note says so)."""

    name, unit = "max_decel", "m/s^2"

    def __init__(self, threshold: float, rate: float) -> None:
        super().__init__()
        self.threshold = threshold
        self._speeds: deque[tuple[float, float]] = deque(  # ([s], [m/s])
            maxlen=max(2, round(DECEL_WINDOW * rate) + 1))
        self._window = (self._speeds.maxlen or 2) - 1
        self._rate = rate  # [Hz] the criteria rate
        self.peak = 0.0  # [m/s^2] the largest deceleration so far
        self.impulses = ImpulseSpans()

    def after_judging(self, sample: TruthSample) -> None:
        """The contact spans go on (the note shows where they ended)."""
        self.impulses.update(sample)

    def update(self, sample: TruthSample) -> None:
        self.impulses.update(sample)
        self._speeds.append((sample.t, sample.speed))
        if len(self._speeds) < self._window + 1:
            return
        (t0, v0), (t1, v1) = self._speeds[0], self._speeds[-1]
        if self.impulses.meets(t0, t1):
            return
        decel = (v0 - v1) * self._rate / self._window
        self.peak = max(self.peak, decel)
        if decel > self.threshold:
            self._fail(sample, f"deceleration {beside(decel, self.threshold, 2)} m/s^2 over "
                               f"{self.threshold:g} m/s^2")

    def result(self) -> CriterionResult:
        return CriterionResult(self.name, self.peak <= self.threshold, self.peak,
                               self.threshold, self.unit, self.first_failure,
                               note=self.impulses.describe())


SPEED_LIMIT: Declaration[None] = Declaration(
    build=lambda _, run: [SpeedLimit(run.road)], needs=frozenset({Need.MAP}), always=True)

MAX_DECEL: Declaration[float] = Declaration(
    build=lambda threshold, run: [MaxDecel(threshold, run.rate)], needs=frozenset({Need.RATE}),
    key="max_decel", setting=PosFloat,
    doc="[m/s^2] the ego's deceleration (0.2 s average) never exceeds it, > 0; a contact's "
    "impulse (from its onset until 0.5 s after the bodies part) is left out. Default: off.",
    example=5.0)

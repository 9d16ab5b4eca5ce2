"""Speed criteria: the posted limit and the deceleration."""

from __future__ import annotations

import math
from collections import deque

from avsim.criteria.base import (
    DECEL_WINDOW,
    KPH,
    SPEED_TOLERANCE_KPH,
    Criterion,
    CriterionResult,
    TruthSample,
)
from world.hdmap import RoadMap


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

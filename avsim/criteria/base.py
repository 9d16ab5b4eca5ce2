"""The criteria's common types: the ground-truth sample they watch, a verdict, the base
class and the set of a run.

Each criterion sees a `TruthSample` at the criteria rate (and `no_collision` sees every
contact onset) and keeps what it needs; `result()` returns a `CriterionResult`. The run's
verdict is the conjunction. Definitions follow SCENARIO_FORMAT.md (default criteria) and
the ICCAS normal-driving rule (tyres must not leave the lane).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from world.actors.actor_set import ActorPoses

KPH = 1 / 3.6  # [m/s] per km/h
SPEED_TOLERANCE_KPH = 1.0  # [km/h] the speed_limit rule's tolerance
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

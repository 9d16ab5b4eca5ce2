"""The route: the ego gets where it goes (`completes`), or after a flat tyre comes to a
minimum-risk stop (`minimum_risk_stop`, which also judges the stops in lane after sensor
faults). Both always apply; the scenario's `reach_s` sets
the station to reach (default: the route's end less `END_MARGIN`), and `completes: false`
turns route completion off (a test of a behaviour that need not get anywhere)."""

from __future__ import annotations

import math
from collections import deque

from avsim.criteria.base import (
    DECEL_WINDOW,
    Criterion,
    CriterionResult,
    Need,
    TruthSample,
)
from avsim.criteria.declaration import Declaration
from avsim.criteria.lane import footprint
from avsim.criteria.wording import beside
from avsim.scenario.fields import PosFloat
from world.hdmap import SHOULDER, RoadMap

END_MARGIN = 30.0  # [m] default station to reach: the route's end less this
MRM_DECEL = 4.0  # [m/s^2] the most a minimum-risk manoeuvre may brake (UN R157 5.5.3.4.1)
STOPPED, STOPPED_FOR = 0.1, 2.0  # [m/s], [s] the ego stands: below this speed for this long


class StopAfterFlat:
    """The watch of a minimum-risk stop (truth and map) after a flat tyre, or
    (``after_fault``) after a sensor fault: from the first sample with one on, the
    deceleration's peak (`DECEL_WINDOW` moving average over the samples), and the first
    standstill (below `STOPPED` for `STOPPED_FOR`; after a sensor fault, one that began while
    a fault was running): where it stands and whether the hazard lights flash then. After a
    flat tyre the car stands on the shoulder where the road has one; after a sensor fault it
    stops in its lane (the stack keeps its lane while it stops)."""

    def __init__(self, road: RoadMap, half_tread: float, rate: float,
                 after_fault: bool = False) -> None:
        self.road, self.half_tread = road, half_tread
        self.after_fault = after_fault
        self.flat_at: float | None = None  # [s] the flat tyre (or the first sensor fault)
        #   happened (first sample with it)
        self.peak = 0.0  # [m/s^2] the largest deceleration since the flat
        self.stop: tuple[float, str | None] | None = None  # ([s] the standstill's start, what
        #   is wrong with it: None when it is a minimum-risk stop)
        self._speeds: deque[float] = deque(maxlen=max(2, round(DECEL_WINDOW * rate) + 1))
        self._rate = rate
        self._since: float | None = None  # [s] standing since
        self._in_fault = False  # the standstill began while a sensor fault was running

    def _started(self, sample: TruthSample) -> bool:
        return self.flat_at is not None or (sample.sensor_fault if self.after_fault
                                             else sample.flat)

    def update(self, sample: TruthSample) -> float | None:
        """Watch `sample`; the deceleration [m/s^2] over the window ending now, once the flat
        has happened and the window is full (else None)."""
        self._speeds.append(sample.speed)
        if not self._started(sample) or self.stop is not None:
            return None
        if self.flat_at is None:
            self.flat_at = sample.t
        if sample.speed >= STOPPED:
            self._since = None
        else:
            if self._since is None:
                self._since, self._in_fault = sample.t, sample.sensor_fault
            if sample.t - self._since >= STOPPED_FOR and (self._in_fault or
                                                          not self.after_fault):
                self.stop = (self._since, self._wrong(sample))
        if len(self._speeds) < (self._speeds.maxlen or 2):
            return None
        decel = (self._speeds[0] - self._speeds[-1]) * self._rate / (len(self._speeds) - 1)
        self.peak = max(self.peak, decel)
        return decel

    def _wrong(self, sample: TruthSample) -> str | None:
        """What keeps the standstill at `sample` from being a minimum-risk stop, or None."""
        place = footprint(self.road, sample, self.half_tread)
        shoulder = self.road.cross_section_at(sample.station).shoulder > 0.0
        if not self.after_fault and shoulder and place.lane != SHOULDER:
            return "stood off the shoulder, which the road has there"
        if self.after_fault and (place.lane is None or place.lane < 0):
            return "stood outside a lane of its direction"
        if not shoulder and (place.lane is None or place.lane < 0):
            return "stood outside a lane (the road has no shoulder there)"
        if not sample.hazard_lights:
            return "stood without hazard lights"
        return None

    @property
    def done(self) -> bool:
        """A minimum-risk stop was made."""
        return self.stop is not None and self.stop[1] is None


class MinimumRiskStop(Criterion):
    """After a flat tyre the ego comes to a minimum-risk stop: it stands (below `STOPPED`
    for `STOPPED_FOR`) with every tyre on the paved shoulder where the road has one there,
    else wholly inside a lane of its direction, with its hazard lights flashing, and never
    decelerates harder than `MRM_DECEL` on the way (0.2 s average; UN R157's bound for a
    minimum-risk manoeuvre). After a sensor fault (a scenario's fault event running) the ego
    may drive on (slowed, on the sensors left), but never decelerates harder than
    `MRM_DECEL` from the fault on, and where it stands still during the fault it stands
    wholly inside a lane of its direction with its hazard lights flashing. Value: the peak
    deceleration [m/s^2] from the flat (or the first fault) on. Not applicable without a
    flat tyre or a sensor fault."""

    name, unit = "minimum_risk_stop", "m/s^2"

    def __init__(self, road: RoadMap, half_tread: float, rate: float) -> None:
        super().__init__()
        self.watch = StopAfterFlat(road, half_tread, rate)
        self.fault = StopAfterFlat(road, half_tread, rate, after_fault=True)

    def update(self, sample: TruthSample) -> None:
        for watch, what in ((self.watch, "the flat tyre"), (self.fault, "the sensor fault")):
            stopped = watch.stop is not None
            decel = watch.update(sample)
            if decel is not None and decel > MRM_DECEL:
                shown = beside(decel, MRM_DECEL, 2)
                self._fail(sample, f"deceleration {shown} m/s^2 after {what}, over "
                                   f"{MRM_DECEL:g} m/s^2")
            stop = watch.stop
            if not stopped and stop is not None and stop[1] is not None:
                self._fail(sample, f"after {what} it {stop[1]}", at=stop[0])

    def result(self) -> CriterionResult:
        w, f = self.watch, self.fault
        if w.flat_at is None and f.flat_at is None:
            return CriterionResult.not_applicable(self.name, MRM_DECEL, self.unit,
                                                  "no flat tyre, no sensor fault")
        if w.flat_at is not None:
            note = ("no standstill after the flat tyre" if w.stop is None
                    else None if w.stop[1] is None else f"it {w.stop[1]}")
            passed = w.done
        else:
            note = ("it drove on through the sensor fault" if f.stop is None
                    else "a minimum-risk stop in lane during the sensor fault"
                    if f.stop[1] is None else f"it {f.stop[1]}")
            passed = f.stop is None or f.done
        return CriterionResult(self.name, self.first_failure is None and passed,
                               max(w.peak, f.peak), MRM_DECEL, self.unit, self.first_failure,
                               note)


class Completes(Criterion):
    """The ego's centre reaches `reach_s` before the end, or after a flat tyre it makes a
    minimum-risk stop (`StopAfterFlat`, what `minimum_risk_stop` judges). Value: the
    farthest centre station [m] (the note says when the stop completed it)."""

    name, unit = "completes", "m"

    def __init__(self, reach_s: float, road: RoadMap, half_tread: float, rate: float) -> None:
        super().__init__()
        self.reach_s = reach_s  # [m] station to reach
        self.farthest = -math.inf  # [m] the farthest centre station so far
        self.stop = StopAfterFlat(road, half_tread, rate)

    def update(self, sample: TruthSample) -> None:
        self.farthest = max(self.farthest, sample.station)
        self.stop.update(sample)

    @property
    def done(self) -> bool:
        """Whether the route is completed (reached, or a minimum-risk stop made)."""
        return self.farthest >= self.reach_s or self.stop.done

    def result(self) -> CriterionResult:
        if math.isinf(self.farthest):
            return CriterionResult.not_applicable(self.name, self.reach_s, self.unit,
                                                  "the run had no sample")
        note = ("a minimum-risk stop after a flat tyre" if self.stop.done
                and self.farthest < self.reach_s else None)
        return CriterionResult(self.name, self.done, self.farthest, self.reach_s, self.unit,
                               note=note)


COMPLETES: Declaration[float | None] = Declaration(
    build=lambda reach_s, run: [Completes(
        reach_s if reach_s is not None else run.road.length - END_MARGIN, run.road,
        run.car.tyre_width / 2, run.rate)],
    needs=frozenset({Need.MAP, Need.CAR, Need.RATE}), key="reach_s", always=True,
    on_route=True, setting=PosFloat, switch="completes",
    doc="[m] station the ego must reach, > 0, on the route. Default: the end of the route "
    "less 30 m.", example=300.0)

MINIMUM_RISK_STOP: Declaration[None] = Declaration(
    build=lambda _, run: [MinimumRiskStop(run.road, run.car.tyre_width / 2, run.rate)],
    needs=frozenset({Need.MAP, Need.CAR, Need.RATE}), always=True)

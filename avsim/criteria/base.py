"""The criteria's common types: the ground-truth sample they watch, what they may need from
the run, a verdict, an infraction, the base class and the set of a run.

Each criterion sees a `TruthSample` at the criteria rate (and `no_collision` sees every
contact onset) and keeps what it needs; `result()` returns a `CriterionResult`. The run's
verdict is the conjunction. When a criterion is broken it says so at once: an `Infraction`
(when, which criterion, what happened, where), which the runner collects after each update
and the recording logs at its sim time. A threshold criterion reports its first failure (a
limit exceeded for several seconds is one infraction, at its start); an event that breaks a
rule each time it happens (a contact, a stop line run, a red light entered, a wait too
long) is reported every time. Definitions follow SCENARIO_FORMAT.md (default criteria) and
the ICCAS normal-driving rule (tyres must not leave the lane).
"""

from __future__ import annotations

import dataclasses
import enum
import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, TypeVar

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from world.actors.actor_set import ActorPoses

SPEED_TOLERANCE_KPH = 1.0  # [km/h] the speed_limit rule's tolerance
DECEL_WINDOW = 0.2  # [s] moving average of the max_decel criterion
MAX_LANE_CHANGE = 8.0  # [s] a lane change's bound for `tyres_in_lane` when the scenario
#   sets no `lane_change` (then its `max_duration`)


class Need(enum.Enum):
    """What a criterion needs from the run besides the ego's truth in each sample. The
    value is the name of the `avsim.criteria.declaration.RunInputs` field it is built from,
    or (`ACTORS`) of the `TruthSample` field the run fills for it."""

    MAP = "road"  # the route's static map (`world.hdmap.RoadMap`)
    CAR = "car"  # the ego's geometry (`vehicle_urdf.CarGeometry`)
    RATE = "rate"  # [Hz] the criteria rate
    SIGNALS = "signals"  # the route's signal plans (`World.signals`, ground truth)
    SET_SPEED = "set_speed"  # [m/s] the driver's set speed
    BODIES = "bodies"  # what each body the ego may touch is (body id -> name)
    ACTORS = "actors"  # the NPCs' true poses in every sample (costly: only when needed)
    LANE_CHANGE = "lane_change_max"  # [s] how long a lane change may take
    STORY = "story"  # the scenario's required actions and events (`story_label`s)
    STORY_OFF = "story_off"  # the actions the file switches off by configuration, and why
    ACTOR_BODIES = "actor_bodies"  # which actor each NPC body is (body id -> actor id)
    TOWN = "town"  # the town's layout (`world.spec.TownSpec`; None on a road)
    PARAMETERS = "parameters"  # an OpenSCENARIO file's global parameters (name -> value)


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
    actors: ActorPoses | None = None  # every NPC now; None unless a criterion needs them
    #   (`Need.ACTORS`)
    lateral_accel: float = 0.0  # [m/s^2] speed * yaw rate, left +
    road_curvature: float = 0.0  # [1/m] the route's curvature at the ego's station
    flat: bool = False  # a flat tyre event has happened to the ego
    hazard_lights: bool = False  # the ego's hazard lights are flashing (its lamps' state)
    sensor_fault: bool = False  # a scenario's sensor fault is running now (the event's truth)
    fired: frozenset[str] = frozenset()  # the scripted actions and events fired so far
    #   (`avsim.criteria.story.story_label`)
    rear_station: float | None = None  # [m] rear bumper station; None: as far behind the
    #   centre as the front bumper is ahead of it (the body is centred on the car's centre)
    axle_stations: tuple[float, float] | None = None  # [m] (front, rear) axle stations;
    #   None: the centre station plus / less the criterion's axle distances
    xy: tuple[float, float] | None = None  # [m] the ego's centre, map frame; None: unknown


@dataclass(frozen=True, slots=True)
class Infraction:
    """A criterion broken at one moment, reported when it happens."""

    t: float  # [s] sim time
    kind: str  # the criterion's name (`no_collision`, `speed_limit`, ...)
    message: str  # what happened, one line with its values and units
    where: tuple[float, float] | None  # [m] map frame (x, y): the ego's centre then

    def as_json(self) -> dict[str, object]:
        """As the result file has it: t [s] and where [m] rounded."""
        where = None if self.where is None else [round(x, 3) + 0.0 for x in self.where]  # no -0
        return {"t": round(self.t, 4), "kind": self.kind, "message": self.message,
                "where": where}


class Verdict(enum.Enum):
    """A criterion's verdict. `NOT_APPLICABLE`: its situation never happened in the run (no
    stop line on the route, no pedestrian on a crosswalk); it neither passes nor fails the
    run. A criterion the scenario asked for by name fails instead (its note says what never
    happened)."""

    PASS = "pass"
    FAIL = "fail"
    NOT_APPLICABLE = "not_applicable"


@dataclass(frozen=True, slots=True)
class CriterionResult:
    """A criterion's verdict: its measured value against its threshold, in `unit`.

    `passed` is None when the criterion is not applicable (its value is then None too, and
    `note` says what never happened). Values and thresholds are finite or None: a run's
    result is strict JSON."""

    name: str  # the criterion's name
    passed: bool | None  # None: not applicable
    value: float | None  # [unit] the measured value the verdict rests on; None: none
    threshold: float | None  # [unit]; None: none (a limit that depends on what was met)
    unit: str  # the unit of value and threshold
    first_failure: float | None = None  # [s] sim time it first failed, if it did
    note: str | None = None  # why it failed when the value does not say, what never
    #   happened (not applicable), or what qualifies a verdict (a contact a rule excuses,
    #   samples left out, the judging ended early)
    details: tuple[tuple[str, str | float | bool | None], ...] = ()  # (key, value) of a
    #   verdict that is more than a value (the Euro NCAP test, its speeds and points)

    def __post_init__(self) -> None:
        for what, x in (("value", self.value), ("threshold", self.threshold)):
            if x is not None and not math.isfinite(x):
                raise ValueError(f"criterion {self.name}: {what} {x} is not finite")
        if self.passed is None and (self.value is not None or self.note is None):
            raise ValueError(f"criterion {self.name}: not applicable needs no value and a note")

    @classmethod
    def not_applicable(cls, name: str, threshold: float | None, unit: str,
                       note: str) -> CriterionResult:
        """The result of a criterion whose situation never happened: `note` says what."""
        return cls(name, None, None, threshold, unit, None, note)

    @property
    def verdict(self) -> Verdict:
        if self.passed is None:
            return Verdict.NOT_APPLICABLE
        return Verdict.PASS if self.passed else Verdict.FAIL

    @property
    def failed(self) -> bool:
        """It failed (a criterion not applicable did not)."""
        return self.passed is False

    def as_json(self) -> dict[str, object]:
        """As the result file has it: values rounded, optional keys only when set."""
        out: dict[str, object] = {
            "name": self.name, "verdict": self.verdict.value, "passed": self.passed,
            "value": _round(self.value), "threshold": _round(self.threshold),
            "unit": self.unit,
        }
        if self.first_failure is not None:
            out["first_failure"] = round(self.first_failure, 3)
        if self.note is not None:
            out["note"] = self.note
        if self.details:
            out["details"] = {k: _round(v) if isinstance(v, float) else v
                              for k, v in self.details}
        return out


def judged_so_far(results: list[CriterionResult], t: float,
                  why: str = "the run was interrupted") -> list[CriterionResult]:
    """The results of a run whose judging stopped at `t` [s] (`why`: interrupted, or an
    unavoidable collision): what was judged so far stands (a pass so far, a failure seen
    happen, which has its `first_failure`); a failure that only the run's end would have
    settled (the goal not reached yet, an action not fired yet, no standstill yet: no
    `first_failure`) could not be judged, and is not applicable."""
    return [r if r.passed is not False or r.first_failure is not None else
            CriterionResult.not_applicable(
                r.name, r.threshold, r.unit,
                f"not judged: {why} at {t:.2f} s"
                + (f" ({r.note})" if r.note else ""))
            for r in results]


def _noted(result: CriterionResult, note: str) -> CriterionResult:
    """`result` with `note` after its own note."""
    both = note if result.note is None else f"{result.note}; {note}"
    return dataclasses.replace(result, note=both)


def _round(x: float | None) -> float | None:
    """x to 4 decimals (no -0.0); None as it is."""
    return None if x is None else round(x, 4) + 0.0


class Criterion:
    """Base of the criteria: a name, a unit, `update` per sample and a `result`; failures
    and infractions through `_fail` and `_infraction`."""

    name = ""  # the result's name
    unit = ""  # the value's unit

    def __init__(self) -> None:
        self.first_failure: float | None = None  # [s] sim time of the first failure
        self.idle = False  # this run gives it nothing to watch (no such feature on the map):
        #   the samples need not carry what only it needs
        self.ends_judging: str | None = None  # set when what it saw ends the judging of the
        #   whole run (an unavoidable collision): what happened, for the other results' notes
        self._new: list[Infraction] = []  # not yet taken by the run

    def update(self, sample: TruthSample) -> None:
        """Watch one sample."""
        raise NotImplementedError

    def after_judging(self, sample: TruthSample) -> None:
        """Watch one sample after the judging of the run has ended (`CriteriaSet`): not
        judged, but a criterion may keep counting what the run's metrics report (every
        contact). Nothing by default."""

    def result(self) -> CriterionResult:
        """The verdict on the samples seen."""
        raise NotImplementedError

    def take_infractions(self) -> list[Infraction]:
        """The infractions since the last call, in the order they happened."""
        new, self._new = self._new, []
        return new

    def _fail(self, sample: TruthSample, message: str, at: float | None = None) -> None:
        """It fails now (`at`: it is known now that it failed then, [s]); its first failure
        is an infraction, later ones (the same condition going on, or again) are not."""
        if self.first_failure is None:
            self._infraction(sample, message, at)

    def _infraction(self, sample: TruthSample, message: str, at: float | None = None) -> None:
        """An infraction now (it fails too): for an event that breaks the rule each time."""
        if self.first_failure is None:
            self.first_failure = sample.t if at is None else at
        self._new.append(Infraction(sample.t, self.name, message, sample.xy))


C = TypeVar("C", bound=Criterion)


@dataclass
class CriteriaSet:
    """All criteria of a run; `verdict` is their conjunction. A criterion may end the
    judging (`Criterion.ends_judging`: a collision UN R157 labels unavoidable, whose
    aftermath, the car pushed across the lane, is no behaviour of the stack's): from then
    on no criterion judges a sample (each still sees it through `after_judging`), and the
    results are those judged until then, each of the others' verdicts noted so."""

    items: list[Criterion] = field(default_factory=list)
    needs: frozenset[Need] = frozenset()  # what the samples must carry for them
    ended: tuple[float, str] | None = None  # ([s], why) the judging ended, None: it goes on

    def update(self, sample: TruthSample) -> list[Infraction]:
        """Every criterion sees the sample; the infractions it brought, in criteria order."""
        if self.ended is not None:
            for c in self.items:
                c.after_judging(sample)
            return []
        for c in self.items:
            c.update(sample)
        for c in self.items:
            if c.ends_judging is not None:
                self.ended = (sample.t, c.ends_judging)
                break
        return [i for c in self.items for i in c.take_infractions()]

    def results(self) -> list[CriterionResult]:
        """Every criterion's result, in the set's order."""
        results = [c.result() for c in self.items]
        if self.ended is None:
            return results
        t, why = self.ended
        judged = judged_so_far(results, t, f"judging ended with {why}")
        return [r if r.passed is None or c.ends_judging is not None else
                _noted(r, f"judged until {t:.2f} s: judging ended with {why}")
                for c, r in zip(self.items, judged, strict=True)]

    def find(self, kind: type[C]) -> C:
        """The set's criterion of class `kind` (the first, if there are several)."""
        for c in self.items:
            if isinstance(c, kind):
                return c
        raise LookupError(f"the set has no {kind.__name__}")

    @property
    def passed(self) -> bool:
        """The run's verdict: no criterion failed (one not applicable does not fail it)."""
        return not any(r.failed for r in self.results())

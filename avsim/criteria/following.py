"""Following criteria, against the vehicle ahead in the ego's lane: the gap while moving
(`min_gap`), the gap at a standstill (`standstill_gap`), and the time to resume once the
lane clears (`resume_within`, criterion `time_to_resume`); each when the scenario sets
its key. They read the NPCs' true poses (`Need.ACTORS`)."""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

from pydantic import AfterValidator, BeforeValidator, Field

from avsim.criteria.base import (
    SPEED_TOLERANCE_KPH,
    Criterion,
    CriterionResult,
    Need,
    TruthSample,
)
from avsim.criteria.declaration import Declaration
from avsim.criteria.regulations import r157_min_gap
from avsim.criteria.wording import beside
from avsim.scenario.fields import NonNegFloat, PosFloat, problem
from world.frames import kph
from world.hdmap import RoadMap
from world.truth import VehicleAhead, vehicles_ahead

R157 = "r157"  # the min_gap setting for UN R157's d_min(v)


class MinGap(Criterion):
    """The bumper gap to the nearest vehicle ahead in the ego's lane is never below the
    threshold (UN R157's d_min(v), or a fixed number of metres) while the ego moves faster
    than `MIN_SPEED`, except for `grace` [s] after that vehicle entered the lane ahead (a
    cut-in) and while it brakes harder than `HARD_BRAKE`. Value: the gap [m] at the least
    margin (gap - threshold) checked, reported with its threshold at that moment."""

    name, unit = "min_gap", "m"
    MIN_SPEED = 2.0  # [m/s] the ego slower than this is not judged
    HARD_BRAKE = 3.0  # [m/s^2] a vehicle ahead braking harder is not held against the ego

    def __init__(self, threshold: float | str, road: RoadMap, ego_length: float,
                 grace: float = 10.0) -> None:
        super().__init__()
        self.fixed = None if threshold == R157 else float(threshold)
        self.road = road
        self.ego_length = ego_length
        self.grace = grace
        self.entered: dict[str, float] = {}  # actor id -> [s] when it entered the lane ahead
        self._started = False  # a sample has been seen (vehicles ahead then: no cut-in)
        self.margin = math.inf  # [m] the least gap - threshold so far
        self.gap: float | None = None  # [m] at the least margin; None: no gap checked
        self.threshold = self.fixed  # [m] at the least margin (r157: None until a gap is
        #   checked)

    def update(self, sample: TruthSample) -> None:
        ahead = ahead_of(sample, self.road, self.ego_length)
        names = {v.id for v in ahead}
        for name in list(self.entered):
            if name not in names:
                del self.entered[name]
        for name in names:  # a vehicle ahead from the start has not cut in: no grace
            self.entered.setdefault(name, sample.t if self._started else -math.inf)
        self._started = True
        if not ahead or sample.speed <= self.MIN_SPEED:
            return
        lead = ahead[0]
        name, gap = lead.id, lead.gap
        if sample.t - self.entered[name] < self.grace or lead.accel < -self.HARD_BRAKE:
            return
        d_min = self.fixed if self.fixed is not None else r157_min_gap(sample.speed)
        if gap - d_min < self.margin:
            self.margin, self.gap, self.threshold = gap - d_min, gap, d_min
        if gap < d_min:
            self._fail(sample, f"gap {beside(gap, d_min)} m to {name} under {d_min:.1f} m")

    def result(self) -> CriterionResult:
        if self.gap is None:  # asked for by name: it fails
            return CriterionResult(self.name, False, None, self.threshold, self.unit, None,
                                   "no vehicle ahead in the ego's lane was ever judged (the "
                                   "ego faster than 2 m/s, no cut-in grace)")
        return CriterionResult(self.name, self.first_failure is None, self.gap,
                               self.threshold, self.unit, self.first_failure)


class FollowingGap(MinGap):
    """UN R157 5.2.3.3's minimum following distance d_min(v), where the regulation applies
    it: while the ego follows a moving vehicle ahead in its lane, as `MinGap` judges it (the
    same grace after a cut-in and exemption while the vehicle ahead brakes hard), but not
    behind a vehicle at rest (a blocking target is not a vehicle to follow). Not applicable
    when the ego followed no vehicle."""

    name = "following_gap"
    LEAD_MOVING = 2.0  # [m/s] a vehicle ahead slower than this is not followed

    def __init__(self, road: RoadMap, ego_length: float) -> None:
        super().__init__(R157, road, ego_length)

    def update(self, sample: TruthSample) -> None:
        ahead = ahead_of(sample, self.road, self.ego_length)
        if ahead and ahead[0].speed < self.LEAD_MOVING:
            self._forget_standing(sample, ahead[0].id)
            return
        super().update(sample)

    def _forget_standing(self, sample: TruthSample, name: str) -> None:
        """Behind a standing vehicle: nothing judged (its entry time kept for the grace)."""
        self.entered.setdefault(name, sample.t if self._started else -math.inf)
        self._started = True

    def result(self) -> CriterionResult:
        if self.gap is None:
            return CriterionResult.not_applicable(
                self.name, self.threshold, self.unit,
                "the ego followed no moving vehicle in its lane (UN R157 5.2.3.3 applies "
                "to following)")
        return super().result()


def ahead_of(sample: TruthSample, road: RoadMap,
             ego_length: float) -> tuple[VehicleAhead, ...]:
    """The vehicles ahead of the ego in its lane at `sample`, nearest first
    (`world.truth.vehicles_ahead`: from the truth and the map)."""
    if sample.actors is None:
        return ()
    return vehicles_ahead(road, sample.actors, sample.station, sample.offset, ego_length)


class StandstillGap(Criterion):
    """Each time the ego stands (below `STOPPED` for `HOLD`) behind a vehicle in its lane
    within `REACH` that stands too, the bumper gap is within [low, high] (UN R157 4.2.1:
    the gap to a vehicle at rest; once it drives off the gap opens until the ego follows).
    Value: the standstill gap farthest from the band's middle [m], against the bound on its
    side; not applicable if it never stood behind a standing vehicle (the vehicle ahead
    drove off before the ego came to rest behind it)."""

    name, unit = "standstill_gap", "m"
    STOPPED, HOLD, REACH = 0.1, 1.0, 15.0  # [m/s], [s], [m]

    def __init__(self, low: float, high: float, road: RoadMap, ego_length: float) -> None:
        super().__init__()
        self.low, self.high, self.road, self.ego_length = low, high, road, ego_length
        self.worst: float | None = None  # [m] the standstill gap judged farthest from the
        #   band's middle (None: none judged; one number, not every sample: an hour's run)
        self._since: float | None = None  # [s] since when the ego stands

    def update(self, sample: TruthSample) -> None:
        if sample.speed >= self.STOPPED:
            self._since = None
            return
        self._since = sample.t if self._since is None else self._since
        ahead = ahead_of(sample, self.road, self.ego_length)
        gap = ahead[0].gap if ahead else math.inf
        if sample.t - self._since < self.HOLD or gap > self.REACH or \
                ahead[0].speed >= self.STOPPED:
            return
        mid = 0.5 * (self.low + self.high)
        if self.worst is None or abs(gap - mid) > abs(self.worst - mid):
            self.worst = gap
        if not self.low <= gap <= self.high:
            shown = beside(gap, self.low if gap < self.low else self.high)
            self._fail(sample, f"standing {shown} m behind the vehicle ahead, outside "
                               f"[{self.low:g}, {self.high:g}] m")

    def result(self) -> CriterionResult:
        if self.worst is None:
            return CriterionResult.not_applicable(
                self.name, self.low, self.unit, "the ego never stood behind a standing vehicle")
        mid = 0.5 * (self.low + self.high)
        worst = self.worst
        bound = self.low if worst < mid else self.high
        return CriterionResult(self.name, self.first_failure is None, worst, bound, self.unit,
                               self.first_failure)


class TimeToResume(Criterion):
    """Once the lane ahead clears while the ego is slow, the ego is back at its wanted speed
    within `threshold` [s].

    The wanted speed is the set speed, or the posted limit where lower; slow is below it
    less `SPEED_TOLERANCE_KPH`. The lane is blocked by a vehicle ahead in it, within
    3 s at the wanted speed + 10 m, that is itself slow; it clears when it was blocked and
    is not. A wait runs from the clearing until the ego is no longer slow or the lane is
    blocked again. Value: the longest wait [s] (one still open at the end counts to the
    end); fails if the lane never cleared with the ego slowed."""

    name, unit = "time_to_resume", "s"

    def __init__(self, threshold: float, set_speed: float, road: RoadMap,
                 ego_length: float) -> None:
        super().__init__()
        self.threshold, self.set_speed, self.road = threshold, set_speed, road
        self.ego_length = ego_length
        self.waits: list[float] = []  # [s] every closed wait
        self._clear_at: float | None = None  # [s] when the open wait began
        self._was_blocked = False  # the lane was blocked at the last sample
        self._t = 0.0  # [s] the last sample's time

    def update(self, sample: TruthSample) -> None:
        self._t = sample.t
        want = min(self.set_speed, float(self.road.speed_limit_at(sample.front_station)))
        slow = sample.speed < want - kph(SPEED_TOLERANCE_KPH)
        reach = 3.0 * want + 10.0
        blocking = any(v.gap <= reach and v.speed < want - kph(SPEED_TOLERANCE_KPH)
                       for v in ahead_of(sample, self.road, self.ego_length))
        if self._clear_at is not None and (not slow or blocking):
            self._close(sample)
        if self._clear_at is None and slow and not blocking and self._was_blocked:
            self._clear_at = sample.t
        self._was_blocked = blocking

    def _close(self, sample: TruthSample) -> None:
        """End the open wait now; an infraction if it was too long."""
        assert self._clear_at is not None
        wait = sample.t - self._clear_at
        self.waits.append(wait)
        if wait > self.threshold:
            shown = beside(wait, self.threshold)
            self._infraction(sample, f"{shown} s to resume after the lane ahead cleared, "
                                     f"over {self.threshold:g} s")
        self._clear_at = None

    def result(self) -> CriterionResult:
        waits = self.waits + ([self._t - self._clear_at] if self._clear_at is not None else [])
        if not waits:
            return CriterionResult(self.name, False, None, self.threshold, self.unit, None,
                                   "the lane ahead never cleared with the ego slowed")
        value = max(waits)
        return CriterionResult(self.name, value <= self.threshold, value, self.threshold,
                               self.unit, self.first_failure)


def _r157_or_metres(value: Any) -> Any:
    """`min_gap`'s value if it is `r157` or a number > 0, else the format's problem."""
    is_number = isinstance(value, int | float) and not isinstance(value, bool)
    if value == R157 or (is_number and value > 0):
        return value
    raise problem(f"must be r157 or a number of metres > 0, got {value!r}")


def _low_below_high(value: tuple[float, float]) -> tuple[float, float]:
    """`standstill_gap`'s band if low < high, else the format's problem."""
    if not value[0] < value[1]:
        raise problem(f"low must be below high, got {list(value)}")
    return value


MinGapSetting = Annotated[Literal["r157"] | PosFloat, BeforeValidator(_r157_or_metres)]
StandstillGapSetting = Annotated[tuple[NonNegFloat, PosFloat], Field(strict=False),
                                 AfterValidator(_low_below_high)]

MIN_GAP: Declaration[float | str] = Declaration(
    build=lambda threshold, run: [MinGap(threshold, run.road, run.car.body_length)],
    needs=frozenset({Need.MAP, Need.CAR, Need.ACTORS}), key="min_gap", setting=MinGapSetting,
    doc="`r157` (UN R157 d_min(v)) or a number [m] > 0: minimum bumper gap to the vehicle "
    "ahead. Default: off.", example=R157)

FOLLOWING_GAP: Declaration[str] = Declaration(
    build=lambda _, run: [FollowingGap(run.road, run.car.body_length)],
    needs=frozenset({Need.MAP, Need.CAR, Need.ACTORS}), key="following_gap",
    setting=Literal["r157"],
    doc="`r157`: UN R157 5.2.3.3's minimum following distance d_min(v) while the ego "
    "follows a moving vehicle in its lane, as `min_gap: r157` judges it; not applicable "
    "when it follows none. Default: off.", example=R157)

STANDSTILL_GAP: Declaration[tuple[float, float]] = Declaration(
    build=lambda band, run: [StandstillGap(*band, run.road, run.car.body_length)],
    needs=frozenset({Need.MAP, Need.CAR, Need.ACTORS}), key="standstill_gap",
    setting=StandstillGapSetting,
    doc="[m] `[low, high]`: the bumper gap to the vehicle ahead each time the ego stands "
    "behind it while it stands too; not applicable if that never happens. Default: off.",
    example=[2.0, 6.0])

RESUME_WITHIN: Declaration[float] = Declaration(
    build=lambda threshold, run: [TimeToResume(threshold, run.set_speed, run.road,
                                               run.car.body_length)],
    needs=frozenset({Need.MAP, Need.CAR, Need.SET_SPEED, Need.ACTORS}), key="resume_within",
    setting=PosFloat,
    doc="[s] once the lane ahead clears, the ego is back at its wanted speed within this, "
    "> 0; the lane must clear at least once with the ego slowed. Default: off.",
    example=15.0)

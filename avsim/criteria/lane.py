"""Lane criteria, judged from the truth and the map only (never the stack's plan): the
tyres stay inside the lanes of the ego's direction (`tyres_in_lane`, always) and cross a
lane line only to change lanes, quickly; lane changes are quick and gentle
(`lane_change_duration` and `lane_change_lateral_accel`, when the scenario sets
`lane_change`).

Where the footprint is (`footprint`): each tyre patch, with its tread's half width, is in a
lane when it lies wholly inside that lane's painted lines (a tyre on the paint is on the
line). The lanes are the route's lanes of the ego's direction at the tyre's station; after
a flat tyre the paved shoulder counts as one more (a minimum-risk stop pulls onto it).
Where the map paints the centre line broken (on a segment of uniform lanes), the oncoming
lanes count too, as lanes -1, -2, ...: a pass through them is lane changes out and back,
each bounded like any, and a stay wholly in an oncoming lane of at most
`MAX_ONCOMING_STAY`. Across a solid centre line (what a road not painted by a map file
has) the oncoming lanes are a departure, as ever.
Inside a town junction (the ego's centre station between a junction's `s_enter` and
`s_exit`) there is no paint: the tyres must stay inside the turn corridor, the route's
lanes of the ego's direction along its turn path, edge to edge.

A lane change, from the truth (`LaneChanges`): the footprint leaves the lane all its tyres
were in (a tyre on or over a line), and it ends when all tyres are in one lane again. It is
a lane change when that lane is another; when it is the same lane the tyres crossed the
line and came back, which no lane change allows.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from pydantic import Field

from avsim.criteria.base import (
    DECEL_WINDOW,
    MAX_LANE_CHANGE,
    Criterion,
    CriterionResult,
    Need,
    TruthSample,
)
from avsim.criteria.declaration import Declaration, RunInputs
from avsim.criteria.wording import beside, signed
from avsim.scenario.fields import FormatModel, PosFloat
from world.hdmap import SHOULDER, MarkKind, RoadMap

LINE_HALF_WIDTH = 0.075  # [m] half a painted lane line: a tyre touching paint is on the line
MAX_ONCOMING_STAY = 10.0  # [s] the longest stay wholly inside an oncoming lane: a pass draws
#   past the vehicle it passes and returns (a 5 m van passed at 30 km/h with 8 m of room
#   either side takes under 3 s alongside)


@dataclass(frozen=True, slots=True)
class Footprint:
    """Where the ego's tyres are across its route's lanes at one sample."""

    lane: int | None  # the lane all four tyres are wholly inside (`SHOULDER` for the
    #   shoulder); None: a tyre on or over a line, or inside a junction
    margin: float  # [m] the least distance of a tyre's outer edge inside the outer lines of
    #   the lanes it may use (the ego's direction, the shoulder after a flat tyre; a
    #   junction's corridor edges): negative past them
    sides: tuple[float, float]  # [m] (right, left): the least distance of a tyre's outer
    #   edge inside `lane`'s right and left lines ((inf, inf): lane is None)
    junction: bool  # the ego's centre is inside a town junction (no lines there)


def footprint(road: RoadMap, sample: TruthSample, half_tread: float) -> Footprint:
    """The footprint of `sample`'s tyres on `road` (`half_tread`: [m] a tyre's half width)."""
    s, y = sample.tyre_stations, sample.tyre_offsets
    seg = road.line.segment_index(s)
    if road.section_profiled[seg].any():
        bottom, top, band, lo, hi, shoulder = _profiled_bands(road, s, y)
    else:
        w, n = road.section_widths[seg], road.section_lanes[seg]
        c0 = np.asarray(road.lane(0).offset_at(s), dtype=np.float64)
        passable = _passable(road, seg)
        top = c0 + (n + passable - 0.5) * w  # the leftmost lane's left edge (oncoming lanes
        #   beyond a broken centre line included)
        bottom = c0 - 0.5 * w  # lane 0's right edge
        band = np.floor((y - c0 + 0.5 * w) / w)  # the lane whose edges hold the patch centre
        lo, hi = c0 + (band - 0.5) * w, c0 + (band + 0.5) * w
        band = np.where(band >= n, n - 1 - band, band)  # oncoming lanes -1, -2, ...
        shoulder = road.section_shoulders[seg]
    junction = any(j.s_enter <= sample.station <= j.s_exit for j in road.junctions)
    if junction:
        margins = np.minimum(y - half_tread - bottom, top - (y + half_tread))
        return Footprint(None, float(margins.min()), (math.inf, math.inf), True)
    shoulder = shoulder if sample.flat else np.zeros(4)
    low = np.where(shoulder > 0.0, bottom - shoulder, bottom + LINE_HALF_WIDTH)
    margins = np.minimum(y - half_tread - low, top - LINE_HALF_WIDTH - (y + half_tread))
    right = y - half_tread - (lo + LINE_HALF_WIDTH)
    left = hi - LINE_HALF_WIDTH - (y + half_tread)
    on_shoulder = (band < 0) & (shoulder > 0.0)
    right = np.where(on_shoulder, y - half_tread - low, right)
    left = np.where(on_shoulder, bottom - LINE_HALF_WIDTH - (y + half_tread), left)
    lanes = np.where(on_shoulder, SHOULDER, band)
    if ((lanes == lanes[0]).all() and (right >= 0.0).all() and (left >= 0.0).all()
            and margins.min() >= 0.0):
        return Footprint(int(lanes[0]), float(margins.min()),
                         (float(right.min()), float(left.min())), False)
    return Footprint(None, float(margins.min()), (math.inf, math.inf), False)


def _passable(road: RoadMap, seg: NDArray[np.intp]) -> NDArray[np.float64]:
    """[-] per tyre (its segment `seg`), the oncoming lanes a pass may use: all of them
    where the map paints the centre line broken, none where it is solid (the road's own
    double solid yellow line when no map file paints it)."""
    out = np.zeros(len(seg))
    for k, i in enumerate(seg.tolist()):
        section = road.sections[i]
        paint = section.paint
        if paint is not None and paint.left_edge.kind is MarkKind.BROKEN:
            out[k] = section.oncoming_lanes
    return out


def _profiled_bands(road: RoadMap, s: NDArray[np.float64],
                    y: NDArray[np.float64]) -> tuple[NDArray[np.float64], ...]:
    """`footprint`'s edges where a tyre's segment has a lane profile (the lanes where they
    lie at each tyre's station): ([m] lane 0's right edge, the leftmost ego lane's left
    edge, [-] the band of lanes holding the patch centre (`RoadMap.band_edges`), [m] its
    right and left edge, the shoulder's width), each (4,)."""
    out = np.empty((6, len(s)))
    for k, (si, yi) in enumerate(zip(s.tolist(), y.tolist(), strict=True)):
        b = road.lane_boundaries(si)
        band, lo, hi = road.band_edges(si, yi)
        out[:, k] = b[1], b[road.cross_section_at(si).lanes + 1], band, lo, hi, b[1] - b[0]
    return tuple(out)


@dataclass(frozen=True, slots=True)
class Crossing:
    """The footprint off one whole lane: from `since` [s], out of lane `origin` (None: it
    started so, or left a junction so)."""

    origin: int | None
    since: float  # [s]
    origin_margin: float  # [m] the least margin of the tyres to `origin`'s lines meanwhile


@dataclass(frozen=True, slots=True)
class LaneChange:
    """A lane change made, from the truth: the footprint left `origin` at `start` and was
    wholly inside `target` at `end`."""

    origin: int | None
    target: int
    start: float  # [s]
    end: float  # [s]

    @property
    def duration(self) -> float:
        return self.end - self.start


class LaneChanges:
    """The footprint's lane over the samples: which lane it is in, and the crossings and
    lane changes it makes (the module's doc). `update` returns the lane change or the line
    crossed and come back from (a `Crossing` back into its origin) that ended at the sample,
    if any."""

    def __init__(self, road: RoadMap, half_tread: float) -> None:
        self.road, self.half_tread = road, half_tread
        self.lane: int | None = None  # the lane the footprint was last wholly inside
        self.crossing: Crossing | None = None  # the crossing under way
        self.changes: list[LaneChange] = []  # every lane change made
        self.place: Footprint | None = None  # at the last sample
        self._overdue: Crossing | None = None  # the crossing `overdue` last returned

    def update(self, sample: TruthSample) -> LaneChange | Crossing | None:
        """Watch `sample` (its footprint is then `place`)."""
        place = self.place = footprint(self.road, sample, self.half_tread)
        if place.junction:  # no lines: a turn corridor, no lane to keep or change
            self.lane, self.crossing = None, None
            return None
        if place.lane is None:
            if self.crossing is None:
                self.crossing = Crossing(self.lane, sample.t, math.inf)
            if self.lane is not None:
                self.crossing = _with_margin(self.crossing, self._margin_to(self.lane, sample))
            return None
        ended: LaneChange | Crossing | None = None
        crossing = self.crossing
        if crossing is not None and crossing.origin is not None:
            if crossing.origin == place.lane:
                ended = crossing
            else:
                ended = LaneChange(crossing.origin, place.lane, crossing.since, sample.t)
                self.changes.append(ended)
        self.lane, self.crossing = place.lane, None
        return ended

    def overdue(self, t: float, limit: float) -> Crossing | None:
        """The crossing under way at `t` [s] once it has lasted over `limit` [s]: returned
        once, the first time; None otherwise."""
        crossing = self.crossing
        if crossing is None or crossing is self._overdue or t - crossing.since <= limit:
            return None
        self._overdue = crossing
        return crossing

    def _margin_to(self, lane: int, sample: TruthSample) -> float:
        """[m] the least margin of the tyres inside `lane`'s lines (negative: over)."""
        return float(np.min(lane_margins(self.road, sample, lane, lane))) - self.half_tread


def _with_margin(crossing: Crossing, margin: float) -> Crossing:
    return Crossing(crossing.origin, crossing.since, min(crossing.origin_margin, margin))


@dataclass
class Stay:
    """The footprint wholly in one lane, sample after sample: the least margins of its
    tyres to that lane's right and left lines, and the side it came in by a lane change
    (None: it did not), whose margin does not count."""

    right: float = math.inf  # [m]
    left: float = math.inf  # [m]
    came_by: str | None = None  # "right" or "left"

    def add(self, sides: tuple[float, float]) -> None:
        self.right, self.left = min(self.right, sides[0]), min(self.left, sides[1])

    def margin(self, left_by: str | None) -> float:
        """[m] its least margin to the lines it kept to: not on the side it came in by, nor
        on the side it left by (`left_by`) in a lane change."""
        skip = {self.came_by, left_by}
        return min(math.inf if "right" in skip else self.right,
                   math.inf if "left" in skip else self.left)

    @property
    def nearer(self) -> str:
        """The side whose line the tyres came nearest."""
        return "left" if self.left < self.right else "right"


def _side(change: LaneChange) -> str:
    """The side a lane change goes to (the shoulder is right of every lane, the oncoming
    lanes -1, -2, ... left of every lane of the ego's direction)."""
    return "left" if change.origin is not None and _across(change.target) > _across(
        change.origin) else "right"


def _across(lane: int) -> int:
    """[-] a lane's rank from right to left (oncoming lane -j after every ego lane)."""
    return -lane + ONCOMING_RANK if SHOULDER < lane < 0 else lane


ONCOMING_RANK = 1000  # [-] more than any road's lanes of the ego's direction


class TyresInLane(Criterion):
    """Every tyre stays inside the lanes of the ego's direction on its route (the shoulder
    too after a flat tyre; a junction's turn corridor inside one), and crosses a lane line
    only in a lane change done within `max_duration` (the module's doc).

    Value: the least margin [m] of a tyre's outer edge inside the lines it had to keep to
    (positive: inside; negative: that far over): the outer lines of the lanes it may use,
    a junction's corridor edges, and while it keeps a lane that lane's lines, but for the
    line it leaves or enters that lane by in a lane change. A crossing back into the same
    lane counts with its margin to that lane's lines."""

    name, unit = "tyres_in_lane", "m"

    def __init__(self, road: RoadMap, half_tread: float,
                 max_duration: float = MAX_LANE_CHANGE) -> None:
        super().__init__()
        self.lanes = LaneChanges(road, half_tread)
        self.max_duration = max_duration  # [s]
        self.margin = math.inf  # [m] the least margin so far
        self._stay: Stay | None = None  # the lane kept now
        self._left: Stay | None = None  # the lane kept before the crossing under way
        self._oncoming: float | None = None  # [s] since when the footprint is wholly in an
        #   oncoming lane (None: it is not)

    def update(self, sample: TruthSample) -> None:
        ended = self.lanes.update(sample)
        place = self.lanes.place
        assert place is not None
        self.margin = min(self.margin, place.margin)
        if place.margin < 0.0:
            where = "the junction's corridor" if place.junction else "the lanes"
            self._fail(sample, f"a tyre's margin inside {where} {signed(place.margin)} m "
                               f"(negative: over their outer lines)")
        if place.junction:
            self._close(None)
        elif place.lane is None:
            if self._stay is not None:
                self._left, self._stay = self._stay, None
        else:
            if self._stay is None:
                self._open(ended)
            assert self._stay is not None
            self._stay.add(place.sides)
        self._judge_crossings(sample, ended)
        self._judge_oncoming(sample, place)

    def _judge_oncoming(self, sample: TruthSample, place: Footprint) -> None:
        """A stay wholly in an oncoming lane (a pass) fails once it lasts over
        `MAX_ONCOMING_STAY`."""
        if place.lane is None or not SHOULDER < place.lane < 0:
            self._oncoming = None
            return
        if self._oncoming is None:
            self._oncoming = sample.t
        elif math.isfinite(self._oncoming) and sample.t - self._oncoming > MAX_ONCOMING_STAY:
            self._oncoming = -math.inf  # failed once for this stay
            self._fail(sample, f"in the oncoming lane {place.lane} for over "
                               f"{MAX_ONCOMING_STAY:g} s")

    def _open(self, ended: LaneChange | Crossing | None) -> None:
        """A new stay in a lane, after a lane change, a crossing back, or neither."""
        side = _side(ended) if isinstance(ended, LaneChange) else None
        self._close(side)
        self._stay = Stay(came_by=None if side is None else
                          ("right" if side == "left" else "left"))

    def _close(self, left_by: str | None) -> None:
        """Count the stays that ended: the one before the crossing (left by `left_by`) and
        the current one."""
        for stay, by in ((self._left, left_by), (self._stay, None)):
            if stay is not None:
                self.margin = min(self.margin, stay.margin(by))
        self._left = self._stay = None

    def _judge_crossings(self, sample: TruthSample, ended: LaneChange | Crossing | None) -> None:
        if self.lanes.overdue(sample.t, self.max_duration) is not None:
            self._fail(sample, f"a tyre on or over a lane line for over "
                               f"{self.max_duration:g} s")
        if isinstance(ended, Crossing) and ended.origin_margin < 0.0:
            self.margin = min(self.margin, ended.origin_margin)
            self._fail(sample, f"the tyres' margin inside the lines of lane {ended.origin} "
                               f"{signed(ended.origin_margin)} m (negative: over them) from "
                               f"t = {ended.since:.1f} s and back: no lane change",
                       at=ended.since)

    def result(self) -> CriterionResult:
        margin = self.margin
        for stay, by in ((self._left, self._left.nearer if self._left else None),
                         (self._stay, None)):
            if stay is not None:  # still open at the end (a crossing under way: its side)
                margin = min(margin, stay.margin(by))
        if math.isinf(margin):
            return CriterionResult.not_applicable(self.name, 0.0, self.unit,
                                                  "the run had no sample")
        return CriterionResult(self.name, self.first_failure is None, margin, 0.0,
                               self.unit, self.first_failure)


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
    """Each lane change (from the truth: `LaneChanges`) takes at most `threshold` seconds
    from the first tyre leaving the origin lane's lines to all tyres inside the target
    lane's. Value: the longest [s] (a crossing still under way at the end counts to the
    end); fails if no lane change was made (the scenario asks for one)."""

    name, unit = "lane_change_duration", "s"

    def __init__(self, road: RoadMap, half_tread: float, threshold: float) -> None:
        super().__init__()
        self.lanes = LaneChanges(road, half_tread)
        self.threshold = threshold
        self._t = 0.0  # [s] the last sample's time

    def update(self, sample: TruthSample) -> None:
        self._t = sample.t
        self.lanes.update(sample)
        crossing = self.lanes.overdue(sample.t, self.threshold)
        if crossing is not None:
            self._fail(sample, f"a lane change from lane {crossing.origin} takes over "
                               f"{self.threshold:g} s")

    def result(self) -> CriterionResult:
        durations = [c.duration for c in self.lanes.changes]
        crossing = self.lanes.crossing
        if crossing is not None:
            durations.append(self._t - crossing.since)
        if not self.lanes.changes:
            return CriterionResult(self.name, False, max(durations, default=None),
                                   self.threshold, self.unit, self.first_failure,
                                   "no lane change was made")
        value = max(durations)
        return CriterionResult(self.name, value <= self.threshold, value, self.threshold,
                               self.unit, self.first_failure)


class LaneChangeLateralAccel(Criterion):
    """Around each lane change (from the truth: `LaneChanges`), from `AROUND` before the
    first tyre leaves the origin lane's lines to `AROUND` after all are inside the target
    lane's, the lateral acceleration the change adds (speed * yaw rate less speed^2 * the
    road's curvature, moving average over `DECEL_WINDOW`) stays within `threshold`. Value:
    its peak [m/s^2]; fails if no lane change was made."""

    name, unit = "lane_change_lateral_accel", "m/s^2"
    AROUND = 1.0  # [s] judged this long before and after a lane change

    def __init__(self, road: RoadMap, half_tread: float, threshold: float,
                 rate: float) -> None:
        super().__init__()
        self.lanes = LaneChanges(road, half_tread)
        self.threshold = threshold
        self.window: deque[float] = deque(maxlen=max(1, round(DECEL_WINDOW * rate)))
        self.recent: deque[tuple[float, float, TruthSample]] = deque()  # (t, |a|, sample)
        #   within AROUND before now, not yet judged
        self.peak = 0.0  # [m/s^2] the largest averaged magnitude judged
        self._until = -math.inf  # [s] judged up to this time

    def update(self, sample: TruthSample) -> None:
        self.window.append(sample.lateral_accel - sample.speed**2 * sample.road_curvature)
        ended = self.lanes.update(sample)
        if isinstance(ended, LaneChange) or self.lanes.crossing is not None:
            self._until = sample.t + self.AROUND
        if len(self.window) == self.window.maxlen:
            self.recent.append((sample.t, abs(sum(self.window) / len(self.window)), sample))
        while self.recent and self.recent[0][0] < sample.t - self.AROUND:
            self.recent.popleft()
        if sample.t <= self._until:  # the AROUND before a change, and now
            while self.recent:
                _, a, at = self.recent.popleft()
                self.peak = max(self.peak, a)
                if a > self.threshold:
                    self._fail(at, f"lane change lateral acceleration "
                                   f"{beside(a, self.threshold, 2)} m/s^2 over "
                                   f"{self.threshold:g} m/s^2")

    def result(self) -> CriterionResult:
        if not self.lanes.changes:
            return CriterionResult(self.name, False, None, self.threshold, self.unit,
                                   self.first_failure, "no lane change was made")
        return CriterionResult(self.name, self.peak <= self.threshold, self.peak,
                               self.threshold, self.unit, self.first_failure)


class LaneChangeSetting(FormatModel):
    """Bounds on every lane change; at least one must happen."""

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
    half_tread = run.car.tyre_width / 2
    return [LaneChangeDuration(run.road, half_tread, setting.max_duration),
            LaneChangeLateralAccel(run.road, half_tread, setting.max_lateral_accel, run.rate)]


TYRES_IN_LANE: Declaration[None] = Declaration(
    build=lambda _, run: [TyresInLane(run.road, run.car.tyre_width / 2, run.lane_change_max)],
    needs=frozenset({Need.MAP, Need.CAR, Need.LANE_CHANGE}), always=True)

LANE_CHANGE: Declaration[LaneChangeSetting] = Declaration(
    build=_lane_change, needs=frozenset({Need.MAP, Need.CAR, Need.RATE}), key="lane_change",
    setting=LaneChangeSetting,
    doc="`{max_duration, max_lateral_accel}`: bounds on each lane change; at least one must "
    "happen. Default: off.", example={"max_duration": 5.0, "max_lateral_accel": 1.0})

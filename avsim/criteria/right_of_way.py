"""`max_wait_with_right_of_way`: in a town, no vehicle (the ego or an NPC car) stands longer
than the threshold [s] while it has the right of way: the town never deadlocks. Off unless
the scenario sets it (`criteria: {max_wait_with_right_of_way: 60}`); judged from the truth
alone (true poses and speeds, the town's layout and signal plans), never from what the
stack or the NPC drivers decided.

At each sample, for every vehicle (the ego; each NPC car or truck in the world):

1. It **stands** when slower than ``STANDING`` [m/s]. A standstill lasts while it stands.
2. It is **queued**, without the right of way, when another vehicle is ahead of it in its
   lane: that vehicle's centre within ``LANE_HALF`` of its axis across, ahead of it with
   a bumper gap of at most ``QUEUE_GAP``, and heading within 45 deg of its own (a vehicle
   crossing in front of it is not a queue).
3. Else, when it stands **at a stop line** (its front bumper ``-LINE_OVER`` to
   ``LINE_ZONE`` before an approach's line, within the approach's lanes, heading within
   45 deg of the approach's), it has the right of way
   - at a traffic light: while the light (its true signal plan) is green and no moving
     vehicle that has the right of way over it is in its way: none moving inside the
     junction's box, and none coming the other way (heading within 45 deg of the
     opposite, moving, on the far side of the junction's centre within the street's half
     width across) that reaches the box within ``YIELD_GAP`` [s] at its speed. Its turn
     is not in the truth: one that stands on green for oncoming traffic may turn left
     across it (oncoming traffic has the way), and a town in which traffic still moves
     through the junction is not deadlocked;
   - at an all-way stop: while it is its turn in order of arrival
     (`world.actors.all_way_stop`, arrivals from these samples: first to stop at its line,
     first to go, ties to the right; a turn here never passes on for not being taken) and
     no other vehicle's centre is in the junction's box.
4. Else (nothing ahead in its lane, no line to keep) it has the right of way.

Value: the longest time [s] one vehicle had the right of way within one standstill
(green phases of one long wait at a light add up). It fails when that exceeds the
threshold, an infraction at that moment naming the vehicle. Not applicable (then, asked
for by name, failed) when no vehicle ever stood with the right of way, or the map is not a
town.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from avsim.criteria.base import Criterion, CriterionResult, Need, TruthSample
from avsim.criteria.declaration import Declaration, RunInputs
from avsim.criteria.wording import beside
from avsim.scenario.fields import PosFloat
from world.actors.all_way_stop import AllWayStop
from world.hdmap import LightColour
from world.map.signals import light_colour
from world.map.town import Approach, TownLayout
from world.spec import TownSpec

STANDING = 0.1  # [m/s] slower than this a vehicle stands
LANE_HALF = 1.5  # [m] a vehicle this near one's axis, across, is in one's lane
QUEUE_GAP = 8.0  # [m] bumper gap to the vehicle ahead within which one is queued
LINE_ZONE = 6.0  # [m] front bumper this far before a line, or nearer: at the line
LINE_OVER = 1.0  # [m] ... or this far over it
SAME_WAY = math.cos(math.radians(45.0))  # [-] headings within 45 deg: the same way
YIELD_GAP = 5.0  # [s] oncoming traffic this near the box in time keeps the way from a left
#   turn on green (the critical gap of a left turn across oncoming traffic, ~4-5 s)
EGO = "ego"

FloatArray = NDArray[np.float64]


class MaxWaitWithRightOfWay(Criterion):
    """No vehicle stands longer than the threshold [s] with the right of way (module doc)."""

    name, unit = "max_wait_with_right_of_way", "s"

    def __init__(self, threshold: float, town: TownSpec | None, half_length: float) -> None:
        super().__init__()
        self.threshold = threshold
        self.ego_half = half_length  # [m] the ego's centre to its bumpers
        self.layout = TownLayout(town) if town is not None else None
        self.idle = self.layout is None
        self.approaches: list[Approach] = self.layout.approaches() if self.layout else []
        lines = np.array([a.stop_line for a in self.approaches]).reshape(-1, 2)
        self._line_xy: FloatArray = lines
        h = np.array([_HEADINGS[a.heading] for a in self.approaches])
        self._line_f: FloatArray = np.column_stack([np.cos(h), np.sin(h)])
        self._lane_half = 0.5 * self.layout.half_width if self.layout else 0.0
        self.order = AllWayStop(grant_timeout=math.inf)
        self._at: dict[str, int] = {}  # vehicle -> approach it stands at (arrived)
        self._with_way: dict[str, float] = {}  # vehicle -> [s] right of way, this standstill
        self._reported: set[str] = set()
        self._last_t: float | None = None
        self.longest = 0.0  # [s]
        self.worst: str | None = None
        self.judged = False  # a vehicle stood with the right of way

    def update(self, sample: TruthSample) -> None:
        if self.layout is None or sample.actors is None or sample.xy is None:
            return
        dt = 0.0 if self._last_t is None else sample.t - self._last_t
        self._last_t = sample.t
        keys, xy, heading, speed, half = self._vehicles(sample)
        fwd = np.column_stack([np.cos(heading), np.sin(heading)])
        queued = _queued(xy, fwd, half)
        line = self._at_line(xy, fwd, half)
        standing = speed < STANDING
        for i, key in enumerate(keys):
            self._arrivals(sample.t, key, int(line[i]), bool(standing[i]))
        moving = Moving(xy, fwd, speed)
        for i, key in enumerate(keys):
            if not standing[i]:
                self._with_way.pop(key, None)
                continue
            way = not queued[i] and self._has_way(sample.t, key, int(line[i]), moving, i)
            if way:
                self._count(sample, key, dt)

    def _count(self, sample: TruthSample, key: str, dt: float) -> None:
        self.judged = True
        waited = self._with_way.get(key, 0.0) + dt
        self._with_way[key] = waited
        if waited > self.longest:
            self.longest, self.worst = waited, key
        if waited > self.threshold and key not in self._reported:
            self._reported.add(key)
            shown = beside(waited, self.threshold)
            self._infraction(sample, f"{key} has stood {shown} s with the right of way "
                                     f"(more than {self.threshold:g} s)")

    def _vehicles(self, sample: TruthSample) -> tuple[list[str], FloatArray, FloatArray,
                                                      FloatArray, FloatArray]:
        """Keys, centres (N, 2), headings, speeds and half lengths of the ego (first) and
        the NPC vehicles in the world."""
        a = sample.actors
        assert a is not None and sample.xy is not None
        rows = [i for i in range(len(a.ids))
                if a.truth_class(i) is not None
                and a.centres[i, 2] > 0.0]
        tyres = sample.tyres  # front left, front right, rear left, rear right
        ego_h = math.atan2(*(tyres[:2].mean(axis=0) - tyres[2:].mean(axis=0))[::-1])
        keys = [EGO] + [a.ids[i] for i in rows]
        xy = np.vstack([[sample.xy], a.centres[rows, :2]])
        heading = np.concatenate([[ego_h], a.yaws[rows]])
        speed = np.abs(np.concatenate([[sample.speed], a.speeds[rows]]))
        half = np.concatenate([[self.ego_half], a.half_sizes[rows, 0]])
        return keys, xy, heading, speed, half

    def _at_line(self, xy: FloatArray, fwd: FloatArray, half: FloatArray) -> FloatArray:
        """Per vehicle, the approach whose line it is at (module doc), -1 for none."""
        if not self.approaches:
            return np.full(len(xy), -1)
        rel = xy[:, None, :] - self._line_xy[None, :, :]  # (N, A, 2)
        f = self._line_f[None, :, :]
        along = (rel * f).sum(axis=2)
        across = rel[..., 1] * f[..., 0] - rel[..., 0] * f[..., 1]
        gap = -along - half[:, None]  # [m] front bumper to the line
        same = (fwd[:, None, :] * f).sum(axis=2) > SAME_WAY
        at = (gap > -LINE_OVER) & (gap < LINE_ZONE) & (np.abs(across) < self._lane_half) & same
        out: FloatArray = np.where(at.any(axis=1), np.argmax(at, axis=1), -1)
        return out

    def _arrivals(self, t: float, key: str, line: int, standing: bool) -> None:
        """The all-way-stop order from the truth: arrive standing at a stop sign's line,
        leave on moving off from it."""
        was = self._at.get(key)
        if was is not None and (line != was or not standing):
            self.order.leave(self.approaches[was].junction, key)
            del self._at[key]
        if standing and line >= 0 and key not in self._at and \
                self.approaches[line].light is None:
            a = self.approaches[line]
            self.order.arrive(a.junction, key, _HEADINGS[a.heading], t)
            self._at[key] = line

    def _has_way(self, t: float, key: str, line: int, moving: Moving, i: int) -> bool:
        """Whether vehicle i (`key`, not queued) standing at approach `line` (-1: none) has
        the right of way."""
        if line < 0:
            return True
        a = self.approaches[line]
        assert self.layout is not None
        centre, hw = self.layout.centre(a.junction), self.layout.half_width
        if a.light is not None:
            return light_colour(a.light, t) is LightColour.GREEN and \
                not _yields_on_green(moving, i, centre, hw, self._line_f[line])
        if key not in self._at or self.order.turn(a.junction, t) != key:
            return False
        others = np.delete(moving.xy, i, axis=0)
        return not bool(_in_box(others, centre, hw).any())

    def result(self) -> CriterionResult:
        if self.layout is None:
            return CriterionResult.not_applicable(self.name, self.threshold, self.unit,
                                                  "not a town")
        if not self.judged:
            return CriterionResult.not_applicable(
                self.name, self.threshold, self.unit,
                "no vehicle ever stood with the right of way")
        note = f"longest: {self.worst}" if self.worst is not None else None
        return CriterionResult(self.name, self.longest <= self.threshold, self.longest,
                               self.threshold, self.unit, self.first_failure, note)


@dataclass(frozen=True, slots=True)
class Moving:
    """The vehicles at one sample: centres (N, 2) [m], unit headings (N, 2), speeds (N,)
    [m/s]."""

    xy: FloatArray
    fwd: FloatArray
    speed: FloatArray


def _in_box(xy: FloatArray, centre: tuple[float, float], hw: float) -> NDArray[np.bool_]:
    """Per centre (N, 2) [m], whether it is inside the junction's box (half width hw)."""
    out: NDArray[np.bool_] = (np.abs(xy[:, 0] - centre[0]) < hw) & \
        (np.abs(xy[:, 1] - centre[1]) < hw)
    return out


def _yields_on_green(v: Moving, i: int, centre: tuple[float, float], hw: float,
                     f: FloatArray) -> bool:
    """Whether vehicle i, standing on green at an approach heading `f` (unit) into the
    junction at `centre` [m] (half width hw [m]), waits for a vehicle with the right of way
    over it (module doc): one moving inside the box, or one coming the other way that
    reaches the box within `YIELD_GAP`."""
    rel = v.xy - np.asarray(centre)
    along = rel @ f  # [m] beyond the centre, the way vehicle i heads in
    across = rel[:, 1] * f[0] - rel[:, 0] * f[1]  # [m] left +
    moving = v.speed >= STANDING
    moving[i] = False
    inside = _in_box(v.xy, centre, hw)
    oncoming = (v.fwd @ f < -SAME_WAY) & (along > 0.0) & (np.abs(across) < hw) & \
        ((along - hw) <= YIELD_GAP * v.speed)
    return bool((moving & (inside | oncoming)).any())


def _queued(xy: FloatArray, fwd: FloatArray, half: FloatArray) -> NDArray[np.bool_]:
    """Per vehicle, whether another is ahead of it in its lane within QUEUE_GAP, travelling
    the same way (module doc)."""
    rel = xy[None, :, :] - xy[:, None, :]  # (N, N, 2): j relative to i
    along = (rel * fwd[:, None, :]).sum(axis=2)
    across = rel[..., 1] * fwd[:, None, 0] - rel[..., 0] * fwd[:, None, 1]
    gap = along - half[:, None] - half[None, :]
    same = (fwd @ fwd.T) > SAME_WAY
    ahead = (along > 0.0) & (gap < QUEUE_GAP) & (np.abs(across) < LANE_HALF) & same
    np.fill_diagonal(ahead, False)
    out: NDArray[np.bool_] = ahead.any(axis=1)
    return out


_HEADINGS = {"east": 0.0, "north": 0.5 * math.pi, "west": math.pi, "south": -0.5 * math.pi}


def _build(threshold: float, run: RunInputs) -> Sequence[Criterion]:
    return [MaxWaitWithRightOfWay(threshold, run.town, 0.5 * run.car.body_length)]


MAX_WAIT_WITH_RIGHT_OF_WAY: Declaration[float] = Declaration(
    build=_build, needs=frozenset({Need.TOWN, Need.CAR, Need.ACTORS}),
    key="max_wait_with_right_of_way", setting=PosFloat, example=60.0,
    doc="[s] in a town, no vehicle (the ego or an NPC car) stands longer than this while it "
    "has the right of way, judged from the truth: not queued behind a vehicle ahead in its "
    "lane, and at a stop line only on green with no moving vehicle in the box or coming the "
    "other way within 5 s of it, or in its turn at an all-way stop (first to "
    "stop, first to go, ties to the right) with the box clear; > 0. Default: off.")

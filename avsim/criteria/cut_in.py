"""UN R157's cut-in rule (para. 5.2.5.2): which collisions with a cutting-in vehicle the
regulation requires an ALKS to avoid, judged from the truth.

UN R157 (ECE/TRANS/WP.29/2020/81, 5.2.5.2) requires the ALKS to avoid a collision with a
cutting-in vehicle provided that (a) it keeps a longitudinal speed lower than the ALKS
vehicle's, (b) its lateral movement has been visible for at least 0.72 s before the lane
intrusion, and (c) at the lane intrusion TTC > v_rel / (2 x 6 m/s^2) + 0.35 s. A collision
with a vehicle that cut in outside those conditions is one the regulation labels
unavoidable.

Here, from the truth: a vehicle's lane intrusion is the first moment its box's corner
nearest the ego's lane lies `INTRUSION` inside that lane's edge while it is ahead of the ego
(the regulation's reference is the outside of the front tyre crossing a line 0.3 m beyond
the outside edge of the lane marking: with a 0.15 m line that is 0.225 m into the lane; the
box corner is used for the tyre, which it covers). Its lateral movement started at the last
moment before the intrusion that its lateral speed towards the lane rose above
`MOVING_LATERALLY`. TTC is the bumper gap along the route over the closing speed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from avsim.criteria.base import TruthSample
from world.hdmap import RoadMap
from world.spec import ActorType
from world.truth import ego_lane_edges

R157_DECEL = 6.0  # [m/s^2] 5.2.5.2 (c): the deceleration in the TTC bound
R157_REACTION = 0.35  # [s] 5.2.5.2 (c)
R157_VISIBLE = 0.72  # [s] 5.2.5.2 (b): the lateral movement visible at least this long
INTRUSION = 0.225  # [m] into the ego's lane past its edge (module doc)
MOVING_LATERALLY = 0.1  # [m/s] a lateral speed towards the lane that counts as moving
VEHICLES = (ActorType.CAR, ActorType.TRUCK)


@dataclass(frozen=True, slots=True)
class CutIn:
    """One lane intrusion ahead of the ego, and whether UN R157 requires avoiding it."""

    actor: str
    t: float  # [s] the lane intrusion
    ttc: float  # [s] at the intrusion (inf: not closing)
    v_rel: float  # [m/s] the ego's speed less the vehicle's
    visible_for: float  # [s] how long its lateral movement had been visible
    required: bool  # UN R157 5.2.5.2 requires the ALKS to avoid a collision with it

    def reason(self) -> str:
        """Why the regulation does or does not require avoiding it."""
        bound = self.v_rel / (2.0 * R157_DECEL) + R157_REACTION
        if self.v_rel <= 0.0:
            return f"it was not slower than the ego (v_rel {self.v_rel:.1f} m/s <= 0)"
        if self.visible_for < R157_VISIBLE:
            return (f"its lateral movement was visible {self.visible_for:.2f} s before the "
                    f"lane intrusion < bound {R157_VISIBLE} s")
        relation = ">" if self.ttc > bound else "<="
        return f"TTC at lane intrusion {self.ttc:.2f} s {relation} bound {bound:.2f} s"


class CutInWatch:
    """Every lane intrusion of a vehicle (a car or truck: not a pedestrian or an obstacle)
    into the ego's lane ahead of it (module doc)."""

    def __init__(self, road: RoadMap, ego_length: float) -> None:
        self.road = road
        self.ego_length = ego_length
        self.cut_ins: dict[str, CutIn] = {}  # actor id -> its (first) lane intrusion
        self._offsets: dict[str, tuple[float, float]] = {}  # id -> (t, offset) last seen
        self._moving_since: dict[str, float | None] = {}  # id -> [s] lateral move start
        self._clear: set[str] = set()  # ids seen outside the ego's lane (not intruding)

    def update(self, sample: TruthSample) -> None:
        poses = sample.actors
        if poses is None or not len(poses.ids):
            return
        lo, hi = ego_lane_edges(self.road, sample.station, sample.offset)
        rel = poses.yaws - np.asarray(self.road.heading_at(poses.stations))
        across = (poses.half_sizes[:, 1] * np.abs(np.cos(rel))
                  + poses.half_sizes[:, 0] * np.abs(np.sin(rel)))
        along = (poses.half_sizes[:, 0] * np.abs(np.cos(rel))
                 + poses.half_sizes[:, 1] * np.abs(np.sin(rel)))
        for i, actor in enumerate(poses.ids):
            if poses.kinds[i] not in VEHICLES:
                continue  # 5.2.5.2 is about cutting-in vehicles
            offset = float(poses.offsets[i])
            centre = 0.5 * (lo + hi)
            towards = self._lateral_towards(actor, sample.t, offset, centre)
            if actor in self.cut_ins:
                continue
            inside = (offset - float(across[i]) < hi - INTRUSION if offset > centre
                      else offset + float(across[i]) > lo + INTRUSION)
            if not inside:
                self._clear.add(actor)
                continue
            gap = float(poses.stations[i]) - sample.station - float(along[i]) \
                - 0.5 * self.ego_length
            came_in = actor in self._clear
            if came_in and gap > 0.0:
                self._intrusion(actor, sample, gap, float(poses.speeds[i]), towards)

    def _lateral_towards(self, actor: str, t: float, offset: float, centre: float) -> float:
        """[m/s] the actor's lateral speed towards the lane's centre (tracks when its
        movement started)."""
        last = self._offsets.get(actor)
        self._offsets[actor] = (t, offset)
        if last is None or t <= last[0]:
            self._moving_since.setdefault(actor, None)
            return 0.0
        speed = (offset - last[1]) / (t - last[0]) * (1.0 if centre > offset else -1.0)
        if speed > MOVING_LATERALLY:
            if self._moving_since.get(actor) is None:
                self._moving_since[actor] = last[0]
        else:
            self._moving_since[actor] = None
        return speed

    def _intrusion(self, actor: str, sample: TruthSample, gap: float, speed: float,
                   towards: float) -> None:
        v_rel = sample.speed - speed
        ttc = gap / v_rel if v_rel > 0.0 else math.inf
        since = self._moving_since.get(actor)
        visible = sample.t - since if since is not None and towards > 0.0 else 0.0
        bound = v_rel / (2.0 * R157_DECEL) + R157_REACTION
        required = v_rel > 0.0 and visible >= R157_VISIBLE and ttc > bound
        self.cut_ins[actor] = CutIn(actor, sample.t, ttc, v_rel, visible, required)

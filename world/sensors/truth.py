"""The `truth` sensor of privileged truth mode: the ground truth handed to the stack.

Not a sensor a real car has: in privileged truth mode only (the run is labelled privileged
in every result), for a user testing a planner without perception, it hands the stack a
`world.frames.GroundTruth` at the control rate (`world.core.rates.TRUTH`, no latency): the
ego's true pose, speed, yaw rate and steering angle, and every actor's box in the map frame.
An actor hidden from the sensors (an OpenSCENARIO VisibilityAction with sensors false) or out
of the world (deleted, or a town driver that arrived) is not in it. No noise, no delay.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Collection
from dataclasses import dataclass, field

from world.actors.actor_set import ActorPoses
from world.core.rates import TRUTH, Rate
from world.ego.body import EgoTruth
from world.frames import GroundTruth, TruthObject, wrap_angle
from world.sensors.sensor import Reading
from world.sensors.setup import TRUTH_SENSOR

Place = tuple[float, float, float]  # [s, m, m] a capture's time and an object's centre


def truth_objects(poses: ActorPoses, absent: Collection[int], t: float = math.nan,
                  before: dict[str, Place] | None = None,
                  period: float = TRUTH.rate.period) -> tuple[TruthObject, ...]:
    """Every actor of `poses` at time `t` [s] but those of index in `absent`, as
    `TruthObject`s. Its velocity over ground is its centre's motion since the previous
    capture (`before`: id -> that capture's time and centre; one capture `period` [s] back
    at most), exact for any motion (a walker crossing, a lane change); without one (its first
    capture, or shown again), its speed along its yaw. `before` is updated to this capture."""
    out = []
    seen: dict[str, Place] = {}
    for i, ident in enumerate(poses.ids):
        if i in absent:
            continue
        yaw = float(poses.yaws[i])
        x, y = float(poses.centres[i, 0]), float(poses.centres[i, 1])
        speed = float(poses.speeds[i])
        vx, vy = speed * math.cos(yaw), speed * math.sin(yaw)
        last = before.get(ident) if before is not None else None
        if last is not None and 0.0 < t - last[0] <= 1.5 * period:
            vx, vy = (x - last[1]) / (t - last[0]), (y - last[2]) / (t - last[0])
        seen[ident] = (t, x, y)
        length, width, height = (2.0 * float(h) for h in poses.half_sizes[i])
        out.append(TruthObject(
            id=ident, kind=poses.kinds[i].value, x=x, y=y, yaw=wrap_angle(yaw), vx=vx, vy=vy,
            length=length, width=width, height=height))
    if before is not None:
        before.clear()
        before.update(seen)
    return tuple(out)


@dataclass(frozen=True, slots=True)
class TruthSensor:
    """The ground truth at each capture (module doc). `actors` gives the actors' truth now;
    `absent` the indices of the actors not in the frame now (hidden from the sensors, or out
    of the world)."""

    actors: Callable[[], ActorPoses]
    absent: Callable[[], Collection[int]]
    _before: dict[str, Place] = field(default_factory=dict)  # the last capture's centres

    @property
    def name(self) -> str:
        return TRUTH_SENSOR

    @property
    def rate(self) -> Rate:
        return TRUTH.rate

    @property
    def latency(self) -> float:
        return TRUTH.latency

    def capture(self, t: float, ego: EgoTruth) -> Reading:
        return Reading(self.name, GroundTruth(
            t=t, x=float(ego.position[0]), y=float(ego.position[1]),
            heading=wrap_angle(ego.yaw), speed=ego.speed, yaw_rate=ego.yaw_rate,
            steering_angle=ego.steering_angle,
            objects=truth_objects(self.actors(), self.absent(), t, self._before)))

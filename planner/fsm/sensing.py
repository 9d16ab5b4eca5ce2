"""The sensors' state of health as the planner answers it: drive normally, slow down, or
make a minimum-risk stop in lane. The camera's faults are the lane-source machine's
(`planner.fsm.lane_source`: the lane is kept on the map, then the car stops in it); this
machine answers the LiDAR's and the GNSS's, and a camera's view partly occluded (its frames
still show the lane on the rest), as `perception.health` noticed them from their data
(`SensingInput`: how each fault was noticed, None while the sensor is sound).

What each state does (`planner.planner`): NOMINAL drives as planned. DEGRADED keeps the lane
from the sources left (the camera's lane and the odometry without GNSS: the map's stations
drift along the route, and a fix that jumped is not fused; the lines the occluded camera
still sees, `planner.fsm.lane_source`'s ONE_LINE) and slows down, ramped at
``a_comf``, to ``slow_speed``. MINIMUM_RISK stops in lane, ramped at ``a_comf`` (at most
4 m/s^2: UN R157's bound for a minimum-risk manoeuvre), with the hazard lights on
(`planner.fsm.hazard`): without the LiDAR (its scans missing, empty or late) nothing ahead
is seen, and the car cannot drive on safely. Each resumes when the sensors are sound again.
Transitions (`TABLE`, as data): for the state it is in, the rows that leave it are tried in
this order and the first that holds is taken:

1. nominal, degraded -> minimum_risk: the LiDAR's scans are faulty
2. nominal -> degraded: the GNSS's fixes are faulty, or the camera's view is partly occluded
3. minimum_risk -> degraded: the LiDAR's scans are sound; the GNSS's fixes faulty, or the
   camera's view partly occluded
4. degraded, minimum_risk -> nominal: the LiDAR's scans, the GNSS's fixes and the camera's
   view are sound

Every change carries how the fault was noticed, or that it is over.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

from planner.fsm.machine import Row, Table, Transition, next_state, render
from world.frames import kph


class Sensing(enum.Enum):
    NOMINAL = "nominal"
    DEGRADED = "degraded"
    MINIMUM_RISK = "minimum_risk"


@dataclass(frozen=True, slots=True)
class SensingParams:
    slow_speed: float = kph(30.0)  # [m/s] the most the car drives at in DEGRADED


@dataclass(frozen=True, slots=True)
class SensingInput:
    lidar: str | None = None  # how a fault of the LiDAR was noticed; None: sound
    gnss: str | None = None  # how a fault of the GNSS was noticed; None: sound
    occlusion: str | None = None  # how a partial occlusion of the camera was noticed; None:
    #   its view is clear


def _slow_fault(x: SensingInput) -> str | None:
    """What the car slows down for: a faulty GNSS, a partly occluded camera; None."""
    return x.gnss if x.gnss is not None else x.occlusion


def _slowing(x: SensingInput, p: SensingParams) -> str:
    what = ("the lane kept without GNSS" if x.gnss is not None
            else "the lane on what the camera sees")
    return f"{_slow_fault(x)}: {what}, slowing to {p.slow_speed:.1f} m/s"


def _lidar(_s: Sensing, x: SensingInput, _p: SensingParams) -> bool:
    return x.lidar is not None


def _slow(_s: Sensing, x: SensingInput, _p: SensingParams) -> bool:
    return _slow_fault(x) is not None


def _lidar_back(_s: Sensing, x: SensingInput, _p: SensingParams) -> bool:
    return x.lidar is None and _slow_fault(x) is not None


def _sound(_s: Sensing, x: SensingInput, _p: SensingParams) -> bool:
    return x.lidar is None and _slow_fault(x) is None


S = Sensing

TABLE: Table[Sensing, SensingInput, SensingParams] = Table(Sensing, (
    Row(frozenset({S.NOMINAL, S.DEGRADED}), S.MINIMUM_RISK, _lidar,
        "the LiDAR's scans are faulty",
        lambda x, p: f"{x.lidar}: nothing ahead is seen, minimum-risk stop in lane"),
    Row(frozenset({S.NOMINAL}), S.DEGRADED, _slow,
        "the GNSS's fixes are faulty, or the camera's view is partly occluded",
        _slowing),
    Row(frozenset({S.MINIMUM_RISK}), S.DEGRADED, _lidar_back,
        "the LiDAR's scans are sound; the GNSS's fixes faulty, or the camera's view partly "
        "occluded",
        lambda x, p: f"LiDAR scans again; {_slowing(x, p)}"),
    Row(frozenset({S.DEGRADED, S.MINIMUM_RISK}), S.NOMINAL, _sound,
        "the LiDAR's scans, the GNSS's fixes and the camera's view are sound",
        "sensors sound again: resuming"),
))


def transition(state: Sensing, x: SensingInput, p: SensingParams) -> Transition[Sensing] | None:
    """The change of state for input `x`, or None to stay (`TABLE`)."""
    return next_state(TABLE, state, x, p)


if __name__ == "__main__":  # print the table for the module doc
    print(render(TABLE))

"""The min_gap criterion on synthetic truth: R157's d_min, the cut-in grace, the hard-brake
and low-speed exemptions, and other lanes."""

from __future__ import annotations

import numpy as np
import pytest

from avsim.criteria.base import TruthSample
from avsim.criteria.following import MinGap
from planner.fsm.acc import r157_min_gap
from tests.roads import make_map, seg
from world.actors.actor_set import ActorPoses
from world.spec import ActorType

ROAD = make_map(seg(1000.0))
EGO_LENGTH = 4.8
CAR_HALF = np.array([2.3, 0.9, 0.75])


def poses(stations: list[float], offsets: list[float], accels: list[float] | None = None,
          ids: tuple[str, ...] | None = None) -> ActorPoses:
    n = len(stations)
    ids = ids or tuple(f"car{i}" for i in range(n))
    return ActorPoses(ids=ids, kinds=(ActorType.CAR,) * n,
                      centres=np.zeros((n, 3)), yaws=np.zeros(n),
                      half_sizes=np.tile(CAR_HALF, (n, 1)), stations=np.array(stations),
                      offsets=np.array(offsets), speeds=np.zeros(n),
                      accels=np.array(accels if accels is not None else [0.0] * n))


def sample(t: float, speed: float, station: float, actors: ActorPoses) -> TruthSample:
    return TruthSample(t=t, speed=speed, station=station, front_station=station + 2.4,
                       tyres=np.zeros((4, 2)), tyre_stations=np.zeros(4),
                       tyre_offsets=np.zeros(4), touching=frozenset(), offset=0.0,
                       actors=actors)


def gap_of(lead_s: float, ego_s: float) -> float:
    return lead_s - ego_s - (2 * CAR_HALF[0] + EGO_LENGTH) / 2


def test_lead_too_close_fails_with_value_and_threshold() -> None:
    c = MinGap("r157", ROAD, EGO_LENGTH)
    c.update(sample(0.0, 20.0, 100.0, poses([150.0], [0.0])))  # gap 45.3 > 34.4
    assert c.first_failure is None
    c.update(sample(1.0, 20.0, 100.0, poses([130.0], [0.0])))  # gap 25.3 < 34.4
    r = c.result()
    assert not r.passed and r.first_failure == 1.0
    assert r.value == pytest.approx(gap_of(130.0, 100.0))
    assert r.threshold == pytest.approx(r157_min_gap(20.0)) and r.unit == "m"


def test_exemptions_low_speed_other_lane_hard_braking() -> None:
    c = MinGap("r157", ROAD, EGO_LENGTH)
    c.update(sample(0.0, 1.5, 100.0, poses([110.0], [0.0])))  # crawling: not checked
    c.update(sample(0.1, 20.0, 100.0, poses([110.0], [3.5])))  # next lane: not the lead
    c.update(sample(0.2, 20.0, 100.0, poses([110.0], [0.0], [-4.0])))  # lead brakes hard
    assert c.result().passed


def test_a_cut_in_has_ten_seconds_of_grace() -> None:
    c = MinGap("r157", ROAD, EGO_LENGTH)
    c.update(sample(0.0, 20.0, 100.0, poses([125.0], [3.5])))  # beside, in the next lane
    for t in np.arange(1.0, 11.0, 1.0):  # it cuts in 25 m ahead at t = 1 and stays
        c.update(sample(float(t), 20.0, 100.0, poses([125.0], [0.0])))
    assert c.result().passed  # within the grace
    c.update(sample(11.5, 20.0, 100.0, poses([125.0], [0.0])))
    assert c.result().first_failure == 11.5


def test_a_lead_from_the_start_gets_no_grace_and_a_fixed_threshold() -> None:
    c = MinGap(10.0, ROAD, EGO_LENGTH)
    c.update(sample(0.0, 10.0, 100.0, poses([115.5], [0.0])))  # gap 10.8 >= 10
    c.update(sample(0.1, 10.0, 100.0, poses([114.8], [0.0])))  # 10.1
    assert c.result().passed and c.result().threshold == 10.0
    assert c.result().value == pytest.approx(gap_of(114.8, 100.0))
    c.update(sample(0.2, 10.0, 100.0, poses([114.0], [0.0])))  # 9.3 < 10
    assert not c.result().passed

"""The min_gap criterion on synthetic truth: R157's d_min, the cut-in grace, the hard-brake
and low-speed exemptions, other lanes, and what counts as the vehicle ahead (its footprint
in the ego's lane, travelling along it)."""

from __future__ import annotations

import numpy as np
import pytest

from avsim.criteria.base import TruthSample
from avsim.criteria.following import MinGap
from avsim.criteria.regulations import r157_min_gap
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
    return float(lead_s - ego_s - (2 * CAR_HALF[0] + EGO_LENGTH) / 2)


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
    r = c.result()  # nothing judged: asked for by name, it fails, with no failure moment
    assert not r.passed and r.value is None and r.first_failure is None
    assert r.note is not None and r.note.startswith("no vehicle ahead in the ego's lane")
    c.update(sample(11.0, 20.0, 100.0, poses([160.0], [0.0])))  # judged (its cut-in at
    #   0.2 s long past): far enough
    assert c.result().passed and c.result().value == pytest.approx(gap_of(160.0, 100.0))


def test_a_cut_in_has_ten_seconds_of_grace() -> None:
    c = MinGap("r157", ROAD, EGO_LENGTH)
    c.update(sample(0.0, 20.0, 100.0, poses([125.0], [3.5])))  # beside, in the next lane
    for t in np.arange(1.0, 11.0, 1.0):  # it cuts in 25 m ahead at t = 1 and stays
        c.update(sample(float(t), 20.0, 100.0, poses([125.0], [0.0])))
    assert c.first_failure is None and c.result().value is None  # within the grace
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


def test_the_vehicle_ahead_is_one_whose_footprint_is_in_the_lane_travelling_along_it() -> None:
    """A car astride the line (its footprint over it) is ahead; one just beyond it, or
    crossing the lane (turned 90 deg: a junction's cross traffic), or oncoming, is not."""
    near = 100.0 + 30.0
    astride = poses([near], [1.75 + 0.8])  # its right side 0.1 m into the ego's lane
    beside = poses([near], [1.75 + 0.95])
    c = MinGap(40.0, ROAD, EGO_LENGTH)
    c.update(sample(0.0, 20.0, 100.0, astride))
    assert c.result().failed  # 30 m ahead, under 40 m: it counts
    for turned in (np.pi / 2, np.pi):
        crossing = ActorPoses(**{**{f: getattr(astride, f) for f in astride.__dataclass_fields__},
                                 "offsets": np.array([0.0]), "yaws": np.array([turned])})
        c = MinGap(40.0, ROAD, EGO_LENGTH)
        c.update(sample(0.0, 20.0, 100.0, crossing))
        assert c.result().value is None  # never judged
    c = MinGap(40.0, ROAD, EGO_LENGTH)
    c.update(sample(0.0, 20.0, 100.0, beside))
    assert c.result().value is None

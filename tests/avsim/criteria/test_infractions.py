"""Infractions (`avsim.criteria.base.Infraction`): reported when they happen, at the sample's
time and the ego's place. A threshold criterion reports its first failure once; an event that
breaks a rule each time (a contact, a stop line run, a red light entered, a wait too long)
is reported every time; the set hands them over after each update, in criteria order."""

from __future__ import annotations

import numpy as np

from avsim.criteria.base import CriteriaSet, Infraction, TruthSample
from avsim.criteria.collision import NoCollision
from avsim.criteria.road_rules import RedLights, StopSigns
from avsim.criteria.speed import SpeedLimit
from tests.roads import KPH, make_map, seg
from world.hdmap import StopSign
from world.spec import TrafficLightSpec

RATE = 40.0  # [Hz]
ROAD = make_map(seg(500.0), features=(StopSign(100.0), StopSign(200.0)))  # 50 km/h


def sample(t: float, station: float, speed: float,
           touching: frozenset[int] = frozenset()) -> TruthSample:
    return TruthSample(t=t, speed=speed, station=station, front_station=station + 2.4,
                       tyres=np.zeros((4, 2)), tyre_stations=np.full(4, station),
                       tyre_offsets=np.zeros(4), touching=touching, xy=(station, 1.5))


def test_a_threshold_criterion_reports_its_first_failure_only() -> None:
    c = SpeedLimit(ROAD)
    assert c.take_infractions() == []
    fast = 60 * KPH  # 10 km/h over the limit, for 2 s
    got = []
    for k in range(120):
        t = k / RATE
        c.update(sample(t, 10.0 + fast * t, 40 * KPH if k < 20 or k >= 100 else fast))
        got += c.take_infractions()
    assert got == [Infraction(0.5, "speed_limit",
                              "speed 60.0 km/h over the limit 50 km/h by 10.0 km/h",
                              (10.0 + fast * 0.5, 1.5))]
    assert c.result().first_failure == 0.5
    assert c.take_infractions() == []  # taken once


def test_each_contact_is_an_infraction_with_what_was_hit() -> None:
    c = NoCollision({3: "actor lead", 4: "kerb"})
    touches = [frozenset(), frozenset({3}), frozenset({3}), frozenset(), frozenset({3, 4}),
               frozenset({9})]
    for k, touching in enumerate(touches):
        c.update(sample(k * 0.1, 10.0 + k, 5.0, touching))
    got = c.take_infractions()
    assert [(i.t, i.message) for i in got] == [
        (0.1, "collision with actor lead"), (0.4, "collision with actor lead"),
        (0.4, "collision with kerb"), (0.5, "collision with body 9")]
    assert all(i.kind == "no_collision" for i in got)
    assert got[0].where == (11.0, 1.5)
    r = c.result()
    assert (r.value, r.first_failure) == (4, 0.1)
    assert r.note == ("actor lead at 0.10 s; actor lead at 0.40 s; kerb at 0.40 s; "
                      "body 9 at 0.50 s")


def test_each_stop_line_run_is_an_infraction() -> None:
    c = StopSigns(ROAD)
    for k in range(2000):  # 10 m/s without stopping, over both lines
        c.update(sample(k / RATE, 50.0 + 10.0 * k / RATE, 10.0))
    got = c.take_infractions()
    assert [i.message for i in got] == [
        "over the stop line at s = 100 m after a 0.0 s stop (1 s needed)",
        "over the stop line at s = 200 m after a 0.0 s stop (1 s needed)"]
    front = np.array([50.0 + 10.0 * k / RATE + 2.4 for k in range(2000)])
    first_over = [int(np.argmax(front > s)) / RATE for s in (100.0, 200.0)]
    assert [i.t for i in got] == first_over
    assert c.result().first_failure == first_over[0]


def test_each_red_light_entered_is_an_infraction() -> None:
    light = TrafficLightSpec(s=100.0, green=5.0, yellow=1.0, red=4.0, phase=0.0)  # red 6..10
    c = RedLights([light, TrafficLightSpec(s=130.0, green=5.0, yellow=1.0, red=4.0, phase=0.0)])
    for k in range(400):  # the front bumper over 100 m at t = 7.575 s, over 130 m at 8.775 s
        c.update(sample(k / RATE, 25.0 * k / RATE - 91.4, 25.0))
    got = c.take_infractions()
    assert [i.message for i in got] == [
        "entered the junction at s = 100 m with a margin of -1.58 s to red (negative: into "
        "red)",
        "entered the junction at s = 130 m with a margin of -2.78 s to red (negative: into "
        "red)"]
    assert [i.t for i in got] == [303 / RATE, 351 / RATE]
    assert c.result().first_failure == 303 / RATE


def test_the_set_hands_over_each_samples_infractions_in_criteria_order() -> None:
    collisions, limit = NoCollision({3: "actor lead"}), SpeedLimit(ROAD)
    criteria = CriteriaSet([limit, collisions])
    assert criteria.update(sample(0.0, 10.0, 5.0)) == []
    both = criteria.update(sample(0.025, 10.1, 60 * KPH, frozenset({3})))
    assert [(i.kind, i.t) for i in both] == [("speed_limit", 0.025), ("no_collision", 0.025)]
    assert criteria.update(sample(0.05, 10.2, 60 * KPH, frozenset({3}))) == []
    assert criteria.find(NoCollision) is collisions


def test_an_infraction_as_json() -> None:
    placed = Infraction(1.23456, "min_gap", "gap 3.2 m to lead under 14.1 m", (1.23449, -4e-4))
    assert placed.as_json() == {"t": 1.2346, "kind": "min_gap",
                                "message": "gap 3.2 m to lead under 14.1 m",
                                "where": [1.234, 0.0]}
    assert Infraction(2.0, "completes", "x", None).as_json()["where"] is None

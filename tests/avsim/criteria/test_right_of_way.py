"""`max_wait_with_right_of_way` on synthetic truth in a small town: a vehicle standing with
nothing ahead of it counts, one queued behind another does not (the one at the front
does); at a light only the green time counts, summed over one standstill; at an all-way
stop only the vehicle whose turn it is (first to stop), and only while the box is clear;
not a town: not applicable."""

from __future__ import annotations

import math

import numpy as np
import pytest

from avsim.criteria.base import TruthSample
from avsim.criteria.right_of_way import MaxWaitWithRightOfWay
from world.actors.actor_set import ActorPoses
from world.map.signals import light_colour
from world.map.town import TownLayout
from world.spec import ActorType, TownSpec

HALF = 2.4  # [m]
RATE = 4.0  # [Hz] enough for these tests


def town(junctions: str) -> TownSpec:
    return TownSpec(blocks_x=2, blocks_y=2, block=80.0, lanes=1, lane_width=3.5,
                    speed_limit=11.0, junctions=junctions)


def sample(t: float, ego: tuple[float, float, float], npcs: list[tuple[float, float, float]],
           ego_speed: float = 0.0, npc_speeds: list[float] | None = None) -> TruthSample:
    """The ego at (x, y, heading) and NPC sedans at theirs, standing unless `npc_speeds`
    [m/s] says."""
    x, y, h = ego
    f, left = np.array([math.cos(h), math.sin(h)]), np.array([-math.sin(h), math.cos(h)])
    tyres = np.array([(x, y) + a * f + b * left
                      for a, b in ((1.4, 0.8), (1.4, -0.8), (-1.3, 0.8), (-1.3, -0.8))])
    n = len(npcs)
    poses = ActorPoses(
        ids=tuple(f"car_{i}" for i in range(n)), kinds=(ActorType.CAR,) * n,
        centres=np.array([(px, py, 0.7) for px, py, _ in npcs]).reshape(-1, 3),
        yaws=np.array([ph for _, _, ph in npcs]), half_sizes=np.tile([HALF, 0.9, 0.7], (n, 1)),
        stations=np.zeros(n), offsets=np.zeros(n),
        speeds=np.array(npc_speeds or [0.0] * n, dtype=np.float64), accels=np.zeros(n))
    return TruthSample(t=t, speed=ego_speed, station=0.0, front_station=HALF, tyres=tyres,
                       tyre_stations=np.zeros(4), tyre_offsets=np.zeros(4),
                       touching=frozenset(), actors=poses, xy=(x, y))


def run(spec: TownSpec | None, ego: tuple[float, float, float],
        npcs: list[tuple[float, float, float]], seconds: float,
        threshold: float = 60.0) -> MaxWaitWithRightOfWay:
    c = MaxWaitWithRightOfWay(threshold, spec, HALF)
    for k in range(int(seconds * RATE) + 1):
        c.update(sample(k / RATE, ego, npcs))
    return c


def at_line(layout: TownLayout, junction: tuple[int, int], heading: str,
            back: float = 0.0) -> tuple[float, float, float]:
    """A car standing at `junction`'s line for `heading` traffic (its front 0.5 m before
    the line), `back` [m] further back."""
    a = next(a for a in layout.approaches() if a.junction == junction and a.heading == heading)
    h = {"east": 0.0, "north": 0.5 * math.pi, "west": math.pi, "south": -0.5 * math.pi}[heading]
    d = HALF + 0.5 + back
    return (a.stop_line[0] - d * math.cos(h), a.stop_line[1] - d * math.sin(h), h)


def test_a_vehicle_standing_with_nothing_ahead_fails_after_the_threshold() -> None:
    c = run(town("stop_signs"), (40.0, -1.75, 0.0), [], 70.0)
    r = c.result()
    assert r.failed and r.value is not None and r.value > 60.0 and r.note == "longest: ego"
    infractions = c.take_infractions()
    assert len(infractions) == 1 and "ego" in infractions[0].message
    assert not run(town("stop_signs"), (40.0, -1.75, 0.0), [], 50.0).result().failed


def test_a_queued_vehicle_waits_for_the_one_ahead_which_is_judged() -> None:
    ahead = (47.2, -1.75, 0.0)  # 7.2 m ahead of the ego: a 2.4 m bumper gap, same way
    r = run(town("stop_signs"), (40.0, -1.75, 0.0), [ahead], 70.0).result()
    assert r.failed and r.note == "longest: car_0"  # the car at the front, not the ego
    crossing = (47.2, -1.75, 0.5 * math.pi)  # across the ego's way: no queue
    r = run(town("stop_signs"), (40.0, -1.75, 0.0), [crossing], 70.0).result()
    assert r.note is not None and "ego" in r.note


def test_at_a_light_only_green_counts_over_one_standstill() -> None:
    spec = town("traffic_lights")
    layout = TownLayout(spec)
    ego = at_line(layout, (1, 1), "east")
    c = run(spec, ego, [], 200.0, threshold=60.0)
    light = layout.signal((1, 1), "east")
    green = sum(light_colour(light, k / RATE).value == "green"
                for k in range(1, int(200.0 * RATE) + 1)) / RATE
    value = c.result().value
    assert value is not None
    assert abs(value - green) < 0.5  # the green phases add up
    assert c.result().failed  # ~75 s of green over five cycles: stuck


def test_at_an_all_way_stop_the_first_to_stop_has_the_turn() -> None:
    spec = town("stop_signs")
    layout = TownLayout(spec)
    ego = at_line(layout, (1, 1), "east")
    c = MaxWaitWithRightOfWay(60.0, spec, HALF)
    south = at_line(layout, (1, 1), "north")
    for k in range(8):
        c.update(sample(k / RATE, ego, []))  # the ego stops first (2 s before: no tie)
    for k in range(8, 48):
        c.update(sample(k / RATE, ego, [south]))
    assert c._with_way.get("ego", 0.0) > 8.0  # its turn, the box clear
    assert "car_0" not in c._with_way  # it waits its turn: no right of way
    # a tie: the car on the ego's right goes first
    tie = MaxWaitWithRightOfWay(60.0, spec, HALF)
    tie.update(sample(0.0, ego, []))
    for k in range(1, 40):
        tie.update(sample(k / RATE, ego, [south]))
    assert tie._with_way.get("car_0", 0.0) > 8.0 and "ego" not in tie._with_way
    # a car in the box: the ego's turn, but it may not go
    c2 = MaxWaitWithRightOfWay(60.0, spec, HALF)
    box = (80.0, 80.0, 0.5 * math.pi)
    for k in range(40):
        c2.update(sample(k / RATE, ego, [box]))
    assert "ego" not in c2._with_way


def test_not_a_town_is_not_applicable() -> None:
    c = run(None, (40.0, -1.75, 0.0), [], 5.0)
    assert c.result().passed is None and c.idle


def _green_from(layout: TownLayout, t0: float) -> float:
    """[s] the first time from t0 at which the east light of junction (1, 1) is green."""
    light = layout.signal((1, 1), "east")
    k = 0
    while light_colour(light, t0 + k / RATE).value != "green":
        k += 1
    return t0 + k / RATE


@pytest.mark.parametrize(("case", "counted"), [
    ("clear junction", True),
    ("oncoming car approaching", False),  # a left turn on green yields to it: its way
    ("car moving in the box", False),
    ("oncoming car standing", True),  # it waits at its own line: not in the ego's way
    ("oncoming car far away", True),  # over YIELD_GAP from the box at its speed
    ("car behind the ego going away", True),  # not oncoming: it heads away from the box
])
def test_on_green_waiting_for_a_vehicle_with_the_way_is_not_counted(case: str,
                                                                    counted: bool) -> None:
    spec = town("traffic_lights")
    layout = TownLayout(spec)
    ego = at_line(layout, (1, 1), "east")
    cx, cy = layout.centre((1, 1))
    west = math.pi
    npcs = {  # (x, y, heading), speed [m/s]
        "clear junction": [],
        "oncoming car approaching": [((cx + 25.0, cy + 1.75, west), 8.0)],
        "car moving in the box": [((cx + 1.0, cy - 1.0, 0.5 * math.pi), 5.0)],
        "oncoming car standing": [((cx + 12.0, cy + 1.75, west), 0.0)],
        "oncoming car far away": [((cx + 80.0, cy + 1.75, west), 8.0)],
        "car behind the ego going away": [((cx - 40.0, cy + 1.75, west), 8.0)],
    }[case]
    c = MaxWaitWithRightOfWay(60.0, spec, HALF)
    start = _green_from(layout, 0.0)
    for k in range(20):  # 5 s of green
        c.update(sample(start + k / RATE, ego, [p for p, _ in npcs],
                        npc_speeds=[v for _, v in npcs]))
    assert (c._with_way.get("ego", 0.0) > 4.0) is counted, c._with_way
    assert ("ego" in c._with_way) is counted

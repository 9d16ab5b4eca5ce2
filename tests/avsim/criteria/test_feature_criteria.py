"""The feature criteria (`stop_signs`, `crosswalks`, `speed_bumps`) on synthetic ground truth:
the rule as SCENARIO_FORMAT.md states it, the value and first failure, and maps without the
feature."""

from __future__ import annotations

from collections.abc import Callable, Iterable

import numpy as np
import pytest

from avsim.criteria.base import TruthSample
from avsim.criteria.road_rules import Crosswalks, SpeedBumps, StopSigns
from tests.roads import KPH, W, make_map, seg
from world.actors.actor_set import ActorPoses
from world.hdmap import Crosswalk, RoadMap, SpeedBump, StopSign
from world.spec import ActorType, FeatureSpec

DT = 1 / 40  # [s] the criteria rate
HALF_LENGTH = 2.4  # [m] the ego's centre to its bumpers
FRONT_AXLE = REAR_AXLE = 1.35  # [m]
HALF_TRACK = 0.7  # [m]
PEDESTRIAN_HALF = (0.25, 0.3, 0.875)  # [m]
STOP_S, ZEBRA_S, ZEBRA_W, BUMP_S = 100.0, 150.0, 4.0, 200.0  # [m]


def road(*features: FeatureSpec) -> RoadMap:
    """300 m straight, 2 ego lanes and 1 oncoming (lane 0 centre at 0, lane 1 at 3.5 m)."""
    return make_map(seg(300.0), features=tuple(features))


def sample(t: float, speed: float, station: float, offset: float = 0.0,
           actors: ActorPoses | None = None,
           axles: tuple[float, float] | None = None) -> TruthSample:
    """The ego (centre at `station`, `offset` left of lane 0's centre, straight along the
    road) at time t."""
    tyre_s = np.array([station + FRONT_AXLE] * 2 + [station - REAR_AXLE] * 2)
    tyre_d = offset + np.array([HALF_TRACK, -HALF_TRACK] * 2)
    return TruthSample(
        t=t, speed=speed, station=station, front_station=station + HALF_LENGTH,
        tyres=np.column_stack([tyre_s, tyre_d]), tyre_stations=tyre_s, tyre_offsets=tyre_d,
        touching=frozenset(), offset=offset, actors=actors,
        rear_station=station - HALF_LENGTH, axle_stations=axles,
    )


def walkers(*where: tuple[float, float], kinds: Iterable[ActorType] | None = None
            ) -> ActorPoses:
    """Actors at (station, offset from the reference line), pedestrians unless told."""
    n = len(where)
    s = np.array([w[0] for w in where])
    d = np.array([w[1] for w in where])
    kinds_t = tuple(kinds) if kinds is not None else (ActorType.PEDESTRIAN,) * n
    return ActorPoses(
        ids=tuple(f"p{i}" for i in range(n)), kinds=kinds_t,
        centres=np.column_stack([s, d, np.full(n, 0.875)]), yaws=np.full(n, np.pi / 2),
        half_sizes=np.tile(PEDESTRIAN_HALF, (n, 1)), stations=s, offsets=d,
        speeds=np.zeros(n), accels=np.zeros(n),
    )


Profile = Callable[[float], tuple[float, float]]  # t -> (centre station, speed)


def drive(criterion: StopSigns | Crosswalks | SpeedBumps, profile: Profile, until: float,
          offset: float = 0.0, actors: ActorPoses | None = None) -> None:
    """Feed the criterion 40 Hz samples of the ego following `profile` from t = 0."""
    for i in range(round(until / DT) + 1):
        t = i * DT
        station, speed = profile(t)
        criterion.update(sample(t, speed, station, offset, actors))


def approach_and_stop(stop_front: float, t_stop: float, hold: float, speed: float = 5.0,
                      start_front: float = 60.0) -> Profile:
    """Front bumper from `start_front` at `speed` to `stop_front` (arriving at t_stop), held
    there `hold` seconds, then on at `speed` again."""
    def profile(t: float) -> tuple[float, float]:
        if t < t_stop:
            front = stop_front - speed * (t_stop - t)
            return max(front, start_front) - HALF_LENGTH, speed
        if t < t_stop + hold:
            return stop_front - HALF_LENGTH, 0.0
        return stop_front + speed * (t - t_stop - hold) - HALF_LENGTH, speed
    return profile


# -- stop_signs ----------------------------------------------------------------------------


def test_stop_of_a_second_and_more_before_the_line_passes() -> None:
    c = StopSigns(road(StopSign(STOP_S)))
    drive(c, approach_and_stop(STOP_S - 2.0, t_stop=8.0, hold=1.5), 12.0)
    r = c.result()
    assert r.passed and r.first_failure is None
    assert r.name == "stop_signs" and r.unit == "s" and r.threshold == 1.0
    assert r.value == pytest.approx(1.5 - DT, abs=DT)  # the standstill's samples span it


def test_running_the_line_fails_when_the_bumper_goes_over() -> None:
    c = StopSigns(road(StopSign(STOP_S)))
    drive(c, lambda t: (60.0 + 5.0 * t, 5.0), 12.0)  # front bumper at 100 m at t = 7.52
    r = c.result()
    assert not r.passed and r.value == 0.0
    crossing = (STOP_S - HALF_LENGTH - 60.0) / 5.0
    assert r.first_failure is not None
    assert crossing < r.first_failure <= crossing + DT


@pytest.mark.parametrize(("stop_front", "hold", "value"), [
    (STOP_S - 2.0, 0.5, 0.5 - DT),  # too short (its samples span 0.5 s less one period)
    (STOP_S - 5.0, 2.0, 0.0),  # long enough, but 5 m before the line: outside the zone
    (STOP_S + 0.5, 2.0, 0.0),  # over the line already
])
def test_a_stop_that_does_not_count_fails(stop_front: float, hold: float,
                                          value: float) -> None:
    c = StopSigns(road(StopSign(STOP_S)))
    drive(c, approach_and_stop(stop_front, t_stop=8.0, hold=hold), 14.0)
    r = c.result()
    assert not r.passed
    assert r.value == pytest.approx(value, abs=DT)
    assert r.first_failure is not None and r.first_failure > 7.0


@pytest.mark.parametrize("front", [STOP_S, STOP_S - 4.0])
def test_the_zone_ends_are_in_it(front: float) -> None:
    c = StopSigns(road(StopSign(STOP_S)))
    drive(c, approach_and_stop(front, t_stop=8.0, hold=1.2), 14.0)
    assert c.result().passed


def test_each_line_is_judged_and_the_worst_is_the_value() -> None:
    second = STOP_S + 50.0
    c = StopSigns(road(StopSign(STOP_S), StopSign(second)))

    def profile(t: float) -> tuple[float, float]:  # stops 2 s at the first, runs the second
        station, speed = approach_and_stop(STOP_S - 1.0, t_stop=8.0, hold=2.0)(t)
        return station, speed

    drive(c, profile, 30.0)
    r = c.result()
    assert not r.passed and r.value == 0.0
    assert c.judged == [True, True]
    assert c.longest[0] == pytest.approx(2.0, abs=DT)
    crossing = 8.0 + 2.0 + (second - STOP_S + 1.0) / 5.0
    assert r.first_failure == pytest.approx(crossing, abs=DT + 1e-9)


def test_lines_not_reached_or_already_passed_are_not_judged() -> None:
    c = StopSigns(road(StopSign(30.0), StopSign(STOP_S)))
    drive(c, lambda t: (50.0 + 2.0 * t, 2.0), 10.0)  # front from 52.4 to 72.4 m
    r = c.result()
    assert r.passed is None and r.value is None and c.judged == [False, False]
    assert r.verdict.value == "not_applicable" and r.note == "the ego met no stop line"


def test_no_stop_line_is_not_applicable() -> None:
    c = StopSigns(road())
    drive(c, lambda t: (10.0 + 10.0 * t, 10.0), 20.0)
    r = c.result()
    assert r.passed is None and r.value is None and r.first_failure is None
    assert r.note == "no stop line on the route" and not r.failed


# -- crosswalks ----------------------------------------------------------------------------


def crosswalk_run(*where: tuple[float, float], stop_front: float | None = None,
                  offset: float = 0.0, kinds: Iterable[ActorType] | None = None) -> Crosswalks:
    """The ego drives at 5 m/s over the crosswalk (or stops with its front bumper at
    `stop_front`) while actors stand at `where` (station, offset) the whole time."""
    c = Crosswalks(road(Crosswalk(ZEBRA_S, ZEBRA_W)))
    assert not c.idle  # it watches the pedestrians: the samples carry the actors
    actors = walkers(*where, kinds=kinds)
    profile = ((lambda t: (120.0 + 5.0 * t, 5.0)) if stop_front is None else
               approach_and_stop(stop_front, t_stop=6.0, hold=100.0, start_front=120.0))
    drive(c, profile, 12.0, actors=actors, offset=offset)
    return c


def test_stopping_short_of_an_occupied_crosswalk_passes() -> None:
    c = crosswalk_run((ZEBRA_S + 2.0, 0.5), stop_front=ZEBRA_S - 2.0)
    r = c.result()
    assert r.passed and r.first_failure is None
    assert r.name == "crosswalks" and r.unit == "m" and r.threshold == 0.0
    assert r.value == pytest.approx(-2.0)  # the closest the ego came: 2 m short


def test_entering_an_occupied_crosswalk_fails() -> None:
    c = crosswalk_run((ZEBRA_S + 2.0, 0.5))
    r = c.result()
    assert not r.passed
    assert r.value == pytest.approx(ZEBRA_W)  # the whole crosswalk under the car at once
    enter = (ZEBRA_S - HALF_LENGTH - 120.0) / 5.0  # front bumper at the near edge
    assert r.first_failure == pytest.approx(enter, abs=DT + 1e-9)


@pytest.mark.parametrize(("where", "conflict"), [
    ((ZEBRA_S + 2.0, W / 2 + 0.9), True),  # in lane 1, 0.9 m from lane 0
    ((ZEBRA_S + 2.0, W / 2 + 1.0 + 0.29), True),  # its footprint's edge 0.01 m inside 1 m
    ((ZEBRA_S + 2.0, W / 2 + 1.0 + 0.31), False),  # just beyond 1 m of lane 0
    ((ZEBRA_S + 2.0, -(W / 2 + 2.5) - 0.5), False),  # on the pavement: off the crosswalk
    ((ZEBRA_S - 0.5, 0.0), False),  # in the lane, 0.5 m before the zebra (0.3 m reach)
    ((ZEBRA_S + ZEBRA_W + 0.2, 0.0), True),  # overlapping its far edge
])
def test_which_pedestrians_count(where: tuple[float, float], conflict: bool) -> None:
    r = crosswalk_run(where).result()
    assert r.failed is conflict
    assert (r.value is not None and r.value > 0.0) is conflict
    if not conflict:  # nobody on the crosswalk in the ego's lane: nothing to judge
        assert r.passed is None and r.value is None


def test_the_lane_is_where_the_tyres_are() -> None:
    """In lane 1, a pedestrian in lane 0 more than 1 m from lane 1 does not count, one in
    lane 1 does; straddling both lanes, both count."""
    far = (ZEBRA_S + 2.0, -1.0)
    assert crosswalk_run(far, offset=W).result().passed is None  # not in its lane
    assert crosswalk_run((ZEBRA_S + 2.0, W), offset=W).result().failed
    assert crosswalk_run(far, offset=W / 2).result().failed


def test_other_actors_on_the_crosswalk_do_not_count() -> None:
    r = crosswalk_run((ZEBRA_S + 2.0, 0.0), kinds=[ActorType.CAR]).result()
    assert r.passed is None and r.value is None
    assert r.note == "no pedestrian was on a crosswalk in the ego's lane"


def test_no_crosswalk_is_not_applicable() -> None:
    c = Crosswalks(road(StopSign(STOP_S)))
    assert c.idle  # no crosswalk: the samples need not carry the actors
    drive(c, lambda t: (120.0 + 5.0 * t, 5.0), 12.0, actors=walkers((ZEBRA_S, 0.0)))
    r = c.result()
    assert r.passed is None and r.value is None and r.first_failure is None
    assert r.note == "no crosswalk on the route"


# -- speed_bumps ---------------------------------------------------------------------------

BUMP = SpeedBump(BUMP_S, 0.1, 0.9, 5 * KPH)


def bump_run(speed_kph: float, slow_from: float, slow_to: float, fast_kph: float = 30.0,
             axles: tuple[float, float] | None = None) -> SpeedBumps:
    """The ego's centre runs from 180 to 220 m at `fast_kph`, at `speed_kph` between
    stations slow_from and slow_to."""
    c = SpeedBumps(road(BUMP), FRONT_AXLE, REAR_AXLE)
    station, t = 180.0, 0.0
    while station < 220.0:
        kph = speed_kph if slow_from <= station <= slow_to else fast_kph
        c.update(sample(t, kph * KPH, station, axles=axles))
        station += kph * KPH * DT
        t += DT
    return c


NEAR_LO = BUMP_S - 0.45 - 1.0  # [m] the first axle station within 1 m of the bump
NEAR_HI = BUMP_S + 0.45 + 1.0


def test_taking_the_bump_slowly_passes() -> None:
    c = bump_run(4.0, NEAR_LO - FRONT_AXLE - 0.2, NEAR_HI + REAR_AXLE + 0.2)
    r = c.result()
    assert r.passed and r.first_failure is None
    assert r.name == "speed_bumps" and r.unit == "km/h" and r.threshold == 1.0
    assert r.value == pytest.approx(-1.0)  # 4 km/h at a 5 km/h bump


def test_too_fast_while_an_axle_is_near_fails() -> None:
    # slow until the front axle is over, then 10 km/h with the rear axle still near
    c = bump_run(4.0, NEAR_LO - FRONT_AXLE - 0.2, BUMP_S)
    r = c.result()
    assert not r.passed
    assert r.value == pytest.approx(25.0)  # 30 km/h once the slow stretch ends
    assert r.first_failure is not None
    c2 = bump_run(5.9, 150.0, 250.0)  # 5.9 km/h throughout: within pass + 1
    assert c2.result().passed and c2.result().value == pytest.approx(0.9)
    c3 = bump_run(6.2, 150.0, 250.0)
    assert not c3.result().passed and c3.result().value == pytest.approx(1.2)


def test_fast_until_just_outside_the_metre_passes() -> None:
    c = bump_run(4.0, NEAR_LO - FRONT_AXLE - 0.05, NEAR_HI + REAR_AXLE + 0.05)
    assert c.result().passed


def test_the_samples_axle_stations_are_used() -> None:
    """Axle stations given with the sample win over the centre +- the axle distances."""
    c = SpeedBumps(road(BUMP), FRONT_AXLE, REAR_AXLE)
    c.update(sample(0.0, 30 * KPH, 150.0, axles=(BUMP_S, BUMP_S - 2.7)))
    assert not c.result().passed
    c = SpeedBumps(road(BUMP), FRONT_AXLE, REAR_AXLE)
    c.update(sample(0.0, 30 * KPH, BUMP_S, axles=(150.0, 147.3)))
    assert c.result().passed is None and c.result().note == "no axle came near a speed bump"


def test_no_bump_is_not_applicable() -> None:
    c = SpeedBumps(road(StopSign(STOP_S)), FRONT_AXLE, REAR_AXLE)
    c.update(sample(0.0, 30 * KPH, BUMP_S))
    r = c.result()
    assert r.passed is None and r.value is None and r.first_failure is None
    assert r.note == "no speed bump on the route"

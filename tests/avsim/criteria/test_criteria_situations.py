"""The situation criteria on synthetic truth (no World): tyres_in_lane and the lane changes
it allows, judged from the truth and the map only (a weave fails whatever a stack declares),
lane_change_duration, lane_change_lateral_accel, standstill_gap, time_to_resume, and the
`note` a criterion whose situation never happened carries into the result file."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from avsim.criteria.base import CriterionResult, TruthSample, Verdict
from avsim.criteria.following import StandstillGap, TimeToResume
from avsim.criteria.lane import (
    LINE_HALF_WIDTH,
    MAX_ONCOMING_STAY,
    LaneChangeDuration,
    LaneChangeLateralAccel,
    TyresInLane,
)
from tests.roads import SHOULDER, W, make_map, seg
from tests.vehicle import CAR
from world.actors.actor_set import ActorPoses
from world.frames import MPS_PER_KPH as KPH
from world.hdmap import (
    Control,
    Junction,
    LineMark,
    LinePaint,
    Manoeuvre,
    MarkKind,
    PaintColour,
    RoadMap,
)
from world.map.road import build_road_map
from world.spec import ActorType, RoadSpec, SegmentSpec

ROAD = make_map(seg(1000.0))  # lane 0 centred on offset 0, lane 1 on W; 50 km/h
TYRE = CAR.tyre_width / 2  # [m] tyre half width (the URDF car's)
TRACK = 0.8  # [m] half the track: tyres at offset +-TRACK from the ego's centre
EGO_LENGTH = 4.8
CAR_HALF = np.array([2.3, 0.9, 0.75])
RATE = 40.0  # [Hz]
DT = 1 / RATE
IN_LANE = W / 2 - LINE_HALF_WIDTH - TRACK - TYRE  # [m] margin of a centred ego
STAGGER = np.array([1.4, 1.4, -1.4, -1.4])  # [m] tyre stations from the ego's centre


def cars(stations: list[float], offsets: list[float], speeds: list[float]) -> ActorPoses:
    n = len(stations)
    return ActorPoses(ids=tuple(f"car{i}" for i in range(n)), kinds=(ActorType.CAR,) * n,
                      centres=np.zeros((n, 3)), yaws=np.zeros(n),
                      half_sizes=np.tile(CAR_HALF, (n, 1)), stations=np.array(stations),
                      offsets=np.array(offsets), speeds=np.array(speeds), accels=np.zeros(n))


def truth(t: float, d: float = 0.0, *, speed: float = 10.0, station: float = 100.0,
          actors: ActorPoses | None = None, lat: float = 0.0, curv: float = 0.0,
          flat: bool = False) -> TruthSample:
    """The ego with its centre at offset d, tyres at d +- TRACK, 1.4 m before/after it."""
    return TruthSample(t=t, speed=speed, station=station, front_station=station + 2.4,
                       tyres=np.zeros((4, 2)), tyre_stations=station + STAGGER,
                       tyre_offsets=d + np.array([TRACK, -TRACK, TRACK, -TRACK]),
                       touching=frozenset(), offset=d, actors=actors, lateral_accel=lat,
                       road_curvature=curv, flat=flat)


def gap_ahead(gap: float, station: float = 100.0) -> float:
    """The station of a car `gap` metres (bumper to bumper) ahead of the ego at `station`."""
    return station + gap + float(CAR_HALF[0]) + EGO_LENGTH / 2


def judge(*offsets: float, every: float = 1.0, road: RoadMap = ROAD, flat: bool = False,
          station: float = 100.0, max_duration: float = 8.0) -> CriterionResult:
    """tyres_in_lane over the ego's centre at `offsets`, one sample each `every` seconds."""
    c = TyresInLane(road, TYRE, max_duration)
    for k, d in enumerate(offsets):
        c.update(truth(k * every, d, flat=flat, station=station))
    return c.result()


def test_centred_in_its_lane_the_margin_is_to_the_lanes_lines() -> None:
    r = judge(0.0, 0.0)
    assert r.passed and r.value == pytest.approx(IN_LANE) and r.threshold == 0.0


def test_a_tyre_over_the_line_and_back_is_no_lane_change_and_fails() -> None:
    r = judge(0.0, 1.0, 1.0, 0.0)  # left tyres at 1.8 from t = 1: over the line at 1.75
    assert not r.passed and r.first_failure == 1.0  # when it went over, known at t = 3
    assert r.value == pytest.approx(W / 2 - LINE_HALF_WIDTH - 1.8 - TYRE)
    assert r.verdict.value == "fail"


@pytest.mark.parametrize("path", [(0.0, 1.0, W / 2, 2.5, W), (W, 2.5, W / 2, 1.0, 0.0)])
def test_a_lane_change_into_the_next_lane_may_cross_the_line(path: tuple[float, ...]) -> None:
    r = judge(*path)
    assert r.passed and r.value == pytest.approx(IN_LANE)


def test_a_lane_change_and_back_are_two_lane_changes() -> None:
    assert judge(0.0, W / 2, W, W, W / 2, 0.0).passed


def test_a_lane_change_over_its_max_duration_fails_when_it_runs_over() -> None:
    r = judge(0.0, *[W / 2] * 10, W, max_duration=8.0)  # on the line from t = 1 to 10
    assert not r.passed and r.first_failure == 10.0  # 9 s after it left lane 0
    assert judge(0.0, *[W / 2] * 6, W, max_duration=8.0).passed


@pytest.mark.parametrize("d", [W + 1.0, -1.0])  # over lane 1's left line, lane 0's right
def test_beyond_the_lanes_of_its_direction_fails_at_once(d: float) -> None:
    r = judge(d)
    assert not r.passed and r.first_failure == 0.0
    assert r.value == pytest.approx(W / 2 - LINE_HALF_WIDTH - 1.0 - TRACK - TYRE)


def test_the_shoulder_is_a_lane_only_after_a_flat_tyre() -> None:
    on_shoulder = -(W + SHOULDER) / 2  # its middle
    assert not judge(0.0, -W / 2, on_shoulder).passed
    r = judge(0.0, -W / 2, on_shoulder, flat=True)
    # entered by its left line: the margin is to the paved edge (no paint there)
    assert r.passed and r.value == pytest.approx(SHOULDER / 2 - TRACK - TYRE)


def junction_road() -> RoadMap:
    """ROAD with a junction box from s = 200 to 220 (no lines there)."""
    j = Junction(index=(0, 0), manoeuvre=Manoeuvre.LEFT, control=Control.STOP_SIGNS,
                 s_stop=195.0, s_enter=200.0, s_exit=220.0, x=210.0, y=0.0, heading=0.0,
                 half_width=7.0)
    return RoadMap(ROAD.pieces, ROAD.sections, ROAD.features, ROAD.speed_limits,
                   junctions=(j,))


def test_in_a_junction_the_tyres_keep_to_the_turn_corridor() -> None:
    road = junction_road()
    # astride the (unpainted) line between the lanes inside the junction, then in lane 0
    c = TyresInLane(road, TYRE)
    for k, (station, d) in enumerate([(190.0, 0.0), (205.0, W / 2), (215.0, W / 2),
                                      (230.0, 0.0)]):
        c.update(truth(float(k), d, station=station))
    r = c.result()
    assert r.passed and r.value == pytest.approx(IN_LANE)
    edge = -W / 2 + TRACK + TYRE  # the right tyres' outer edge on the corridor's edge
    r = judge(edge - 0.1, road=road, station=210.0)
    assert not r.passed and r.value == pytest.approx(-0.1)


def weave_with_a_declared_change() -> CriterionResult:
    """A stack that says it changes lanes but weaves: its plan cannot help it, the
    criterion never sees it. Over the line and back, twice."""
    return judge(0.0, 1.2, 0.0, 1.2, 0.0, every=0.5)


def test_a_weave_fails_whatever_the_stack_declares() -> None:
    r = weave_with_a_declared_change()
    assert not r.passed and r.first_failure == 0.5
    fields = {f.name for f in dataclasses.fields(TruthSample)}
    assert not fields & {"lane", "origin_lane", "turning"}  # nothing of the plan to read


def change(v_lat: float, end: float = 20.0, start: float = 1.0) -> LaneChangeDuration:
    """Lane keeping in lane 0, then from `start` the centre moves left at v_lat [m/s] to
    lane 1's centre, then keeps lane 1."""
    c = LaneChangeDuration(ROAD, TYRE, 5.0)
    for k in range(round(end * RATE)):
        t = k * DT
        c.update(truth(t, float(np.clip(v_lat * (t - start), 0.0, W))))
    return c


def crossing(v_lat: float) -> float:
    """[s] from the left tyre's outer edge reaching the line to the right one's leaving it."""
    return (2 * TRACK + 2 * TYRE + 2 * LINE_HALF_WIDTH) / v_lat


def test_a_lane_change_is_timed_from_the_first_tyre_out_to_all_tyres_in() -> None:
    c = change(0.75)
    r = c.result()
    assert r.passed and r.first_failure is None and r.note is None
    assert r.value == pytest.approx(crossing(0.75), abs=DT) and r.unit == "s"
    assert [x.duration for x in c.lanes.changes] == [r.value]  # one change, timed once


def test_a_too_slow_lane_change_fails_when_it_runs_over() -> None:
    r = change(0.32).result()
    assert not r.passed and r.value == pytest.approx(crossing(0.32), abs=DT)
    out = 1.0 + IN_LANE / 0.32  # the left tyre leaves lane 0
    assert r.first_failure == pytest.approx(out + 5.0, abs=2 * DT)


def test_a_lane_change_left_unfinished_counts_to_the_end() -> None:
    c = change(0.75, end=30.0)
    for k in range(round(10 * RATE)):  # a second change stops astride the line for 10 s
        c.update(truth(30.0 + k * DT, W / 2))
    r = c.result()
    assert not r.passed and r.value == pytest.approx(10.0, abs=DT) and r.note is None
    assert r.first_failure == pytest.approx(35.0, abs=2 * DT)


def accel_run(lat: float, when: tuple[float, float] = (2.0, 6.0), speed: float = 20.0,
              curv: float = 0.0) -> CriterionResult:
    """10 s at 40 Hz, the centre moving from lane 0 to lane 1 from 2 to 6 s (the first
    tyre out at 2.9 s, all in at 5.1 s: judged from 1.9 to 6.1 s), `lat` lateral accel
    within `when`."""
    c = LaneChangeLateralAccel(ROAD, TYRE, 1.0, RATE)
    for k in range(round(10 * RATE)):
        t = k * DT
        c.update(truth(t, float(np.clip((t - 2.0) * W / 4.0, 0.0, W)), speed=speed,
                       curv=curv, lat=lat if when[0] <= t < when[1] else 0.0))
    return c.result()


def test_lateral_accel_within_the_bound_passes() -> None:
    r = accel_run(0.8)
    assert r.passed and r.value == pytest.approx(0.8) and r.first_failure is None


def test_lateral_accel_over_the_bound_fails_once_the_average_exceeds_it() -> None:
    r = accel_run(1.2)
    assert not r.passed and r.value == pytest.approx(1.2)
    assert r.first_failure == pytest.approx(2.0 + 6 * DT)  # 7 of the 8 samples at 1.2


def test_the_roads_curvature_is_not_the_changes() -> None:
    r = accel_run(1.2, when=(0.0, 10.0), curv=1.2 / 20.0**2)  # at 20 m/s
    assert r.passed and r.value == pytest.approx(0.0, abs=1e-9)


def test_lateral_accel_counts_from_1_s_before_to_1_s_after_the_change_only() -> None:
    assert accel_run(2.0, when=(0.5, 1.5)).passed
    assert accel_run(2.0, when=(6.4, 9.0)).passed
    for when in ((2.0, 2.3), (5.5, 5.8)):  # before the first tyre is out; after all are in
        r = accel_run(2.0, when=when)
        assert not r.passed and r.first_failure is not None
        assert when[0] < r.first_failure < when[1] + 0.1


def test_no_lane_change_fails_both_with_a_note() -> None:
    items = (LaneChangeDuration(ROAD, TYRE, 5.0), LaneChangeLateralAccel(ROAD, TYRE, 1.0, RATE))
    for k in range(100):  # lane 0 kept, a little off centre and swerving
        for c in items:
            c.update(truth(k * DT, 0.2, lat=0.3))
    for r in (c.result() for c in items):
        assert not r.passed and r.value is None and r.note == "no lane change was made"
        assert r.as_json()["note"] == "no lane change was made"


def stood(*stops: tuple[float, float]) -> CriterionResult:
    """Per stop (hold [s], gap [m]): roll at 2 m/s for 1 s, then stand `hold` s behind a car
    `gap` ahead; band [2, 6] m."""
    c, t = StandstillGap(2.0, 6.0, ROAD, EGO_LENGTH), 0.0
    for hold, gap in stops:
        lead = cars([gap_ahead(gap)], [0.1], [0.0])
        for k in range(round((1.0 + hold) * RATE)):
            c.update(truth(t + k * DT, speed=2.0 if k < RATE else 0.0, actors=lead))
        t += (1.0 + hold) * RATE * DT
    return c.result()


def test_standing_4_m_behind_a_car_passes() -> None:
    r = stood((2.0, 4.0))
    assert r.passed and r.value == pytest.approx(4.0) and r.note is None
    assert "note" not in r.as_json()


def test_standing_too_close_fails_once_it_has_stood_1_s() -> None:
    r = stood((2.0, 4.0), (2.0, 1.5))  # the second stop from t = 3 s
    assert not r.passed and r.value == pytest.approx(1.5) and r.threshold == 2.0
    assert r.first_failure == pytest.approx(3.0 + 2.0, abs=DT)


@pytest.mark.parametrize("stop", [(0.9, 1.5), (3.0, 16.0)])  # short, nothing within 15 m
def test_a_short_stop_or_one_with_nothing_near_is_no_standstill(stop: tuple[float, float]) -> None:
    r = stood(stop)
    assert r.verdict is Verdict.NOT_APPLICABLE and r.first_failure is None
    assert r.note == "the ego never stood behind a standing vehicle"


def test_never_standing_is_not_applicable_with_a_note_in_the_json() -> None:
    c = StandstillGap(2.0, 6.0, ROAD, EGO_LENGTH)
    for k in range(100):
        c.update(truth(k * DT, speed=5.0, actors=cars([gap_ahead(4.0)], [0.0], [5.0])))
    assert c.result().as_json() == {
        "name": "standstill_gap", "verdict": "not_applicable", "passed": None, "value": None,
        "threshold": 2.0, "unit": "m", "note": "the ego never stood behind a standing vehicle"}


def test_the_gap_opening_as_the_vehicle_ahead_drives_off_is_not_judged() -> None:
    """The ego stands 2 s 4 m behind a standing car, which then drives off at 2 m/s while
    the ego still stands 2 s: the gap judged is 4 m, not the 8 m it opens to."""
    c = StandstillGap(2.0, 6.0, ROAD, EGO_LENGTH)
    for k in range(round(4.0 * RATE)):
        t = k * DT
        moving = t >= 2.0
        gap = 4.0 + (2.0 * (t - 2.0) if moving else 0.0)
        c.update(truth(t, speed=0.0, actors=cars([gap_ahead(gap)], [0.1],
                                                 [2.0 if moving else 0.0])))
    r = c.result()
    assert r.passed and r.value == pytest.approx(4.0)


def resume(back_at: float, *, leaves: bool = True, fast: float = 12.0, station: float = 100.0,
           road: RoadMap = ROAD) -> CriterionResult:
    """30 s at 10 Hz, set speed 12 m/s, 15 s allowed: the ego at 5 m/s behind a car at 5 m/s
    20 m ahead, which moves out to the left (offset 0 to W from 4 to 6 s: its footprint,
    0.9 m either side of its centre, out of the lane at 5.6 s); the ego at `fast` from
    `back_at`."""
    c = TimeToResume(15.0, 12.0, road, EGO_LENGTH)
    for k in range(300):
        t = k * 0.1
        d = float(np.clip((t - 4.0) * W / 2, 0.0, W)) if leaves else 0.0
        lead = cars([gap_ahead(20.0, station)], [d], [5.0])
        c.update(truth(t, speed=fast if t >= back_at - 1e-9 else 5.0, station=station,
                       actors=lead))
    return c.result()


def test_back_at_the_set_speed_5_4_s_after_the_lane_clears() -> None:
    r = resume(11.0)  # 12 m/s set, under the 50 km/h limit
    assert r.passed and r.value == pytest.approx(5.4, abs=0.11) and r.unit == "s"


@pytest.mark.parametrize(("back_at", "wait", "first_failure"),
                         [(25.0, 19.4, 25.0), (99.0, 24.4, None)])  # late; never (to the end)
def test_a_late_resume_fails(back_at: float, wait: float, first_failure: float | None) -> None:
    r = resume(back_at)
    assert not r.passed and r.value == pytest.approx(wait, abs=0.11) and r.note is None
    assert r.first_failure == (None if first_failure is None else pytest.approx(first_failure))


def test_a_lane_that_never_clears_fails_with_a_note() -> None:
    r = resume(11.0, leaves=False)
    assert not r.passed and r.note == "the lane ahead never cleared with the ego slowed"


def test_the_wanted_speed_is_the_posted_limit_at_the_front_bumper_where_lower() -> None:
    road = make_map(seg(200.0), seg(800.0, speed_kph=30.0))  # 30 km/h from s = 200
    # the centre at 198 (under 50 km/h), the front bumper at 200.4 (under 30 km/h)
    r = resume(8.0, fast=30 * KPH, station=198.0, road=road)
    assert r.passed and r.value == pytest.approx(2.4, abs=0.11)
    r = resume(8.0, fast=30 * KPH, station=198.0)  # 50 km/h: 12 m/s wanted, 8.3 is slow
    assert not r.passed and r.value == pytest.approx(24.4, abs=0.11)


def test_a_lane_changes_own_lines_do_not_count_against_its_margin() -> None:
    """Leaving lane 0 by its left line and entering lane 1 by its right one, the tyres come
    to those lines by necessity: the margin is to the lines kept (lane 0's right, lane 1's
    left); hugging lane 0's right line still shows."""
    r = judge(0.0, 0.7, 1.0, W / 2, W - 1.0, W - 0.7, W, every=0.5)
    assert r.passed and r.value == pytest.approx(IN_LANE)
    hug = -IN_LANE + 0.05  # the right tyres 0.05 m from lane 0's right line
    r = judge(hug, 0.7, W / 2, W, every=0.5)
    assert r.passed and r.value == pytest.approx(0.05)


def _one_each_way(centre: MarkKind | None) -> RoadMap:
    """A straight 1 + 1 road whose centre line is painted `centre` (None: the road's own
    double solid yellow line)."""
    paint = None if centre is None else LinePaint(
        LineMark(MarkKind.SOLID, 0.15), (), LineMark(MarkKind.BROKEN, 0.15, PaintColour.YELLOW)
        if centre is MarkKind.BROKEN else LineMark(MarkKind.SOLID, 0.15, PaintColour.YELLOW),
        (LineMark(MarkKind.SOLID, 0.15),))
    segment = SegmentSpec(length=1000.0, curvature=0.0, lanes=1, oncoming_lanes=1,
                          lane_width=W, shoulder=1.0, paint=paint)
    return build_road_map(RoadSpec(segments=(segment,), speed_limit=30.0 * KPH))


def test_a_pass_through_the_oncoming_lane_beyond_a_broken_centre_line_is_lane_changes(
) -> None:
    """Out into the oncoming lane (-1), a stay in it, and back: two lane changes, inside a
    lane's lines all along; the same path across a solid centre line is a departure."""
    path = (0.0, W / 2, W, W, W, W / 2, 0.0)
    r = judge(*path, road=_one_each_way(MarkKind.BROKEN))
    assert r.passed and r.value == pytest.approx(IN_LANE)
    c = TyresInLane(_one_each_way(MarkKind.BROKEN), TYRE, 8.0)
    for k, d in enumerate(path):
        c.update(truth(float(k), d))
    assert [(x.origin, x.target) for x in c.lanes.changes] == [(0, -1), (-1, 0)]
    for centre in (None, MarkKind.SOLID):
        r = judge(*path, road=_one_each_way(centre))
        assert not r.passed and r.first_failure == 1.0


def test_a_stay_in_the_oncoming_lane_is_bounded() -> None:
    """A pass draws past and returns: over MAX_ONCOMING_STAY wholly in the oncoming lane
    fails, once, when it runs over."""
    road = _one_each_way(MarkKind.BROKEN)
    n = int(MAX_ONCOMING_STAY) + 2
    r = judge(0.0, W / 2, *[W] * n, W / 2, 0.0, road=road)
    assert not r.passed and r.first_failure == 2.0 + MAX_ONCOMING_STAY + 1.0
    assert judge(0.0, W / 2, *[W] * (n - 2), W / 2, 0.0, road=road).passed

"""Map matching in the localiser (`Localizer.on_lane`): the camera's lane offset and heading
correct a biased GNSS pose across the lane; a reading that cannot be the car's lane is
gated out."""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import replace

import numpy as np
import pytest
from numpy.typing import NDArray

from perception.localization import Localizer, clear_ahead
from perception.messages import EgoState, LaneBoundary, LaneEstimate, ObjectClass, Track
from tests.roads import W, arc, make_map, seg
from world.frames import GnssFix, Odometry, wrap_angle
from world.hdmap import RoadMap

SPEED = 12.0  # [m/s]
ODO_RATE = 40.0  # [Hz]
GNSS_EVERY = 4  # odometry samples per fix and per camera frame (10 Hz)
CAMERA_DELAY = 0.1  # [s] a frame reaches the localiser one period after its capture
WHEEL_RADIUS = 0.33  # [m]
STATED_SIGMA = 1.24  # [m] a consumer receiver's stated accuracy


def drive(road: RoadMap, duration: float, bias: tuple[float, float], *, camera: bool = True,
          lane: int = 0, start_lane: int = 0, seed: int = 0, s0: float = 20.0,
          stated: float = STATED_SIGMA, noise: float = 0.3, confidence: float = 0.9,
          age: float = 0.0) -> tuple[Localizer, np.ndarray, np.ndarray]:
    """Drive the centre of `lane` at SPEED with a constant GNSS `bias`; the camera (if any)
    sees the lane with 4 cm / 0.5 deg noise at `confidence`, its last detection `age` [s] old.
    Returns the localiser, the times and the
    estimate's lateral errors [m] (left +, across the lane) at each tick."""
    rng = np.random.default_rng(seed)
    loc = Localizer(road=road, start_lane=start_lane)
    map_lane = road.lane(lane)
    poses: dict[int, EgoState] = {}
    times, errors = [], []
    for k in range(round(duration * ODO_RATE) + 1):
        t = k / ODO_RATE
        s = s0 + SPEED * t
        xy = map_lane.position(s, 0.0)
        heading = float(map_lane.heading_at(s))
        yaw_rate = SPEED * float(map_lane.curvature_at(s))
        spin = SPEED / WHEEL_RADIUS
        loc.on_odometry(Odometry(t, (spin, spin, spin, spin), WHEEL_RADIUS,
                                 yaw_rate + rng.normal(0.0, 0.005), 0.0))
        if k % GNSS_EVERY:
            continue
        loc.on_gnss(GnssFix(t, float(xy[0]) + bias[0] + rng.normal(0.0, noise),
                            float(xy[1]) + bias[1] + rng.normal(0.0, noise),
                            wrap_angle(heading + rng.normal(0.0, 0.005)), stated, 0.005))
        late = k - round(CAMERA_DELAY * ODO_RATE)
        if camera and late in poses:
            loc.on_lane(replace(estimate(t - CAMERA_DELAY, rng.normal(0.0, 0.04),
                                         rng.normal(0.0, math.radians(0.5)), confidence),
                                age=age), poses[late])
        est = loc.estimate(t)
        poses[k] = est
        normal = np.array([-math.sin(heading), math.cos(heading)])
        times.append(t)
        errors.append(float(normal @ (np.array([est.x, est.y]) - xy)))
    return loc, np.array(times), np.array(errors)


def estimate(t: float, offset: float, heading_error: float = 0.0,
             confidence: float = 0.9) -> LaneEstimate:
    return LaneEstimate(t=t, offset=offset, heading_error=heading_error, curvature=0.0,
                        width=W, confidence=confidence, left=None, right=None)


ROAD = make_map(seg(300.0), arc(120.0, 60.0), seg(200.0))  # two lanes, one oncoming


@pytest.mark.parametrize("bias", [(0.0, 1.5), (0.0, -1.5), (1.06, 1.06), (-1.2, -0.9)])
def test_biased_gnss_with_the_camera_converges_across_the_lane(
        bias: tuple[float, float]) -> None:
    """Straight (+x), then a left arc: the camera's lane takes the GNSS bias out across the
    lane within 2 s and keeps it out through the curve."""
    _, t, err = drive(ROAD, 40.0, bias)
    settled = t >= 2.0
    assert float(np.sqrt(np.mean(err[settled] ** 2))) < 0.05
    assert float(np.max(np.abs(err[settled]))) < 0.15


def test_a_receiver_that_understates_its_error_is_corrected_too() -> None:
    """0.5 m stated but 1.5 m off sideways (a receiver without a carrier-phase fix does not
    know of every offset): the camera's lane takes it out."""
    _, t, err = drive(ROAD, 20.0, (0.0, 1.5), stated=0.5, noise=0.05)
    settled = t >= 2.0
    assert float(np.sqrt(np.mean(err[settled] ** 2))) < 0.05
    assert float(np.max(np.abs(err[settled]))) < 0.15


def test_a_receiver_stating_rtk_accuracy_is_taken_at_its_word() -> None:
    """5 cm stated (an RTK fix): the camera's lane does not move the pose against it, so a
    wrong RTK fix (1.5 m off) is followed; a right one is not disturbed by the camera's own
    errors. (In the stack `perception.health` notices such a fix against the camera's lane
    and the localiser stops believing it: `test_gnss_consistency`.)"""
    _, t, err = drive(ROAD, 20.0, (0.0, 1.5), stated=0.05, noise=0.05)
    assert float(np.mean(err[t >= 2.0])) == pytest.approx(1.5, abs=0.2)


def test_without_the_camera_the_estimate_follows_the_bias() -> None:
    _, t, err = drive(ROAD, 20.0, (0.0, 1.5), camera=False)
    assert float(np.mean(err[t >= 2.0])) == pytest.approx(1.5, abs=0.2)


def test_a_bias_beyond_half_a_lane_matches_the_start_lane() -> None:
    """2.5 m to the left puts the fixes in lane 1: the first match is with the lane the car
    starts in, after that the nearest."""
    loc, t, err = drive(ROAD, 10.0, (0.0, 2.5))
    assert loc.matched
    assert float(np.max(np.abs(err[t >= 2.0]))) < 0.15


@pytest.mark.parametrize("bias", [(0.78, -4.56), (0.0, 4.0)])
def test_an_unstated_bias_of_more_than_a_lane_is_taken_out_at_the_first_frame(
        bias: tuple[float, float]) -> None:
    """A degraded receiver stating 0.71 m but 4.6 m off across the lane (beyond the gate of
    the bias's 1 m floor): the first frame is matched with the start lane all the same, and
    the estimate is in the car's lane from then on (gated, it stayed 4.6 m off for 3 s and
    the car steered out of its lane to bring it into the lane)."""
    loc, t, err = drive(ROAD, 10.0, bias, stated=0.71, noise=0.34)
    assert loc.matched
    assert float(np.max(np.abs(err[t >= 0.5]))) < 0.15


def test_a_wrong_lane_reading_is_gated_out() -> None:
    """Once matched, a reading that puts the car 1.6 m off the estimate (no lane has its
    centre there) is rejected and changes nothing; one of the lane next to it that agrees
    with the estimate is a match with that lane."""
    loc, t, _ = drive(ROAD, 5.0, (0.0, 1.5))
    pose = loc.estimate(t[-1])
    r = float(ROAD.lane(0).local_coordinates(np.array([pose.x, pose.y]))[1])
    before = loc.state
    wrong = loc.on_lane(estimate(t[-1], r + 1.6), pose)
    assert wrong is not None and not wrong.accepted and wrong.distance2 > 13.8
    assert np.array_equal(loc.state, before)
    beside = loc.on_lane(estimate(t[-1], r - W), pose)  # seen from lane 1's centre
    assert beside is not None and beside.accepted and beside.lane == 1
    assert abs(beside.innovation[0]) < 0.1


def test_one_lane_road_rejects_the_oncoming_lane() -> None:
    road = make_map(seg(400.0, lanes=1, oncoming=1))
    loc, t, _ = drive(road, 5.0, (0.0, -1.0))
    pose = loc.estimate(t[-1])
    reading = loc.on_lane(estimate(t[-1], W), pose)  # as if in the oncoming lane
    assert reading is not None and not reading.accepted and reading.lane == 0


def test_a_lane_kept_on_one_line_still_corrects_the_bias() -> None:
    """Beside a truck the camera keeps the lane on one line and the map's width: each
    frame's detection, taken by the lane filter, is less confident (0.3) but still measures
    the car across the lane (ALKS 4.1.3: a 1 m bias drift over 7 s, unmeasured, took the
    car into the truck). Its noise is larger: it converges, more slowly."""
    _, t, err = drive(ROAD, 40.0, (0.0, 1.5), confidence=0.3)
    settled = t >= 5.0
    assert float(np.sqrt(np.mean(err[settled] ** 2))) < 0.08
    assert float(np.max(np.abs(err[settled]))) < 0.2
    _, t, err = drive(ROAD, 20.0, (0.0, 1.5), confidence=0.3, age=0.2)
    assert float(np.mean(err[t >= 5.0])) == pytest.approx(1.5, abs=0.2)  # no detection
    #   taken, only the filter's prediction: not a measurement, the bias stays


@pytest.mark.parametrize(("confidence", "age"), [(0.15, 0.0), (0.4, 0.1)])
def test_an_unconfident_estimate_or_an_outage_changes_nothing(confidence: float,
                                                              age: float) -> None:
    """Below `weak_lane_confidence`, or under `lane_confidence` without this frame's
    detection taken (the lane filter's prediction): no map matching."""
    loc, t, _ = drive(ROAD, 3.0, (0.0, 1.0))
    pose = loc.estimate(t[-1])
    before = loc.state
    weak = replace(estimate(t[-1], 0.4, confidence=confidence), age=age)
    assert loc.on_lane(weak, pose) is None
    loc.on_gnss(GnssFix(t[-1], math.nan, math.nan, math.nan, STATED_SIGMA, 0.005,
                        valid=False))
    assert np.array_equal(loc.state, before)


def along_the_lane(loc: Localizer, road: RoadMap, rng: np.random.Generator, s0: float,
                   duration: float, bias_x: float,
                   ) -> Iterator[tuple[float, float, NDArray[np.float64], EgoState]]:
    """Drive lane 0 of a street heading +x from station `s0` [m] at SPEED for `duration`
    [s]: wheel odometry every tick, a GNSS fix every GNSS_EVERY ticks biased `bias_x` [m]
    along the street (noise 0.3 m); yields (t [s], station [m], true position, the pose
    estimate) after each fix."""
    lane = road.lane(0)
    for k in range(round(duration * ODO_RATE) + 1):
        t = k / ODO_RATE
        s = s0 + SPEED * t
        xy = lane.position(s, 0.0)
        spin = SPEED / WHEEL_RADIUS
        loc.on_odometry(Odometry(t, (spin, spin, spin, spin), WHEEL_RADIUS, 0.0, 0.0))
        if k % GNSS_EVERY:
            continue
        loc.on_gnss(GnssFix(t, float(xy[0]) + bias_x + rng.normal(0.0, 0.3),
                            float(xy[1]) + rng.normal(0.0, 0.3), rng.normal(0.0, 0.005),
                            STATED_SIGMA, 0.005))
        yield t, s, xy, loc.estimate(t)


def test_where_the_lines_end_at_a_town_junction_fixes_the_station() -> None:
    """A 2.5 m GNSS bias along the street: the camera's lane pins the lateral position but
    not the station, until the painted lines end at the junction's mouth within view."""
    from avsim.scenario.load import load_scenario
    from world.map.road import build_road_map

    road = build_road_map(load_scenario("town_left_turn").world.road)
    mouth = road.junctions[0].s_enter  # [m] 71: the lines of the approach end there
    rng = np.random.default_rng(1)
    loc = Localizer(road=road)
    along: list[tuple[float, float]] = []
    for t, s, xy, pose in along_the_lane(loc, road, rng, 20.0, 4.0, 2.5):  # s 20 -> 68
        end = min(mouth - s, 34.0)  # [m] where the lines end, or the view does
        line = LaneBoundary((1.75, 0.0, 0.0), 5.0, end + rng.normal(0.0, 0.2), 400)
        seen = replace(estimate(t, rng.normal(0.0, 0.04)), left=line,
                       right=replace(line, coefficients=(-1.75, 0.0, 0.0)))
        loc.on_lane(seen, pose)
        loc.on_line_end(seen, pose)
        est = loc.estimate(t)
        along.append((mouth - s, est.x - float(xy[0])))  # the street heads +x
    errors = dict(along)
    far = [e for d, e in along if d > 30.0]
    assert min(far) > 1.5  # the bias along the street: nothing sees it yet
    near = [e for d, e in along if d < 12.0]
    assert max(abs(e) for e in near) < 0.5, errors


def test_a_stop_line_seen_fixes_the_station() -> None:
    """A 2 m GNSS bias along the road, a stop line at s = 150 m: once the camera sees its
    near edge (6 to 17 m ahead) the station is the map's less that distance."""
    from world.hdmap import StopSign

    stop = 150.0
    road = make_map(seg(400.0), features=(StopSign(stop),))
    rng = np.random.default_rng(2)
    loc = Localizer(road=road)
    along: list[tuple[float, float, bool]] = []
    for t, s, xy, pose in along_the_lane(loc, road, rng, 30.0, 10.0, 2.0):  # s 30 -> 150
        loc.on_lane(estimate(t, rng.normal(0.0, 0.04)), pose)
        match = None
        if 6.0 <= stop - s <= 17.0:
            match = loc.on_stop_line(stop - s + rng.normal(0.0, 0.05), pose)
            assert match is not None
        along.append((stop - s, loc.estimate(t).x - float(xy[0]),
                      match is not None and match.accepted))
    assert min(e for d, e, _ in along if d > 20.0) > 1.2  # the bias: nothing sees it yet
    assert all(ok for d, _, ok in along if 6.0 <= d <= 17.0)
    assert max(abs(e) for d, e, _ in along if 0.0 <= d < 12.0) < 0.3
    back = replace(loc.estimate(t), x=100.0)  # 50 m before the line: none 3 m ahead
    assert loc.on_stop_line(3.0, back) is None


REAR_AXLE = 1.35  # [m] the car's centre ahead of its rear axle


def turn_through_junction(rear_axle: float) -> tuple[float, list[bool]]:
    """The town's left turn (radius 11.25 m) at 8 m/s, the rear axle on the lane's centre, a
    1.2 m GNSS bias across the approach: the camera sees the lane before the junction's
    mouth and after its exit, nothing in between. Returns the largest position error [m] in
    the junction and the gate's verdicts on the first 2 s of camera frames after it."""
    from avsim.scenario.load import load_scenario
    from world.map.road import build_road_map

    road = build_road_map(load_scenario("town_left_turn").world.road)
    junction = road.junctions[0]
    lane = road.lane(0)
    rng = np.random.default_rng(3)
    loc = Localizer(replace(Localizer().params, rear_axle=rear_axle), road=road)
    speed, s0 = 8.0, 20.0  # [m/s], [m]
    spin = speed / WHEEL_RADIUS
    worst, after = 0.0, []
    for k in range(round((junction.s_exit + 16.0 - s0) / speed * ODO_RATE) + 1):
        t = k / ODO_RATE
        s = s0 + speed * t
        heading = float(lane.heading_at(s))
        centre = lane.position(s, 0.0) + REAR_AXLE * np.array([math.cos(heading),
                                                               math.sin(heading)])
        # the gyro reads the rate of the step that starts now (the filter's convention)
        rate = speed * float(lane.curvature_at(s + 0.5 * speed / ODO_RATE))
        loc.on_odometry(Odometry(t, (spin, spin, spin, spin), WHEEL_RADIUS, rate, 0.0))
        if k % GNSS_EVERY:
            continue
        loc.on_gnss(GnssFix(t, float(centre[0]) + rng.normal(0.0, 0.3),
                            float(centre[1]) - 1.2 + rng.normal(0.0, 0.3),
                            wrap_angle(heading + rng.normal(0.0, 0.005)), STATED_SIGMA,
                            0.005))
        pose = loc.estimate(t)
        if junction.s_enter <= s <= junction.s_exit:
            worst = max(worst, math.hypot(pose.x - centre[0], pose.y - centre[1]))
            continue
        match = loc.on_lane(estimate(t, rng.normal(0.0, 0.04)), pose)
        if s > junction.s_exit and match is not None:
            after.append(match.accepted)
    return worst, after[:20]


def test_the_lane_after_a_junction_turn_is_matched_at_once() -> None:
    """Through the turn the pose is dead reckoning from the rear wheels and the gyro; the
    centre, 1.35 m ahead of the rear axle, swings out with the heading. Carried by the
    motion model, the pose stays within 0.3 m through the junction (the lateral bias
    before it becomes one along the street after it: the lane takes it out), and the
    camera's lane after it is matched from the first frame."""
    worst, after = turn_through_junction(REAR_AXLE)
    assert worst < 0.3
    assert after and all(after)
    unmodelled, _ = turn_through_junction(0.0)
    assert unmodelled > 1.0  # what the turn did to the pose without the lever


def approach_behind_a_car(clear: bool) -> tuple[list[float], int]:
    """A 2.5 m GNSS bias along the street; a car 13 m ahead (its rear) hides the lines beyond
    it, so they seem to end there, until it has crossed the junction's mouth. Returns the
    errors [m] along the street from s = 20 to 61 m (the mouth at 71 m) and the number of
    line-end updates accepted."""
    from avsim.scenario.load import load_scenario
    from world.map.road import build_road_map

    road = build_road_map(load_scenario("town_left_turn").world.road)
    mouth = road.junctions[0].s_enter
    rng = np.random.default_rng(4)
    loc = Localizer(road=road)
    gap = 13.0  # [m] the car ahead's rear from the ego's centre
    errors, accepted = [], 0
    for t, s, xy, pose in along_the_lane(loc, road, rng, 20.0, 41.0 / SPEED, 2.5):
        end = min(mouth - s, gap, 34.0)  # [m] the mouth, the car ahead or the view
        line = LaneBoundary((1.75, 0.0, 0.0), 5.0, end + rng.normal(0.0, 0.2), 400)
        seen = replace(estimate(t, rng.normal(0.0, 0.04)), left=line,
                       right=replace(line, coefficients=(-1.75, 0.0, 0.0)))
        loc.on_lane(seen, pose)
        match = loc.on_line_end(seen, pose, gap if clear else math.inf)
        accepted += match is not None and match.accepted
        errors.append(loc.estimate(t).x - float(xy[0]))  # the street heads +x
    return errors, accepted


def test_lines_a_car_ahead_hides_do_not_place_the_car() -> None:
    """Behind a car the lines seem to end at its rear: that is no junction's mouth. Told how
    far the lane is clear, the localiser does not take those ends (the bias along the
    street stays what it was, 2.5 m); taking them moved the car metres the wrong way."""
    errors, accepted = approach_behind_a_car(clear=True)
    assert accepted == 0
    assert max(abs(e - 2.5) for e in errors) < 0.6
    fooled, taken = approach_behind_a_car(clear=False)
    assert taken > 0
    assert max(abs(e - 2.5) for e in fooled) > 2.0


def track(rel_x: float, rel_y: float) -> Track:
    return Track(id=1, t=0.0, x=0.0, y=0.0, vx=0.0, vy=0.0, rel_x=rel_x, rel_y=rel_y,
                 rel_vx=0.0, rel_vy=0.0, length=4.5, width=1.8, height=1.5,
                 yaw=0.0, cls=ObjectClass.CAR, hits=5, misses=0, position_sigma=0.2)


@pytest.mark.parametrize(("tracks", "clear"), [
    ((), math.inf),
    ((track(20.0, 0.3),), 17.75),  # in the lane: its rear
    ((track(20.0, 0.3), track(12.0, -2.5)), 9.75),  # one overlapping the lane's edge
    ((track(12.0, 3.5), track(-8.0, 0.0)), math.inf),  # the next lane, behind
])
def test_the_lane_is_clear_up_to_the_nearest_car_in_it(tracks: tuple[Track, ...],
                                                         clear: float) -> None:
    assert clear_ahead(tracks, 1.75) == pytest.approx(clear)


@pytest.mark.parametrize(("lane", "off", "dpsi"), [(0, 0.4, 0.02), (1, -0.3, -0.05)])
def test_the_map_lane_on_the_pose_is_the_lane_the_camera_would_see(lane: int, off: float,
                                                                   dpsi: float) -> None:
    """Where the camera's lane is no measurement, the stop line is looked for across the
    map's lane on the pose (`Localizer.map_lane`): the car's centre `off` [m] left of the
    centre of `lane` and `dpsi` [rad] left of its heading, in the vehicle frame there."""
    loc = Localizer(road=ROAD)
    centre = ROAD.lane(lane).position(100.0, 0.0)
    normal = np.array([0.0, 1.0])  # the road runs along +x there
    xy = centre + off * normal
    pose = EgoState(t=5.0, x=float(xy[0]), y=float(xy[1]), heading=dpsi, speed=8.0,
                    yaw_rate=0.0, steering_angle=0.0, position_sigma=0.5)
    m = loc.map_lane(pose, 4.9)
    assert m is not None and m.t == 4.9 and m.confidence == 0.0 and m.lines == 0
    assert m.offset == pytest.approx(off) and m.heading_error == pytest.approx(dpsi)
    assert m.width == pytest.approx(W) and m.curvature == 0.0
    assert m.centre_y(0.0) == pytest.approx(-off)
    assert Localizer().map_lane(pose, 4.9) is None  # no map

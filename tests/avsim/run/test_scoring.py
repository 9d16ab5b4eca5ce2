"""Perception scoring against ground truth, on synthetic captures (no PyBullet).

Each test builds the ground truth (`CaptureTruth` with `ActorPoses`), the LiDAR ray truth
(`LidarTruth`: returns per actor) and the stack's output (detections in the vehicle frame,
tracks in the map frame) by hand, with numbers chosen so that the expected scores follow
from the definitions in `avsim.run.scoring`'s docstring.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pytest

from avsim.run.scoring import CaptureTruth, PerceptionScore, ScoringParams
from perception.messages import Detection, LaneEstimate, ObjectClass, Track
from world.actors.actor_set import ActorPoses
from world.actors.catalogue import VehicleClass
from world.sensors.lidar import LidarTruth
from world.spec import ActorType

MIN_RETURNS = ScoringParams().min_returns
SEEN = 3 * MIN_RETURNS  # returns on a car that is clearly seen
OBJECT_KEYS = {"detection_recall", "detection_precision", "track_recall",
               "track_position_rmse", "track_speed_rmse", "id_switches",
               "max_id_switches_per_car_per_100s"}
LANE_KEYS = {"lane_offset_rmse", "lane_offset_max", "lane_heading_rmse_deg",
             "lane_heading_max_deg", "lane_raw_offset_rmse", "lane_frames"}


@dataclass(frozen=True, slots=True)
class Npc:
    """One ground-truth actor of a synthetic capture."""

    id: str
    x: float  # [m] map frame
    y: float  # [m]
    kind: ActorType = ActorType.CAR
    speed: float = 10.0  # [m/s]
    yaw: float = 0.0  # [rad]
    returns: int = SEEN  # LiDAR returns on it in the scan
    cls: VehicleClass | None = None  # its catalogue class; None: its type's default model's


def poses(npcs: list[Npc]) -> ActorPoses:
    n = len(npcs)
    return ActorPoses(
        ids=tuple(a.id for a in npcs),
        kinds=tuple(a.kind for a in npcs),
        centres=np.array([[a.x, a.y, 0.75] for a in npcs], dtype=np.float64).reshape(n, 3),
        yaws=np.array([a.yaw for a in npcs], dtype=np.float64),
        half_sizes=np.tile([2.3, 0.9, 0.75], (n, 1)).astype(np.float64),
        stations=np.zeros(n),
        offsets=np.zeros(n),
        speeds=np.array([a.speed for a in npcs], dtype=np.float64),
        accels=np.zeros(n),
        classes=(tuple(a.cls for a in npcs) if any(a.cls is not None for a in npcs)
                 else ()),
    )


def capture(npcs: list[Npc], t: float = 0.0, ego: tuple[float, float] = (0.0, 0.0),
            yaw: float = 0.0, lane_offset: float | None = 0.0,
            lane_heading_error: float = 0.0) -> tuple[CaptureTruth, LidarTruth]:
    """The truth of one capture and the ray truth of its scan (ground returns mixed in)."""
    truth = CaptureTruth(t=t, ego_xy=np.array(ego, dtype=np.float64), ego_yaw=yaw,
                         lane_offset=lane_offset, lane_heading_error=lane_heading_error,
                         actors=poses(npcs))
    hits = [np.full(a.returns, i, dtype=np.int16) for i, a in enumerate(npcs)]
    ground = np.full(500, -1, dtype=np.int16)
    actor = np.concatenate([ground, *hits]) if hits else ground
    rng = np.random.default_rng(0)
    return truth, LidarTruth(actor=rng.permutation(actor))


def to_vehicle(truth: CaptureTruth, x: float, y: float) -> tuple[float, float]:
    """A map point in the vehicle frame of the capture's TRUE pose."""
    dx, dy = x - truth.ego_xy[0], y - truth.ego_xy[1]
    c, s = math.cos(truth.ego_yaw), math.sin(truth.ego_yaw)
    return c * dx + s * dy, -s * dx + c * dy


def det(x: float, y: float, cls: ObjectClass = ObjectClass.CAR) -> Detection:
    """A detection at (x, y) in the vehicle frame."""
    return Detection(x=x, y=y, z=0.75, length=4.6, width=1.8, height=1.5, yaw=0.0, cls=cls,
                     points=SEEN)


def det_at(truth: CaptureTruth, x: float, y: float,
           cls: ObjectClass = ObjectClass.CAR) -> Detection:
    """A detection of something at map point (x, y)."""
    return det(*to_vehicle(truth, x, y), cls=cls)


def perfect_dets(truth: CaptureTruth, npcs: list[Npc]) -> tuple[Detection, ...]:
    return tuple(det_at(truth, a.x, a.y) for a in npcs)


def track(id_: int, x: float, y: float, vx: float = 10.0, vy: float = 0.0,
          cls: ObjectClass = ObjectClass.CAR) -> Track:
    """A track at map point (x, y) (the relative fields are not scored)."""
    return Track(id=id_, t=0.0, x=x, y=y, vx=vx, vy=vy, rel_x=0.0, rel_y=0.0, rel_vx=0.0,
                 rel_vy=0.0, length=4.6, width=1.8, height=1.5, yaw=0.0, cls=cls, hits=5,
                 misses=0, position_sigma=0.2)


def perfect_tracks(npcs: list[Npc], first_id: int = 1) -> tuple[Track, ...]:
    return tuple(track(first_id + i, a.x, a.y, a.speed * math.cos(a.yaw),
                       a.speed * math.sin(a.yaw)) for i, a in enumerate(npcs))


def lane(offset: float, heading_error: float = 0.0, confidence: float = 1.0) -> LaneEstimate:
    return LaneEstimate(t=0.0, offset=offset, heading_error=heading_error, curvature=0.0,
                        width=3.5, confidence=confidence, left=None, right=None)


# -- objects ---------------------------------------------------------------------------------


def test_perfect_perception_scores_one_and_zero_errors() -> None:
    ego = (120.0, -40.0)
    yaw = 0.7
    npcs = [Npc("a", 140.0, -30.0, yaw=0.7, speed=12.0),
            Npc("b", 100.0, -45.0, yaw=-2.4, speed=8.0),
            Npc("t", 125.0, -10.0, kind=ActorType.TRUCK, yaw=0.7, speed=5.0)]
    score = PerceptionScore()
    for k in range(5):
        truth, scan = capture(npcs, t=0.1 * k, ego=ego, yaw=yaw)
        score.objects(perfect_dets(truth, npcs), perfect_tracks(npcs), truth, scan)
    m = score.metrics()
    assert score.visible == 15 and score.detections == 15
    assert m["detection_recall"] == 1.0
    assert m["detection_precision"] == 1.0
    assert m["track_recall"] == 1.0
    assert m["track_position_rmse"] == pytest.approx(0.0, abs=1e-9)
    assert m["track_speed_rmse"] == pytest.approx(0.0, abs=1e-9)
    assert m["id_switches"] == 0.0
    assert m["max_id_switches_per_car_per_100s"] == 0.0


def test_missed_car_lowers_recall_by_its_share() -> None:
    npcs = [Npc(f"c{i}", 10.0 + 8.0 * i, 3.5 * (i % 2)) for i in range(4)]
    score = PerceptionScore()
    truth, scan = capture(npcs, t=0.0)
    score.objects(perfect_dets(truth, npcs[:3]), (), truth, scan)  # c3 missed
    assert score.metrics()["detection_recall"] == pytest.approx(3 / 4)
    truth, scan = capture(npcs, t=0.1)
    score.objects(perfect_dets(truth, npcs), (), truth, scan)  # all found
    m = score.metrics()
    assert m["detection_recall"] == pytest.approx(7 / 8)
    assert m["detection_precision"] == 1.0  # nothing false was reported
    assert m["track_recall"] == 0.0  # no tracks at all


def test_detection_with_no_car_near_lowers_precision() -> None:
    npcs = [Npc("a", 15.0, 0.0), Npc("b", 30.0, 3.5)]
    truth, scan = capture(npcs)
    gate = ScoringParams().match_distance
    dets = (*perfect_dets(truth, npcs),
            det(22.0, -6.0),  # nothing there
            det(30.0, 3.5 + gate + 0.5))  # beside b, but beyond the match distance
    score = PerceptionScore()
    score.objects(dets, (), truth, scan)
    m = score.metrics()
    assert m["detection_precision"] == pytest.approx(2 / 4)
    assert m["detection_recall"] == 1.0
    # a detection off by less than the match distance still counts
    score = PerceptionScore()
    score.objects((det(15.0 + 0.8 * gate, 0.0), det(30.0, 3.5)), (), truth, scan)
    assert score.metrics()["detection_precision"] == 1.0
    assert score.metrics()["detection_recall"] == 1.0


def test_two_detections_of_one_car_match_it_once() -> None:
    truth, scan = capture([Npc("a", 15.0, 0.0)])
    score = PerceptionScore()
    score.objects((det(15.0, 0.3), det(15.0, -0.3)), (), truth, scan)
    m = score.metrics()
    assert m["detection_recall"] == 1.0
    assert m["detection_precision"] == pytest.approx(1 / 2)


def test_occluded_car_is_not_counted_in_recall() -> None:
    hidden = Npc("hidden", 35.0, 0.0, returns=MIN_RETURNS - 1)
    npcs = [Npc("a", 15.0, 0.0), hidden]
    truth, scan = capture(npcs)
    score = PerceptionScore()
    score.objects(perfect_dets(truth, npcs[:1]), perfect_tracks(npcs[:1]), truth, scan)
    m = score.metrics()
    assert score.visible == 1
    assert m["detection_recall"] == 1.0
    assert m["track_recall"] == 1.0
    # a detection of the occluded car is not a false one (it matches a true vehicle) ...
    score = PerceptionScore()
    score.objects(perfect_dets(truth, npcs), perfect_tracks(npcs), truth, scan)
    m = score.metrics()
    assert m["detection_precision"] == 1.0 and m["detection_recall"] == 1.0
    assert score.tracked == 1  # ... and its track is not scored
    # exactly `min_returns` returns make it seen: now missing it lowers recall
    npcs[1] = Npc("hidden", 35.0, 0.0, returns=MIN_RETURNS)
    truth, scan = capture(npcs)
    score = PerceptionScore()
    score.objects(perfect_dets(truth, npcs[:1]), (), truth, scan)
    assert score.metrics()["detection_recall"] == pytest.approx(1 / 2)


def test_min_returns_parameter_is_used() -> None:
    npcs = [Npc("a", 15.0, 0.0, returns=25)]
    truth, scan = capture(npcs)
    for min_returns, visible in ((25, 1), (26, 0)):
        score = PerceptionScore(ScoringParams(min_returns=min_returns))
        score.objects((), (), truth, scan)
        assert score.visible == visible


def test_car_beyond_detection_range_is_not_counted() -> None:
    rng = ScoringParams().detection_range
    ego, yaw = (300.0, 200.0), -1.1
    far = Npc("far", ego[0] + (rng + 5.0) * math.cos(0.3), ego[1] + (rng + 5.0) * math.sin(0.3))
    edge = Npc("edge", ego[0] - (rng - 1.0), ego[1])  # just inside, behind-left
    near = Npc("near", ego[0] + 12.0, ego[1] - 4.0)
    truth, scan = capture([near, edge, far], ego=ego, yaw=yaw)
    score = PerceptionScore()
    score.objects(perfect_dets(truth, [near, edge]), (), truth, scan)  # far: not detected
    m = score.metrics()
    assert score.visible == 2
    assert m["detection_recall"] == 1.0
    # detecting it anyway neither raises the detection count nor lowers the precision
    score = PerceptionScore()
    score.objects(perfect_dets(truth, [near, edge, far]), (), truth, scan)
    assert score.detections == 2
    assert score.metrics()["detection_precision"] == 1.0
    # missing the one just inside the range counts
    score = PerceptionScore()
    score.objects(perfect_dets(truth, [near]), (), truth, scan)
    assert score.metrics()["detection_recall"] == pytest.approx(1 / 2)


def test_pedestrians_and_obstacles_are_not_vehicles() -> None:
    ped = Npc("ped", 12.0, -3.0, kind=ActorType.PEDESTRIAN, speed=1.2)
    box = Npc("box", 25.0, 0.0, kind=ActorType.OBSTACLE, speed=0.0)
    car = Npc("car", 40.0, 3.5)
    truth, scan = capture([ped, box, car])
    score = PerceptionScore()
    score.objects(perfect_dets(truth, [car]), perfect_tracks([car]), truth, scan)
    m = score.metrics()
    assert score.visible == 1
    assert m["detection_recall"] == 1.0 and m["track_recall"] == 1.0
    # their own (non-vehicle class) detections and tracks are ignored ...
    score = PerceptionScore()
    dets = (*perfect_dets(truth, [car]), det_at(truth, ped.x, ped.y, ObjectClass.PEDESTRIAN),
            det_at(truth, box.x, box.y, ObjectClass.OTHER))
    tracks = (*perfect_tracks([car]), track(9, ped.x, ped.y, 1.2, 0.0, ObjectClass.PEDESTRIAN))
    score.objects(dets, tracks, truth, scan)
    m = score.metrics()
    assert score.detections == 1 and m["detection_precision"] == 1.0
    assert score.tracked == 1
    # ... but calling a pedestrian a car is a false vehicle detection
    score = PerceptionScore()
    score.objects((*perfect_dets(truth, [car]), det_at(truth, ped.x, ped.y)), (), truth, scan)
    assert score.metrics()["detection_precision"] == pytest.approx(1 / 2)


@pytest.mark.parametrize(("ego", "yaw"), [((10.0, -5.0), math.pi / 2),
                                           ((-250.0, 80.0), -2.5),
                                           ((0.0, 0.0), math.pi)])
def test_detections_are_placed_with_the_true_ego_pose(ego: tuple[float, float],
                                                      yaw: float) -> None:
    c, s = math.cos(yaw), math.sin(yaw)
    ahead = Npc("ahead", ego[0] + 20.0 * c, ego[1] + 20.0 * s)  # 20 m straight ahead
    left = Npc("left", ego[0] - 10.0 * s, ego[1] + 10.0 * c)  # 10 m to the left
    truth, scan = capture([ahead, left], ego=ego, yaw=yaw)
    score = PerceptionScore()
    score.objects((det(20.0, 0.0), det(0.0, 10.0)), (), truth, scan)
    m = score.metrics()
    assert m["detection_recall"] == 1.0 and m["detection_precision"] == 1.0
    # the same detections with the frame mirrored (x, y swapped) match nothing
    score = PerceptionScore()
    score.objects((det(0.0, 20.0), det(10.0, 0.0)), (), truth, scan)
    m = score.metrics()
    assert m["detection_recall"] == 0.0 and m["detection_precision"] == 0.0


def test_detection_of_a_rotated_ego_lands_on_the_car_ahead() -> None:
    """The ego rotated by 90 deg and offset: a detection 20 m ahead is at ego + 20 m along
    +y, not along +x (the car there is found; one placed as if the yaw were 0 is not)."""
    ego = (10.0, -5.0)
    car = Npc("car", 10.0, 15.0)
    decoy = Npc("decoy", 30.0, -5.0)  # where an unrotated detection would land
    truth, scan = capture([car, decoy], ego=ego, yaw=math.pi / 2)
    score = PerceptionScore()
    score.objects((det(20.0, 0.0),), (), truth, scan)
    assert score.metrics()["detection_recall"] == pytest.approx(1 / 2)
    assert score.detected == 1 and score.true_detections == 1
    # which of the two it was: without the car, the detection is false
    truth, scan = capture([decoy], ego=ego, yaw=math.pi / 2)
    score = PerceptionScore()
    score.objects((det(20.0, 0.0),), (), truth, scan)
    assert score.detected == 0 and score.metrics()["detection_precision"] == 0.0


def test_track_position_and_speed_errors() -> None:
    a = Npc("a", 20.0, 0.0, speed=10.0)
    b = Npc("b", 35.0, 3.5, speed=5.0, yaw=math.pi)  # oncoming
    truth, scan = capture([a, b])
    tracks = (track(1, a.x + 0.3, a.y + 0.4, 11.0 * 0.6, 11.0 * 0.8),  # 0.5 m, +1 m/s
              track(2, b.x - 0.6, b.y + 0.8, -3.0, 0.0),  # 1.0 m, -2 m/s
              track(3, 80.0, 80.0))  # nothing there: not scored
    score = PerceptionScore()
    score.objects(perfect_dets(truth, [a, b]), tracks, truth, scan)
    m = score.metrics()
    assert m["track_position_rmse"] == pytest.approx(math.sqrt((0.5**2 + 1.0**2) / 2))
    assert m["track_speed_rmse"] == pytest.approx(math.sqrt((1.0**2 + 2.0**2) / 2))
    assert m["track_recall"] == 1.0
    np.testing.assert_allclose(sorted(score.track_pos_err), [0.5, 1.0])
    np.testing.assert_allclose(sorted(score.track_speed_err), [-2.0, 1.0])


def test_track_speed_is_compared_with_the_speed_magnitude() -> None:
    """A car reversing (negative speed along its travel direction) at 4 m/s, tracked moving
    at 4 m/s over ground: no speed error."""
    a = Npc("a", 20.0, 0.0, speed=-4.0)
    truth, scan = capture([a])
    score = PerceptionScore()
    score.objects((), (track(1, a.x, a.y, -4.0, 0.0),), truth, scan)
    assert score.metrics()["track_speed_rmse"] == pytest.approx(0.0, abs=1e-12)


def test_non_vehicle_tracks_are_not_matched_to_cars() -> None:
    a = Npc("a", 20.0, 0.0)
    truth, scan = capture([a])
    score = PerceptionScore()
    for cls in (ObjectClass.PEDESTRIAN, ObjectClass.OTHER):
        score.objects((), (track(1, a.x, a.y, cls=cls),), truth, scan)
    assert score.tracked == 0 and score.metrics()["track_recall"] == 0.0
    score.objects((), (track(1, a.x, a.y, cls=ObjectClass.TRUCK),), truth, scan)
    assert score.tracked == 1


def test_track_beyond_match_distance_is_not_matched() -> None:
    gate = ScoringParams().match_distance
    a = Npc("a", 20.0, 0.0)
    truth, scan = capture([a])
    score = PerceptionScore()
    score.objects((), (track(1, a.x + gate + 0.1, a.y),), truth, scan)
    m = score.metrics()
    assert m["track_recall"] == 0.0 and math.isnan(m["track_position_rmse"])
    score = PerceptionScore()
    score.objects((), (track(1, a.x + gate - 0.1, a.y),), truth, scan)
    assert score.metrics()["track_position_rmse"] == pytest.approx(gate - 0.1)


def _switching_run(times: list[float]) -> PerceptionScore:
    """Car a's track id: 1, 1, 2, (unmatched), 2, 3 -> 2 switches; car b's: 7 then 8 -> 1;
    car c: always 9 -> 0."""
    a_ids: list[int | None] = [1, 1, 2, None, 2, 3]
    b_ids = [7, 7, 7, 8, 8, 8]
    assert len(times) == len(a_ids)
    npcs = [Npc("a", 20.0, 0.0), Npc("b", 30.0, 3.5), Npc("c", 40.0, 3.5)]
    score = PerceptionScore()
    for t, a_id, b_id in zip(times, a_ids, b_ids, strict=True):
        truth, scan = capture(npcs, t=t)
        tracks = [track(b_id, 30.0, 3.5), track(9, 40.0, 3.5)]
        if a_id is not None:
            tracks.append(track(a_id, 20.0, 0.0))
        score.objects(perfect_dets(truth, npcs), tuple(tracks), truth, scan)
    return score


def test_id_switches_are_counted_per_car() -> None:
    score = _switching_run([0.0, 0.1, 0.2, 0.3, 0.4, 0.5])
    assert dict(score.switches) == {"a": 2, "b": 1}
    m = score.metrics()
    assert m["id_switches"] == 3.0
    assert m["track_recall"] == pytest.approx(17 / 18)


@pytest.mark.parametrize("span", [200.0, 400.0, 1000.0])
def test_id_switch_rate_scales_with_the_scored_span(span: float) -> None:
    times = list(np.linspace(50.0, 50.0 + span, 6))
    m = _switching_run(times).metrics()
    assert m["max_id_switches_per_car_per_100s"] == pytest.approx(2 * 100.0 / span)  # car a


def test_id_switch_rate_of_a_short_run_is_per_100s_at_least() -> None:
    """Runs shorter than 100 s are rated as 100 s long (no blow-up of a short run)."""
    m = _switching_run([0.0, 0.1, 0.2, 0.3, 0.4, 0.5]).metrics()
    assert m["max_id_switches_per_car_per_100s"] == pytest.approx(2.0)


# -- lanes -----------------------------------------------------------------------------------


def test_lane_offset_and_heading_errors() -> None:
    score = PerceptionScore()
    frames = [  # (estimate offset, heading; truth offset, heading) -> errors
        (0.30, 0.02, 0.10, 0.00),  # +0.2 m, +0.02 rad
        (-0.50, -0.05, -0.10, 0.03),  # -0.4 m, -0.08 rad
        (0.0, math.pi - 0.05, 0.0, -math.pi + 0.05),  # 0 m, -0.1 rad across +-pi
        (0.0, -math.pi + 0.02, 0.0, math.pi - 0.02),  # 0 m, +0.04 rad across +-pi
    ]
    for est_off, est_head, true_off, true_head in frames:
        truth, _ = capture([], lane_offset=true_off, lane_heading_error=true_head)
        score.lane(None, lane(est_off, est_head), truth)
    m = score.metrics()
    assert m["lane_frames"] == 4.0
    assert m["lane_offset_rmse"] == pytest.approx(math.sqrt((0.2**2 + 0.4**2) / 4))
    assert m["lane_offset_max"] == pytest.approx(0.4)
    heading = [0.02, -0.08, -0.1, 0.04]
    assert m["lane_heading_rmse_deg"] == pytest.approx(
        math.degrees(math.sqrt(np.mean(np.square(heading)))))
    assert m["lane_heading_max_deg"] == pytest.approx(math.degrees(0.1))
    assert math.isnan(m["lane_raw_offset_rmse"])  # no raw estimates given


def test_lane_frames_without_a_lane_are_skipped() -> None:
    score = PerceptionScore()
    truth, _ = capture([], lane_offset=0.1)
    score.lane(lane(0.2, confidence=0.5), lane(0.3), truth)
    off_road, _ = capture([], lane_offset=None, lane_heading_error=0.0)
    score.lane(lane(5.0), lane(9.0, 1.0), off_road)  # would dominate every error
    m = score.metrics()
    assert m["lane_frames"] == 1.0
    assert m["lane_offset_rmse"] == pytest.approx(0.2)
    assert m["lane_raw_offset_rmse"] == pytest.approx(0.1)
    assert m["lane_heading_max_deg"] == pytest.approx(0.0)


def test_raw_lane_with_zero_confidence_is_not_scored() -> None:
    score = PerceptionScore()
    truth, _ = capture([], lane_offset=-0.2)
    score.lane(lane(0.8, confidence=0.0), lane(-0.1), truth)  # raw: a prediction only
    score.lane(lane(0.1, confidence=0.3), lane(-0.1), truth)  # raw: +0.3 m
    score.lane(lane(0.6, confidence=0.9), None, truth)  # raw: +0.8 m, no filtered
    m = score.metrics()
    assert m["lane_raw_offset_rmse"] == pytest.approx(math.sqrt((0.3**2 + 0.8**2) / 2))
    assert m["lane_frames"] == 2.0  # frames with a filtered estimate
    assert m["lane_offset_rmse"] == pytest.approx(0.1)


# -- metrics ---------------------------------------------------------------------------------


def test_metrics_of_an_empty_score_are_nan() -> None:
    m = PerceptionScore().metrics()
    assert set(m) == LANE_KEYS  # object scores only once something was in range
    assert m["lane_frames"] == 0.0
    for key in LANE_KEYS - {"lane_frames"}:
        assert math.isnan(m[key]), key


def test_metrics_keys_and_nan_where_nothing_was_scored() -> None:
    # a scan with only a false detection: recall and track errors have nothing to score
    score = PerceptionScore()
    truth, scan = capture([Npc("far", 200.0, 0.0)])
    score.objects((det(10.0, 0.0),), (), truth, scan)
    m = score.metrics()
    assert set(m) == LANE_KEYS | OBJECT_KEYS | {"detection_precision_car",
                                                "first_tracked_distance_far"}
    assert math.isnan(m["first_tracked_distance_far"])  # never tracked
    assert m["detection_precision"] == m["detection_precision_car"] == 0.0
    for key in ("detection_recall", "track_recall", "track_position_rmse",
                "track_speed_rmse"):
        assert math.isnan(m[key]), key
    assert m["id_switches"] == 0.0 and m["max_id_switches_per_car_per_100s"] == 0.0
    # a seen car that was neither detected nor tracked: precision has nothing to score
    score = PerceptionScore()
    truth, scan = capture([Npc("a", 20.0, 0.0)])
    score.objects((), (), truth, scan)
    m = score.metrics()
    car_keys = {f"{k}_car" for k in ("detection_recall", "track_recall",
                                     "track_position_rmse", "track_speed_rmse", "id_switches")}
    # no precision_car: no car detected
    assert set(m) == LANE_KEYS | OBJECT_KEYS | car_keys | {"first_tracked_distance_a"}
    assert m["detection_recall"] == 0.0 and m["track_recall"] == 0.0
    assert m["detection_recall_car"] == 0.0 and m["track_recall_car"] == 0.0
    assert math.isnan(m["detection_precision"])
    assert math.isnan(m["track_position_rmse"]) and math.isnan(m["track_speed_rmse"])
    assert all(isinstance(v, float) for v in m.values())


def test_scans_without_any_actor() -> None:
    score = PerceptionScore()
    truth, scan = capture([])
    score.objects((), (), truth, scan)
    assert score.visible == 0 and score.detections == 0
    score.objects((det(12.0, 1.0),), (track(1, 12.0, 1.0),), truth, scan)
    m = score.metrics()
    assert m["detection_precision"] == 0.0 and math.isnan(m["detection_recall"])


# -- per class ---------------------------------------------------------------------------------


def test_scores_per_true_and_detected_class() -> None:
    """Recall and track scores by the truth's catalogue class, precision by the detector's
    class: a car, a rigid truck, a bus and a motorbike; the bus is missed (its box 3 m off,
    no track), the motorbike called a car, one phantom car."""
    npcs = [Npc("car", 20.0, 0.0, cls=VehicleClass.CAR),
            Npc("truck", 40.0, 3.5, kind=ActorType.TRUCK, cls=VehicleClass.TRUCK),
            Npc("bus", 30.0, -20.0, kind=ActorType.TRUCK, cls=VehicleClass.BUS),
            Npc("bike", -15.0, 0.0, cls=VehicleClass.MOTORBIKE)]
    score = PerceptionScore()
    for k in range(2):
        truth, scan = capture(npcs, t=0.1 * k)
        dets = (det_at(truth, 20.0, 0.0), det_at(truth, 40.0, 3.5, ObjectClass.TRUCK),
                det_at(truth, 33.0, -20.0, ObjectClass.TRUCK), det_at(truth, -15.0, 0.0),
                det_at(truth, 0.0, 30.0))
        tracks = (track(1, 20.0, 0.0), track(2, 41.0, 3.5, cls=ObjectClass.TRUCK),
                  track(3, -15.0, 0.0))
        score.objects(dets, tracks, truth, scan)
    m = score.metrics()
    assert m["detection_recall"] == pytest.approx(3 / 4)
    for cls, recall in (("car", 1.0), ("truck", 1.0), ("bus", 0.0), ("motorbike", 1.0)):
        assert m[f"detection_recall_{cls}"] == recall, cls
        assert m[f"track_recall_{cls}"] == recall, cls
    assert m["detection_precision_car"] == pytest.approx(2 / 3)  # car, motorbike; phantom
    assert m["detection_precision_truck"] == pytest.approx(1 / 2)  # truck; bus box off
    assert m["track_position_rmse_truck"] == pytest.approx(1.0)
    assert m["track_position_rmse_car"] == 0.0
    assert math.isnan(m["track_position_rmse_bus"])
    assert "detection_recall_pedestrian" not in m
    assert m["id_switches_car"] == m["id_switches_truck"] == 0.0


def test_id_switches_per_class() -> None:
    npcs = [Npc("car", 20.0, 0.0), Npc("truck", 40.0, 3.5, kind=ActorType.TRUCK)]
    score = PerceptionScore()
    for k, ids in enumerate([(1, 2), (1, 5), (1, 6)]):
        truth, scan = capture(npcs, t=0.1 * k)
        tracks = (track(ids[0], 20.0, 0.0), track(ids[1], 40.0, 3.5, cls=ObjectClass.TRUCK))
        score.objects(perfect_dets(truth, npcs), tracks, truth, scan)
    m = score.metrics()
    assert (m["id_switches"], m["id_switches_car"], m["id_switches_truck"]) == (2.0, 0.0, 2.0)


def test_default_classes_follow_the_type() -> None:
    """Poses without classes: a car actor is a car, a truck actor a truck (their default
    models' classes)."""
    npcs = [Npc("a", 10.0, 0.0), Npc("t", 25.0, 3.5, kind=ActorType.TRUCK)]
    score = PerceptionScore()
    truth, scan = capture(npcs)
    score.objects(perfect_dets(truth, npcs[:1]), (), truth, scan)
    m = score.metrics()
    assert (m["detection_recall_car"], m["detection_recall_truck"]) == (1.0, 0.0)


def test_the_range_at_which_each_actor_was_first_tracked() -> None:
    """Recorded once, at the first confirmed track on the actor, at any range."""
    score = PerceptionScore()
    truth, scan = capture([Npc("far", 200.0, 0.0), Npc("near", 30.0, 3.5)])
    score.objects((), (), truth, scan)  # nothing tracked yet
    truth_far = capture([Npc("far", 120.0, 0.0), Npc("near", 30.0, 3.5)])
    score.objects((), (track(1, 120.5, 0.3),), *truth_far)
    truth_later = capture([Npc("far", 60.0, 0.0), Npc("near", 30.0, 3.5)])
    score.objects((), (track(1, 60.0, 0.0),), *truth_later)
    m = score.metrics()
    assert m["first_tracked_distance_far"] == pytest.approx(120.0)
    assert math.isnan(m["first_tracked_distance_near"])

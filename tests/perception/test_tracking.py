"""Multi-object tracker: synthetic scans through the detector, and synthetic detections
(centre noise 0.05 m per axis, about what the detector gives for a car within 50 m)."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import numpy as np
import pytest

from perception.messages import Detection, EgoState, ObjectClass, Track
from perception.objects import ObjectDetector
from perception.tracking import MultiObjectTracker, TrackerParams, process_noise, relative
from tests.perception.lidar_synth import CAR, TRUCK, cast, lidar_info, on_ground

DEG = math.pi / 180.0
DT = 0.1  # [s] scan period (10 Hz)


@dataclass(frozen=True)
class Mover:
    """A map-frame object moving straight at constant speed."""

    x0: float  # [m] position at t = 0
    y0: float  # [m]
    heading: float  # [rad]
    speed: float  # [m/s]

    def at(self, t: float) -> tuple[float, float]:
        return (self.x0 + self.speed * t * math.cos(self.heading),
                self.y0 + self.speed * t * math.sin(self.heading))

    def velocity(self) -> tuple[float, float]:
        return self.speed * math.cos(self.heading), self.speed * math.sin(self.heading)


def ego_state(t: float, ego: Mover) -> EgoState:
    x, y = ego.at(t)
    return EgoState(t=t, x=x, y=y, heading=ego.heading, speed=ego.speed, yaw_rate=0.0,
                    steering_angle=0.0, position_sigma=0.05)


def in_vehicle_frame(ego: EgoState, x: float, y: float) -> tuple[float, float]:
    c, s = math.cos(ego.heading), math.sin(ego.heading)
    return c * (x - ego.x) + s * (y - ego.y), -s * (x - ego.x) + c * (y - ego.y)


def wrap_half_pi(a: float) -> float:
    w = math.remainder(a, math.pi)
    return math.pi / 2 if w == -math.pi / 2 else w


def observe(ego: EgoState, obj: Mover, t: float, rng: np.random.Generator | None = None,
            sigma: float = 0.05, cls: ObjectClass = ObjectClass.CAR,
            size: tuple[float, float, float] = CAR) -> Detection:
    """A detection of ``obj`` at ``t`` as the detector would give it (vehicle frame), with
    Gaussian centre noise ``sigma`` [m] if ``rng`` is given."""
    x, y = in_vehicle_frame(ego, *obj.at(t))
    if rng is not None:
        x, y = x + rng.normal(0.0, sigma), y + rng.normal(0.0, sigma)
    return Detection(x=x, y=y, z=0.5 * size[2], length=size[0], width=size[1], height=size[2],
                     yaw=wrap_half_pi(obj.heading - ego.heading), cls=cls, points=50)


def run(ego: Mover, objects: Sequence[Mover], scans: int, seed: int = 0,
        visible: Callable[[int, int], bool] = lambda k, i: True,
        params: TrackerParams | None = None) -> list[tuple[Track, ...]]:
    """Track synthetic detections of ``objects`` over ``scans`` scans; ``visible(k, i)``
    says whether object i is detected in scan k."""
    rng = np.random.default_rng(seed)
    tracker = MultiObjectTracker(params or TrackerParams())
    out = []
    for k in range(scans):
        t = k * DT
        state = ego_state(t, ego)
        dets = tuple(observe(state, obj, t, rng) for i, obj in enumerate(objects) if visible(k, i))
        out.append(tracker.update(t, state, dets))
    return out


def nearest(tracks: tuple[Track, ...], x: float, y: float) -> Track:
    return min(tracks, key=lambda tr: math.hypot(tr.x - x, tr.y - y))


# ---- through the detector -------------------------------------------------------------------


def test_car_seen_through_lidar_scans() -> None:
    """Ego at 10 m/s, a car overtaking in the left lane at 15 m/s: one confirmed track with
    a stable id, the right speed, position and relative velocity."""
    heading = 0.3
    ego = Mover(0.0, 0.0, heading, 10.0)
    left = (-math.sin(heading), math.cos(heading))
    car = Mover(15.0 * math.cos(heading) + 3.5 * left[0],
                15.0 * math.sin(heading) + 3.5 * left[1], heading, 15.0)
    detector, tracker = ObjectDetector(), MultiObjectTracker()
    info = lidar_info()
    ids, pos_err, speed_err = set(), [], []
    for k in range(45):
        t = k * DT
        state = ego_state(t, ego)
        x, y = in_vehicle_frame(state, *car.at(t))
        scan = cast(info, [on_ground(x, y, CAR, heading - state.heading)], t=t, seed=k)
        tracks = tracker.update(t, state, detector.detect(scan))
        assert len(tracks) == (0 if k < 2 else 1), (k, tracks)
        if not tracks:
            continue
        tr = tracks[0]
        ids.add(tr.id)
        if t >= 2.0:
            cx, cy = car.at(t)
            pos_err.append(math.hypot(tr.x - cx, tr.y - cy))
            speed_err.append(abs(tr.speed - car.speed))
            assert tr.rel_vx == pytest.approx(5.0, abs=0.3)
            assert tr.rel_vy == pytest.approx(0.0, abs=0.3)
            assert (tr.rel_x, tr.rel_y) == pytest.approx(in_vehicle_frame(state, cx, cy), abs=0.3)
            assert abs(tr.yaw - heading) <= 3.0 * DEG  # along the motion, not flipped
            assert tr.cls is ObjectClass.CAR
            # what the LiDAR saw of the car, completed by the generic prior: between the two
            prior = detector.params.car
            for size, true, assumed in zip((tr.length, tr.width, tr.height), CAR,
                                           (prior.length, prior.width, prior.height),
                                           strict=True):
                assert min(true, assumed) - 0.1 <= size <= max(true, assumed) + 0.1, tr
    assert ids == {1}
    assert max(speed_err) <= 0.3
    assert math.sqrt(np.mean(np.square(pos_err))) <= 0.2


# ---- synthetic detections ---------------------------------------------------------------------


@pytest.mark.parametrize("ego_heading", [0.0, 2.5, -3.0])
def test_relative_velocity_with_a_moving_ego(ego_heading: float) -> None:
    ego = Mover(5.0, -3.0, ego_heading, 10.0)
    c, s = math.cos(ego_heading), math.sin(ego_heading)
    ahead = Mover(5.0 + 20.0 * c, -3.0 + 20.0 * s, ego_heading, 15.0)  # same way, faster
    parked = Mover(5.0 + 40.0 * c + 3.0 * s, -3.0 + 40.0 * s - 3.0 * c, ego_heading, 0.0)
    oncoming = Mover(5.0 + 60.0 * c - 3.5 * s, -3.0 + 60.0 * s + 3.5 * c,
                     ego_heading + math.pi, 10.0)
    tracks = run(ego, [ahead, parked, oncoming], 40)[-1]
    assert len(tracks) == 3
    t = 39 * DT
    for obj, rel_vx in [(ahead, 5.0), (parked, -10.0), (oncoming, -20.0)]:
        tr = nearest(tracks, *obj.at(t))
        assert tr.rel_vx == pytest.approx(rel_vx, abs=0.3)
        assert tr.rel_vy == pytest.approx(0.0, abs=0.3)
        assert tr.speed == pytest.approx(obj.speed, abs=0.3)
        if obj.speed > 0.0:
            assert abs(math.remainder(tr.yaw - obj.heading, 2.0 * math.pi)) <= 3.0 * DEG


def test_relative_helper() -> None:
    ego = EgoState(t=0.0, x=1.0, y=2.0, heading=math.pi / 2, speed=10.0, yaw_rate=0.0,
                   steering_angle=0.0, position_sigma=0.0)
    # 5 m north of the ego is 5 m ahead; moving north at 15 m/s: +5 m/s relative, forward
    assert relative(1.0, 7.0, 0.0, 15.0, ego) == pytest.approx((5.0, 0.0, 5.0, 0.0))
    # 3 m east is 3 m to the right; standing still: -10 m/s forward
    assert relative(4.0, 2.0, 0.0, 0.0, ego) == pytest.approx((0.0, -3.0, -10.0, 0.0))


def test_passing_cars_keep_their_ids() -> None:
    """Two cars meet in adjacent lanes (3.5 m apart) at 25 m/s closing speed."""
    ego = Mover(0.0, 0.0, 0.0, 0.0)
    a = Mover(10.0, 0.0, 0.0, 12.5)
    b = Mover(60.0, 3.5, math.pi, 12.5)
    history = run(ego, [a, b], 40, seed=3)
    ids: dict[str, set[int]] = {"a": set(), "b": set()}
    for k, tracks in enumerate(history[2:], start=2):
        assert len(tracks) == 2
        for name, obj in (("a", a), ("b", b)):
            ids[name].add(nearest(tracks, *obj.at(k * DT)).id)
    assert len(ids["a"]) == 1 and len(ids["b"]) == 1 and ids["a"] != ids["b"]


def test_crossing_cars_keep_their_ids() -> None:
    """Two cars on crossing paths, 0.3 s apart at the crossing (2.1 m at the closest)."""
    ego = Mover(0.0, 0.0, 0.0, 5.0)
    a = Mover(0.0, 0.0, 0.0, 10.0)  # through (20, 0) at t = 2
    b = Mover(20.0, -23.0, math.pi / 2, 10.0)  # through (20, 0) at t = 2.3
    history = run(ego, [a, b], 45, seed=5)
    first = {name: nearest(history[5], *obj.at(5 * DT)).id for name, obj in
             (("a", a), ("b", b))}
    assert first["a"] != first["b"]
    for k, tracks in enumerate(history[5:], start=5):
        for name, obj in (("a", a), ("b", b)):
            tr = nearest(tracks, *obj.at(k * DT))
            assert tr.id == first[name], (k, name, tracks)
            assert math.hypot(tr.x - obj.at(k * DT)[0], tr.y - obj.at(k * DT)[1]) < 0.5


def test_track_coasts_through_missed_scans_then_is_deleted() -> None:
    ego = Mover(0.0, 0.0, 0.0, 10.0)
    car = Mover(20.0, 0.0, 0.0, 12.0)
    hidden = set(range(10, 13)) | set(range(16, 25))  # 3 missed scans, then 9

    history = run(ego, [car], 30, visible=lambda k, i: k not in hidden)
    for k in range(2, 10):
        assert [tr.id for tr in history[k]] == [1] and history[k][0].misses == 0
    for k, misses in zip(range(10, 13), (1, 2, 3), strict=True):  # coasting
        (tr,) = history[k]
        assert tr.id == 1 and tr.misses == misses
        x, y = car.at(k * DT)
        assert math.hypot(tr.x - x, tr.y - y) < 0.3  # predicted along
        assert tr.position_sigma > history[9][0].position_sigma
    for k in range(13, 16):  # re-acquired, same id
        assert [(tr.id, tr.misses) for tr in history[k]] == [(1, 0)]
    for k in range(16, 21):  # coasting up to max_coast (0.5 s)
        assert [(tr.id, tr.misses) for tr in history[k]] == [(1, k - 15)]
    for k in range(21, 27):  # deleted; the new track is tentative (2 hits at k = 26)
        assert history[k] == (), k
    assert [tr.id for tr in history[27]] == [2]  # a new id, never the old one


@pytest.mark.parametrize(("hits", "confirmed_at"), [
    ((0, 1, 2), 2),
    ((0, 2, 4), 4),  # 3 of 5
    ((0, 3, 4), 4),
    ((0, 1), None),  # too few
    ((0,), None),  # a one-off
    ((0, 4, 5), None),  # 1 of the first 4, then a new tentative track (not confirmed yet)
])
def test_birth_needs_m_of_n(hits: tuple[int, ...], confirmed_at: int | None) -> None:
    ego = Mover(0.0, 0.0, 0.0, 0.0)
    car = Mover(20.0, 0.0, 0.0, 5.0)
    history = run(ego, [car], 8, visible=lambda k, i: k in hits)
    for k, tracks in enumerate(history[:6]):
        expect_output = confirmed_at is not None and k >= confirmed_at
        assert len(tracks) == (1 if expect_output else 0), (k, tracks)
        if expect_output:
            assert tracks[0].id == 1


def test_far_tracks_are_deleted() -> None:
    ego = Mover(-40.0, 0.0, 0.0, 20.0)  # drives past a parked car at the origin
    parked = Mover(0.0, 3.5, 0.0, 0.0)
    params = TrackerParams(max_distance=30.0)
    history = run(ego, [parked], 60, params=params)
    for k, tracks in enumerate(history):
        distance = math.hypot(*(np.subtract(parked.at(0.0), ego.at(k * DT))))
        if distance > 30.0:
            assert tracks == (), (k, tracks)
    assert any(len(tracks) == 1 for tracks in history)


def test_class_vote_size_smoothing_and_heading() -> None:
    ego_mover = Mover(0.0, 0.0, 0.0, 0.0)
    car = Mover(30.0, -10.0, 2.0, 8.0)  # heading 2 rad: the box says 2 - pi
    rng = np.random.default_rng(7)
    tracker = MultiObjectTracker()
    tracks: tuple[Track, ...] = ()
    for k in range(30):
        t = k * DT
        ego = ego_state(t, ego_mover)
        cls = ObjectClass.TRUCK if k % 3 == 2 else ObjectClass.CAR
        det = observe(ego, car, t, rng, cls=cls, size=TRUCK if cls is ObjectClass.TRUCK else CAR)
        length = det.length + rng.normal(0.0, 0.2)
        det = Detection(det.x, det.y, det.z, length, det.width, det.height, det.yaw, det.cls,
                        det.points)
        tracks = tracker.update(t, ego, (det,))
    (tr,) = tracks
    assert tr.cls is ObjectClass.CAR  # 2 of 3
    assert CAR[0] < tr.length < TRUCK[0]  # smoothed between the two
    assert tr.yaw == pytest.approx(2.0, abs=3.0 * DEG)  # along the velocity


def test_deterministic() -> None:
    ego = Mover(0.0, 0.0, 0.3, 8.0)
    objects = [Mover(10.0, 3.0, 0.3, 12.0), Mover(50.0, 20.0, 0.3 + math.pi, 10.0),
               Mover(30.0, 5.0, 0.0, 0.0)]
    first = run(ego, objects, 30, seed=11, visible=lambda k, i: (k + i) % 7 != 0)
    second = run(ego, objects, 30, seed=11, visible=lambda k, i: (k + i) % 7 != 0)
    assert first == second
    assert all(list(tr.id for tr in tracks) == sorted(tr.id for tr in tracks)
               for tracks in first)


def test_process_noise_is_white_acceleration() -> None:
    q = process_noise(0.1, 2.0)
    assert q[0, 0] == pytest.approx(2.0 * 0.1**3 / 3.0)
    assert q[0, 2] == pytest.approx(2.0 * 0.1**2 / 2.0)
    assert q[2, 2] == pytest.approx(2.0 * 0.1)
    assert q[0, 1] == 0.0 and q[0, 3] == 0.0
    np.testing.assert_allclose(q, q.T)


@pytest.mark.parametrize("turn", [0.0, 3.0 * DEG])
def test_tracks_follow_a_jump_of_the_ego_pose(turn: float) -> None:
    """The localiser finds a 2.2 m GNSS bias (the camera's lane matched on the map) and moves
    the pose estimate across the road at once, and turns it by ``turn``: a truck driving
    beside the car stays one track, beside the car, at its speed (not left coasting into the
    car's lane with a second track for the same truck: ALKS 4.1.3)."""
    ego, truck = Mover(0.0, 0.0, 0.0, 16.7), Mover(5.0, 3.0, 0.0, 16.7)
    tracker = MultiObjectTracker()
    out = []
    for k in range(15):
        t = k * DT
        true_ego = ego_state(t, ego)
        det = observe(true_ego, truck, t, size=TRUCK, cls=ObjectClass.TRUCK)
        belief = true_ego if k >= 5 else EgoState(  # before the correction: off by the bias
            t=t, x=true_ego.x, y=true_ego.y - 2.2, heading=true_ego.heading - turn,
            speed=true_ego.speed, yaw_rate=0.0, steering_angle=0.0, position_sigma=2.0)
        out.append(tracker.update(t, belief, (det,)))
    for tracks in out[5:]:
        (only,) = tracks
        assert only.id == 1
        assert only.rel_y == pytest.approx(3.0, abs=0.1)
        assert only.rel_vx == pytest.approx(0.0, abs=0.3)
    assert out[-1][0].misses == 0


def test_a_box_that_grows_moves_its_far_end_not_its_velocity() -> None:
    """A car standing 60 m ahead, revealed by a cut-out: its first returns make a
    pedestrian's box (0.73 m), then a car's (4.61 m), each grown away from the sensor from
    the rear face seen (`perception.objects`). The track measures that face: its velocity
    stays the car's (0), its rear where it is, its centre moving away with its length (the
    box centre had moved 1.9 m away in 0.3 s: a car driving off at 0.7 m/s, to the ACC)."""
    ego = Mover(0.0, 0.0, 0.0, 16.7)
    rear = 60.0  # [m] the standing car's rear face, map frame
    tracker = MultiObjectTracker()
    tracks: tuple[Track, ...] = ()
    for k in range(12):
        t = k * DT
        state = ego_state(t, ego)
        cls, size = (ObjectClass.PEDESTRIAN, (0.73, 0.66, 1.76)) if k < 3 else \
            (ObjectClass.CAR, CAR)
        x, y = in_vehicle_frame(state, rear + 0.5 * size[0], 0.0)
        det = Detection(x=x, y=y, z=0.5 * size[2], length=size[0], width=size[1],
                        height=size[2], yaw=0.0, cls=cls, points=8)
        tracks = tracker.update(t, state, (det,))
        if k >= 3:
            (track,) = tracks
            assert abs(track.vx) < 0.2, (k, track.vx)
            assert track.x - 0.5 * track.length == pytest.approx(rear, abs=0.1)
    (track,) = tracks
    assert track.cls is ObjectClass.CAR
    assert track.length > 3.5  # smoothed towards the car's


def _follow_with_setback(setback: float, from_scan: int,
                         scans: int = 60) -> list[tuple[Track, ...]]:
    """The ego at 15 m/s behind a car at 13 m/s, 30 m ahead; from ``from_scan`` on, the
    detector sees only a face ``setback`` [m] beyond the car's rear (a cabin's, set back
    from the bumper: its box grown from there, ``end_seen`` False)."""
    ego, car = Mover(0.0, 0.0, 0.0, 15.0), Mover(30.0, 0.0, 0.0, 13.0)
    rng = np.random.default_rng(3)
    tracker = MultiObjectTracker()
    out = []
    for k in range(scans):
        t = k * DT
        state = ego_state(t, ego)
        det = observe(state, car, t, rng)
        if k >= from_scan:
            det = replace(det, x=det.x + setback, end_seen=False)
        out.append(tracker.update(t, state, (det,)))
    return out


def test_a_face_set_back_from_a_tracked_car_does_not_move_it() -> None:
    """A car followed with its rear seen, then for 2 s only above its boot (0.9 m set back):
    the track does not move to the face (it moved 0.8 m away, its speed with it): the face
    measures its lateral place only, its range coasts on its velocity (which the filter
    knows to within about 0.2 m/s here: 0.4 m in 2 s)."""
    out = _follow_with_setback(0.9, from_scan=20, scans=40)
    car = Mover(30.0, 0.0, 0.0, 13.0)
    for k in range(20, 40):
        (track,) = out[k]
        x, _ = car.at(k * DT)
        assert track.x == pytest.approx(x, abs=0.5), k
        assert track.x - x < 0.1, k  # never towards the face
        assert track.speed == pytest.approx(13.0, abs=0.3), k


def test_a_set_back_face_nearer_than_the_track_is_measured() -> None:
    """A face above the lower body but nearer than the track's end (the car braking, or the
    track too far) is taken: the car's end cannot lie beyond the body seen."""
    out = _follow_with_setback(-0.8, from_scan=20, scans=30)
    car = Mover(30.0, 0.0, 0.0, 13.0)
    (track,) = out[-1]
    assert track.x == pytest.approx(car.at(29 * DT)[0] - 0.8, abs=0.2)


def test_a_new_track_takes_a_set_back_face_as_its_end() -> None:
    """Nothing known of the car yet: its box is the detector's, from the face seen."""
    out = _follow_with_setback(0.9, from_scan=0, scans=10)
    car = Mover(30.0, 0.0, 0.0, 13.0)
    (track,) = out[-1]
    assert track.x == pytest.approx(car.at(9 * DT)[0] + 0.9, abs=0.2)

"""LiDAR object detector on synthetic scans (numpy ray caster, VLP-16-like, 2 cm range noise)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from perception.messages import Detection, ObjectClass
from perception.objects import (
    DetectorParams,
    ObjectDetector,
    fit_ground,
    grow_interval,
    inside_box,
    wrap_half_pi,
)
from tests.perception.lidar_synth import (
    CAR,
    FLAT,
    OBSTACLE,
    PEDESTRIAN,
    TRUCK,
    Box,
    Ground,
    cast,
    lidar_info,
    on_ground,
)
from world.actors.bodies import SIZES
from world.actors.catalogue import CATALOGUE
from world.actors.shapes.targets import EBTA, EMT, EPTA, EPTC, GVT
from world.frames import LidarScan, SensorMount

DEG = math.pi / 180.0
POSITION_TOL = 0.3  # [m] box centre error
YAW_TOL = 5.0 * DEG  # [rad] box heading error (mod pi)


@pytest.fixture(scope="module")
def detector() -> ObjectDetector:
    return ObjectDetector(DetectorParams())


def detect(detector: ObjectDetector, boxes: list[Box], columns: int = 1800,
           ground: Ground | None = FLAT, seed: int = 0) -> tuple[Detection, ...]:
    return detector.detect(cast(lidar_info(columns), boxes, ground=ground, seed=seed))


def yaw_error(a: float, b: float) -> float:
    """[rad] heading difference modulo pi (a box has no front)."""
    return abs(math.remainder(a - b, math.pi))


def assert_box(det: Detection, box: Box, cls: ObjectClass, check_yaw: bool = True) -> None:
    assert det.cls is cls, det
    assert math.hypot(det.x - box.x, det.y - box.y) <= POSITION_TOL, (det, box)
    if check_yaw:
        assert yaw_error(det.yaw, box.yaw) <= YAW_TOL, (det, box)
    assert -math.pi / 2 < det.yaw <= math.pi / 2


def assert_rear_in_place(det: Detection, box: Box) -> None:
    """A vehicle ahead (yaw 0) seen from behind: its rear face is where the truth's is, and
    the box is across the truth's centre line."""
    assert det.x - 0.5 * det.length == pytest.approx(box.x - 0.5 * box.length, abs=0.1), det
    assert det.y == pytest.approx(box.y, abs=POSITION_TOL), det
    assert yaw_error(det.yaw, box.yaw) <= YAW_TOL, det


@pytest.mark.parametrize("distance", [10.0, 30.0, 50.0])
@pytest.mark.parametrize("columns", [1800, 900])
def test_car_ahead_is_completed_from_its_rear(detector: ObjectDetector, distance: float,
                                              columns: int) -> None:
    box = on_ground(distance, 0.0, CAR)
    found = detect(detector, [box], columns)
    assert len(found) == 1, found
    det = found[0]
    assert_box(det, box, ObjectClass.CAR)
    # a rear says nothing of a car's length (nor, from below, of its roof): the generic
    # prior's box, grown away from the sensor, so that the rear face stays where it was seen
    prior = detector.params.car
    assert (det.length, det.width, det.height) == pytest.approx(
        (prior.length, max(prior.width, CAR[1]), prior.height), abs=0.05)
    assert_rear_in_place(det, box)
    assert det.z == pytest.approx(0.5 * prior.height, abs=0.05)
    assert det.points >= 4


@pytest.mark.parametrize(("x", "y"), [(0.0, 5.0), (3.0, -4.5), (-12.0, 3.5), (30.0, -3.5)])
def test_car_beside_or_in_an_adjacent_lane(detector: ObjectDetector, x: float, y: float) -> None:
    box = on_ground(x, y, CAR)
    found = detect(detector, [box])
    assert len(found) == 1, found
    assert_box(found[0], box, ObjectClass.CAR)


@pytest.mark.parametrize(("x", "y"), [(3.0, 3.5), (-3.0, -3.5), (0.0, 3.5), (5.0, -3.5)])
def test_car_close_beside_whose_roof_is_seen(detector: ObjectDetector, x: float,
                                             y: float) -> None:
    """Close beside the car, the LiDAR sees the other car's roof from above: its heading is
    fitted below the roof, so the box is not tilted, not too wide and not taken for a truck."""
    box = on_ground(x, y, CAR, 3.0 * DEG)
    found = detect(detector, [box])
    assert len(found) == 1, found
    assert_box(found[0], box, ObjectClass.CAR)
    assert found[0].width == pytest.approx(detector.params.car.width, abs=0.1)


@pytest.mark.parametrize(("x", "y", "yaw_deg"), [(15.0, 3.0, 30.0), (25.0, -6.0, -30.0),
                                                 (-10.0, 8.0, 60.0), (40.0, 10.0, 60.0)])
def test_car_at_an_angle(detector: ObjectDetector, x: float, y: float, yaw_deg: float) -> None:
    box = on_ground(x, y, CAR, yaw_deg * DEG)
    found = detect(detector, [box])
    assert len(found) == 1, found
    assert_box(found[0], box, ObjectClass.CAR)


@pytest.mark.parametrize(("x", "y"), [(20.0, 0.0), (40.0, -3.5)])
def test_truck_ahead(detector: ObjectDetector, x: float, y: float) -> None:
    """Seen from behind (its side at grazing incidence at most): the rear face in place and
    the generic truck prior's length (a rigid truck is longer: the box's centre is short)."""
    box = on_ground(x, y, TRUCK)
    found = detect(detector, [box])
    assert len(found) == 1, found  # its side, seen at grazing incidence, is not a second one
    assert found[0].cls is ObjectClass.TRUCK
    assert_rear_in_place(found[0], box)
    assert found[0].length == pytest.approx(detector.params.truck.length, abs=0.05)


@pytest.mark.parametrize(("model", "x", "y", "yaw_deg"), [
    ("rigid_truck", 12.0, -6.0, 20.0), ("bus", 10.0, 6.0, -10.0),
    ("semi_trailer", 4.0, -7.0, 0.0),
    pytest.param("semi_trailer", 14.0, 8.0, 15.0, marks=pytest.mark.xfail(
        strict=True, reason="known limit: the far end of a 16.5 m side seen at an angle "
        "breaks into fragments beyond the fitted box (15.1 m), which are kept as two OTHERs"))])
def test_truck_seen_along_its_side_has_its_length(detector: ObjectDetector, model: str,
                                                  x: float, y: float, yaw_deg: float) -> None:
    """Beside the car, the side is seen whole: the box has the vehicle's real length, longer
    than the prior (a semi-trailer's 16.5 m too: not taken for a structure)."""
    m = CATALOGUE[model]
    box = on_ground(x, y, (m.length, m.width, m.height), yaw_deg * DEG)
    found = detect(detector, [box])
    assert len(found) == 1, found
    assert_box(found[0], box, ObjectClass.TRUCK)
    assert found[0].length == pytest.approx(m.length, abs=0.15)


@pytest.mark.parametrize(("x", "y"), [(12.0, 2.0), (8.0, -5.5), (-6.0, 4.0), (20.0, 6.0)])
def test_pedestrian(detector: ObjectDetector, x: float, y: float) -> None:
    box = on_ground(x, y, PEDESTRIAN)
    found = detect(detector, [box])
    assert len(found) == 1, found
    assert_box(found[0], box, ObjectClass.PEDESTRIAN, check_yaw=False)


def test_obstacle_is_other(detector: ObjectDetector) -> None:
    box = on_ground(8.0, 0.0, OBSTACLE)
    found = detect(detector, [box])
    assert len(found) == 1, found
    assert_box(found[0], box, ObjectClass.OTHER, check_yaw=False)
    assert abs(math.remainder(found[0].yaw, math.pi / 2)) <= YAW_TOL  # a square: mod 90 deg
    assert (found[0].length, found[0].width) == pytest.approx((1.0, 1.0), abs=0.1)


@pytest.mark.parametrize("distance", [8.0, 15.0, 30.0])
def test_two_cars_side_by_side_are_two_detections(detector: ObjectDetector,
                                                  distance: float) -> None:
    gap = 1.5  # [m] between the bodies (adjacent lanes)
    boxes = [on_ground(distance, 0.0, CAR), on_ground(distance, CAR[1] + gap, CAR)]
    found = detect(detector, boxes)
    assert len(found) == 2, found
    for box in boxes:
        nearest = min(found, key=lambda d: math.hypot(d.x - box.x, d.y - box.y))
        assert_box(nearest, box, ObjectClass.CAR)


@pytest.mark.parametrize(("pitch_deg", "roll_deg"), [(1.0, 0.0), (-1.0, 0.0), (1.5, -1.0),
                                                     (0.0, 2.0)])
def test_tilted_ground_gives_no_detection(detector: ObjectDetector, pitch_deg: float,
                                          roll_deg: float) -> None:
    ground = Ground(pitch=pitch_deg * DEG, roll=roll_deg * DEG)
    assert detect(detector, [], ground=ground) == ()
    plane = detector.ground
    assert plane.a == pytest.approx(math.tan(pitch_deg * DEG), abs=1e-3)
    assert plane.b == pytest.approx(math.tan(roll_deg * DEG), abs=1e-3)


def test_car_on_a_pitched_ground_is_still_found(detector: ObjectDetector) -> None:
    pitch = 1.0 * DEG  # nose down: the ground rises ahead, the car stands on it
    x = 25.0
    box = Box(x, 0.0, x * math.tan(pitch) + 0.75, *CAR, yaw=0.0)
    found = detect(detector, [box], ground=Ground(pitch=pitch))
    assert len(found) == 1, found
    assert_box(found[0], box, ObjectClass.CAR)


def test_ground_fit_ignores_walls_and_roofs() -> None:
    scan = cast(lidar_info(), [on_ground(20.0, -14.0, (40.0, 10.0, 12.0)),
                               on_ground(6.0, 0.0, CAR), on_ground(6.0, 3.5, CAR)],
                ground=Ground(pitch=0.5 * DEG, offset=0.02))
    points = scan.info.mount.to_vehicle(scan.points)
    plane = fit_ground(points, DetectorParams())
    assert plane.a == pytest.approx(math.tan(0.5 * DEG), abs=1e-3)
    assert plane.b == pytest.approx(0.0, abs=1e-3)
    assert plane.c == pytest.approx(0.02, abs=0.01)


@pytest.mark.parametrize("building", [
    on_ground(20.0, -25.0, (30.0, 15.0, 10.0)),  # set back from the road
    on_ground(0.0, 9.0, (40.0, 8.0, 6.0)),  # a long wall alongside
    on_ground(30.0, 0.0, (8.0, 8.0, 6.0)),  # short but too tall
])
def test_building_is_not_a_detection(detector: ObjectDetector, building: Box) -> None:
    assert detect(detector, [building]) == ()


def test_empty_scans(detector: ObjectDetector) -> None:
    info = lidar_info()
    empty = LidarScan(t=0.0, info=info, points=np.zeros((0, 3), dtype=np.float32),
                      ring=np.zeros(0, dtype=np.uint8), column=np.zeros(0, dtype=np.uint16))
    assert detector.detect(empty) == ()
    assert detect(detector, []) == ()  # ground only
    box = on_ground(10.0, 0.0, CAR)
    assert len(detect(detector, [box], ground=None)) == 1  # no ground at all


def test_street_scene(detector: ObjectDetector) -> None:
    """Buildings, sign poles and traffic together: every vehicle and the pedestrian found
    once and right, nothing that is not there."""
    vehicles = [on_ground(12.0, 0.0, CAR), on_ground(25.0, 3.5, CAR), on_ground(-15.0, 0.0, CAR),
                on_ground(40.0, -3.5, TRUCK), on_ground(-30.0, 3.5, CAR, 3.0 * DEG)]
    pedestrian = on_ground(8.0, -5.5, PEDESTRIAN)
    poles = [on_ground(x, side * 7.5, (0.08, 0.08, 2.5)) for x in range(-57, 60, 20)
             for side in (1.0, -1.0)]
    buildings = [on_ground(x, 20.0, (18.0, 14.0, 12.0)) for x in range(-70, 80, 25)]
    buildings += [on_ground(x + 10.0, -19.0, (16.0, 12.0, 9.0)) for x in range(-70, 80, 25)]
    truth = [*vehicles, pedestrian, *poles]
    found = detect(detector, [*truth, *buildings], ground=Ground(pitch=0.7 * DEG))
    truck = vehicles[3]  # seen from behind: its box is the truck prior's, the rear in place
    for det in found:  # no phantom: each detection is on a real object
        on_truck = bool(inside_box(np.array([[truck.x, truck.y]]), det, 0.0)[0])
        assert on_truck or min(math.hypot(det.x - b.x, det.y - b.y) for b in truth) < 0.5, det
    for box, cls in [*((v, ObjectClass.CAR) for v in vehicles if v.length == CAR[0]),
                     (pedestrian, ObjectClass.PEDESTRIAN)]:
        near = [d for d in found if math.hypot(d.x - box.x, d.y - box.y) < 1.0]
        assert len(near) == 1, (box, near)
        assert_box(near[0], box, cls, check_yaw=cls is not ObjectClass.PEDESTRIAN)
    covering = [d for d in found if inside_box(np.array([[truck.x, truck.y]]), d, 0.0)[0]]
    assert len(covering) == 1, covering
    assert covering[0].cls is ObjectClass.TRUCK
    assert_rear_in_place(covering[0], truck)


def test_mount_offset_and_tilt_are_undone(detector: ObjectDetector) -> None:
    mount = SensorMount(x=1.2, y=-0.3, z=1.65, roll=0.5 * DEG, pitch=1.0 * DEG, yaw=2.0 * DEG)
    box = on_ground(20.0, 3.5, CAR, 10.0 * DEG)
    found = detector.detect(cast(lidar_info(mount=mount), [box]))
    assert len(found) == 1, found
    assert_box(found[0], box, ObjectClass.CAR)


def test_noise_and_dropout(detector: ObjectDetector) -> None:
    info = lidar_info(range_sigma=0.03, dropout=0.1)
    boxes = [on_ground(18.0, 0.0, CAR), on_ground(14.0, -3.5, CAR, -5.0 * DEG)]
    for seed in range(3):
        found = detector.detect(cast(info, boxes, seed=seed))
        assert len(found) == 2, found
        for box in boxes:
            nearest = min(found, key=lambda d: math.hypot(d.x - box.x, d.y - box.y))
            assert_box(nearest, box, ObjectClass.CAR)


def test_deterministic_and_sorted_by_range(detector: ObjectDetector) -> None:
    boxes = [on_ground(30.0, 3.5, CAR), on_ground(10.0, 0.0, CAR), on_ground(-20.0, 0.0, TRUCK)]
    scan = cast(lidar_info(), boxes)
    first = detector.detect(scan)
    assert ObjectDetector().detect(scan) == first
    assert detector.detect(scan) == first
    ranges = [math.hypot(d.x, d.y) for d in first]
    assert ranges == sorted(ranges)


def test_grow_interval_keeps_the_faces_that_were_seen() -> None:
    assert grow_interval(10.0, 10.1, 4.6, 0.0) == pytest.approx((10.0, 14.6))  # grow away
    assert grow_interval(-10.1, -10.0, 4.6, 0.0) == pytest.approx((-14.6, -10.0))
    assert grow_interval(-0.8, 0.8, 1.8, 0.0) == pytest.approx((-0.9, 0.9))  # head-on
    assert grow_interval(1.0, 6.0, 4.6, 0.0) == (1.0, 6.0)  # never shrunk


def test_wrap_half_pi() -> None:
    assert wrap_half_pi(math.pi) == pytest.approx(0.0, abs=1e-12)
    assert wrap_half_pi(-math.pi / 2) == pytest.approx(math.pi / 2)
    assert wrap_half_pi(2.0) == pytest.approx(2.0 - math.pi)


# ---- sparse clusters at range ------------------------------------------------------------------


@pytest.mark.parametrize("distance", [35.0, 45.0, 55.0])
def test_a_walker_far_ahead_hit_by_one_ring_is_a_pedestrian(detector: ObjectDetector,
                                                             distance: float) -> None:
    """Beyond 30 m the ring below meets the road before a walker and one ring crosses it, at
    knee height, on two or three columns: fewer returns than a near cluster needs, a top
    below a pedestrian's least height; but the ring above passes over it metres higher, so
    it may be that tall (ALKS 4.2.3: first tracked at 22 m, now at 55 m)."""
    box = on_ground(distance, -1.0, PEDESTRIAN, math.pi / 2)  # crossing: its side seen
    found = detect(detector, [box])
    assert len(found) == 1, found
    assert found[0].cls is ObjectClass.PEDESTRIAN, found
    assert math.hypot(found[0].x - box.x, found[0].y - box.y) <= 0.5, found
    if distance > 50.0:
        assert found[0].points < detector.params.min_points  # what the near gate dropped


def test_a_thin_pole_far_away_is_not_an_object(detector: ObjectDetector) -> None:
    """A sign's pole at 50 m: two returns, one above the other in one column, like the
    fragments of a surface seen at grazing incidence: too few for one column."""
    assert detect(detector, [on_ground(50.0, -6.0, (0.08, 0.08, 3.0))]) == ()


@pytest.mark.parametrize("distance", [20.0, 23.0])
def test_a_low_object_near_is_not_a_pedestrian(detector: ObjectDetector,
                                               distance: float) -> None:
    """At 20 m one ring crosses a 0.6 m bollard too, but the ring above passes only 1.2 m
    high: an adult would have been hit by it, so this is an obstacle, not a walker."""
    found = detect(detector, [on_ground(distance, -5.0, (0.4, 0.4, 0.6))])
    assert [d.cls for d in found] == [ObjectClass.OTHER]


# ---- articulated trucks ------------------------------------------------------------------------


@pytest.mark.parametrize(("gap", "boxes"), [(0.65, 1), (1.2, 1), (3.0, 2)])
def test_a_tractor_and_its_trailer_beside_are_one_truck(detector: ObjectDetector, gap: float,
                                                        boxes: int) -> None:
    """A cab and a box trailer in the next lane, a coupling's clearance apart (wider than the
    clustering's reach): one truck as long as both; a truck queued 3 m behind another
    stays apart."""
    rear = -8.0  # [m] the trailer's rear (its ends seen at 15 deg or more from its side)
    trailer = on_ground(rear + 6.8, 3.5, (13.6, 2.55, 4.0))
    cab = on_ground(rear + 13.6 + gap + 1.15, 3.5, (2.3, 2.5, 3.8))
    found = [d for d in detect(detector, [trailer, cab]) if d.cls is ObjectClass.TRUCK]
    assert len(found) == boxes, found
    if boxes == 1:
        assert found[0].length == pytest.approx(13.6 + gap + 2.3, abs=0.3), found


# ---- motorcycles --------------------------------------------------------------------------------

MOTORBIKE = (CATALOGUE["motorbike"].length, CATALOGUE["motorbike"].width,
             CATALOGUE["motorbike"].height)


@pytest.mark.parametrize(("x", "y"), [(0.0, 3.5), (3.0, -3.5), (-3.0, 3.5), (10.0, 3.5)])
def test_a_motorcycle_beside_is_boxed_where_it_is(detector: ObjectDetector, x: float,
                                                  y: float) -> None:
    """ALKS 4.6.2: its 2.2 m side beside the car is longer than a car is wide, so no car's
    rear, and the ring above passes just over its rider, so no truck's rear (which was
    grown 6.7 m away, its centre 2.9 m off): a motorcycle, completed away from the sensor."""
    box = on_ground(x, y, MOTORBIKE)
    found = detect(detector, [box])
    assert len(found) == 1, found
    assert_box(found[0], box, ObjectClass.MOTORCYCLE)
    assert found[0].width < 1.2


@pytest.mark.parametrize("distance", [10.0, 30.0])
def test_a_car_seen_from_behind_is_no_motorcycle(detector: ObjectDetector,
                                                 distance: float) -> None:
    """A car's rear is as long as a motorcycle's side is short: of equal fits the car."""
    box = on_ground(distance, -3.5, CAR)
    found = detect(detector, [box])
    assert [d.cls for d in found] == [ObjectClass.CAR]


# ---- shaped bodies: a lower body and a cabin set back from its ends ---------------------------

LOWER = 0.9  # [m] top of the lower body (the waist) of a three-box car


def shaped_car(x: float, y: float, yaw: float = 0.0, rear_setback: float = 0.9,
               front_setback: float = 1.5) -> list[Box]:
    """A three-box car of the simulator's sedan size standing at (x, y) [m]: a lower body
    to the waist, the full footprint, and a cabin above it, set back from the rear and the
    front by ``rear_setback`` and ``front_setback`` [m] (the boot deck and the bonnet)."""
    length, width, height = CAR
    cabin = length - rear_setback - front_setback
    shift = 0.5 * (rear_setback - front_setback)  # [m] the cabin's centre, along the car
    c, s = math.cos(yaw), math.sin(yaw)
    return [Box(x, y, 0.5 * LOWER, length, width, LOWER, yaw),
            Box(x + shift * c, y + shift * s, 0.5 * (LOWER + height), cabin, width - 0.1,
                height - LOWER, yaw)]


@pytest.mark.parametrize(("x", "y"), [(12.0, -3.5), (16.0, 3.5), (10.0, 0.0), (-14.0, -3.5)])
def test_a_shaped_car_is_fitted_on_its_lower_body(detector: ObjectDetector, x: float,
                                                  y: float) -> None:
    """A car in the next lane whose cabin, set back from its bumpers, is seen with its lower
    body: the heading and the near end are the lower body's (the cabin's rear face and its
    sides, fitted with the bumper, tilted the box by 5 - 10 deg)."""
    boxes = shaped_car(x, y)
    (det,) = detect(detector, boxes)
    assert det.cls is ObjectClass.CAR
    assert yaw_error(det.yaw, 0.0) <= 1.0 * DEG, det
    near = det.x - 0.5 * det.length if x > 0 else det.x + 0.5 * det.length
    assert near == pytest.approx(x - math.copysign(0.5 * CAR[0], x), abs=0.1), det
    assert det.end_seen


@pytest.mark.parametrize("distance", [28.0, 32.0])
def test_a_car_seen_above_its_lower_body_says_so(detector: ObjectDetector,
                                                 distance: float) -> None:
    """Beyond about 27 m one ring crosses a car ahead, above its boot deck: the face seen is
    the cabin's, 0.9 m before its rear. The box is grown from it (nothing in the scan tells
    where the bumper is: a box's rear crossed as high gives the same returns), and the
    detection says that its near end was not seen (`end_seen`), for the tracker."""
    (det,) = detect(detector, shaped_car(distance, 0.0))
    assert det.cls is ObjectClass.CAR
    assert not det.end_seen, det
    assert det.x - 0.5 * det.length == pytest.approx(distance - 0.5 * CAR[0] + 0.9, abs=0.1)


def test_the_end_of_a_car_near_is_seen(detector: ObjectDetector) -> None:
    """... and a car 8 m ahead shows its bumper to the lower rings."""
    (det,) = detect(detector, shaped_car(8.0, 0.0))
    assert det.end_seen and det.x - 0.5 * det.length == pytest.approx(8.0 - 0.5 * CAR[0],
                                                                      abs=0.1)


@pytest.mark.parametrize("cls", [ObjectClass.CAR, ObjectClass.TRUCK, ObjectClass.MOTORCYCLE,
                                 ObjectClass.PEDESTRIAN])
def test_no_detector_prior_equals_a_body(cls: ObjectClass) -> None:
    """Every size prior is its class's generic size (nuScenes' means, `DetectorParams`),
    none a simulated body: each differs from every catalogue vehicle, Euro NCAP target and
    box body the world builds by at least 10 cm in some dimension."""
    prior = DetectorParams().prior(cls)
    assert prior is not None
    bodies = [(m.length, m.width, m.height) for m in CATALOGUE.values()]
    bodies += [(b.length, b.width, b.height) for b in SIZES.values()]
    bodies += [(t.length, t.width, t.height) for t in (GVT, EPTA, EPTC, EBTA, EMT)]
    for body in bodies:
        diff = max(abs(a - b) for a, b in zip((prior.length, prior.width, prior.height), body,
                                              strict=True))
        assert diff >= 0.1, (cls, prior, body)

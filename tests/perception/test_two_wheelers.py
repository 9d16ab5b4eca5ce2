"""Two-wheelers seen end-on by the LiDAR detector: the shaped Euro NCAP bicyclist (EBTa) and
motorcyclist (EMT) targets riding ahead in the car's lane (seen from behind) or towards it,
cast by the numpy/Open3D synthetic LiDAR (VLP-16-like, 1800 columns, 2 cm range noise).

From behind, a bicycle and its rider are about as wide as a walker (0.5 m across the bars)
but the rings cross them at different depths: the rear wheel low, the rider's back, the
bars and the front wheel higher and farther, so that the returns span 1 - 1.3 m along the
line of sight. Such a cluster is a two-wheeler seen end-on (a MOTORCYCLE box, the detector's
two-wheeler class), neither an obstacle (OTHER, which the planner does not brake for) nor a
car's rear (a car box 1.95 m wide grown across the lane). Where the rings leave only its
rider's back (0.3 - 0.8 m deep: at some ranges beyond 15 m) it is a PEDESTRIAN, a road
user the planner keeps as a candidate too.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from perception.messages import Detection, ObjectClass
from perception.objects import DetectorParams, ObjectDetector
from tests.perception.lidar_synth import Mesh, cast, lidar_info
from world.actors.shapes.body import Body
from world.actors.shapes.catalogue import bodies
from world.actors.shapes.mesh import part_mesh

POSITION_TOL = 0.3  # [m] box centre error of a two-wheeler's box
ROAD_USERS = (ObjectClass.MOTORCYCLE, ObjectClass.PEDESTRIAN)


@pytest.fixture(scope="module")
def detector() -> ObjectDetector:
    return ObjectDetector(DetectorParams())


@pytest.fixture(scope="module")
def shapes() -> dict[str, Body]:
    return bodies()


def posed(body: Body, x: float, y: float, yaw: float) -> list[Mesh]:
    """The body's part meshes standing at (x, y) [m], heading ``yaw`` [rad], vehicle frame."""
    c, s = math.cos(yaw), math.sin(yaw)
    rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    return [(v @ rot.T + np.array([x, y, 0.0]), tri) for v, tri in map(part_mesh, body.parts)]


def seen(detector: ObjectDetector, body: Body, x: float, yaw: float = 0.0,
         seed: int = 0) -> tuple[Detection, ...]:
    return detector.detect(cast(lidar_info(), meshes=posed(body, x, 0.0, yaw), seed=seed))


@pytest.mark.parametrize("yaw", [0.0, math.pi], ids=["from_behind", "oncoming"])
@pytest.mark.parametrize("distance", [6.0, 8.0, 10.0, 12.0, 15.0, 20.0])
def test_a_bicyclist_in_the_lane_is_a_two_wheeler(detector: ObjectDetector,
                                                  shapes: dict[str, Body], distance: float,
                                                  yaw: float) -> None:
    """Within 20 m the EBTa's returns span more than a walker's stride along the ray and
    less than its bars across it: one MOTORCYCLE box, along the lane, over the bicycle (not
    an OTHER square of the longer side, nor a car's rear grown across the lane)."""
    for seed in (0, 1):
        found = seen(detector, shapes["ncap_ebta"], distance, yaw, seed)
        assert len(found) == 1, found
        (det,) = found
        assert det.cls is ObjectClass.MOTORCYCLE, det
        assert math.hypot(det.x - distance, det.y) <= POSITION_TOL, det
        assert abs(det.yaw) <= 2.0 * math.pi / 180.0, det


@pytest.mark.parametrize("distance", [18.0, 25.0, 30.0, 35.0, 40.0, 45.0])
def test_a_bicyclist_ahead_is_a_road_user_as_far_as_two_returns(
        detector: ObjectDetector, shapes: dict[str, Body], distance: float) -> None:
    """Farther, a two-wheeler or (the rider's back alone) a pedestrian, never an obstacle
    or a car, as long as a ring leaves two returns on it."""
    found = seen(detector, shapes["ncap_ebta"], distance)
    assert [d.cls in ROAD_USERS for d in found] == [True], found
    assert math.hypot(found[0].x - distance, found[0].y) <= 0.5, found


@pytest.mark.parametrize("distance", [6.0, 10.0, 15.0])
def test_a_motorcyclist_ahead_is_a_two_wheeler(detector: ObjectDetector,
                                               shapes: dict[str, Body], distance: float) -> None:
    """The EMT from behind is found as one two-wheeler too."""
    found = seen(detector, shapes["ncap_emt"], distance)
    assert [d.cls for d in found] == [ObjectClass.MOTORCYCLE], found
    assert math.hypot(found[0].x - distance, found[0].y) <= 0.5, found


@pytest.mark.parametrize("distance", [6.0, 10.0, 20.0, 30.0])
def test_a_car_from_behind_stays_a_car(detector: ObjectDetector, shapes: dict[str, Body],
                                       distance: float) -> None:
    """A shaped saloon's rear is wider than deep: no two-wheeler."""
    found = seen(detector, shapes["sedan"], distance)
    assert [d.cls for d in found] == [ObjectClass.CAR], found


@pytest.mark.parametrize("phase", range(0, 8, 2))
@pytest.mark.parametrize("distance", [6.0, 10.0, 20.0])
def test_a_walker_walking_away_stays_a_pedestrian(detector: ObjectDetector,
                                                  shapes: dict[str, Body], distance: float,
                                                  phase: int) -> None:
    """An EPTa walking along the lane, seen from behind at every stride: its stride is no
    two-wheeler's depth."""
    found = seen(detector, shapes[f"ncap_epta_phase{phase}"], distance)
    assert [d.cls for d in found] == [ObjectClass.PEDESTRIAN], found

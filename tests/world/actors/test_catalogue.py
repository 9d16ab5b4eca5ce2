"""The vehicle catalogue (`world.actors.catalogue`): names, real and legal dimensions, the
types' defaults, and the bodies a world builds from it (`world.actors.actor_set`)."""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from avsim.scenario.load import load_scenario
from perception.messages import Detection, ObjectClass
from perception.objects import DetectorParams, ObjectDetector, SizePrior
from world.actors.bodies import SIZES
from world.actors.catalogue import (
    CATALOGUE,
    DEFAULT_MODEL,
    EU_MAX_HEIGHT,
    EU_MAX_LENGTH_ARTICULATED,
    EU_MAX_LENGTH_BUS,
    EU_MAX_LENGTH_RIGID,
    EU_MAX_WIDTH,
    TYPE_CLASSES,
    VehicleClass,
    vehicle_model,
)
from world.sensors.sensor import vehicle_pose
from world.sensors.setup import Profile, sensor_setup
from world.sensors.tessellate import body_triangles
from world.world import World

NAMES = ("small_car", "sedan", "suv", "van", "bus", "rigid_truck", "semi_trailer", "motorbike")
# [m] (length, width, height) bounds of real vehicles of each class: passenger cars and light
# vans (M1 / N1), buses and trucks up to the EU maxima, motorcycles
BOUNDS = {
    VehicleClass.CAR: ((3.0, 7.0), (1.5, 2.1), (1.3, 3.0)),
    VehicleClass.BUS: ((8.0, EU_MAX_LENGTH_BUS), (2.3, EU_MAX_WIDTH), (2.8, EU_MAX_HEIGHT)),
    VehicleClass.TRUCK: ((6.0, EU_MAX_LENGTH_ARTICULATED), (2.3, EU_MAX_WIDTH),
                         (2.8, EU_MAX_HEIGHT)),
    VehicleClass.MOTORBIKE: ((1.8, 2.6), (0.6, 1.1), (1.0, 1.6)),
}
HULL_MARGIN = 5e-3  # [m] Bullet's bounding box beyond a hull's points
SIZE_TOL = 1e-3  # [m] a body's bounding box against its model (boxes are exact)


def test_names_are_the_format_s_snake_case_names() -> None:
    assert tuple(CATALOGUE) == NAMES
    for name, model in CATALOGUE.items():
        assert re.fullmatch(r"[a-z]+(_[a-z]+)*", name)
        assert model.name == name and vehicle_model(name) is model
    with pytest.raises(KeyError, match="unknown vehicle model 'tank'"):
        vehicle_model("tank")


@pytest.mark.parametrize("name", NAMES)
def test_dimensions_are_real_and_legal(name: str) -> None:
    m = CATALOGUE[name]
    (lo_l, hi_l), (lo_w, hi_w), (lo_h, hi_h) = BOUNDS[m.cls]
    assert lo_l <= m.length <= hi_l, m
    assert lo_w <= m.width <= hi_w, m
    assert lo_h <= m.height <= hi_h, m
    assert m.width <= EU_MAX_WIDTH and m.height <= EU_MAX_HEIGHT  # Directive 96/53/EC
    assert 0.0 < m.wheelbase < m.length  # an articulated vehicle: its tractor's
    assert m.mass > 0.0 and m.source
    assert m.half_sizes == (0.5 * m.length, 0.5 * m.width, 0.5 * m.height)


def test_only_a_bus_or_an_articulated_vehicle_is_longer_than_a_rigid_truck_may_be() -> None:
    long = [m.name for m in CATALOGUE.values() if m.length > EU_MAX_LENGTH_RIGID]
    assert long == ["bus", "semi_trailer"]  # a Citaro: 12.135 m, a two-axle bus may be 13.5
    assert CATALOGUE["semi_trailer"].length == EU_MAX_LENGTH_ARTICULATED


def test_types_defaults_and_classes() -> None:
    assert DEFAULT_MODEL == {"car": "sedan", "truck": "rigid_truck"}
    for kind, name in DEFAULT_MODEL.items():
        assert CATALOGUE[name].cls in TYPE_CLASSES[kind]
    # every model is taken by exactly one type
    for m in CATALOGUE.values():
        assert sum(m.cls in classes for classes in TYPE_CLASSES.values()) == 1, m


def _differs(prior: SizePrior, size: tuple[float, float, float]) -> float:
    """[m] the largest difference of a prior from a body's (length, width, height)."""
    return max(abs(a - b) for a, b in zip((prior.length, prior.width, prior.height), size,
                                          strict=True))


def test_vehicle_priors_equal_no_simulated_body() -> None:
    """The detector's vehicle size priors are generic: neither is (within 10 cm in every
    dimension) a catalogue vehicle or another body the world builds. (The pedestrian prior
    still is the pedestrian's body: `perception.objects.DetectorParams.pedestrian`.)"""
    p = DetectorParams()
    bodies = [(m.length, m.width, m.height) for m in CATALOGUE.values()]
    bodies += [(s.length, s.width, s.height) for s in SIZES.values()]
    for prior in (p.car, p.truck):
        for body in bodies:
            assert _differs(prior, body) >= 0.1, (prior, body)


SCENARIO = """\
format: avsim/1
name: catalogue
duration: 5
road:
  lanes: 2
  speed_limit_kph: 50
  segments:
    - straight: 200
ego: {s: 10, set_speed_kph: 0}
actors:
  - {id: semi, type: truck, lane: 1, s: 40, model: semi_trailer}
  - {id: bike, type: car, lane: 0, s: 40, model: motorbike}
  - {id: car, type: car, lane: 0, s: 60}
  - {id: lorry, type: truck, lane: 1, s: 80}
  - {id: walker, type: pedestrian, s: 90, offset: -5}
"""


@pytest.fixture(scope="module")
def world(tmp_path_factory: pytest.TempPathFactory) -> Iterator[World]:
    path: Path = tmp_path_factory.mktemp("catalogue") / "catalogue.yaml"
    path.write_text(SCENARIO, encoding="utf-8")
    w = World(load_scenario(path).world)
    try:
        w.step()
        yield w
    finally:
        w.close()


def test_bodies_have_their_models_size(world: World) -> None:
    """Each vehicle's PyBullet body spans its model's box (the bodies stand at yaw 0 on a
    straight road heading east: length along x): the collision shape's solids, posed where
    Bullet has the body, exactly; Bullet's own bounding box adds its margin around convex
    hulls (`test_actor_bodies`: the two agree within 5 mm)."""
    expected = [CATALOGUE["semi_trailer"], CATALOGUE["motorbike"], CATALOGUE["sedan"],
                CATALOGUE["rigid_truck"]]
    for body, m in zip(world.actors.bodies, expected, strict=False):
        position, quaternion = world.client.getBasePositionAndOrientation(body)
        rotation = np.array(world.client.getMatrixFromQuaternion(quaternion)).reshape(3, 3)
        vertices, _ = body_triangles(world.shapes.parts(body), np.array(position), rotation)
        lo, hi = vertices.min(axis=0), vertices.max(axis=0)
        assert (hi - lo).tolist() == pytest.approx([m.length, m.width, m.height],
                                                   abs=SIZE_TOL), m.name
        assert lo[2] == pytest.approx(0.0, abs=SIZE_TOL)  # standing on the ground
    box = SIZES[world.actors.specs[4].type]
    walker = world.actors.walkers[4]
    assert walker is not None  # a pedestrian is a walker, standing: its head at its stature
    body = world.actors.bodies[4]
    bounds = [world.client.getAABB(body, link)
              for link in range(-1, world.client.getNumJoints(body))]
    lo_z, hi_z = min(b[0][2] for b in bounds), max(b[1][2] for b in bounds)
    assert hi_z - lo_z == pytest.approx(walker.height, abs=HULL_MARGIN)
    assert walker.height <= box.height


def test_truth_carries_each_models_size_and_class(world: World) -> None:
    poses = world.actors.poses
    assert poses.classes == (VehicleClass.TRUCK, VehicleClass.MOTORBIKE, VehicleClass.CAR,
                             VehicleClass.TRUCK, None)
    semi = CATALOGUE["semi_trailer"]
    assert tuple(poses.half_sizes[0]) == semi.half_sizes
    assert poses.centres[0, 2] == pytest.approx(0.5 * semi.height)
    assert [poses.truth_class(i) for i in range(5)] == list(poses.classes)



BESIDE = """\
format: avsim/1
name: semi_beside
duration: 5
road:
  lanes: 2
  speed_limit_kph: 50
  segments:
    - straight: 200
ego: {s: 10, set_speed_kph: 0}
actors:
  - {id: semi, type: truck, lane: 1, s: 20, model: semi_trailer}
  - {id: bike, type: car, lane: 0, s: 30, model: motorbike}
"""


def beside_detections(tmp_path: Path, shift: float) -> tuple[Detection, ...]:
    """The detector's boxes in one scan of `BESIDE`, the semi-trailer `shift` [m] further."""
    path = tmp_path / "beside.yaml"
    path.write_text(BESIDE.replace("s: 20,", f"s: {20 + shift},"), encoding="utf-8")
    w = World(load_scenario(path).world, sensor_setup(Profile.DEFAULT), cameras=False)
    try:
        w.step()
        lidar = w.rig.sensor("lidar").lidar  # type: ignore[attr-defined]
        scan, _ = lidar.scan(w.t, *vehicle_pose(w.ego_truth, w.ego.geometry.ride_height))
        return ObjectDetector().detect(scan)
    finally:
        w.close()


@pytest.mark.parametrize("shift", [0.0, pytest.param(12.0, marks=pytest.mark.xfail(
    strict=True, reason="known limit: a semi-trailer ahead in the next lane (centre 22 m "
    "ahead) shows its side at grazing incidence; the side breaks into one-column fragments "
    "(kept as OTHERs) and the rest is boxed with the 6.74 m truck prior, 4.9 m short"))])
def test_lidar_detector_sees_a_semi_trailer_beside_whole(tmp_path: Path, shift: float) -> None:
    """A semi-trailer in the next lane, its side in full view of the roof LiDAR: the detector
    (which knows no catalogue) boxes it as a truck of its real 16.5 m, well beyond the truck
    prior. Its tractor's cab and its trailer are two solids 0.65 m apart (a coupling's
    clearance, wider than the clustering's reach): two clusters, one vehicle."""
    found = beside_detections(tmp_path, shift)
    semi = CATALOGUE["semi_trailer"]
    beside = [d for d in found if abs(d.y - 3.5) < 1.0 and abs(d.x - (10.0 + shift)) < 2.0]
    assert len(beside) == 1, found
    assert beside[0].cls is ObjectClass.TRUCK
    assert beside[0].length == pytest.approx(semi.length, abs=0.3)
    assert beside[0].length > DetectorParams().truck.length + 5.0


@pytest.mark.xfail(strict=True, reason="known limit: seen from behind 19-21 m ahead, a "
                   "riderless motorbike is crossed by one ring at 0.57 m (its rear wheel and "
                   "the engine's rear) and the next at 1.22 m (its handlebar), 0.7 m apart "
                   "along the sight, more than the clustering's 0.6 m: two small OTHERs")
def test_lidar_detector_sees_a_motorbike_ahead_as_one_object(tmp_path: Path) -> None:
    """A motorbike 20 m ahead in the ego's lane is one object."""
    found = beside_detections(tmp_path, 0.0)
    bike = [d for d in found if abs(d.y) < 1.0 and abs(d.x - 20.0) < 2.0]
    assert len(bike) == 1, found

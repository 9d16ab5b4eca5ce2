"""Tests of the roadside layout: buildings clear of the road and of each other, signs."""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.typing import NDArray

from tests.roads import KPH, arc, seg
from world.hdmap import RoadMap, SpeedLimitSign
from world.map.road import build_road_map
from world.scene.scenery import (
    DEPTH_RANGE,
    FRONTAGE_RANGE,
    HEIGHT_RANGE,
    SIGN_CLEARANCE,
    BuildingBox,
    layout_buildings,
    layout_speed_limit_signs,
    speed_limit_sign_image,
)
from world.spec import BuildingsSpec, RoadSpec


@pytest.fixture(scope="module")
def road() -> RoadMap:
    """Tight arcs both ways (buildings on their inner sides must move out) and a widening."""
    segments = (
        seg(200.0, lanes=1, oncoming=0),
        seg(150.0, lanes=3, oncoming=2, speed_kph=70.0),
        arc(45.0, 90.0),
        seg(100.0),
        arc(-35.0, -120.0, lanes=1, oncoming=1),
        seg(80.0),
        arc(300.0, 40.0),
        seg(200.0),
    )
    features = (SpeedLimitSign(120.0, 40 * KPH), SpeedLimitSign(600.0, 30 * KPH))
    return build_road_map(RoadSpec(segments, 50 * KPH, features))


def footprint_grid(box: BuildingBox, step: float = 0.5) -> NDArray[np.float64]:
    """(K, 2) [m] points covering the box's footprint, outline and inside."""
    hx, hy = box.half_extents[0], box.half_extents[1]
    u = np.linspace(-hx, hx, max(2, math.ceil(2 * hx / step) + 1))
    v = np.linspace(-hy, hy, max(2, math.ceil(2 * hy / step) + 1))
    local = np.stack(np.meshgrid(u, v), axis=-1).reshape(-1, 2)
    c, s = math.cos(box.yaw), math.sin(box.yaw)
    rotation: NDArray[np.float64] = np.array([[c, s], [-s, c]])
    centre: NDArray[np.float64] = np.array(box.centre[:2])
    return local @ rotation + centre


def inside(
    box: BuildingBox, points: NDArray[np.float64], shrink: float = 1e-6
) -> NDArray[np.bool_]:
    """Whether points (K, 2) are strictly inside the box's footprint."""
    c, s = math.cos(box.yaw), math.sin(box.yaw)
    rel = points - np.array(box.centre[:2])
    along = rel @ np.array([c, s])
    across = rel @ np.array([-s, c])
    return np.asarray(
        (np.abs(along) < box.half_extents[0] - shrink)
        & (np.abs(across) < box.half_extents[1] - shrink)
    )


@pytest.mark.parametrize("density", [0.4, 0.8, 1.0])
def test_buildings_stay_clear_of_the_road_and_its_setback(road: RoadMap, density: float) -> None:
    setback = 6.0
    boxes = layout_buildings(road, BuildingsSpec(density, setback), np.random.default_rng(7))
    assert len(boxes) > 20
    for box in boxes:
        s, d = road.local_coordinates(footprint_grid(box))
        right, left = road.paved_edges(s)
        clear = (d <= right - setback + 1e-6) | (d >= left + setback - 1e-6)
        assert clear.all(), box


def test_buildings_do_not_overlap_each_other(road: RoadMap) -> None:
    boxes = layout_buildings(road, BuildingsSpec(1.0, 4.0), np.random.default_rng(11))
    grids = [footprint_grid(b, 0.4) for b in boxes]
    for i, a in enumerate(boxes):
        for j, b in enumerate(boxes):
            if i != j and math.dist(a.centre[:2], b.centre[:2]) < 40.0:
                assert not inside(a, grids[j]).any(), (a, b)


def test_buildings_line_both_sides_with_the_drawn_sizes(road: RoadMap) -> None:
    boxes = layout_buildings(road, BuildingsSpec(0.7, 5.0), np.random.default_rng(1))
    _, d = road.local_coordinates(np.array([b.centre[:2] for b in boxes]))
    assert (d < 0).sum() > 10 and (d > 0).sum() > 10
    for b in boxes:
        hx, hy, hz = b.half_extents
        assert FRONTAGE_RANGE[0] <= 2 * hx <= FRONTAGE_RANGE[1]
        assert DEPTH_RANGE[0] <= 2 * hy <= DEPTH_RANGE[1]
        assert HEIGHT_RANGE[0] <= 2 * hz <= HEIGHT_RANGE[1]
        assert b.centre[2] == pytest.approx(hz)  # standing on the ground
        assert all(0.0 <= c <= 1.0 for c in b.rgb)
        assert -math.pi < b.yaw <= math.pi


def test_buildings_face_the_road_on_straights(road: RoadMap) -> None:
    boxes = layout_buildings(road, BuildingsSpec(0.7, 5.0), np.random.default_rng(1))
    s, _ = road.local_coordinates(np.array([b.centre[:2] for b in boxes]))
    on_first_straight = [b for b, x in zip(boxes, s, strict=True) if 20.0 < x < 180.0]
    assert on_first_straight
    for b in on_first_straight:  # the route runs along +x there
        assert abs(b.yaw) < 1e-9


def test_building_layout_is_deterministic_for_a_seed(road: RoadMap) -> None:
    spec = BuildingsSpec(0.6, 6.0)
    a = layout_buildings(road, spec, np.random.default_rng(42))
    b = layout_buildings(road, spec, np.random.default_rng(42))
    c = layout_buildings(road, spec, np.random.default_rng(43))
    assert a == b
    assert a != c


def test_density_sets_the_built_frontage(road: RoadMap) -> None:
    def frontage(density: float) -> float:
        spec = BuildingsSpec(density, 6.0)
        boxes = layout_buildings(road, spec, np.random.default_rng(5))
        return sum(2 * b.half_extents[0] for b in boxes)

    assert frontage(0.0) == 0.0
    sparse, dense = frontage(0.2), frontage(0.8)
    assert 0.0 < sparse < 0.5 * dense
    assert dense < 2 * road.length  # two sides at most


def test_speed_limit_signs_stand_right_of_the_road_facing_the_traffic(road: RoadMap) -> None:
    signs = layout_speed_limit_signs(road)
    assert [(sg.s, sg.kph) for sg in signs] == [(0.0, 50), (120.0, 40), (200.0, 70), (600.0, 30)]
    for sign in signs:
        s, d = road.local_coordinates(np.array(sign.pole_xy))
        right, _ = road.paved_edges(sign.s)
        assert float(s) == pytest.approx(sign.s, abs=1e-9)
        assert float(d) == pytest.approx(float(right) - SIGN_CLEARANCE, abs=1e-9)
        facing = np.array([math.cos(sign.yaw), math.sin(sign.yaw)])
        heading = float(road.heading_at(sign.s))
        route = np.array([math.cos(heading), math.sin(heading)])
        assert float(facing @ route) == pytest.approx(-1.0)
        assert sign.plate_height == 2.0 and sign.plate_diameter == 0.75
        assert sign.limit == pytest.approx(sign.kph * KPH)


def test_speed_limit_sign_image() -> None:
    img = speed_limit_sign_image(80)
    assert img.shape == (128, 128, 4) and img.dtype == np.uint8
    alpha = img[..., 3]
    assert alpha[0, 0] == 0 and alpha[-1, -1] == 0 and alpha[0, -1] == 0  # outside the disc
    assert alpha[64, 64] == 255 and alpha[64, 3] == 255  # inside, near the rim
    r, g, b = (int(x) for x in img[64, 6, :3])  # on the red ring
    assert r > 150 and g < 80 and b < 80
    ring_inner = img[64, 22, :3]  # white between the ring and the number
    assert np.all(ring_inner > 200)
    centre = img[40:88, 30:98, :3].astype(int)
    assert (centre.sum(-1) < 150).sum() > 100  # black digits in the middle
    assert not np.array_equal(speed_limit_sign_image(30), img)
    assert speed_limit_sign_image(120, size=64).shape == (64, 64, 4)

"""Painted marks (stop lines, zebras), the stop sign's picture and placement, and the speed
bump's geometry, as layout data (no PyBullet)."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from numpy.typing import NDArray

from tests.roads import KPH, SHOULDER, W, arc, seg
from world.hdmap import Crosswalk, RoadMap, SpeedBump, StopSign
from world.map.road import build_road_map
from world.scene.bump import (
    VISUAL_LIFT,
    bump_height_at,
    bump_mesh,
    bump_profile,
    hull_vertices,
    layout_speed_bumps,
)
from world.scene.road_marks import (
    MARK_Z,
    STOP_LINE_WIDTH,
    ZEBRA_BAR,
    ZEBRA_GAP,
    build_road_marks,
    crosswalk_mesh,
    stop_line_mesh,
    zebra_bars,
)
from world.scene.road_mesh import SURFACE_Z, TexturedMesh
from world.scene.scenery import (
    RED_RGB,
    SIGN_CLEARANCE,
    SIGN_PLATE_HEIGHT,
    layout_stop_signs,
    octagon_corners,
    stop_sign_image,
)
from world.spec import RoadSpec

STOP_STRAIGHT, STOP_ARC = 60.0, 160.0  # [m] stations: on the first straight, on the arc
ZEBRA_STRAIGHT, ZEBRA_ARC = 80.0, 180.0
BUMP_S = 100.0


@pytest.fixture(scope="module")
def road() -> RoadMap:
    """2 + 1 lanes, a straight to 120 m, then a 60 m radius left arc of 90 deg."""
    features = (
        StopSign(STOP_STRAIGHT), StopSign(STOP_ARC),
        Crosswalk(ZEBRA_STRAIGHT, 4.0), Crosswalk(ZEBRA_ARC, 3.0),
        SpeedBump(BUMP_S, 0.1, 0.9, 5 * KPH),
    )
    return build_road_map(RoadSpec((seg(120.0), arc(60.0, 90.0), seg(50.0)), 50 * KPH,
                                      features))


def route_coords(road: RoadMap, mesh: TexturedMesh) -> tuple[NDArray[np.float64],
                                                              NDArray[np.float64]]:
    s, d = road.local_coordinates(mesh.vertices[:, :2])
    return np.asarray(s), np.asarray(d)


def triangle_area(mesh: TexturedMesh) -> float:
    """[m^2] the mesh's area seen from above (positive: counter-clockwise triangles)."""
    a, b, c = (mesh.vertices[mesh.indices[:, k], :2] for k in range(3))
    ab, ac = b - a, c - a
    return float(np.sum(ab[:, 0] * ac[:, 1] - ab[:, 1] * ac[:, 0]) / 2)


def check_well_formed(mesh: TexturedMesh) -> None:
    n = len(mesh.vertices)
    assert mesh.vertices.shape == (n, 3) and mesh.uvs.shape == (n, 2)
    assert mesh.normals.shape == (n, 3)
    assert mesh.indices.dtype == np.int32 and mesh.indices.max() < n
    assert ((mesh.uvs >= 0.0) & (mesh.uvs <= 1.0)).all()
    assert mesh.texture.dtype == np.uint8 and mesh.texture.ndim == 3


# -- stop lines ----------------------------------------------------------------------------


@pytest.mark.parametrize("s", [STOP_STRAIGHT, STOP_ARC])
def test_stop_line_lies_across_the_ego_lanes_from_its_station(road: RoadMap, s: float) -> None:
    mesh = stop_line_mesh(road, StopSign(s), 3)
    check_well_formed(mesh)
    assert mesh.name == "stop_line_3"
    assert np.allclose(mesh.vertices[:, 2], MARK_Z) and MARK_Z > SURFACE_Z
    vs, vd = route_coords(road, mesh)
    assert vs.min() == pytest.approx(s, abs=1e-6)
    assert vs.max() == pytest.approx(s + STOP_LINE_WIDTH, abs=1e-6)
    assert vd.min() == pytest.approx(-W / 2, abs=1e-6)  # lane 0's right edge
    assert vd.max() == pytest.approx(1.5 * W, abs=1e-6)  # the centre line (2 ego lanes)
    assert np.all(mesh.texture.min(axis=(0, 1)) > 200)  # white paint
    k = float(road.curvature_at(s + STOP_LINE_WIDTH / 2))  # an arc's band: (1 - k d) wider
    area = 2 * W * STOP_LINE_WIDTH * (1 - k * W / 2)
    assert triangle_area(mesh) == pytest.approx(area, rel=0.005)  # upward-facing, no gaps


# -- zebras --------------------------------------------------------------------------------


def test_zebra_bars_fill_the_paved_road_centred() -> None:
    road = build_road_map(RoadSpec((seg(100.0),), 50 * KPH))
    bars = zebra_bars(road, 50.0)
    right, left = -(W / 2 + SHOULDER), 2.5 * W  # 2 + 1 lanes: 12.75 m paved
    n = math.floor((left - right + ZEBRA_GAP) / (ZEBRA_BAR + ZEBRA_GAP))
    assert len(bars) == n == 13
    for (a0, a1), (b0, _) in itertools.pairwise(bars):
        assert a1 - a0 == pytest.approx(ZEBRA_BAR)
        assert b0 - a1 == pytest.approx(ZEBRA_GAP)
    margin_right, margin_left = bars[0][0] - right, left - bars[-1][1]
    assert margin_right == pytest.approx(margin_left) and margin_right >= 0.0


@pytest.mark.parametrize(("s", "width"), [(ZEBRA_STRAIGHT, 4.0), (ZEBRA_ARC, 3.0)])
def test_zebra_mesh_has_its_bars_where_they_should_be(road: RoadMap, s: float,
                                                      width: float) -> None:
    mesh = crosswalk_mesh(road, Crosswalk(s, width), 1)
    check_well_formed(mesh)
    assert mesh.name == "crosswalk_1"
    assert np.allclose(mesh.vertices[:, 2], MARK_Z)
    vs, vd = route_coords(road, mesh)
    assert vs.min() == pytest.approx(s, abs=1e-6) and vs.max() == pytest.approx(s + width,
                                                                                abs=1e-6)
    bars = zebra_bars(road, s)
    edges = np.array(bars).ravel()
    # every vertex lies on a bar's edge, and every bar edge has vertices
    assert np.abs(vd[:, None] - edges[None, :]).min(axis=1).max() < 1e-6
    assert np.abs(vd[:, None] - edges[None, :]).min(axis=0).max() < 1e-6
    # the painted area is the bars' (arcs: a band's area grows with (1 - k d))
    k = float(road.curvature_at(s + width / 2))
    area = sum((b - a) * width * (1 - k * (a + b) / 2) for a, b in bars)
    assert triangle_area(mesh) == pytest.approx(area, rel=0.01)
    # a point in the middle of each bar is inside a triangle, a point in each gap is not
    mid = s + width / 2
    for (a, b), (c, _) in itertools.pairwise(bars):
        assert covered(road, mesh, mid, (a + b) / 2)
        assert not covered(road, mesh, mid, (b + c) / 2)


def covered(road: RoadMap, mesh: TexturedMesh, s: float, d: float) -> bool:
    """Whether the map point at (s, d) is inside one of the mesh's triangles (from above)."""
    p = road.position(s, d)
    a, b, c = (mesh.vertices[mesh.indices[:, k], :2] for k in range(3))

    def side(u: NDArray[np.float64], v: NDArray[np.float64]) -> NDArray[np.float64]:
        cross = (v[:, 0] - u[:, 0]) * (p[1] - u[:, 1]) - (v[:, 1] - u[:, 1]) * (p[0] - u[:, 0])
        return np.asarray(cross, dtype=np.float64)

    return bool(np.any((side(a, b) >= 0) & (side(b, c) >= 0) & (side(c, a) >= 0)))


def test_build_road_marks_names_every_mark_in_station_order(road: RoadMap) -> None:
    names = [m.name for m in build_road_marks(road)]
    assert names == ["stop_line_0", "crosswalk_0", "stop_line_1", "crosswalk_1"]
    assert build_road_marks(build_road_map(RoadSpec((seg(50.0),), 10.0))) == []


# -- the stop sign -------------------------------------------------------------------------


def test_stop_sign_image_is_a_red_octagon_with_white_text() -> None:
    size = 128
    rgba = stop_sign_image(size)
    assert rgba.shape == (size, size, 4) and rgba.dtype == np.uint8
    rgb, alpha = rgba[..., :3].astype(int), rgba[..., 3]
    red = (np.abs(rgb - np.array(RED_RGB)).max(axis=2) < 40) & (alpha > 250)
    white = (rgb.min(axis=2) > 220) & (alpha > 250)
    # an octagon, not a disc: opaque near a corner, transparent as far out on a flat's middle
    c, r = size / 2, size / 2
    for k in range(8):
        corner = math.pi / 8 + k * math.pi / 4
        flat = k * math.pi / 4
        u, v = c + 0.95 * r * math.cos(corner), c - 0.95 * r * math.sin(corner)
        assert alpha[int(v), int(u)] > 128, k
        u, v = c + 0.97 * r * math.cos(flat), c - 0.97 * r * math.sin(flat)
        assert alpha[int(v), int(u)] < 128, k
        # a white border just inside the edge, red further in (between the text and border)
        u, v = c + 0.89 * r * math.cos(flat), c - 0.89 * r * math.sin(flat)
        assert white[int(v), int(u)], k
        u, v = c + 0.75 * r * math.cos(flat), c - 0.75 * r * math.sin(flat)
        assert red[int(v), int(u)], k
    assert alpha[0, 0] == alpha[0, -1] == alpha[-1, 0] == alpha[-1, -1] == 0
    # most of the octagon is red, and white text in its middle band
    inside = alpha > 250
    assert red[inside].mean() > 0.55
    band = white[int(0.42 * size):int(0.58 * size), int(0.2 * size):int(0.8 * size)]
    assert 0.2 < band.mean() < 0.8  # letters, not a white bar
    assert not white[int(0.3 * size):int(0.34 * size), int(0.3 * size):int(0.7 * size)].any()


def test_octagon_corners_have_flat_top_and_bottom() -> None:
    corners = octagon_corners((0.0, 0.0), 1.0)
    assert corners.shape == (8, 2)
    ys = np.sort(corners[:, 1])
    assert ys[0] == pytest.approx(ys[1]) and ys[-1] == pytest.approx(ys[-2])  # flat edges
    assert np.allclose(np.hypot(corners[:, 0], corners[:, 1]), 1.0)


@pytest.mark.parametrize("index", [0, 1])
def test_stop_signs_stand_right_of_the_road_facing_the_traffic(road: RoadMap,
                                                               index: int) -> None:
    signs = layout_stop_signs(road)
    assert [x.s for x in signs] == [STOP_STRAIGHT, STOP_ARC]
    sign = signs[index]
    s, d = road.local_coordinates(np.array(sign.pole_xy))
    right, _ = road.paved_edges(sign.s)
    assert float(s) == pytest.approx(sign.s, abs=1e-6)
    assert float(d) == pytest.approx(float(right) - SIGN_CLEARANCE, abs=1e-6)
    heading = float(road.heading_at(sign.s))
    assert math.cos(sign.yaw - heading) == pytest.approx(-1.0)  # faces the approaching cars
    assert sign.plate_height == SIGN_PLATE_HEIGHT
    assert sign.corner_radius * math.cos(math.pi / 8) == pytest.approx(sign.plate_width / 2)


# -- the speed bump ------------------------------------------------------------------------


def test_bump_profile_is_a_circular_segment() -> None:
    x, z = bump_profile(0.1, 0.9)
    assert x[0] == pytest.approx(-0.45) and x[-1] == pytest.approx(0.45)
    assert z[0] == z[-1] == 0.0 and z.max() == pytest.approx(0.1)
    radius = (0.45**2 + 0.1**2) / 0.2
    assert np.allclose(np.hypot(x, z + radius - 0.1), radius)  # on one circle
    assert np.all(np.diff(z, 2) < 0)  # convex


def test_bump_spans_the_ego_lanes_and_the_shoulder(road: RoadMap) -> None:
    (bump,) = layout_speed_bumps(road)
    assert (bump.s, bump.height, bump.length, bump.pass_speed) == (BUMP_S, 0.1, 0.9, 5 * KPH)
    assert bump.band == (-(W / 2 + SHOULDER), 1.5 * W)
    s, d = road.local_coordinates(np.array(bump.centre))
    assert float(s) == pytest.approx(BUMP_S) and float(d) == pytest.approx(sum(bump.band) / 2)
    hull = hull_vertices(bump)
    assert hull[:, 0].min() == pytest.approx(-0.45) and hull[:, 0].max() == pytest.approx(0.45)
    assert hull[:, 1].max() - hull[:, 1].min() == pytest.approx(bump.band[1] - bump.band[0])
    assert hull[:, 2].min() == 0.0 and hull[:, 2].max() == pytest.approx(0.1)
    assert bump_height_at(bump, np.array([0.0, 0.45, 0.6])) == pytest.approx([0.1, 0.0, 0.0])


def test_bump_mesh_covers_the_bump_above_the_road(road: RoadMap) -> None:
    (bump,) = layout_speed_bumps(road)
    mesh = bump_mesh(bump, 2)
    check_well_formed(mesh)
    assert mesh.name == "speed_bump_2"
    vs, vd = route_coords(road, mesh)
    assert vs.min() == pytest.approx(BUMP_S - 0.45) and vs.max() == pytest.approx(BUMP_S + 0.45)
    assert vd.min() == pytest.approx(bump.band[0]) and vd.max() == pytest.approx(bump.band[1])
    assert mesh.vertices[:, 2].max() == pytest.approx(0.1 + VISUAL_LIFT)
    top = mesh.normals[:, 2] > 0.5
    assert mesh.vertices[top, 2].min() == pytest.approx(VISUAL_LIFT)
    assert VISUAL_LIFT > SURFACE_Z  # its foot shows over the road surface
    assert np.allclose(np.linalg.norm(mesh.normals, axis=1), 1.0)
    colours = {tuple(c) for c in mesh.texture.reshape(-1, 3)}
    assert len(colours) == 2  # yellow and white stripes
    assert triangle_area(mesh) > 0.9 * 0.9 * (bump.band[1] - bump.band[0])  # faces up

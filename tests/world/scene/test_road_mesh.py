"""Tests of the road surface meshes and their painted-marking textures."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.typing import NDArray

from tests.roads import SHOULDER, W, arc, seg
from world.hdmap import CrossSection, RoadMap, Zone
from world.map.road import build_road_map
from world.scene.road_mesh import (
    DASH_LENGTH,
    DASH_PERIOD,
    MAX_CHORD_ERROR,
    MAX_MESH_VERTICES,
    MAX_STEP,
    SURFACE_Z,
    TexturedMesh,
    build_road_surface,
    make_road_texture,
    markings,
)
from world.spec import RoadSpec


@pytest.fixture(scope="module")
def road() -> RoadMap:
    """About 1.5 km: straights, gentle and tight arcs both ways, a one-lane stretch."""
    segments = (
        seg(303.0),
        arc(250.0, 30.0),
        seg(200.0),
        arc(-40.0, -70.0, lanes=1, oncoming=0),
        seg(120.0, lanes=1, oncoming=0),
        arc(25.0, 120.0),
        seg(500.0),
    )
    return build_road_map(RoadSpec(segments, 13.9))


@pytest.fixture(scope="module")
def meshes(road: RoadMap) -> list[TexturedMesh]:
    return build_road_surface(road)


def section(lanes: int = 2, oncoming: int = 1) -> CrossSection:
    return CrossSection(lanes, oncoming, W, SHOULDER, Zone.HIGHWAY)


def column(c: CrossSection, metres_from_right_edge: float, texture_width: int) -> int:
    return int(metres_from_right_edge / c.paved_width * texture_width)


def test_meshes_are_few_small_and_well_formed(meshes: list[TexturedMesh]) -> None:
    assert 2 <= len(meshes) <= 4  # two cross-sections, ~1.5 km
    for m in meshes:
        n = len(m.vertices)
        assert 0 < n <= MAX_MESH_VERTICES
        assert m.vertices.shape == (n, 3) and m.vertices.dtype == np.float64
        assert m.uvs.shape == (n, 2) and m.normals.shape == (n, 3)
        assert m.indices.ndim == 2 and m.indices.shape[1] == 3 and m.indices.dtype == np.int32
        assert m.indices.min() >= 0 and m.indices.max() < n
        assert np.unique(m.indices).size == n  # no unused vertices
        np.testing.assert_array_equal(m.vertices[:, 2], SURFACE_Z)
        np.testing.assert_array_equal(m.normals, np.tile([0.0, 0.0, 1.0], (n, 1)))
        assert m.uvs.min() >= 0.0 and m.uvs.max() <= 1.0
        assert m.texture.ndim == 3 and m.texture.shape[2] == 3 and m.texture.dtype == np.uint8
    assert len({m.name for m in meshes}) == len(meshes)


def test_triangles_face_up_and_are_not_degenerate(meshes: list[TexturedMesh]) -> None:
    for m in meshes:
        a, b, c = (m.vertices[m.indices[:, i], :2] for i in range(3))
        cross = (b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0]
        assert cross.min() > 1e-3  # counter-clockwise seen from above, area > 0


def test_long_roads_are_split_under_the_vertex_limit() -> None:
    road = build_road_map(RoadSpec((seg(9000.0),), 13.9))
    meshes = build_road_surface(road)
    assert len(meshes) >= 3
    assert all(len(m.vertices) <= MAX_MESH_VERTICES for m in meshes)
    assert all(m.texture is meshes[0].texture for m in meshes)
    # together they cover the whole route
    s, _ = road.local_coordinates(np.concatenate([m.vertices[:, :2] for m in meshes]))
    assert s.min() == pytest.approx(0.0, abs=1e-9)
    assert s.max() == pytest.approx(9000.0, abs=1e-9)


def test_every_vertex_is_on_a_paved_edge_with_u_across(
    road: RoadMap, meshes: list[TexturedMesh]
) -> None:
    for m in meshes:
        s, d = road.local_coordinates(m.vertices[:, :2])
        right, left = road.paved_edges(s)
        u = m.uvs[:, 0]
        assert set(np.unique(u).tolist()) == {0.0, 1.0}
        # stations at a segment's end belong to the next segment's section: step back
        inside = np.clip(s, 1e-6, road.length - 1e-6)
        right_in, left_in = road.paved_edges(inside - 1e-6)
        on_right = np.isclose(d, right, atol=1e-6) | np.isclose(d, right_in, atol=1e-6)
        on_left = np.isclose(d, left, atol=1e-6) | np.isclose(d, left_in, atol=1e-6)
        assert np.all(on_right[u == 0.0])
        assert np.all(on_left[u == 1.0])


def test_v_follows_the_station_and_never_wraps_inside_a_triangle(
    road: RoadMap, meshes: list[TexturedMesh]
) -> None:
    for m in meshes:
        s, _ = road.local_coordinates(m.vertices[:, :2])
        v = m.uvs[:, 1]
        phase = v - s / DASH_PERIOD  # a whole number of periods
        np.testing.assert_allclose(phase, np.round(phase), atol=1e-9)
        tri_s, tri_v = s[m.indices], v[m.indices]
        # within a triangle v is linear in s (so it never jumps from 1 back to 0)
        dv = tri_v - tri_v[:, :1]
        ds = tri_s - tri_s[:, :1]
        np.testing.assert_allclose(dv, ds / DASH_PERIOD, atol=1e-9)
        assert np.all(np.ptp(tri_s, axis=1) <= MAX_STEP + 1e-9)


def test_arcs_are_tessellated_within_the_chord_error(
    road: RoadMap, meshes: list[TexturedMesh]
) -> None:
    for m in meshes:
        _, d = road.local_coordinates(m.vertices[:, :2])
        # the strip's long edges: triangle edges joining two vertices with the same u
        edges = np.concatenate([m.indices[:, [0, 1]], m.indices[:, [1, 2]], m.indices[:, [0, 2]]])
        edges = edges[m.uvs[edges[:, 0], 0] == m.uvs[edges[:, 1], 0]]  # along, not across
        mid = 0.5 * (m.vertices[edges[:, 0], :2] + m.vertices[edges[:, 1], :2])
        _, d_mid = road.local_coordinates(mid)
        assert np.max(np.abs(d_mid - d[edges[:, 0]])) < MAX_CHORD_ERROR


def test_texture_is_shared_per_cross_section(road: RoadMap, meshes: list[TexturedMesh]) -> None:
    textures = {id(m.texture): m.texture for m in meshes}
    assert len(textures) == 2  # (2 lanes + 1 oncoming) and (1 lane + 0 oncoming)
    widths = sorted(t.shape[1] for t in textures.values())
    assert widths == [
        round(section(1, 0).paved_width / 0.025),
        round(section().paved_width / 0.025),
    ]
    for t in textures.values():
        assert t.shape[0] == round(DASH_PERIOD / 0.05)


def test_texture_markings_are_where_the_lanes_say() -> None:
    c = section(lanes=2, oncoming=1)
    tex = make_road_texture(c).astype(int)
    rows, cols = tex.shape[:2]
    dash_rows = np.arange(rows) < DASH_LENGTH / DASH_PERIOD * rows - 1
    gap_rows = np.arange(rows) > DASH_LENGTH / DASH_PERIOD * rows + 1

    def is_white(px: NDArray[np.int_]) -> NDArray[np.bool_]:
        return np.asarray(np.all(px > 200, axis=-1))

    def is_asphalt(px: NDArray[np.int_]) -> NDArray[np.bool_]:
        return np.asarray(np.all(px < 110, axis=-1))

    def is_yellow(px: NDArray[np.int_]) -> NDArray[np.bool_]:
        return (px[..., 0] > 180) & (px[..., 1] > 130) & (px[..., 2] < 90)

    lane_boundary = column(c, SHOULDER + W, cols)  # lane 0 / lane 1
    assert np.all(is_white(tex[dash_rows, lane_boundary]))
    assert np.all(is_asphalt(tex[gap_rows, lane_boundary]))
    shoulder_line = column(c, SHOULDER, cols)  # right edge of lane 0: solid white
    assert np.all(is_white(tex[:, shoulder_line]))
    centre = SHOULDER + 2 * W  # double yellow at +-0.12 m from the centre line
    for offset in (-0.12, 0.12):
        assert np.all(is_yellow(tex[:, column(c, centre + offset, cols)]))
    assert np.all(is_asphalt(tex[:, column(c, centre, cols)]))  # between the two lines
    assert np.all(is_white(tex[:, cols - 5]))  # left edge line, just inside the paved edge
    for lane_centre in (SHOULDER + 0.5 * W, SHOULDER + 1.5 * W, SHOULDER + 2.5 * W):
        assert np.all(is_asphalt(tex[:, column(c, lane_centre, cols)]))
    shoulder = tex[:, : column(c, SHOULDER - 0.3, cols)].reshape(-1, 3).mean(0)
    lane = tex[:, column(c, SHOULDER + 0.3, cols) : lane_boundary - 10].reshape(-1, 3).mean(0)
    assert np.all(is_asphalt(shoulder)) and np.abs(shoulder - lane).sum() > 5.0


def test_oncoming_lanes_are_separated_by_white_dashes_and_no_yellow_without_them() -> None:
    c = section(lanes=1, oncoming=2)
    tex = make_road_texture(c)
    cols = tex.shape[1]
    between = column(c, SHOULDER + 2 * W, cols)  # oncoming -1 / -2
    assert np.all(tex[0, between] > 200) and np.all(tex[-1, between] < 110)
    plain = make_road_texture(section(lanes=2, oncoming=0))
    yellowish = (plain[..., 0].astype(int) - plain[..., 2].astype(int)) > 60
    assert not yellowish.any()


def test_textures_are_deterministic_and_markings_ordered() -> None:
    c = section(lanes=3, oncoming=2)
    np.testing.assert_array_equal(make_road_texture(c), make_road_texture(c))
    centres = [m.centre for m in markings(c)]
    assert centres == sorted(centres)
    assert centres[0] > 0.0 and centres[-1] < c.paved_width
    # 1 shoulder line, 2 lane dashes, 2 yellow, 1 oncoming dash, 1 left edge
    assert len(centres) == 7

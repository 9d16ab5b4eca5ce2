"""Lane-keeping reference paths: samples on the lane centre, map headings, clamping."""

from __future__ import annotations

import math

import numpy as np
import pytest

from planner.route import lane_path, path_stations
from tests.planner.maps import LANE_WIDTH, real_map, road_spec, segment, straight_road

R = 60.0  # [m]


def wrap(a: np.ndarray) -> np.ndarray:
    return np.mod(a + math.pi, 2.0 * math.pi) - math.pi


@pytest.mark.parametrize("lane_index", [0, 1, -1])
def test_path_on_lane_centre_through_straight_arc_straight(lane_index: int) -> None:
    road = real_map(road_spec([segment(100.0), segment(80.0, R), segment(100.0)], 50.0))
    lane = road.lane(lane_index)
    path = lane_path(lane, 90.0, 5.0, 120.0, 0.5, length=road.length)
    s, r = lane.local_coordinates(path.xy)
    expected_s = path_stations(90.0, 5.0, 120.0, 0.5, road.length)
    np.testing.assert_allclose(s, expected_s, atol=1e-9)
    np.testing.assert_allclose(r, 0.0, atol=1e-9)
    assert s[0] == pytest.approx(85.0) and s[-1] == pytest.approx(210.0)
    # headings: the map's tangent, and the direction of the chords between samples
    np.testing.assert_allclose(wrap(path.heading - lane.heading_at(s)), 0.0, atol=1e-12)
    chord = np.diff(path.xy, axis=0)
    chord_heading = np.arctan2(chord[:, 1], chord[:, 0])
    mid_heading = 0.5 * (path.heading[1:] + path.heading[:-1])
    np.testing.assert_allclose(wrap(chord_heading - mid_heading), 0.0, atol=2e-3)
    # curvature of the lane centre: 1 / (R - offset) on the arc, 0 on the straights
    offset = float(lane.offset_at(150.0))
    in_arc = (s > 100.0) & (s < 180.0)
    np.testing.assert_allclose(path.curvature[in_arc], 1.0 / (R - offset))
    np.testing.assert_allclose(path.curvature[(s < 100.0) | (s >= 180.0)], 0.0)
    # spacing: 0.5 m of station, (1 - offset / R) * 0.5 m of lane on the arc
    np.testing.assert_allclose(np.diff(s), 0.5, atol=1e-9)
    arc_gaps = np.linalg.norm(chord, axis=1)[in_arc[1:] & in_arc[:-1]]
    np.testing.assert_allclose(arc_gaps, 0.5 * (1.0 - offset / R), rtol=1e-4)


@pytest.mark.parametrize("kind", ["double", "real"])
def test_path_on_straight_lane(kind: str) -> None:
    road = straight_road(kind, 300.0, 50.0)
    lane = road.lane(1)
    path = lane_path(lane, 100.0, 5.0, 25.0, 0.5, length=road.length)
    assert path.xy.shape == (61, 2)
    np.testing.assert_allclose(path.xy[:, 0], np.linspace(95.0, 125.0, 61), atol=1e-9)
    np.testing.assert_allclose(path.xy[:, 1], LANE_WIDTH, atol=1e-9)
    np.testing.assert_allclose(path.heading, 0.0, atol=1e-12)
    np.testing.assert_allclose(path.curvature, 0.0)


@pytest.mark.parametrize("kind", ["double", "real"])
def test_path_clamped_to_route(kind: str) -> None:
    road = straight_road(kind, 300.0, 50.0)
    lane = road.lane(0)
    start = lane_path(lane, 2.0, 5.0, 25.0, 0.5, length=road.length)
    assert start.xy[0, 0] == pytest.approx(0.0)
    assert start.xy[-1, 0] == pytest.approx(27.0)
    end = lane_path(lane, 290.0, 5.0, 25.0, 0.5, length=road.length)
    assert end.xy[0, 0] == pytest.approx(285.0)
    assert end.xy[-1, 0] == pytest.approx(300.0)
    beyond = lane_path(lane, 320.0, 0.0, 25.0, 0.5, length=road.length)
    assert beyond.xy.shape == (2, 2)
    assert beyond.xy[-1, 0] == pytest.approx(300.0)


def test_path_stations() -> None:
    st = path_stations(10.0, 1.0, 2.2, 0.5, 100.0)
    np.testing.assert_allclose(st, [9.0, 9.5, 10.0, 10.5, 11.0, 11.5, 12.0, 12.2])
    np.testing.assert_allclose(path_stations(10.0, 1.0, 2.0, 0.5, 100.0)[-1], 12.0)
    assert len(path_stations(10.0, 1.0, 2.0, 0.5, 100.0)) == 7
    np.testing.assert_allclose(path_stations(5.0, 0.0, 0.0, 0.5, 100.0), [4.5, 5.0])
    np.testing.assert_allclose(path_stations(0.0, 0.0, 0.0, 0.5, 100.0), [0.0, 0.5])
    with pytest.raises(ValueError):
        path_stations(0.0, 1.0, 1.0, 0.0, 100.0)
    with pytest.raises(ValueError):
        path_stations(0.0, 1.0, 1.0, 0.5, 0.0)

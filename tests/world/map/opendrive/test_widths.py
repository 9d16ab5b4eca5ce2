"""An OpenDRIVE road whose lanes change along it (`data/widths.xodr`: a line, an arc and a
spiral; three lane sections; route lane 0 narrowing 3.75 -> 3.25 m over 120 m, route lane 1
widening 3.5 -> 3.6 m in the last section, an oncoming lane of 3.4 m, a cubic lane offset
0 -> 0.4 m, a hard shoulder 2.5 -> 3.0 -> 2.0 m): the HD map built from it has every lane
centre, width and boundary within 1 mm of the file's exact lanes, and so do the painted
lines of the road surface; the world builds on it."""

from __future__ import annotations

from functools import cache
from pathlib import Path

import numpy as np
import pytest

from tests.roads import numeric_curvature
from world.hdmap import FloatArray, RoadMap
from world.map.opendrive import Road, lane_borders, lane_centre_t, load_opendrive
from world.map.opendrive.route import OdrRoute, build_route
from world.map.road import build_road_map
from world.scene.road_mesh import build_road_surface, markings
from world.spec import EgoSpec, WorldSpec
from world.world import World

DATA = Path(__file__).with_name("data")
TOLERANCE = 1e-3  # [m] the route's (`world.map.opendrive.route.TOLERANCE`)
STATIONS = np.linspace(0.25, 249.75, 500)  # [m] file stations all along the road
LANE_IDS = (-2, -1)  # route lanes 0, 1
ONCOMING_ID = 1
SHOULDER_ID = -3


def narrowing(s: float) -> float:
    """[m] lane -2's width by the file's definition: 3.75 m, a cubic with zero slope at both
    ends down to 3.25 m at s = 120 m, 3.25 m on."""
    x = min(s, 120.0) / 120.0
    return 3.75 - 0.5 * x * x * (3.0 - 2.0 * x)


def lane_offset(s: float) -> float:
    """[m] the file's lane offset: 0 -> 0.4 m over 200 m (zero slope at both ends), then 0.4."""
    x = min(s, 200.0) / 200.0
    return 0.4 * x * x * (3.0 - 2.0 * x)


@cache
def route_and_map() -> tuple[OdrRoute, RoadMap]:
    route = build_route(load_opendrive(DATA / "widths.xodr"))
    return route, build_road_map(route.spec)


def map_offset(road_map: RoadMap, xy: tuple[float, float]) -> tuple[float, float]:
    """(s, d) of a map-frame point on the route."""
    s, d = road_map.local_coordinates(np.array(xy))
    return float(s), float(d)


def test_the_file_is_what_the_tests_say() -> None:
    """The analytic widths and offset agree with the file's records (the tests below compare
    the map against the file's exact lanes, and against these)."""
    route, _ = route_and_map()
    road = route.road
    for s in (0.0, 37.0, 60.0, 119.0, 125.0, 150.0, 199.0, 249.0):
        borders = lane_borders(road, s)
        inner, outer = borders[-2]
        assert inner - outer == pytest.approx(narrowing(s), abs=1e-12)
        assert borders[0][0] == pytest.approx(lane_offset(s), abs=1e-12)


def assert_lanes_on_the_file(road: Road, road_map: RoadMap, ids: dict[int, int],
                             stations: FloatArray) -> None:
    """Each map lane (route index: file lane id in `ids`) at `stations`: its centre within
    `TOLERANCE` of the file's lane centre (the point projected onto the file's reference
    line), its width within `TOLERANCE` of the file's there."""
    for index, lane_id in ids.items():
        lane = road_map.lane(index)
        s_file, t = road.plan_view.project(lane.position(stations, 0.0))
        for k, s in enumerate(np.clip(s_file, 0.0, road.length).tolist()):
            assert abs(t[k] - lane_centre_t(road, lane_id, s)) < TOLERANCE, (lane_id, s)
            inner, outer = lane_borders(road, s)[lane_id]
            width = float(lane.width_at(stations[k]))
            assert abs(width - abs(inner - outer)) < TOLERANCE, (lane_id, s)


def test_every_lane_centre_and_width_is_within_1_mm_of_the_files() -> None:
    """Each route lane's centre line `Lane.position(s, 0)`, at stations all along the map,
    within 1 mm of the file's exact lane centre (the point projected onto the file's
    reference line: its offset against the file's lane centre there), and its width
    `Lane.width_at(s)` within 1 mm of the file's there."""
    route, road_map = route_and_map()
    road = route.road
    assert route.layout.lane_ids == LANE_IDS and route.layout.oncoming_ids == (ONCOMING_ID,)
    stations = np.linspace(0.0, road_map.length, 700)
    assert_lanes_on_the_file(road, road_map, dict(enumerate(LANE_IDS)), stations)


def test_the_files_lane_centres_are_on_the_maps_lanes() -> None:
    """The other way round: the file's lane centre at stations all along the road lies in
    its route lane, within 1 mm of the map's lane centre (`RoadMap.lane_at`)."""
    route, road_map = route_and_map()
    for index, lane_id in enumerate(LANE_IDS):
        for s in STATIONS:
            x, y, _ = route.point(float(s), lane_centre_t(route.road, lane_id, float(s)))
            lane, _, r = road_map.lane_at((x, y))
            assert lane == index and abs(r) < TOLERANCE, (lane_id, s, lane, r)


def test_the_narrowing_lane_is_the_analytic_cubic() -> None:
    """Route lane 0's width against the closed form 3.75 -> 3.25 m: at the start, through
    the taper and after it, within 1 mm."""
    route, road_map = route_and_map()
    lane0 = road_map.lane(0)
    widths = []
    for s in (0.5, 30.0, 60.0, 90.0, 119.5, 121.0, 160.0):
        x, y, _ = route.point(s, lane_centre_t(route.road, LANE_IDS[0], s))
        s_map, _ = map_offset(road_map, (x, y))
        widths.append(float(lane0.width_at(s_map)))
        assert widths[-1] == pytest.approx(narrowing(s), abs=TOLERANCE), s
    assert widths[0] > 3.74 and widths[-1] < 3.26  # it does narrow


def test_every_boundary_and_paved_edge_is_within_1_mm_of_the_files() -> None:
    """Each boundary of `RoadMap.lane_boundaries` (shoulder edge, lane 0's edges, the centre
    line, the oncoming lane's outer edge) where the file's border is, within 1 mm; the
    paved edges are the outer ones."""
    route, road_map = route_and_map()
    road = route.road
    for s in STATIONS:
        borders = lane_borders(road, float(s))
        files = [borders[SHOULDER_ID][1], borders[-2][1], borders[-1][1], borders[0][1],
                 borders[ONCOMING_ID][1]]
        for k, t in enumerate(files):
            x, y, _ = route.point(float(s), t)
            s_map, d = map_offset(road_map, (x, y))
            bounds = road_map.lane_boundaries(s_map)
            assert abs(d - float(bounds[k])) < TOLERANCE, (k, s, d - float(bounds[k]))
        right, left = road_map.paved_edges(s_map)
        assert (float(right), float(left)) == (bounds[0], bounds[-1])


def test_lane_of_finds_each_lane_where_it_lies() -> None:
    """A point a quarter of the lane's width inside each of its edges is in that lane."""
    _, road_map = route_and_map()
    for s in STATIONS[::25]:
        bounds = road_map.lane_boundaries(float(s))
        for band, index in enumerate((0, 1, -1)):
            lo, hi = bounds[band + 1], bounds[band + 2]
            for d in (lo + 0.25 * (hi - lo), hi - 0.25 * (hi - lo)):
                lane, r = road_map.lane_of(float(s), float(d))
                assert lane == index
                assert r == pytest.approx(d - float(road_map.lane(index).offset_at(s)))


def test_the_lane_curvature_is_exact_for_varying_offsets() -> None:
    """Route lane 1's curvature (its offset varies) against the curvature of its centre line
    from finite differences of its heading."""
    _, road_map = route_and_map()
    lane = road_map.lane(1)
    for s in (20.0, 70.0, 100.0, 180.0):
        numeric = numeric_curvature(lane, s)
        assert float(lane.curvature_at(s)) == pytest.approx(numeric, abs=1e-5), s


def test_the_painted_lines_follow_the_narrowing_lane() -> None:
    """The road surface's texture maps each painted line's centre to the file's border: at
    every station of the strips, the texture column of a line, mapped through the strip's
    vertices across, lands within 1 mm of where the map's
    boundary is, which is within 1 mm of the file's border (above)."""
    _, road_map = route_and_map()
    (mesh,) = build_road_surface(road_map)  # one canonical texture for the whole road
    section = road_map.sections[0]
    lines = markings(section)
    width = 2.5 + 3 * 3.5  # [m] the canonical section's paved width
    s_v, d_v = road_map.local_coordinates(mesh.vertices[:, :2])
    u_v = mesh.uvs[:, 0]
    starts = np.flatnonzero(u_v == 0.0)  # each station's row of vertices starts at u = 0
    lane0_right = lines[0]  # lane 0's right edge line (the shoulder's boundary)
    assert lane0_right.centre == pytest.approx(2.5)
    checked = 0
    painted_widths = {}  # [m] lane 0 between its painted lines, by station
    for a, b in zip(starts[:-1:2], starts[1::2], strict=True):
        u, d = u_v[a:b], d_v[a:b]
        assert np.all(np.diff(u) >= 0.0) and u[-1] == 1.0  # one row, right to left
        s = float(np.median(s_v[a:b]))
        bounds = road_map.lane_boundaries(s)
        painted = [float(np.interp(line.centre / width, u, d)) for line in lines[:3]]
        for k, at in enumerate(painted, start=1):
            assert abs(at - float(bounds[k])) < TOLERANCE, (s, k)
        painted_widths[s] = painted[1] - painted[0]
        checked += 1
    assert checked > 100
    first, last = min(painted_widths), max(s for s in painted_widths if s < 200.0)
    assert painted_widths[first] == pytest.approx(3.75, abs=0.01)  # it narrows on the road
    assert painted_widths[last] == pytest.approx(3.25, abs=0.01)


def test_a_world_builds_on_the_road() -> None:
    """The physics world builds from the route spec (no sensors): the road surface is there
    and the ego car starts on route lane 0's centre (where the lane is 3.6 m wide), its
    four tyres inside the lane's edges, and stays there a few steps standing still."""
    route, road_map = route_and_map()
    world = World(WorldSpec(road=route.spec, ego=EgoSpec(lane=0, s=30.0, speed=0.0,
                                                       max_speed=15.0)))
    try:
        assert any(m.name.startswith("road_surface") for m in world.scene.road_meshes)
        for _ in range(5):
            world.step()
        truth = world.ego_route
        assert truth.station == pytest.approx(30.0, abs=0.05)
        assert abs(float(truth.offsets[0])) < 0.05
        half = 0.5 * float(road_map.lane(0).width_at(30.0))
        assert np.all(np.abs(truth.offsets[2:]) < half)
    finally:
        world.close()


def test_every_plan_view_shape_takes_a_varying_lane_offset(tmp_path: Path) -> None:
    """`curvy.xodr` (lines, spirals, arcs, poly3, both paramPoly3 ranges; two lanes each way,
    a hard shoulder) with a cubic lane offset 0 -> 0.6 m along the whole road added: every
    lane of the route (ego and oncoming) and the shoulder within 1 mm of the file's, at
    stations all along the map."""
    length = 220.0149959845117
    a, b, c, d = 0.0, 0.0, 3.0 * 0.6 / length**2, -2.0 * 0.6 / length**3
    text = (DATA / "curvy.xodr").read_text().replace(
        "<lanes>", f'<lanes><laneOffset s="0" a="{a}" b="{b}" c="{c!r}" d="{d!r}"/>', 1)
    path = tmp_path / "curvy_offset.xodr"
    path.write_text(text)
    route = build_route(load_opendrive(path))
    road_map = build_road_map(route.spec)
    road = route.road
    assert road_map.section_profiled.all()  # every piece's lanes move along it
    stations = np.linspace(0.0, road_map.length, 500)
    ids = {0: -2, 1: -1, -1: 1, -2: 2}  # route lane: file lane
    assert_lanes_on_the_file(road, road_map, ids, stations)
    right, _ = road_map.paved_edges(stations)
    s_file, t = road.plan_view.project(road_map.position(stations, right))
    for k, s in enumerate(np.clip(s_file, 0.0, road.length).tolist()):
        assert abs(t[k] - lane_borders(road, s)[-3][1]) < TOLERANCE, s


def test_constant_lanes_of_different_widths_make_a_constant_profile(tmp_path: Path) -> None:
    """Driving lanes of 3.0 and 3.5 m and an oncoming lane of 3.25 m, constant along the
    road: each map lane exactly its width, the boundaries constant on every segment."""
    def lane(i: int, width: float) -> str:
        return (f'<lane id="{i}" type="driving"><width sOffset="0" a="{width}" b="0" c="0" '
                f'd="0"/><roadMark sOffset="0" type="solid" width="0.12"/></lane>')

    text = ('<?xml version="1.0"?><OpenDRIVE><header revMajor="1" revMinor="6"/>'
            '<road name="r" length="100" id="1" junction="-1" rule="RHT"><planView>'
            '<geometry s="0" x="0" y="0" hdg="0" length="100"><arc curvature="0.01"/>'
            '</geometry></planView><lanes><laneSection s="0"><left>' + lane(1, 3.25)
            + '</left><center><lane id="0" type="none"/></center><right>' + lane(-1, 3.5)
            + lane(-2, 3.0) + "</right></laneSection></lanes></road></OpenDRIVE>")
    path = tmp_path / "r.xodr"
    path.write_text(text)
    route = build_route(load_opendrive(path))
    road_map = build_road_map(route.spec)
    assert len(road_map.sections) == 1
    (section,) = road_map.sections
    assert section.profile is not None
    assert np.all(np.asarray(section.profile.boundaries)[:, 1:] == 0.0)
    s = np.linspace(0.0, road_map.length, 50)
    for index, width in ((0, 3.0), (1, 3.5), (-1, 3.25)):
        np.testing.assert_allclose(road_map.lane(index).width_at(s), width, atol=1e-12)
    assert road_map.pieces[0].curvature == pytest.approx(1.0 / (100.0 + 3.5 + 1.5),
                                                         rel=1e-12)

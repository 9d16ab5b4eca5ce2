"""The town's static scenery: streets meet the junction asphalt, stop lines, sidewalks around
every corner, buildings clear of it all (pure geometry); then a town `World` seen by the
camera lane finder and the LiDAR object detector."""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence

import numpy as np
import pytest

from perception.lanes import LaneDetector
from perception.objects import DetectorParams, ObjectDetector
from tests.perception.render_scene import lane_truth, pose_ego
from world.frames import CameraFrame, LidarScan
from world.hdmap import Manoeuvre
from world.map.road import build_road_map
from world.map.town import HEADINGS, STOP_SETBACK, TownLayout, compile_route
from world.scene.road_marks import MARK_Z, STOP_LINE_WIDTH
from world.scene.road_mesh import SURFACE_Z, TexturedMesh, build_road_surface
from world.scene.scenery import MIN_BUILDING_GAP
from world.scene.town_scene import (
    KERB_HEIGHT,
    SIDEWALK_WIDTH,
    TownScene,
    block_outline,
    build_town_scene,
    corner_arc,
    junction_outline,
    street_road,
)
from world.sensors.sensor import vehicle_pose
from world.sensors.setup import Profile, sensor_setup
from world.spec import EgoSpec, TownSpec, WorldSpec
from world.world import World

BLOCK = 90.0  # [m]


def layout(lanes: int = 1, junctions: str = "stop_signs") -> TownLayout:
    """3 x 2 blocks: corners, T-junctions and crossings, and x and y told apart."""
    return TownLayout(TownSpec(3, 2, BLOCK, lanes, 3.5, 11.1, junctions))


Town = tuple[TownLayout, TownScene]


@pytest.fixture(scope="module", params=[1, 2], ids=["1_lane", "2_lanes"])
def town(request: pytest.FixtureRequest) -> Town:
    t = layout(request.param)
    return t, build_town_scene(t, np.random.default_rng(7))


# ---- helpers --------------------------------------------------------------------------------


def cover(meshes: Sequence[TexturedMesh], points: np.ndarray, up_only: bool = False) -> np.ndarray:
    """(P,) how many of the meshes' triangles (counter-clockwise from above) contain each point
    strictly inside, in plan view; `up_only`: only the triangles facing up."""
    counts = np.zeros(len(points), int)
    lo, hi = points.min(axis=0), points.max(axis=0)
    for mesh in meshes:
        tris = mesh.indices
        if up_only:
            tris = tris[mesh.normals[tris[:, 0], 2] > 0.5]
        a, b, c = (mesh.vertices[tris[:, k], :2] for k in range(3))
        t_lo, t_hi = np.minimum(np.minimum(a, b), c), np.maximum(np.maximum(a, b), c)
        near = np.all(t_hi >= lo, axis=1) & np.all(t_lo <= hi, axis=1)
        a, b, c = a[near], b[near], c[near]
        for chunk in np.array_split(np.arange(len(points)), max(1, len(points) // 500)):
            p = points[chunk][:, None, :]

            def side(u: np.ndarray, v: np.ndarray, p: np.ndarray = p) -> np.ndarray:
                out: np.ndarray = (v[:, 0] - u[:, 0]) * (p[..., 1] - u[:, 1]) - \
                    (v[:, 1] - u[:, 1]) * (p[..., 0] - u[:, 0])
                return out

            inside = (side(a, b) > 0) & (side(b, c) > 0) & (side(c, a) > 0)
            counts[chunk] += inside.sum(axis=1)
    return counts


def inside_convex(outline: np.ndarray, points: np.ndarray) -> np.ndarray:
    """(P,) whether points lie strictly inside a convex counter-clockwise polygon."""
    a, b = outline, np.roll(outline, -1, axis=0)
    cross = ((b[:, 0] - a[:, 0]) * (points[:, None, 1] - a[:, 1])
             - (b[:, 1] - a[:, 1]) * (points[:, None, 0] - a[:, 0]))
    out: np.ndarray = np.all(cross > 1e-9, axis=1)
    return out


def street_gap(t: TownLayout, xy: np.ndarray) -> np.ndarray:
    """[m] (P,) distance of points from the nearest street centre line inside the town."""
    spec = t.spec
    gx = np.abs(xy[:, 0] - BLOCK * np.clip(np.round(xy[:, 0] / BLOCK), 0, spec.blocks_x))
    gy = np.abs(xy[:, 1] - BLOCK * np.clip(np.round(xy[:, 1] / BLOCK), 0, spec.blocks_y))
    return np.minimum(gx, gy)


# ---- streets and junctions ----------------------------------------------------------------------


def test_street_strips_are_the_roads_build_road_surface_paints(town: Town) -> None:
    t, scene = town
    made = np.concatenate([m.vertices for m in scene.streets])
    each = [build_road_surface(street_road(t, j, h)) for j, h in t.streets()]
    np.testing.assert_allclose(made, np.concatenate([m.vertices for ms in each for m in ms]),
                               atol=1e-9)
    np.testing.assert_array_equal(scene.streets[0].texture, each[0][0].texture)
    road = street_road(t, (1, 1), "north")
    assert road.length == pytest.approx(BLOCK - 2 * t.mouth)
    np.testing.assert_allclose(road.position(0.0, 0.0), (BLOCK + t.kerb_lane, BLOCK + t.mouth))


def test_street_strips_meet_the_junction_asphalt_at_the_mouths(town: Town) -> None:
    """Each strip's end vertices are corners of the junction's outline, the mouth's edge is
    one straight edge of that outline, and everything is at the road's surface height."""
    t, scene = town
    ends = [(0.0, "start"), (BLOCK - 2 * t.mouth, "end")]
    for j, heading in t.streets():
        road = street_road(t, j, heading)
        for s, which in ends:
            junction = j if which == "start" else (j[0] + (heading == "east"),
                                                   j[1] + (heading == "north"))
            outline = junction_outline(t, junction)
            for edge in road.paved_edges(s):
                corner = road.position(s, float(edge))
                assert np.min(np.linalg.norm(outline - corner, axis=1)) < 1e-9, (j, heading)
    for mesh in (*scene.streets, *scene.junctions):
        np.testing.assert_array_equal(mesh.vertices[:, 2], SURFACE_Z)


@pytest.mark.parametrize("junction", [(0, 0), (1, 0), (1, 1), (3, 2), (0, 1)],
                         ids=["corner", "T_south", "cross", "corner_ne", "T_west"])
def test_asphalt_covers_the_street_area_once_and_sidewalks_never(
        town: Town, junction: tuple[int, int]) -> None:
    """Random points around a junction: where no sidewalk is and inside the town's outer kerb,
    exactly one street or junction triangle (no gap, no overlap to z-fight); under a sidewalk
    none; and every sidewalk point is under exactly one pavement top."""
    t, scene = town
    rng = np.random.default_rng(1)
    centre = np.array(t.centre(junction))
    points = centre + rng.uniform(-t.mouth - 12.0, t.mouth + 12.0, size=(6000, 2))
    asphalt = cover((*scene.streets, *scene.junctions), points)
    tops = cover([p.mesh for p in scene.pavements], points, up_only=True)
    on_slab = np.any([inside_convex(p.outline, points) for p in scene.pavements], axis=0)
    hw = t.half_width
    within = ((points >= -hw) & (points <= np.array([3, 2]) * BLOCK + hw)).all(axis=1)
    paved = within & ~on_slab
    assert paved.sum() > 500 and on_slab.sum() > 500
    assert np.all(asphalt[paved] == 1)
    assert np.all(asphalt[~paved] == 0)
    assert np.all(tops[on_slab] == 1)
    assert np.all(tops[~on_slab] == 0)


def test_junction_outlines_per_kind() -> None:
    t = layout()
    hw, m = t.half_width, t.mouth
    arcs = len(corner_arc(t, (0, 0), 0))
    # corner (0, 0): one rounded corner (north-east), the outer corner square
    outline = junction_outline(t, (0, 0))
    assert len(outline) == arcs + 3
    assert np.min(np.linalg.norm(outline - (-hw, -hw), axis=1)) < 1e-9
    # T (1, 0): two rounded corners; the south kerb runs straight on
    assert len(junction_outline(t, (1, 0))) == 2 * arcs + 2
    # crossing (1, 1): four rounded corners, each ending at the mouths
    outline = junction_outline(t, (1, 1))
    assert len(outline) == 4 * arcs
    assert np.max(np.abs(outline - (BLOCK, BLOCK))) == pytest.approx(m)


# ---- stop lines and signs --------------------------------------------------------------------


@pytest.mark.parametrize("kind", ["stop_signs", "traffic_lights", "mixed"])
def test_every_approach_has_its_stop_line(kind: str) -> None:
    t = layout(2, kind)
    scene = build_town_scene(t, np.random.default_rng(0))
    approaches = t.approaches()
    (mesh,) = scene.stop_lines
    quads = mesh.vertices.reshape(-1, 4, 3)
    assert len(quads) == len(approaches) == 6 * 3 + 2 * 4  # 6 T-junctions, 2 crossings
    np.testing.assert_array_equal(mesh.vertices[:, 2], MARK_Z)
    for quad, a in zip(quads, approaches, strict=True):
        centre = np.array(t.centre(a.junction))
        near, far = 0.5 * (quad[0, :2] + quad[3, :2]), 0.5 * (quad[1, :2] + quad[2, :2])
        np.testing.assert_allclose(near, a.stop_line, atol=1e-9)  # its near edge
        ahead = np.array([math.cos(HEADINGS[a.heading]), math.sin(HEADINGS[a.heading])])
        # STOP_SETBACK before the mouth, the far edge STOP_LINE_WIDTH nearer the junction
        assert (centre - near) @ ahead == pytest.approx(t.mouth + STOP_SETBACK)
        assert (centre - far) @ ahead == pytest.approx(t.mouth + STOP_SETBACK - STOP_LINE_WIDTH)
        # kerb to centre line: the lanes heading in, nothing else
        assert np.linalg.norm(quad[0, :2] - quad[3, :2]) == pytest.approx(t.half_width)
        assert street_gap(t, quad[:, :2]).min() == pytest.approx(0.0, abs=1e-9)
        assert street_gap(t, quad[:, :2]).max() == pytest.approx(t.half_width)
        assert cover(scene.streets, np.mean(quad[:, :2], axis=0)[None])[0] == 1


def test_the_routes_stop_station_is_on_the_towns_stop_line() -> None:
    t = layout()
    scene = build_town_scene(t, np.random.default_rng(0))
    road = build_road_map(compile_route(t, (0, 1, "east"), (Manoeuvre.LEFT,), "ego"))
    (junction,) = road.junctions
    at_line = road.position(junction.s_stop, 0.0)
    beyond = road.position(junction.s_stop + STOP_LINE_WIDTH, 0.0)
    assert cover(scene.stop_lines, np.array([0.5 * (at_line + beyond)]))[0] == 1


def test_stop_signs_stand_on_the_sidewalk_at_their_lines() -> None:
    t = layout(1, "mixed")
    scene = build_town_scene(t, np.random.default_rng(0))
    with_signs = [a for a in t.approaches() if a.stop_sign is not None]
    assert len(scene.stop_signs) == len(with_signs) > 0
    poles = np.array([s.pole_xy for s in scene.stop_signs])
    gap = street_gap(t, poles)
    assert np.all((gap > t.half_width) & (gap < t.half_width + SIDEWALK_WIDTH))
    for sign, a in zip(scene.stop_signs, with_signs, strict=True):
        assert a.stop_sign is not None
        assert sign.pole_xy == a.stop_sign[0] and sign.yaw == a.stop_sign[1] and sign.s == 0.0
    assert not build_town_scene(layout(1, "traffic_lights"), np.random.default_rng(0)).stop_signs


# ---- sidewalks -------------------------------------------------------------------------------


def test_sidewalks_wrap_every_block_corner_clear_of_the_right_turn(town: Town) -> None:
    t, scene = town
    blocks = {p.name: p for p in scene.pavements}
    assert len(blocks) == 3 * 2 + 4
    for by in range(2):
        for bx in range(3):
            slab = blocks[f"town_block_{bx}_{by}"]
            np.testing.assert_array_equal(slab.outline, block_outline(t, (bx, by)))
            for j, k in (((bx, by), 0), ((bx + 1, by), 1), ((bx + 1, by + 1), 2),
                         ((bx, by + 1), 3)):
                arc = corner_arc(t, j, k)
                assert np.min(np.linalg.norm(slab.outline[:, None] - arc[None], axis=2),
                              axis=0).max() < 1e-9  # the kerb goes round the corner
                # concrete all round it: half a sidewalk behind the kerb, at the kerb's height
                # (at angles between the arc's points: not on a triangle's edge)
                u = np.array([math.cos(math.pi / 2 * k), math.sin(math.pi / 2 * k)])
                v = np.array([-u[1], u[0]])
                centre = np.array(t.centre(j)) + t.mouth * (u + v)
                phi = np.linspace(-0.5 * math.pi, -math.pi, 7)[1:-1] + 0.01
                radius = t.corner_radius - 0.5 * SIDEWALK_WIDTH
                behind = centre + radius * (np.cos(phi)[:, None] * u + np.sin(phi)[:, None] * v)
                assert np.all(cover([slab.mesh], behind, up_only=True) == 1)
    # a right turn's path keeps at least w / 2 from the kerb corner, most at its middle
    road = build_road_map(compile_route(t, (0, 1, "east"), (Manoeuvre.RIGHT,), "ego"))
    (junction,) = road.junctions
    path = road.position(np.linspace(junction.s_enter, junction.s_exit, 200), 0.0)
    kerb = corner_arc(t, (1, 1), 2)
    clearance = np.min(np.linalg.norm(path[:, None] - kerb[None], axis=2), axis=1)
    assert clearance.min() >= 0.5 * t.spec.lane_width - 0.02
    # at the corner's middle: w / 2 + (sqrt 2 - 1) w / 2 (the kerb's radius is the path's)
    assert clearance.max() == pytest.approx(0.5 * t.spec.lane_width * math.sqrt(2), abs=0.05)


def test_sidewalks_are_kerbed_slabs_along_every_street_edge(town: Town) -> None:
    t, scene = town
    for slab in scene.pavements:
        mesh = slab.mesh
        assert slab.height == KERB_HEIGHT == pytest.approx(0.12)
        top = mesh.normals[:, 2] > 0.5
        np.testing.assert_array_equal(mesh.vertices[top, 2], KERB_HEIGHT)
        # kerb faces all round: vertical quads whose area is perimeter x height
        faces = mesh.indices[mesh.normals[mesh.indices[:, 0], 2] == 0.0]
        v = mesh.vertices
        area = 0.5 * np.linalg.norm(np.cross(v[faces[:, 1]] - v[faces[:, 0]],
                                             v[faces[:, 2]] - v[faces[:, 0]]), axis=1).sum()
        perimeter = np.linalg.norm(slab.outline - np.roll(slab.outline, -1, axis=0),
                                   axis=1).sum()
        assert area == pytest.approx(perimeter * KERB_HEIGHT)
    # a point just behind each kerb of every street, mid-block, is on a slab
    for j, heading in t.streets():
        road = street_road(t, j, heading)
        right, left = road.paved_edges(road.length / 2)
        behind = np.array([road.position(road.length / 2, float(right) - 0.5),
                           road.position(road.length / 2, float(left) + 0.5)])
        assert np.all(cover([p.mesh for p in scene.pavements], behind, up_only=True) == 1)


# ---- buildings -------------------------------------------------------------------------------


def test_buildings_stand_in_the_blocks_clear_of_sidewalks_and_each_other(town: Town) -> None:
    t, scene = town
    boxes = scene.buildings
    assert len(boxes) >= 3 * 2 * 3  # a few per block
    inner = [block_outline(t, (bx, by), SIDEWALK_WIDTH) for by in range(2) for bx in range(3)]
    per_block = np.zeros(len(inner), int)
    for box in boxes:
        corners = box.footprint()
        assert street_gap(t, corners).min() >= t.half_width + SIDEWALK_WIDTH
        homes = [i for i, outline in enumerate(inner) if inside_convex(outline, corners).all()]
        assert len(homes) == 1
        per_block[homes[0]] += 1
        assert box.centre[2] == pytest.approx(box.half_extents[2])  # standing on the ground
    assert np.all(per_block >= 3)
    lo = np.array([b.footprint().min(axis=0) for b in boxes])
    hi = np.array([b.footprint().max(axis=0) for b in boxes])
    gap = np.maximum(lo[:, None] - hi[None], lo[None] - hi[:, None]).max(axis=2)
    np.fill_diagonal(gap, np.inf)
    assert gap.min() >= MIN_BUILDING_GAP - 1e-9


def test_buildings_are_deterministic_for_the_rng() -> None:
    t = layout()
    a, b, c = (build_town_scene(t, np.random.default_rng(seed)).buildings
               for seed in (3, 3, 4))
    assert a == b
    assert a != c


# ---- a town World: camera and LiDAR ----------------------------------------------------------


def town_spec() -> WorldSpec:
    town = TownSpec(blocks_x=2, blocks_y=2, block=90, lanes=1, lane_width=3.5,
                    speed_limit=11.1, junctions="stop_signs")
    return WorldSpec(
        road=compile_route(TownLayout(town), (0, 1, "east"), (Manoeuvre.STRAIGHT,), "ego"),
        ego=EgoSpec(lane=0, s=5.0, speed=0, max_speed=15), seed=1, town=town)


@pytest.fixture(scope="module")
def world() -> Iterator[World]:
    w = World(town_spec(), sensor_setup(Profile.DEFAULT))
    yield w
    w.close()


def test_world_builds_the_town_instead_of_the_route_road(world: World) -> None:
    scene = world.scene
    names = [m.name for m in scene.road_meshes]
    assert all(n.startswith("town_") for n in names)
    assert not scene.signs and not scene.bumps
    t = TownLayout(world.spec.town)  # type: ignore[arg-type]
    assert len(scene.stop_signs) == len([a for a in t.approaches() if a.stop_sign])
    assert len(scene.kerb_bodies) == 2 * 2 + 4
    assert scene.kerb_bodies <= scene.static_bodies
    assert not scene.kerb_bodies & scene.obstacle_bodies
    # the sidewalk's top is where the physics has it: a ray down onto it stops 0.12 m up
    x, y = 40.0, BLOCK + t.half_width + 1.0
    hit = world.client.rayTest([x, y, 5.0], [x, y, -1.0])[0]
    assert hit[0] in scene.kerb_bodies and hit[3][2] == pytest.approx(KERB_HEIGHT, abs=1e-6)


MID_BLOCK = 20.0  # [m] route station: the camera's view (5..35 m) and the LiDAR's stay on the
#   street from (0, 1) to (1, 1), whose stop line is at 73.5


@pytest.mark.parametrize("offset", [-0.3, 0.0, 0.3])
def test_the_camera_finds_the_ego_lane_not_the_sidewalks(world: World, offset: float) -> None:
    pose_ego(world, 0, MID_BLOCK, offset, 0.0)
    frame = world.rig.capture(["front"], world.t, world.ego.truth())[0].frame
    assert isinstance(frame, CameraFrame)
    detector = LaneDetector(frame.info)
    est = detector.detect(frame)
    truth = lane_truth(world, 0)
    assert est.left is not None and est.right is not None and est.confidence >= 0.8
    assert abs(est.offset - truth.offset) <= 0.2
    # the lines are painted inside the lane (the edge line 0.1 m from the kerb, the yellow
    # pair either side of the centre line): the painted lane is ~0.1 m narrower
    assert abs(est.width - truth.width) <= 0.2
    # no paint in the bird's-eye mask on the sidewalks (0.3 m clear of the kerb lines)
    mask = detector.birdseye_mask(frame) >= 128
    grid = detector.params.grid
    y = grid.col_to_y(np.arange(grid.cols))
    right_kerb = -0.5 * 3.5 - truth.offset
    left_kerb = right_kerb + 2 * 3.5
    sidewalks = (((y < right_kerb - 0.3) & (y > right_kerb - SIDEWALK_WIDTH))
                 | ((y > left_kerb + 0.3) & (y < left_kerb + SIDEWALK_WIDTH)))
    street = (y > right_kerb + 0.3) & (y < left_kerb - 0.3)
    assert mask[:, sidewalks].sum() <= 0.02 * mask[:, street].sum()


@pytest.mark.parametrize("s", [MID_BLOCK, 40.0, 55.0])
def test_the_lidar_sees_kerbs_and_sidewalks_as_ground(world: World, s: float) -> None:
    """Sidewalk returns are 0.12 m up, and no object is found on the street or its sidewalks
    but the stop signs' poles."""
    pose_ego(world, 0, s, 0.0, 0.0)
    truth = world.ego.truth()
    scan = world.rig.capture(["lidar"], world.t, truth)[0].frame
    assert isinstance(scan, LidarScan)
    origin, rotation = vehicle_pose(truth, world.ego.geometry.ride_height)
    points = scan.info.mount.to_vehicle(scan.points) @ rotation.T + origin
    t = TownLayout(world.spec.town)  # type: ignore[arg-type]
    hw = t.half_width
    gap = np.abs(points[:, 1] - BLOCK)
    on_sidewalk = (gap > hw + 0.1) & (gap < hw + SIDEWALK_WIDTH - 0.1) & \
        (points[:, 0] > t.mouth) & (points[:, 0] < BLOCK - t.mouth)
    assert on_sidewalk.sum() > 500
    assert np.median(points[on_sidewalk, 2]) == pytest.approx(KERB_HEIGHT, abs=0.01)
    poles = np.array([p.pole_xy for p in world.scene.stop_signs])
    for d in ObjectDetector(DetectorParams()).detect(scan):
        xy = origin[:2] + rotation[:2, :2] @ np.array([d.x, d.y])
        near_pole = np.min(np.linalg.norm(poles - xy, axis=1)) < 1.0
        on_street_or_sidewalk = street_gap(t, xy[None])[0] < hw + SIDEWALK_WIDTH
        assert near_pole or not on_street_or_sidewalk, d

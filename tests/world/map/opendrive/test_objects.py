"""OpenDRIVE road objects: read (`parse_objects`), laid out as solids (`object_layout`) and
built as static bodies the LiDAR hits and the car collides with (`world.world`)."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from tests.world.map.opendrive.roads import road_xml, write
from world.map.opendrive import OpenDriveError, load_opendrive, object_layout, parse_objects
from world.map.opendrive.object_layout import MAX_PIECE, POLE_RADIUS, layout_objects
from world.spec import EgoSpec, RoadSpec, SceneryObjectSpec, SegmentSpec, WorldSpec
from world.world import World

LINE = '<geometry s="0" x="10" y="5" hdg="0" length="1000"><line/></geometry>'
ARC = '<geometry s="0" x="0" y="0" hdg="0" length="300"><arc curvature="0.005"/></geometry>'


def _file(tmp_path: Path, objects: str, geometry: str = LINE, length: float = 1000.0) -> Path:
    text = road_xml(geometry, length).replace("</lanes>", f"</lanes><objects>{objects}</objects>")
    return write(tmp_path / "objects.xodr", text)


LAMP = ('<object id="1" type="streetLamp" name="lamp" s="100" t="-8" zOffset="0" '
        'height="5" hdg="0"/>')
RAIL = ('<object id="2" type="railing" s="0" t="2" zOffset="0.4" height="0.3" width="0.35" '
        'length="0"><repeat s="0" length="1000" distance="0" tStart="2" tEnd="2" '
        'heightStart="0.3" heightEnd="0.3" zOffsetStart="0.4" zOffsetEnd="0.4" '
        'widthStart="0.35" widthEnd="0.35"/></object>')
POSTS = ('<object id="3" type="pole" s="2" t="-6" height="1.2" width="0.1" length="0.1">'
         '<repeat s="2" length="100" distance="4" tStart="-6" tEnd="-10" heightStart="1.2" '
         'heightEnd="1.2" zOffsetStart="0" zOffsetEnd="0"/></object>')
TREE = ('<object id="4" type="tree" s="50" t="12" height="9" radius="2" hdg="0.3"/>')
MARK = ('<object id="5" type="crosswalk" s="60" t="-2" height="0" length="4" width="7"/>')
SHED = ('<object id="6" type="building" s="200" t="-20" height="3" hdg="0"><outline>'
        '<cornerLocal u="0" v="0" z="0" height="3"/><cornerLocal u="4" v="0" z="0" height="3"/>'
        '<cornerLocal u="4" v="3" z="0" height="3"/><cornerLocal u="0" v="3" z="0" height="3"/>'
        '</outline></object>')


def test_objects_are_read(tmp_path: Path) -> None:
    road = load_opendrive(_file(tmp_path, LAMP + RAIL + POSTS + TREE + MARK + SHED)).roads[0]
    lamp, rail, posts, tree, mark, shed = road.objects
    assert (lamp.type, lamp.s, lamp.t, lamp.height, lamp.length, lamp.radius) == (
        "streetLamp", 100.0, -8.0, 5.0, None, None)
    (rep,) = rail.repeats
    assert (rep.distance, rep.length, rep.t_start, rep.width_start) == (0.0, 1000.0, 2.0, 0.35)
    assert posts.repeats[0].t_end == -10.0
    assert (tree.radius, tree.hdg) == (2.0, 0.3)
    assert mark.height == 0.0
    (outline,) = shed.outlines
    assert not outline.road_frame and len(outline.corners) == 4


def test_layout_places_each_kind(tmp_path: Path) -> None:
    solids = layout_objects(load_opendrive(
        _file(tmp_path, LAMP + RAIL + POSTS + TREE + MARK + SHED)))
    by_type: dict[str, list[SceneryObjectSpec]] = {}
    for s in solids:
        by_type.setdefault(s.type, []).append(s)
    (lamp,) = by_type["streetLamp"]  # a point object: a pole, its base on the ground
    assert lamp.round and lamp.half_extents == (POLE_RADIUS, POLE_RADIUS, 2.5)
    assert lamp.centre == pytest.approx((110.0, -3.0, 2.5))
    rails = by_type["railing"]  # continuous: 50 m boxes along the straight road, end to end
    assert len(rails) == round(1000.0 / MAX_PIECE)
    assert sum(2 * r.half_extents[0] for r in rails) == pytest.approx(1000.0)
    assert all(r.centre[1] == pytest.approx(7.0) and r.centre[2] == pytest.approx(0.55)
               for r in rails)
    posts = by_type["pole"]  # a copy every 4 m for 100 m, t going from -6 to -10
    assert len(posts) == 26
    assert posts[0].centre[:2] == pytest.approx((12.0, -1.0))
    assert posts[-1].centre[:2] == pytest.approx((112.0, -5.0))
    (tree,) = by_type["tree"]
    assert tree.round and tree.half_extents == (2.0, 2.0, 4.5)
    assert "crosswalk" not in by_type  # flat: not built
    (shed,) = by_type["building"]
    assert shed.hull and shed.centre == pytest.approx((212.0, -13.5, 1.5))


def test_continuous_object_follows_a_curve(tmp_path: Path) -> None:
    rail = RAIL.replace('length="1000"', 'length="300"')
    solids = layout_objects(load_opendrive(_file(tmp_path, rail, ARC, 300.0)))
    radius = 1.0 / 0.005 - 2.0  # [m] the railing's, 2 m left of the reference line
    assert len(solids) > 300.0 / MAX_PIECE  # shorter boxes on the bend
    for s in solids:  # each box's middle within the sagitta of the circle
        r = math.hypot(s.centre[0], s.centre[1] - 1.0 / 0.005)
        assert abs(r - radius) <= object_layout.SAGITTA + 1e-6


@pytest.mark.parametrize("xml, problem", [
    ('<objectReference id="9" s="1" t="0"/>', "not supported yet (objectReference)"),
    ('<tunnel id="9" s="1" length="5"/>', "not supported yet (tunnel)"),
    ('<bridge id="9" s="1" length="5"/>', "not supported yet (bridge)"),
    ('<object id="9" s="1" t="0" height="1" pitch="0.1"/>', "not supported yet (object pitch)"),
    ('<object id="9" s="1" t="0" height="1"><markings/></object>',
     "not supported yet (object markings)"),
    ('<object id="9" s="1" t="0" height="-1"/>', "height must be >= 0"),
    ('<object id="9" s="1" t="0" height="1"><outline><cornerLocal u="0" v="0"/></outline>'
     '</object>', "fewer than 3"),
])
def test_what_is_not_built_is_refused(tmp_path: Path, xml: str, problem: str) -> None:
    with pytest.raises(OpenDriveError, match=problem.replace("(", r"\(").replace(")", r"\)")):
        load_opendrive(_file(tmp_path, xml))


def test_object_count_is_bounded(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(parse_objects, "MAX_OBJECTS", 2)
    with pytest.raises(OpenDriveError, match="more than 2 objects"):
        load_opendrive(_file(tmp_path, LAMP * 3))


def test_solid_count_is_bounded_before_any_is_made(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    odr = load_opendrive(_file(tmp_path, POSTS.replace('distance="4"', 'distance="1e-6"')))
    made: list[int] = []
    monkeypatch.setattr(object_layout, "_solid", lambda *a: made.append(1))
    with pytest.raises(OpenDriveError, match="more than 20000"):
        layout_objects(odr)
    assert not made


def test_objects_are_static_bodies_the_rays_hit() -> None:
    road = RoadSpec(segments=(SegmentSpec(length=200.0, curvature=0.0, lanes=1,
                                          oncoming_lanes=0, lane_width=3.5, shoulder=1.0),),
                    speed_limit=20.0)
    pole = SceneryObjectSpec("pole", (60.0, -6.0, 2.5), 0.0, (0.1, 0.1, 2.5), round=True)
    rail = SceneryObjectSpec("railing", (100.0, 4.0, 0.55), 0.0, (50.0, 0.2, 0.15))
    w = World(WorldSpec(road=road, ego=EgoSpec(lane=0, s=10.0, speed=0.0, max_speed=10.0),
                        scenery_objects=(pole, rail)), cameras=False, lidar=False)
    try:
        assert len(w.scene.obstacle_bodies) >= 2
        hits = w.client.rayTestBatch([[60.0, -6.0, 10.0], [100.0, 4.0, 10.0]],
                                     [[60.0, -6.0, -1.0], [100.0, 4.0, -1.0]])
        assert hits[0][0] in w.scene.obstacle_bodies
        assert hits[0][3][2] == pytest.approx(5.0, abs=1e-3)  # the pole's top
        assert hits[1][0] in w.scene.obstacle_bodies
        assert hits[1][3][2] == pytest.approx(0.7, abs=1e-3)  # the rail's top
    finally:
        w.close()

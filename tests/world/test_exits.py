"""Exits: the route leaves its road on the right into a ramp; the road goes on straight as
scenery (its own map, mesh and the traffic's reference line)."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from avsim.scenario.load import ScenarioError, load_scenario
from tests.roads import KPH, SHOULDER, W, arc, seg
from world.hdmap import RoadMap, Side, Zone
from world.map.road import build_road_map
from world.scene.road_mesh import THROUGH_DROP, build_road_surface, build_through_roads
from world.spec import RoadSpec

RAMP_RADIUS = 80.0


def exit_map() -> RoadMap:
    ramp = replace(arc(RAMP_RADIUS, -40.0, lanes=1, oncoming=0), speed_limit=25 * KPH,
                   zone=Zone.RAMP, exit=Side.RIGHT)
    return build_road_map(RoadSpec((seg(200.0), ramp, seg(100.0, lanes=1, oncoming=0)),
                                      90 * KPH, ()))


def test_the_map_records_the_fork_and_the_road_it_leaves() -> None:
    road = exit_map()
    (fork,) = road.exits
    assert fork.s == pytest.approx(200.0)
    assert (fork.x, fork.y, fork.heading) == pytest.approx((200.0, 0.0, 0.0))
    assert fork.section.lanes == 2 and fork.section.oncoming_lanes == 1
    assert road.lanes_at(199.0) == 2 and road.lanes_at(201.0) == 1
    assert float(road.speed_limit_at(201.0)) == pytest.approx(25 * KPH)


def test_traffic_goes_on_straight_the_route_turns_right() -> None:
    road = exit_map()
    s = np.array([100.0, 250.0, 400.0])
    x, y, heading = road.through_line.pose(s, np.full(3, W))  # lane 1 of the road
    np.testing.assert_allclose(x, s)
    np.testing.assert_allclose(y, W)
    np.testing.assert_allclose(heading, 0.0, atol=1e-12)
    xr, yr, _ = road.line.pose(s, np.zeros(3))
    assert xr[0] == pytest.approx(100.0) and yr[0] == pytest.approx(0.0)
    assert yr[1] < -10.0  # 50 m into the 80 m arc to the right


def test_the_through_road_is_drawn_straight_on_below_the_route() -> None:
    road = exit_map()
    through = road.through_road(road.exits[0], 400.0)
    assert through.length == pytest.approx(400.0)
    assert float(through.speed_limit_at(10.0)) == pytest.approx(90 * KPH)
    meshes = build_through_roads(road)
    assert meshes and all(m.name.startswith("through0_") for m in meshes)
    v = np.concatenate([m.vertices for m in meshes])
    route_z = build_road_surface(road)[0].vertices[0, 2]
    np.testing.assert_allclose(v[:, 2], route_z - THROUGH_DROP)
    assert v[:, 0].min() == pytest.approx(200.0) and v[:, 0].max() == pytest.approx(600.0)
    right = -(0.5 * W + SHOULDER)
    assert v[:, 1].min() == pytest.approx(right)
    assert v[:, 1].max() == pytest.approx(right + 3 * W + SHOULDER)
    assert not road.exits or math.isfinite(road.exits[0].heading)


def _scenario(tmp_path: Path, exit_on: int, side: str) -> Path:
    segments = ["{straight: 200}", "{straight: 100, lanes: 1, oncoming_lanes: 0}"]
    segments[exit_on] = segments[exit_on][:-1] + f", exit: {side}}}"
    text = ("format: avsim/1\nname: exit\nduration: 10\nroad:\n  lanes: 2\n"
            "  speed_limit_kph: 50\n  segments:\n" + "".join(f"    - {x}\n" for x in segments)
            + "ego: {s: 10, set_speed_kph: 40}\n")
    path = tmp_path / "exit.yaml"
    path.write_text(text, encoding="utf-8")
    return path


def test_scenarios_with_exits_load_and_bad_ones_say_why(tmp_path: Path) -> None:
    spec = load_scenario(str(_scenario(tmp_path, 1, "right"))).world
    assert spec.road.segments[1].exit is Side.RIGHT
    with pytest.raises(ScenarioError, match=r"road\.segments\.1\.exit: not supported yet"):
        load_scenario(str(_scenario(tmp_path, 1, "left")))
    with pytest.raises(ScenarioError, match=r"road\.segments\.0\.exit: the first segment"):
        load_scenario(str(_scenario(tmp_path, 0, "right")))


def test_traffic_before_the_fork_keeps_the_road_traffic_after_it_the_ramp(
        tmp_path: Path) -> None:
    from world.world import World

    text = ("format: avsim/1\nname: exit\nduration: 10\nroad:\n  lanes: 2\n"
            "  oncoming_lanes: 0\n  speed_limit_kph: 90\n  segments:\n"
            "    - {straight: 200}\n"
            "    - {arc: {radius: 80, angle_deg: -60}, lanes: 1, exit: right}\n"
            "    - {straight: 100, lanes: 1}\n"
            "ego: {s: 10, set_speed_kph: 40}\n"
            "actors:\n"
            "  - {id: through, type: car, lane: 1, s: 150, speed_kph: 72}\n"
            "  - {id: on_ramp, type: car, lane: 0, s: 230, speed_kph: 36}\n")
    path = tmp_path / "exit.yaml"
    path.write_text(text, encoding="utf-8")
    world = World(load_scenario(str(path)).world)
    try:
        for _ in range(5 * 240):  # 5 s: 100 m for the first, 50 m for the second
            world.step()
        p = world.actors.poses
        assert p.centres[0, :2] == pytest.approx([250.0, W], abs=0.05)  # straight on
        assert p.yaws[0] == pytest.approx(0.0, abs=1e-6)
        route_xy = world.road.position(280.0, 0.0)
        assert p.centres[1, :2] == pytest.approx(route_xy, abs=0.05)  # along the ramp
        # the truth stations are the route's: the through car is far off the ramp's lane
        s, _ = world.road.local_coordinates(p.centres[0, :2])
        assert p.stations[0] == pytest.approx(float(s)) and abs(p.offsets[0]) > 5.0
    finally:
        world.close()

"""The grid town's geometry: routes compiled into route roads, approaches, signal plans."""

from __future__ import annotations

import math

import numpy as np
import pytest

from world.hdmap import Control, LightColour, Manoeuvre, Zone
from world.map.road import build_road_map
from world.map.signals import light_colour
from world.map.town import OPPOSITE, TownError, TownLayout, compile_route
from world.spec import TownSpec

M = Manoeuvre


def town(lanes: int = 1, junctions: str = "traffic_lights") -> TownLayout:
    return TownLayout(TownSpec(3, 2, 90.0, lanes, 3.5, 40 / 3.6, junctions))


@pytest.mark.parametrize(
    ("lanes", "start", "manoeuvre", "heading_after"),
    [
        (1, (0, 1, "east"), M.STRAIGHT, "east"),
        (1, (0, 1, "east"), M.RIGHT, "south"),
        (1, (0, 1, "east"), M.LEFT, "north"),
        (2, (0, 1, "east"), M.U_TURN, "west"),
        (2, (1, 0, "north"), M.RIGHT, "east"),
        (1, (3, 2, "west"), M.LEFT, "south"),
    ],
)
def test_turn_ends_in_lane_0_of_the_new_street(lanes, start, manoeuvre, heading_after) -> None:
    layout = town(lanes)
    road = build_road_map(compile_route(layout, start, (manoeuvre,), "ego"))
    j = road.junctions[0]
    nxt = (j.index[0], j.index[1])
    expected = layout.point(nxt, heading_after, layout.mouth, layout.kerb_lane)
    np.testing.assert_allclose(road.position(j.s_exit, 0.0), expected, atol=1e-6)
    heading = {"east": 0.0, "north": 90.0, "west": 180.0, "south": -90.0}[heading_after]
    assert math.remainder(math.degrees(float(road.heading_at(j.s_exit))) - heading, 360) \
        == pytest.approx(0.0, abs=1e-6)
    # the stop line lies across the approach, STOP_SETBACK before the mouth, in lane 0
    entry = layout.point(nxt, start[2], -layout.mouth, layout.kerb_lane)
    np.testing.assert_allclose(road.position(j.s_enter, 0.0), entry, atol=1e-6)
    assert j.s_stop == pytest.approx(j.s_enter - 1.0)
    assert road.cross_section_at(j.s_enter + 0.1).zone is Zone.JUNCTION
    assert road.cross_section_at(j.s_exit + 0.1).zone is Zone.CITY


def test_the_route_starts_past_the_start_mouth_and_ends_at_the_next_stop_line() -> None:
    layout = town()
    spec = compile_route(layout, (0, 0, "east"), (M.STRAIGHT, M.LEFT), "ego")
    road = build_road_map(spec)
    np.testing.assert_allclose(road.position(0.0, 0.0), (layout.mouth, -1.75), atol=1e-9)
    end = layout.point((2, 1), "north", -layout.mouth - 1.0, layout.kerb_lane)
    np.testing.assert_allclose(road.position(road.length, 0.0), end, atol=1e-6)
    assert [j.index for j in road.junctions] == [(1, 0), (2, 0)]
    assert road.lanes_at(road.junctions[1].s_enter + 1.0) == 1  # only lane 0 turns


def test_radii() -> None:
    one, two = town(1), town(2)
    assert one.left_turn_radius == pytest.approx(11.25)
    assert two.left_turn_radius == pytest.approx(18.25)
    assert two.kerb_lane == pytest.approx(5.25) and two.u_turn_allowed
    assert not one.u_turn_allowed


@pytest.mark.parametrize(
    ("start", "route", "key", "problem"),
    [
        ((0, 0, "south"), (), "ego.start", "no street leaves junction (0, 0) heading south"),
        ((5, 0, "east"), (), "ego.start", "no junction (5, 0)"),
        ((0, 0, "east"), (M.RIGHT,), "ego.route.0", "no street leaves it heading south"),
        ((0, 0, "east"), (M.STRAIGHT, M.STRAIGHT, M.STRAIGHT), "ego.route.2",
         "no street leaves it heading east"),
        ((0, 0, "east"), (M.U_TURN,), "ego.route.0", "too narrow"),
    ],
)
def test_impossible_routes_are_refused(start, route, key, problem) -> None:
    with pytest.raises(TownError) as error:
        compile_route(town(), start, route, "ego")
    assert error.value.key == key
    assert problem in error.value.problem


def test_a_block_too_short_is_refused() -> None:
    with pytest.raises(TownError, match=r"town\.block: must be at least 29 m"):
        TownLayout(TownSpec(2, 2, 20.0, 1, 3.5, 10.0, "stop_signs")).check("town")


def test_controls_per_junction_kind() -> None:
    mixed = town(junctions="mixed")
    assert mixed.control((0, 0)) is Control.NONE  # a corner: a bend
    assert mixed.control((1, 0)) is Control.STOP_SIGNS  # T, odd
    assert mixed.control((1, 1)) is Control.TRAFFIC_LIGHTS  # cross, even
    approaches = town(junctions="stop_signs").approaches()
    # 4 x 3 junctions: 4 corners (none), 6 T (3 arms), 2 crossings (4 arms)
    assert len(approaches) == 6 * 3 + 2 * 4
    assert all(a.stop_sign is not None and a.light is None for a in approaches)


def test_crossing_directions_are_never_green_together() -> None:
    layout = town()
    for j in [(1, 1), (2, 1), (1, 0)]:
        ew, ns = layout.signal(j, "east"), layout.signal(j, "north")
        assert layout.signal(j, OPPOSITE["east"]).phase == ew.phase
        seen = set()
        for t in np.arange(0.0, 2 * ew.cycle, 0.1):
            a, b = light_colour(ew, t), light_colour(ns, t)
            seen.add((a, b))
            assert LightColour.RED in (a, b)
        assert (LightColour.RED, LightColour.RED) in seen  # the all-red clearance


def test_light_heads_face_their_approach_from_the_far_right_corner() -> None:
    layout = town()
    head = layout.signal((1, 1), "east").head
    assert head is not None
    hw = layout.half_width
    assert head.x > 90.0 + hw and head.y < 90.0 - hw  # beyond the box, on the right
    assert head.facing == pytest.approx(math.pi)

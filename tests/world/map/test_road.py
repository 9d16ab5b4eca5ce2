"""The route-road map kind (`world.map.road`): what the stack's map gets of a traffic light is
its place, never its signal plan (ground truth stays in the world)."""

from __future__ import annotations

import dataclasses
import inspect

import pytest

from tests.roads import seg
from world import hdmap
from world.hdmap import LightColour, LightHead, TrafficLight
from world.map.road import LIGHT_AHEAD, LIGHT_HEIGHT, build_road_map, light_head
from world.map.signals import light_colour, route_signals
from world.spec import RoadSpec, TrafficLightSpec

KPH = 1 / 3.6
TIMED = TrafficLightSpec(s=120.0, green=20.0, yellow=3.0, red=15.0, phase=7.0)
PLACED = LightHead(130.0, -6.0, 4.0, 3.0)
ROAD = RoadSpec(segments=(seg(300.0),), speed_limit=50 * KPH,
                features=(TIMED, dataclasses.replace(TIMED, s=200.0, head=PLACED)))


def test_a_maps_traffic_light_is_its_place_only() -> None:
    road = build_road_map(ROAD)
    lights = [f for f in road.features if isinstance(f, TrafficLight)]
    assert [f.s for f in lights] == [120.0, 200.0]
    assert {f.name for f in dataclasses.fields(TrafficLight)} == {"s", "head"}
    # the map places a head the spec leaves open, on a pole past the line; a given one stays
    assert lights[0].head == light_head(road, TIMED)
    assert lights[0].head.x == pytest.approx(120.0 + LIGHT_AHEAD)
    assert lights[0].head.z == LIGHT_HEIGHT
    assert lights[1].head == PLACED


def test_no_type_of_the_map_has_a_field_of_signal_timing() -> None:
    timing = {"green", "yellow", "red", "phase", "cycle", "all_red"}
    for name, obj in inspect.getmembers(hdmap, inspect.isclass):
        if dataclasses.is_dataclass(obj):
            fields = {f.name for f in dataclasses.fields(obj)}
            assert not fields & timing, (name, fields & timing)


def test_the_world_keeps_the_signal_plans_with_the_maps_heads() -> None:
    road = build_road_map(ROAD)
    signals = route_signals(ROAD, road)
    assert [(x.s, x.green, x.phase) for x in signals] == [(120.0, 20.0, 7.0), (200.0, 20.0, 7.0)]
    heads = [f.head for f in road.features if isinstance(f, TrafficLight)]
    assert [x.head for x in signals] == heads
    # the plan: 7 s into its cycle at t = 0, green for 13 s more, then 3 s of yellow
    assert light_colour(signals[0], 12.9) is LightColour.GREEN
    assert light_colour(signals[0], 13.1) is LightColour.YELLOW
    assert light_colour(signals[0], 16.1) is LightColour.RED

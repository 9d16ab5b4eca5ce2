"""The scenario type (`avsim.scenario.scenario.Scenario`) and the split of a file into it: the
world's spec has only what a world is built from, the driver's settings configure the
stack, the criteria settings are the registry's, and the seed is the world's."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import yaml

from avsim.criteria.registry import CriteriaSettings
from avsim.scenario.load import load_scenario
from avsim.scenario.scenario import DriverSettings, Scenario
from tests.avsim.texts import MINIMAL
from world import spec

KPH = 1 / 3.6


def fields(cls: type) -> list[str]:
    return [f.name for f in dataclasses.fields(cls)]


def test_the_world_spec_is_what_a_world_is_built_from() -> None:
    assert fields(spec.WorldSpec) == ["road", "ego", "seed", "actors", "sensors", "events",
                                      "town", "scenery_roads", "scenery_objects"]
    # the car (and the state of its automated driving function's switch), not the driver
    assert fields(spec.EgoSpec) == ["lane", "s", "speed", "max_speed", "engaged", "scripted",
                                    "offset"]
    assert not hasattr(spec, "CriteriaSpec") and not hasattr(spec, "ScenarioSpec")
    assert fields(Scenario) == ["name", "description", "situation", "duration", "world",
                                "driver", "criteria", "stack", "story", "grid", "sources"]
    assert fields(DriverSettings) == ["set_speed", "overtake"]


def test_a_file_splits_into_world_driver_and_criteria(tmp_path: Path) -> None:
    data = yaml.safe_load(MINIMAL)
    data.update(seed=7, criteria={"min_gap": 12, "reach_s": 90})
    data["ego"].update(speed_kph=30, max_speed_kph=72, overtake=True)
    path = tmp_path / "split.yaml"
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    loaded = load_scenario(path)
    assert (loaded.name, loaded.duration, loaded.seed, loaded.world.seed) == (
        "minimal", 10.0, 7, 7)
    assert loaded.world.ego == spec.EgoSpec(lane=0, s=10.0, speed=30 * KPH, max_speed=72 * KPH)
    assert loaded.driver == DriverSettings(set_speed=40 * KPH, overtake=True)
    assert loaded.criteria == CriteriaSettings.of({"min_gap": 12, "reach_s": 90})
    assert loaded.criteria.keys() == ("min_gap", "reach_s")
    assert loaded.criteria.get("max_decel") is None


def test_criteria_settings_compare_by_content_and_hash() -> None:
    a = CriteriaSettings.of({"min_gap": "r157", "max_decel": 3.0, "reach_s": None})
    b = CriteriaSettings.of({"max_decel": 3.0, "min_gap": "r157"})
    assert a == b and hash(a) == hash(b)
    assert a.keys() == ("max_decel", "min_gap")  # None: left out


def test_a_town_car_starts_5_m_along_its_route_by_default(tmp_path: Path) -> None:
    text = ("format: avsim/1\nname: town_start\nduration: 10\n"
            "town: {blocks_x: 2, blocks_y: 2, block: 90, speed_limit_kph: 40}\n"
            "ego: {start: [0, 0, east], route: [straight], set_speed_kph: 30}\n")
    path = tmp_path / "town.yaml"
    path.write_text(text, encoding="utf-8")
    loaded = load_scenario(path)
    assert loaded.world.ego.s == 5.0 and loaded.world.town is not None
    assert loaded.driver == DriverSettings(set_speed=30 * KPH)
    path.write_text(text.replace("set_speed_kph: 30}", "set_speed_kph: 30, s: 12}"),
                    encoding="utf-8")
    assert load_scenario(path).world.ego.s == 12

"""The ASAM example files on the motorway roads (`AB_RQ31_*`, with static speed-limit
signs): the Ego starting off its lane's centre (CutIn), an Init teleport relative to an
entity placed after it (SlowPrecedingVehicle), both where esmini places them at t = 0."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from avsim.scenario.errors import ScenarioError
from avsim.scenario.load import load_scenario
from world.frames import MPS_PER_KPH
from world.map.road import build_road_map

ASAM = Path("tests/data/asam_examples/exampleFilesVersion1_3")


def test_cut_in_ego_starts_half_a_metre_left_of_its_lane_centre_as_esmini() -> None:
    scenario = load_scenario(ASAM / "CutIn.xosc")
    ego = scenario.world.ego
    assert ego.offset == pytest.approx(0.5)  # the file's LanePosition offset="0.5"
    road = build_road_map(scenario.world.road)
    _, y = road.lane(ego.lane).position(ego.s, ego.offset)
    # esmini's reference (esmini_ref asam_examples/.../CutIn.csv): Ego at y = -7.95 m
    assert float(y) == pytest.approx(-7.95, abs=1e-6)
    # the motorway's signs post 120 km/h from s = 100 m
    assert [round(p.limit / MPS_PER_KPH) for p in road.speed_limits][:2] == [130, 120]


def test_ego_teleported_relative_to_an_entity_placed_after_it() -> None:
    scenario = load_scenario(ASAM / "SlowPrecedingVehicle.xosc")
    (a1,) = scenario.world.actors
    road = build_road_map(scenario.world.road)
    ego = scenario.world.ego
    ego_xy = road.lane(ego.lane).position(ego.s, ego.offset)
    # esmini places A1 at s = 200 m of lane -3 and the Ego 200 m behind it, at s = 0
    assert ego.lane == a1.lane
    assert float(ego_xy[1]) == pytest.approx(-8.45, abs=1e-3)
    assert 195.0 < a1.s - ego.s < 205.0  # centres: the reference points are 200 m apart


def test_init_positions_relative_to_each_other_are_refused(tmp_path: Path) -> None:
    text = (ASAM / "SlowPrecedingVehicle.xosc").read_text()
    text = text.replace('<LanePosition roadId="1" laneId="-3" s="200.0" />',
                        '<RelativeLanePosition entityRef="Ego" dLane="0" ds="200.0" />')
    shutil.copytree(ASAM / "Databases", tmp_path / "Databases")
    (tmp_path / "loop.xosc").write_text(text)
    with pytest.raises(ScenarioError, match=r"Storyboard\.Init\.Ego: entity A1 has no position"):
        load_scenario(tmp_path / "loop.xosc")

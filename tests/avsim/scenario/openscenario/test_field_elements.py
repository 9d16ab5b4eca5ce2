"""Elements of the NCAP and ASAM example files that stopped them loading: an entity an Init
FollowTrajectoryAction places, a parameter declared as `$name`, an empty ObjectController,
a trailer with no FrontAxle (1.3) and the trailer elements avsim refuses."""

from __future__ import annotations

from pathlib import Path

import pytest

from avsim.scenario.errors import ScenarioError
from avsim.scenario.load import load_scenario
from avsim.scenario.openscenario import load_openscenario
from world.map.road import build_road_map

NCAP = Path("tests/data/ncap")
VRU = NCAP / "OpenSCENARIO/NCAP/AEB_VRU_2023"
ASAM = Path("tests/data/asam_examples")


@pytest.mark.parametrize("name", ["CPNA", "CPNCO"])
def test_an_init_trajectory_places_the_vru_where_esmini_does(name: str) -> None:
    scenario = load_scenario(VRU / f"NCAP_AEB_VRU_{name}_2023.xosc", search_paths=[NCAP])
    (vru,) = [a for a in scenario.world.actors if a.id == "vru"]
    lane = build_road_map(scenario.world.road).lane(vru.lane)
    xy = lane.position(vru.s, vru.offset)
    # esmini's reference (tests/data/esmini_ref/ncap/AEB_VRU_2023/*.csv.gz) at t = 0
    expected = {"CPNA": (100.0, -18.0), "CPNCO": (100.0, -18.0)}[name]
    assert tuple(float(v) for v in xy[:2]) == pytest.approx(expected, abs=1e-6)


def test_a_parameter_declared_with_a_dollar_is_referred_to_by_it() -> None:
    osc = load_openscenario(ASAM / "exampleFilesVersion1_2/FollowTrajectory_Nurbs.xosc")
    (group,) = [g for g, _ in osc.storyboard.story_actions()][:1]
    assert group.actors.entities == ("Ego",)


def test_an_empty_object_controller_is_no_controller() -> None:
    osc = load_openscenario(ASAM / "exampleFilesVersion1_2/SimpleOvertake.xosc")
    vehicle = next(e for e in osc.entities if e.name == "Vehicle 1")
    assert vehicle.controller is None


def test_a_trailer_without_front_axle_and_the_refused_trailer_action() -> None:
    path = ASAM / "exampleFilesVersion1_3/TrailerConnect.xosc"
    with pytest.raises(ScenarioError, match=r"TrailerAction: not supported yet \(TrailerAction\)"):
        load_openscenario(path)

"""An OpenSCENARIO file as the scenario the runner takes: the road from its OpenDRIVE file,
the car under test, the actors with the file's boxes where the Init actions put them, the
sidecar's criteria; what cannot run is refused in one line."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from avsim.scenario.errors import ScenarioError
from avsim.scenario.load import load_scenario
from avsim.scenario.openscenario import load_openscenario
from avsim.scenario.openscenario.actions import (
    ActivateControllerAction,
    AssignControllerAction,
    engages,
)
from avsim.scenario.openscenario.convert import starts_engaged
from avsim.scenario.openscenario.entities import Controller
from avsim.scenario.openscenario.sidecar import MAX_DURATION, bundled_sets
from world.spec import GNSS_PRESETS, ActorType

ALKS = Path(__file__).parents[3] / "data" / "alks" / "logical_scenarios" / "concrete_scenarios"
FILES = sorted(ALKS.glob("alks_scenario_*.xosc"))
CUT_IN = ALKS / "alks_scenario_4_4_1_cut_in_no_collision_template.xosc"
REAR_AXLE = 1.35  # [m] behind avsim's car's centre (vehicle_urdf)
DATA = Path(__file__).parent / "data"


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.stem.removeprefix("alks_scenario_"))
def test_every_alks_file_loads_as_a_scenario(path: Path) -> None:
    scenario = load_scenario(path)
    assert scenario.story is not None and scenario.story.ego == "Ego"
    assert scenario.world.ego.lane == 1  # lane -4: the middle of the three route lanes
    assert scenario.world.ego.speed == pytest.approx(60.0 / 3.6)
    assert scenario.driver.set_speed == scenario.world.ego.speed
    assert scenario.duration == MAX_DURATION
    assert scenario.criteria.get("completes") is False  # the StopTrigger ends the run


def _activate(lateral: bool | None, longitudinal: bool | None) -> ActivateControllerAction:
    return ActivateControllerAction(lateral, longitudinal, None, None)


def _assign(lateral: bool | None, longitudinal: bool | None) -> AssignControllerAction:
    return AssignControllerAction(Controller("c", {}), lateral, longitudinal, None, None)


@pytest.mark.parametrize(("action", "before", "after"), [
    (_activate(True, True), False, True),
    (_activate(None, True), False, True),  # one domain activated: the stack drives
    (_activate(True, False), False, True),
    (_activate(None, None), False, True),  # an activation naming no domain: all of them
    (_activate(False, False), True, False),  # both deactivated: the driver again
    (_activate(False, None), True, False),
    (_assign(None, None), False, False),  # assigned, not activated: as it was
    (_assign(None, None), True, True),
    (_assign(None, True), False, True),
    (_assign(False, None), True, False),
])
def test_the_switch_after_a_controller_action(action: ActivateControllerAction
                                              | AssignControllerAction, before: bool,
                                              after: bool) -> None:
    assert engages(action, before) is after


def test_the_car_under_test_starts_engaged_unless_a_story_activates_it() -> None:
    assert all(not load_scenario(path).world.ego.engaged for path in FILES)  # at 3 s
    assert starts_engaged(load_openscenario(DATA / "everything_1_2.xosc"), "Ego")  # in Init
    assert starts_engaged(load_openscenario(DATA / "minimal.xosc"), "Ego")  # never: at once
    assert load_scenario("cut_in_out").world.ego.engaged  # a YAML file: from the start


def test_the_cut_in_vehicle_starts_where_the_file_puts_it() -> None:
    """RelativeLanePosition from the ego: one lane right (dLane -1: lane -5), ds = 30 m +
    10 s x 20 km/h ahead of the ego's reference point (its rear axle at s = 5), 20 km/h
    slower; a 5 x 2 m car whose box centre is 1.4 m ahead of its rear axle."""
    scenario = load_scenario(CUT_IN)
    (car,) = scenario.world.actors
    assert car.id == "cutinvehicle" and car.type is ActorType.CAR
    assert car.lane == 0 and car.offset == pytest.approx(0.0, abs=1e-9)
    ds = 30.0 + 10.0 * 20.0 / 3.6
    ego_rear = scenario.world.ego.s - REAR_AXLE
    assert ego_rear == pytest.approx(5.0)
    assert car.s == pytest.approx(5.0 + ds + 1.4)
    assert car.speed == pytest.approx(40.0 / 3.6)
    assert car.model is not None
    assert (car.model.length, car.model.width, car.model.height) == (5.0, 2.0, 1.8)


def test_an_18_75_m_truck_is_an_18_75_m_truck() -> None:
    scenario = load_scenario(ALKS / "alks_scenario_4_1_3_side_vehicle_template.xosc")
    (truck,) = scenario.world.actors
    assert truck.type is ActorType.TRUCK and truck.model is not None
    assert truck.model.length == 18.75 and truck.model.width == 2.5


def test_a_parameter_override_moves_the_story() -> None:
    base = load_scenario(CUT_IN)
    moved = load_scenario(CUT_IN, {"parameters.CutInVehicle_InitPosition_RelativeLaneId": 1})
    assert base.world.actors[0].lane == 0 and moved.world.actors[0].lane == 2
    slow = load_scenario(CUT_IN, {"parameters.Ego_InitSpeed_Ve0_kph": 40})
    assert slow.world.ego.speed == pytest.approx(40.0 / 3.6)


def test_the_sidecar_beside_the_file_and_a_named_set(tmp_path: Path) -> None:
    copy = tmp_path / CUT_IN.name
    copy.write_text(CUT_IN.read_text(encoding="utf-8-sig"), encoding="utf-8")
    (tmp_path / (copy.stem + ".criteria.yaml")).write_text(
        "criteria:\n  max_decel: 4.5\nseed: 7\nduration: 40\n", encoding="utf-8")
    scenario = load_scenario(copy, search_paths=(ALKS,))  # its road and catalogs there
    assert scenario.criteria.get("max_decel") == 4.5
    assert scenario.seed == 7 and scenario.duration == 40.0
    assert "r157" in bundled_sets()
    r157 = load_scenario(CUT_IN, criteria_file=Path("r157"))
    assert r157.criteria.get("unavoidable") == "r157"
    assert r157.criteria.get("following_gap") == "r157"


NCAP = Path(__file__).parents[3] / "data" / "ncap"
CCR = NCAP / "OpenSCENARIO" / "NCAP" / "AEB_C2C_2023" / "NCAP_AEB_C2C_CCR_2023.xosc"


def test_the_ncap_set_drives_the_vut_as_the_protocol_does() -> None:
    plain = load_scenario(CCR, search_paths=(NCAP,))
    assert plain.world.ego.engaged  # the file gives it no controller: on from the start
    ncap = load_scenario(CCR, criteria_file=Path("ncap"), search_paths=(NCAP,))
    assert not ncap.world.ego.engaged  # the AEB under test: the driver holds the speed
    assert ncap.world.sensors.gnss == GNSS_PRESETS["rtk"]  # on the test path within cm
    assert ncap.criteria.get("ncap") is not None
    on = load_scenario(CCR, {"function": "file"}, Path("ncap"), (NCAP,))
    assert on.world.ego.engaged
    with pytest.raises(ScenarioError, match="function"):
        load_scenario(CCR, {"function": "maybe"}, Path("ncap"), (NCAP,))


@pytest.mark.parametrize(("overrides", "criteria", "message"), [
    ({"parameters.Ego_InitSpeed_Ve0_kph": 70}, None,
     "parameter Ego_InitSpeed_Ve0_kph = 70: breaks lessOrEqual 60"),
    ({"parameters.CutInVehicle_InitPosition_RelativeLaneId": 0}, None,
     "breaks every constraint group: equalTo -1; equalTo 1"),
    ({"parameters.Nope": 1}, None, "(overrides): unknown parameter Nope; declared:"),
    ({"seed": -1}, None, "(overrides): seed: must be >= 0, got -1 (set by an override)"),
    ({"criteria.min_gapp": 3}, None, "criteria.min_gapp: unknown key (did you mean min_gap?)"),
    ({}, "missing.criteria.yaml", "missing.criteria.yaml: (file): no such file"),
])
def test_bad_input_is_one_line(overrides: dict[str, object], criteria: str | None,
                               message: str) -> None:
    with pytest.raises(ScenarioError) as err:
        load_scenario(CUT_IN, overrides, Path(criteria) if criteria else None)
    assert message in str(err.value)
    assert "\n" not in str(err.value)


def test_an_entity_placed_off_the_road_is_refused(tmp_path: Path) -> None:
    copy = tmp_path / "off.xosc"
    text = CUT_IN.read_text(encoding="utf-8-sig")
    copy.write_text(text.replace('s="5.0"></LanePosition>', 's="20000"></LanePosition>'),
                    encoding="utf-8")
    with pytest.raises(ScenarioError) as err:
        load_scenario(copy, search_paths=(ALKS,))
    assert "Storyboard.Init.Ego" in str(err.value) and "off road 0" in str(err.value)


def test_the_route_of_a_curved_alks_road() -> None:
    """The ego on the 250 m radius road: its start on lane -4 at s = 5 m."""
    path = ALKS / "alks_scenario_4_1_1_free_driving_template.xosc"
    scenario = load_scenario(path)  # the different-curvatures road
    segments = scenario.world.road.segments
    assert len(segments) > 100  # its clothoids as arcs
    assert any(seg.curvature != 0.0 for seg in segments)
    assert math.isclose(sum(seg.length for seg in segments), 5100.0, rel_tol=1e-3)

"""Bad input files: each problem is one `<file>: <key>: <problem>` line."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from avsim.scenario.errors import ScenarioError
from avsim.scenario.openscenario import load_openscenario
from avsim.scenario.openscenario.model import Vehicle
from avsim.scenario.openscenario.xmlread import parse_xml_bytes, read_xml

DATA = Path(__file__).parent / "data"
EVENT = (
    "/OpenSCENARIO/Storyboard/Story[MainStory]/Act[MainAct]/ManeuverGroup[Group]"
    "/Maneuver[Maneuver]/Event[Event]"
)


def message(name: str) -> str:
    path = DATA / name
    with pytest.raises(ScenarioError) as info:
        load_openscenario(path)
    text = str(info.value)
    assert "\n" not in text
    assert text.startswith(f"{path}: ") or text.startswith(f"{path.resolve()}")
    return text[len(str(path)) + 2 :]


def test_minimal_file_loads() -> None:
    scenario = load_openscenario(DATA / "minimal.xosc")
    assert scenario.road_network is None
    assert scenario.parameters == {"Speed": 10.0}
    assert isinstance(scenario.entities[0].object, Vehicle)


def test_malformed_xml_names_the_line() -> None:
    assert message("malformed.xosc") == "line 22: malformed XML: mismatched tag"


def test_unsupported_action_names_its_path() -> None:
    assert message("unsupported_action.xosc") == (
        f"line 49: {EVENT}/Action[MainAction]/PrivateAction/TrailerAction: "
        "not supported yet (TrailerAction)"
    )


def test_missing_catalog_directory_names_it() -> None:
    missing = (DATA / "no_such_catalogs").resolve()
    assert message("missing_catalog_dir.xosc") == (
        "line 9: /OpenSCENARIO/CatalogLocations/VehicleCatalog/Directory: "
        f"catalog directory not found: {missing}"
    )


def test_missing_road_network_names_it() -> None:
    missing = (DATA / "roads" / "nowhere.xodr").resolve()
    assert message("missing_road.xosc") == (
        f"line 8: /OpenSCENARIO/RoadNetwork/LogicFile: road network file not found: {missing}"
    )


def test_unresolved_reference_names_it() -> None:
    assert message("unresolved_param.xosc") == (
        "line 32: /OpenSCENARIO/Storyboard/Init/Actions/Private/PrivateAction/TeleportAction"
        "/Position/WorldPosition: x: unresolved parameter reference $nope"
    )


def test_doctype_is_refused() -> None:
    assert message("doctype.xosc") == "line 2: DOCTYPE declarations are not allowed"


def test_other_versions_are_refused() -> None:
    assert message("version_1_4.xosc") == (
        "line 3: /OpenSCENARIO/FileHeader: not supported yet (OpenSCENARIO 1.4)"
    )


def test_catalog_parameter_assignment() -> None:
    scenario = load_openscenario(DATA / "catalog_params.xosc")
    truck = scenario.entities[0].object
    assert isinstance(truck, Vehicle)
    assert truck.name == "tunable" and truck.category == "truck" and truck.mass == 12000.0
    assert truck.max_speed == 40.0  # ${$Speed * 4} assigned, not the default 30
    assert truck.bbox.length == 12.0 and truck.bbox.center_x == 5.0  # ${$Length / 2 - 1}
    assert truck.properties == {"colour": "red"}


def test_catalog_assignment_breaking_a_constraint() -> None:
    path = DATA / "catalog_bad_assignment.xosc"
    with pytest.raises(ScenarioError) as info:
        load_openscenario(path)
    catalog = (DATA / "catalogs" / "vehicles.xosc").resolve()
    assert str(info.value) == (
        f"{catalog}: line 7: /OpenSCENARIO/Catalog[test_vehicles]/Vehicle[tunable]"
        "/ParameterDeclarations/ParameterDeclaration[MaxSpeed]: "
        "parameter MaxSpeed = -10: breaks greaterThan 0"
    )


def test_bom_and_size_and_element_bounds(tmp_path: Path) -> None:
    doc = b'\xef\xbb\xbf<?xml version="1.0" encoding="utf-8"?>\n<a name="x">\n  <b/>\n</a>\n'
    root = parse_xml_bytes(doc, "mem.xml")
    assert root.tag == "a" and root.children[0].line == 3
    assert root.children[0].key == "line 3: /a[x]/b"
    with pytest.raises(ScenarioError) as info:
        parse_xml_bytes(doc, "mem.xml", max_elements=1)
    assert str(info.value) == "mem.xml: line 3: too many elements (more than 1)"
    big = tmp_path / "big.xml"
    big.write_bytes(doc)
    with pytest.raises(ScenarioError) as info:
        read_xml(big, max_bytes=10)
    assert str(info.value) == f"{big}: (file): over 10 bytes: at most 10"
    with pytest.raises(ScenarioError) as info:
        read_xml(tmp_path / "absent.xosc")
    assert str(info.value) == f"{tmp_path / 'absent.xosc'}: (file): no such file"


def test_entity_declaration_is_refused() -> None:
    doc = b'<?xml version="1.0"?>\n<!DOCTYPE a [<!ENTITY x "y">]>\n<a>&x;</a>\n'
    with pytest.raises(ScenarioError) as info:
        parse_xml_bytes(doc, "mem.xml")
    assert str(info.value) == "mem.xml: line 2: DOCTYPE declarations are not allowed"


def test_undefined_entity_is_malformed() -> None:
    with pytest.raises(ScenarioError) as info:
        parse_xml_bytes(b"<a>\n&x;</a>", "mem.xml")
    assert str(info.value) == "mem.xml: line 2: malformed XML: undefined entity"


def test_unknown_storyboard_element_is_named() -> None:
    assert message("bad_element_ref.xosc") == (
        "line 86: /OpenSCENARIO/Storyboard/StopTrigger/ConditionGroup/Condition[End]"
        "/ByValueCondition/StoryboardElementStateCondition: storyboardElementRef: "
        "no action MainActoin (the actions: MainAction)"
    )


def test_unknown_entity_is_named() -> None:
    assert message("bad_entity_ref.xosc") == (
        "line 28: /OpenSCENARIO/Storyboard/Init/Actions/Private: entityRef: "
        "no entity Egoo (entities: Ego)"
    )


_MINIMAL = (DATA / "minimal.xosc").read_text()
SPEED_ACTION = _MINIMAL[
    _MINIMAL.index("<LongitudinalAction>") : _MINIMAL.index("</LongitudinalAction>") + 21
]
SIM_TIME = '<SimulationTimeCondition value="1" rule="greaterOrEqual"/>'
WORLD = '<WorldPosition x="0" y="0" h="0"/>'


@pytest.mark.parametrize(
    ("old", "new", "name"),
    [
        (
            SPEED_ACTION,
            "<RoutingAction><AcquirePositionAction><Position>" + WORLD + "</Position>"
            "</AcquirePositionAction></RoutingAction>",
            "AcquirePositionAction",
        ),
        (
            SPEED_ACTION,
            "<AppearanceAction><AnimationAction><AnimationType><UserDefinedAnimation "
            'userDefinedAnimationType="wave"/></AnimationType></AnimationAction>'
            "</AppearanceAction>",
            "AnimationAction",
        ),
        (WORLD, "<RoutePosition><RouteRef/><InRoutePosition/></RoutePosition>",
         "RoutePosition"),
        (WORLD, '<GeoPosition latitudeDeg="48" longitudeDeg="11"/>', "GeoPosition"),
        (
            SIM_TIME,
            '<UserDefinedValueCondition name="u" value="1" rule="lessThan"/>',
            "UserDefinedValueCondition",
        ),
        (
            "<Private entityRef",
            "<GlobalAction><InfrastructureAction/></GlobalAction><Private entityRef",
            "InfrastructureAction",
        ),
        (
            "<RoadNetwork>",
            "<RoadNetwork><TrafficSignals><TrafficSignalController name='c'/></TrafficSignals>",
            "TrafficSignalController",
        ),
    ],
)
def test_unsupported_elements_are_named(tmp_path: Path, old: str, new: str, name: str) -> None:
    text = _MINIMAL
    assert old in text
    path = tmp_path / "variant.xosc"
    path.write_text(text.replace(old, new, 1))
    with pytest.raises(ScenarioError) as info:
        load_openscenario(path)
    assert str(info.value).startswith(f"{path}: line ")
    assert re.search(rf"/{name}(\[\w+\])?: not supported yet \({name}\)$", str(info.value))


def test_an_override_of_no_control_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "empty_override.xosc"
    path.write_text(_MINIMAL.replace(
        SPEED_ACTION, "<ControllerAction><OverrideControllerValueAction/></ControllerAction>",
        1))
    with pytest.raises(ScenarioError, match="OverrideControllerValueAction: overrides no "
                                            r"control \(Throttle, Brake"):
        load_openscenario(path)

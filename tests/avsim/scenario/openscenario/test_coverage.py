"""The coverage table in docs/openscenario.md is the reader's registry (`coverage.py`), and
the registry tells the truth: every element it marks `not yet` is refused at load with the
one-line error naming it, and every element the reader's tables read is one of the 1.3
schema's."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from avsim.scenario.errors import ScenarioError
from avsim.scenario.openscenario import coverage
from avsim.scenario.openscenario.parse import load_openscenario

REPO = Path(__file__).resolve().parents[4]
DOCS = REPO / "docs" / "openscenario.md"
MINIMAL = (Path(__file__).parent / "data" / "minimal.xosc").read_text()
BLOCK = re.compile(r"<!-- coverage:begin[^\n]*-->\n(.*?)<!-- coverage:end -->", re.DOTALL)

EVENT_ACTION = re.compile(r"<PrivateAction>\s*<LongitudinalAction>.*?</LongitudinalAction>"
                          r"\s*</PrivateAction>", re.DOTALL)
EVENT_CONDITION = re.compile(r"<ByValueCondition>\s*<SimulationTimeCondition value=\"1\""
                             r"[^>]*/>\s*</ByValueCondition>", re.DOTALL)
VEHICLE = re.compile(r"<Vehicle .*?</Vehicle>", re.DOTALL)
TRAJECTORY = ('<RoutingAction><FollowTrajectoryAction><TrajectoryRef>'
              '<Trajectory name="T" closed="false"><Shape><{0}/></Shape></Trajectory>'
              '</TrajectoryRef><TimeReference><None/></TimeReference>'
              '<TrajectoryFollowingMode followingMode="position"/>'
              '</FollowTrajectoryAction></RoutingAction>')
WRAPPED = {"LongitudinalAction", "LateralAction", "RoutingAction", "ControllerAction",
           "AppearanceAction", "TrailerAction"}


def _probe(holder: str, element: str) -> str:
    """The minimal file with `element` where its `holder` holds it."""
    if holder == "Action":
        return EVENT_ACTION.sub(f"<{element}/>", MINIMAL, count=1)
    if holder in WRAPPED:
        body = f"<{holder}><{element}/></{holder}>"
    elif holder == "Shape":
        body = TRAJECTORY.format(element)
    elif holder == "GlobalAction":
        return EVENT_ACTION.sub(f"<GlobalAction><{element}/></GlobalAction>", MINIMAL, count=1)
    elif holder == "ByValueCondition":
        return EVENT_CONDITION.sub(f"<ByValueCondition><{element}/></ByValueCondition>",
                                   MINIMAL, count=1)
    elif holder == "EntityCondition":
        return EVENT_CONDITION.sub(
            '<ByEntityCondition><TriggeringEntities triggeringEntitiesRule="any">'
            '<EntityRef entityRef="Ego"/></TriggeringEntities>'
            f"<EntityCondition><{element}/></EntityCondition></ByEntityCondition>",
            MINIMAL, count=1)
    elif holder == "Position":
        return MINIMAL.replace('<WorldPosition x="0" y="0" h="0"/>', f"<{element}/>", 1)
    elif holder == "EntityObject":
        return VEHICLE.sub(f'<{element} name="x"/>', MINIMAL, count=1)
    else:
        body = f"<{element}/>"
    return EVENT_ACTION.sub(f"<PrivateAction>{body}</PrivateAction>", MINIMAL, count=1)


# distribution kinds are in distribution files: `test_distribution.py` refuses those
PROBED = [(r.holder, r.element) for r in coverage.rows()
          if r.status == "not yet" and "Distribution" not in r.holder]


def test_the_docs_table_is_the_registry() -> None:
    found = BLOCK.search(DOCS.read_text())
    assert found is not None, "docs/openscenario.md has no coverage block"
    expected = coverage.markdown()
    assert found.group(1) == expected, (
        "docs/openscenario.md's coverage table differs from the registry; it should read:\n"
        + expected)


def test_every_element_read_is_named_by_the_schema() -> None:
    named = {e for group in coverage.GROUPS for e in group.elements}
    assert coverage.read_elements() <= named, (
        coverage.read_elements() - named)


def test_every_partly_note_is_of_an_element_read() -> None:
    read = {f"{g.holder}.{e}" for g in coverage.GROUPS for e in g.elements if e in g.read}
    assert set(coverage.PARTLY) <= read


def test_the_registry_reads_what_the_reader_reads() -> None:
    rows = {(r.holder, r.element): r.status for r in coverage.rows()}
    assert rows[("LongitudinalAction", "SpeedAction")] == "yes"
    assert rows[("RoutingAction", "AssignRouteAction")] == "not yet"
    assert rows[("StochasticDistribution", "UserDefinedDistribution")] == "not yet"
    assert rows[("DeterministicSingleParameterDistribution", "DistributionRange")] == "yes"


def test_the_probe_of_a_supported_element_loads(tmp_path: Path) -> None:
    """The probes are sound: the same file with a supported element in the slot loads."""
    path = tmp_path / "probe.xosc"
    path.write_text(_probe("Position", "WorldPosition").replace(
        "<WorldPosition/>", '<WorldPosition x="0" y="0" h="0"/>'))
    load_openscenario(path)


@pytest.mark.parametrize(("holder", "element"), PROBED, ids=[f"{h}.{e}" for h, e in PROBED])
def test_an_element_not_yet_supported_is_refused_in_one_line(
        tmp_path: Path, holder: str, element: str) -> None:
    path = tmp_path / "probe.xosc"
    text = _probe(holder, element)
    assert f"<{element}" in text
    path.write_text(text)
    with pytest.raises(ScenarioError) as info:
        load_openscenario(path)
    message = str(info.value)
    assert "\n" not in message
    # the element, or the holder that is itself not read yet (AppearanceAction, ...)
    assert re.search(rf"not supported yet \(({element}|{holder})\)$", message), message

"""The Euro NCAP scorecard: built from runs' `ncap` verdicts, and end to end through
`avsim suite DIR --criteria ncap` on a small CCRs-like OpenSCENARIO file of our own."""

from __future__ import annotations

import shutil
import xml.etree.ElementTree as ET
from pathlib import Path

from click.testing import CliRunner

from avsim.batch.jobs import RunJob, RunOutcome, Status
from avsim.cli import main
from avsim.report.ncap import rows, scorecard_markdown, totals

ROAD = (Path(__file__).parents[2] / "data" / "alks" / "logical_scenarios"
        / "concrete_scenarios" / "road_networks" / "alks_road_straight.xodr")

VEHICLE = """<Vehicle name="{name}" vehicleCategory="car">
        <BoundingBox><Center x="1.4" y="0" z="0.75"/>
          <Dimensions width="1.8" length="4.4" height="1.5"/></BoundingBox>
        <Performance maxSpeed="50" maxDeceleration="10" maxAcceleration="4"/>
        <Axles>
          <FrontAxle maxSteering="0.5" wheelDiameter="0.6" trackWidth="1.6" positionX="2.7"
                     positionZ="0.3"/>
          <RearAxle maxSteering="0" wheelDiameter="0.6" trackWidth="1.6" positionX="0"
                    positionZ="0.3"/>
        </Axles><Properties/></Vehicle>"""

# Ego at the test speed on lane -4 towards a stationary car 50 m ahead; the run ends at 10 s
CCRS = f"""<?xml version="1.0" encoding="utf-8"?>
<OpenSCENARIO>
  <FileHeader revMajor="1" revMinor="3" date="2024-01-01T00:00:00" description="CCRs-like"
              author="avsim tests"/>
  <ParameterDeclarations>
    <ParameterDeclaration name="Scenario_ID" parameterType="string" value="CCRs"/>
    <ParameterDeclaration name="Ego_speed_kph" parameterType="double" value="50"/>
    <ParameterDeclaration name="Overlap" parameterType="double" value="100"/>
    <ParameterDeclaration name="GVT_init_speed_kph" parameterType="double" value="0"/>
  </ParameterDeclarations>
  <CatalogLocations/>
  <RoadNetwork><LogicFile filepath="road.xodr"/></RoadNetwork>
  <Entities>
    <ScenarioObject name="Ego">{VEHICLE.format(name="vut")}</ScenarioObject>
    <ScenarioObject name="GVT">{VEHICLE.format(name="gvt")}</ScenarioObject>
  </Entities>
  <Storyboard>
    <Init><Actions>
      <Private entityRef="Ego">
        <PrivateAction><TeleportAction><Position>
          <LanePosition roadId="0" laneId="-4" offset="0.0" s="20.0"/>
        </Position></TeleportAction></PrivateAction>
        <PrivateAction><LongitudinalAction><SpeedAction>
          <SpeedActionDynamics dynamicsShape="step" dynamicsDimension="time" value="0"/>
          <SpeedActionTarget><AbsoluteTargetSpeed value="${{$Ego_speed_kph / 3.6}}"/>
          </SpeedActionTarget>
        </SpeedAction></LongitudinalAction></PrivateAction>
      </Private>
      <Private entityRef="GVT">
        <PrivateAction><TeleportAction><Position>
          <LanePosition roadId="0" laneId="-4" offset="0.0" s="75.0"/>
        </Position></TeleportAction></PrivateAction>
      </Private>
    </Actions></Init>
    <StopTrigger><ConditionGroup>
      <Condition name="end" delay="0" conditionEdge="none"><ByValueCondition>
        <SimulationTimeCondition value="10" rule="greaterOrEqual"/>
      </ByValueCondition></Condition>
    </ConditionGroup></StopTrigger>
  </Storyboard>
</OpenSCENARIO>
"""


def outcome(name: str, details: dict[str, object]) -> RunOutcome:
    job = RunJob(name, f"{name}.xosc", Path("out"), {}, "none")
    criterion = {"name": "ncap", "passed": bool(details.get("avoided")), "value": 0.0,
                 "threshold": 0.0, "unit": "km/h", "details": details}
    return RunOutcome(job, Status.PASSED, {"criteria": [criterion], "metrics": {}})


def test_the_scorecard_sums_the_computed_points_per_protocol() -> None:
    runs = [
        outcome("a", {"protocol": "AEB C2C 2023", "scenario_id": "CCRb", "avoided": True,
                      "points": 1.0, "max_points": 1.0}),
        outcome("b", {"protocol": "AEB C2C 2023", "scenario_id": "CCRs", "avoided": False,
                      "impact_speed_kph": 20.0, "points": 0.5 / 6, "max_points": 1 / 6}),
        outcome("c", {"protocol": "AEB C2C 2023", "scenario_id": "CCRm", "avoided": True,
                      "points": None, "max_points": 1 / 6, "points_note": "a chart"}),
        outcome("d", {"protocol": "AEB VRU 2023", "scenario_id": "CPNA-25", "avoided": True,
                      "points": None, "max_points": None}),
    ]
    found = rows(runs)
    c2c = [r for r in found if r.protocol == "AEB C2C 2023"]
    points, most, missing = totals(c2c)
    assert (round(points, 6), round(most, 6), missing) == (round(1 + 0.5 / 6, 6),
                                                           round(1 + 1 / 6, 6), 1)
    text = "\n".join(scorecard_markdown(runs))
    assert "### AEB C2C 2023" in text and "### AEB VRU 2023" in text
    assert "**AEB C2C 2023: 1.083 of 1.167 points** over 2 scored test run(s); 1 not " \
           "computed" in text
    assert "**AEB VRU 2023: 0 of 0 points** over 0 scored test run(s); 1 not computed" in text


def test_no_ncap_verdict_no_scorecard() -> None:
    job = RunJob("x", "x.yaml", Path("out"), {}, "none")
    plain = RunOutcome(job, Status.PASSED, {"criteria": [{"name": "no_collision"}],
                                            "metrics": {}})
    assert scorecard_markdown([plain]) == []


def test_a_suite_with_criteria_ncap_writes_the_scorecard(tmp_path: Path) -> None:
    folder = tmp_path / "ncap"
    folder.mkdir()
    shutil.copy(ROAD, folder / "road.xodr")
    (folder / "ccrs_50.xosc").write_text(CCRS, encoding="utf-8")
    out = tmp_path / "out"
    result = CliRunner().invoke(main, ["suite", str(folder), "--criteria", "ncap",
                                       "--profile", "none", "--jobs", "1",
                                       "--no-snapshots", "--out", str(out)])
    summary = (out / "summary.md").read_text(encoding="utf-8")
    assert "## Euro NCAP scorecard" in summary, result.output
    row = next(line for line in summary.splitlines() if line.startswith("| ccrs_50 |"))
    cells = [c.strip() for c in row.strip("|").split("|")]
    assert cells[1:5] == ["CCRs", "50", "0", "100 %"]
    avoided = cells[5] == "yes"
    # avoided: the 50 km/h point is green, the whole of its share (2/6 at 100 %)
    assert cells[8:11] == (["green", "0.333", "0.333"] if avoided else cells[8:11])
    if not avoided:  # a contact: its impact speed and reduction are there, its colour too
        assert cells[6] != "—" and cells[7] != "—" and cells[8] in {
            "green", "yellow", "orange", "brown", "red"}
    suites = ET.parse(out / "junit.xml").getroot()
    case = next(c for c in suites.iter("testcase") if c.get("name") == "ncap")
    facts = {p.get("name"): p.get("value") for p in case.iter("property")}
    assert facts["ncap.test"] == "CCRs" and facts["ncap.protocol"] == "AEB C2C 2023"

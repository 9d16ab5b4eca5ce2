"""An OpenSCENARIO run's storyboard state in its outputs: the ALKS free-driving file with an
environment set in Init and two variables set by its story (one through the other's
condition), played 2 s on the map (no sensors): the result, its JSON and the recording list
every change at its time."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rerun.chunk import RrdReader

from avsim.record import blueprint as bp
from avsim.run.result import result_json
from avsim.run.runner import Runner, RunResult
from avsim.scenario.load import load_scenario
from avsim.scenario.openscenario.to_yaml import convert_xosc

ALKS = Path(__file__).parents[2] / "data" / "alks" / "logical_scenarios" / "concrete_scenarios"
FREE = ALKS / "alks_scenario_4_1_1_free_driving_template.xosc"
ENVIRONMENT = """<GlobalAction><EnvironmentAction><Environment name="Dusk">
  <TimeOfDay animation="true" dateTime="2020-02-21T18:30:00"/>
  <Weather fractionalCloudCover="threeOktas"><Fog visualRange="250"/>
    <Precipitation precipitationType="rain" precipitationIntensity="2.5"/></Weather>
  <RoadCondition frictionScaleFactor="0.7"/>
</Environment></EnvironmentAction></GlobalAction>"""
VARIABLES = ('<VariableDeclarations>'
             '<VariableDeclaration name="marked" variableType="boolean" value="false"/>'
             '<VariableDeclaration name="seen" variableType="int" value="0"/>'
             '</VariableDeclarations>')


def event(name: str, action: str, condition: str) -> str:
    return (f'<Event name="{name}" priority="parallel"><Action name="{name}Action">'
            f'<GlobalAction>{action}</GlobalAction></Action><StartTrigger><ConditionGroup>'
            f'<Condition name="{name}Condition" delay="0" conditionEdge="none">'
            f'<ByValueCondition>{condition}</ByValueCondition></Condition></ConditionGroup>'
            '</StartTrigger></Event>')


MARK = event("Mark", '<VariableAction variableRef="marked"><SetAction value="true"/>'
             '</VariableAction>', '<SimulationTimeCondition value="1.0" rule="greaterOrEqual"/>')
SEEN = event("Seen", '<VariableAction variableRef="seen"><ModifyAction><Rule>'
             '<AddValue value="2"/></Rule></ModifyAction></VariableAction>',
             '<VariableCondition variableRef="marked" rule="equalTo" value="true"/>')


def scenario_file(tmp_path: Path) -> Path:
    text = FREE.read_text(encoding="utf-8-sig")
    swaps = [
        ('revMinor="1"', 'revMinor="2"'),
        ("</ParameterDeclarations>", "</ParameterDeclarations>" + VARIABLES),
        ('<Actions>\n        <Private entityRef="Ego">',
         '<Actions>' + ENVIRONMENT + '<Private entityRef="Ego">'),
        ("</Event>\n          </Maneuver>", "</Event>" + MARK + SEEN + "</Maneuver>"),
        ('value="${5000.0 / ($Ego_InitSpeed_Ve0_kph / 3.6)}"', 'value="2.0"'),
    ]
    for old, new in swaps:
        assert text.count(old) == 1, old
        text = text.replace(old, new)
    path = tmp_path / "free_driving_state.xosc"
    path.write_text(text)
    return path


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> tuple[RunResult, Path, Path]:
    tmp = tmp_path_factory.mktemp("story_state")
    path = scenario_file(tmp)
    recording = tmp / "run.rrd"
    scenario = load_scenario(path, search_paths=[ALKS])
    return Runner(scenario, recording, profile=None).run(), path, recording


def test_the_result_lists_every_change_at_its_time(run: tuple[RunResult, Path, Path]) -> None:
    result, path, recording = run
    changes = [(c.t, c.kind, c.name, c.value) for c in result.storyboard_state]
    assert changes[0] == (0.0, "environment", "Dusk", None)
    assert changes[1][1:] == ("variable", "marked", True)
    assert changes[1][0] == pytest.approx(1.0, abs=0.05)  # the first check at 1 s or after
    assert changes[2] == (changes[1][0], "variable", "seen", 2)  # in the same check
    assert len(changes) == 3
    payload = result_json(result, path, recording, "none")
    entries: Any = payload["storyboard_state"]
    env = entries[0]["value"]
    assert env["time_of_day"]["date_time"] == "2020-02-21T18:30:00"
    assert env["weather"]["fog"]["visual_range"] == 250.0
    assert env["road_condition"]["friction_scale_factor"] == 0.7
    assert entries[2] == {"t": round(changes[2][0], 4), "kind": "variable", "name": "seen",
                          "value": 2}


def test_the_recording_has_an_event_line_for_each(run: tuple[RunResult, Path, Path]) -> None:
    result, _, recording = run
    chunks = RrdReader(recording).store().stream().filter(
        content=bp.EVENTS, components="TextLog:text").to_chunks()
    batches = [c.to_record_batch() for c in chunks]
    times = [int(t) for b in batches for t in b.column(bp.TIMELINE).to_numpy().astype(np.int64)]
    texts = [v[0] for b in batches for v in b.column("TextLog:text").to_pylist()]
    lines = {text: t for t, text in zip(times, texts, strict=True)
             if text.startswith("storyboard: ")}
    assert lines["storyboard: environment Dusk: time of day 2020-02-21T18:30:00, animated, "
                 "fog 250 m, precipitation rain, friction x0.7 (not applied)"] == 0
    marked = result.storyboard_state[1].t
    assert lines["storyboard: variable marked = true"] == round(1e9 * marked)
    assert lines["storyboard: variable seen = 2"] == round(1e9 * marked)


def test_convert_lists_the_global_actions_as_misfits(tmp_path: Path) -> None:
    conversion = convert_xosc(scenario_file(tmp_path), search_paths=[ALKS])
    assert "the Init's EnvironmentAction (no YAML counterpart)" in conversion.misfits
    assert "action MarkAction: VariableAction (no YAML counterpart)" in conversion.misfits

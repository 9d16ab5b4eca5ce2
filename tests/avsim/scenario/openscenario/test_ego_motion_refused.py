"""The motion actions that cannot apply to the car under test are refused at load, one
line at the action, when a story gives them to the ego."""

from __future__ import annotations

from pathlib import Path

import pytest

from avsim.scenario.errors import ScenarioError
from avsim.scenario.load import load_scenario
from tests.avsim.run.storyboard.test_motion_runs import scenario_file


def test_the_file_with_its_actors_loads(tmp_path: Path) -> None:
    scenario = load_scenario(scenario_file(tmp_path))
    assert scenario.story is not None


@pytest.mark.parametrize(("actor", "action"), [
    ("Sync", "SynchronizeAction"), ("Profile", "SpeedProfileAction"),
    ("Lateral", "LateralDistanceAction"), ("Jumper", "TeleportAction"),
])
def test_a_motion_action_on_the_ego_is_refused(tmp_path: Path, actor: str,
                                               action: str) -> None:
    path = scenario_file(tmp_path)
    text = path.read_text()
    actors = '<Actors selectTriggeringEntities="false"><EntityRef entityRef="{}"/>'
    text = text.replace(actors.format(actor), actors.format("Ego"))
    text = text.replace('entityRef="Ego" distance="4"', 'entityRef="Master" distance="4"')
    path.write_text(text)
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    assert str(info.value) == (
        f"{path}: Storyboard.Action[{actor}Action]: not supported on the car under test "
        f"({action}: avsim's stack drives it)")

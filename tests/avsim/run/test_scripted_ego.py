"""`--ego scripted`: the file's own actions move the car under test (a kinematic body,
`world.ego.scripted`), no stack drives it; with the stack a motion action on it that is not
its driver's input is refused at load, never mid-run."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner

from avsim.cli import main
from avsim.run.runner import Runner
from avsim.scenario.errors import ScenarioError
from avsim.scenario.load import load_scenario

ALKS = Path(__file__).resolve().parents[2] / "data" / "alks" / "logical_scenarios" \
    / "concrete_scenarios"
CUT_IN = ALKS / "alks_scenario_4_4_1_cut_in_no_collision_template.xosc"
ACTIVATE = """<ControllerAction>
                    <ActivateControllerAction lateral="true" longitudinal="true" />
                  </ControllerAction>"""
SLOW_DOWN = """<LongitudinalAction>
                    <SpeedAction>
                      <SpeedActionDynamics dynamicsShape="linear" value="2.0"
                                           dynamicsDimension="rate" />
                      <SpeedActionTarget><AbsoluteTargetSpeed value="10.0" /></SpeedActionTarget>
                    </SpeedAction>
                  </LongitudinalAction>"""


def _ego_slows_down(tmp: Path) -> Path:
    """The cut-in file whose Ego, at 3 s, brakes at 2 m/s^2 to 10 m/s instead of
    activating its controller (beside the original: the same catalogs and road)."""
    text = CUT_IN.read_text()
    assert ACTIVATE in text
    path = tmp / "ego_slows_down.xosc"
    path.write_text(text.replace(ACTIVATE, SLOW_DOWN))
    return path


OFFSET = """<LateralAction>
                    <LaneOffsetAction continuous="false">
                      <LaneOffsetActionDynamics dynamicsShape="linear" maxLateralAcc="0.5" />
                      <LaneOffsetTarget><AbsoluteTargetLaneOffset value="0.5" /></LaneOffsetTarget>
                    </LaneOffsetAction>
                  </LateralAction>"""


def test_a_lane_offset_on_the_stack_s_ego_is_refused_at_load(tmp_path: Path) -> None:
    path = tmp_path / "ego_offset.xosc"
    path.write_text(CUT_IN.read_text().replace(ACTIVATE, OFFSET))
    with pytest.raises(ScenarioError) as info:
        load_scenario(path, search_paths=[ALKS])
    assert "LaneOffsetAction on the car under test: not supported" in str(info.value)
    assert "ActivateALKSControllerAction" in str(info.value)


def test_a_speed_action_on_the_stack_s_ego_loads_as_its_driver_s_set_speed(
        tmp_path: Path) -> None:
    scenario = load_scenario(_ego_slows_down(tmp_path), search_paths=[ALKS])
    assert scenario.story is not None and not scenario.world.ego.scripted


def test_a_scripted_ego_plays_its_speed_action(tmp_path: Path) -> None:
    path = _ego_slows_down(tmp_path)
    scenario = load_scenario(path, {"duration": 12.0}, search_paths=[ALKS],
                             scripted_ego=True)
    assert scenario.world.ego.scripted
    runner = Runner(scenario, profile=None)
    result = runner.run()
    assert result.error is None
    t, speed = result.log.array("t"), result.log.array("speed")
    start = scenario.world.ego.speed
    assert start > 15.0
    assert speed[t < 2.9] == pytest.approx(start, abs=1e-6)  # Init speed held
    assert speed[-1] == pytest.approx(10.0, abs=1e-6)  # the action's target reached
    braking = (t > 3.2) & (speed > 10.5)
    assert braking.any()
    rate = -((speed[1:] - speed[:-1]) / (t[1:] - t[:-1]))[braking[1:]]
    assert rate == pytest.approx(2.0, abs=0.05)  # at the action's rate


def test_run_ego_scripted_says_so_and_plays_the_cut_in(tmp_path: Path) -> None:
    """The scripted cut-in as esmini plays it without controllers: the Ego keeps its
    lane and speed and the cut-in vehicle hits it (esmini: contact at 14.475 s)."""
    out = tmp_path / "run.json"
    res = CliRunner().invoke(main, [
        "run", str(CUT_IN), "--ego", "scripted", "--json", str(out),
        "--out", str(tmp_path / "run.rrd"), "--no-progress"])
    assert res.exit_code == 1, res.output  # the collision fails the run
    payload = json.loads(out.read_text())
    assert payload["ego"] == "scripted"
    assert payload["profile"] == "none"
    hit = [i for i in payload["infractions"] if i["kind"] == "no_collision"]
    assert hit and hit[0]["t"] == pytest.approx(14.475, abs=0.1)


def test_ego_scripted_is_refused_for_a_yaml_scenario() -> None:
    with pytest.raises(ScenarioError) as info:
        load_scenario("lane_change", scripted_ego=True)
    assert "--ego scripted is for OpenSCENARIO files" in str(info.value)

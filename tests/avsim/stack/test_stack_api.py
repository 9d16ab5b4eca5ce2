"""The public stack API: a choice of stack names factories that are found before anything
runs (bad ones are refused in one line), a replaced stage or a whole stack of one's own
drives the car through the same loop, and the result names the stack."""

from __future__ import annotations

import importlib.metadata
import json
import math
from pathlib import Path
from types import SimpleNamespace
from typing import Any, cast

import numpy as np
import pytest
from click.testing import CliRunner

from avsim.cli import main
from avsim.run.runner import MAX_CHANNELS, Runner, RunResult, stack_channels
from avsim.run.stack import ComposedStack
from avsim.run.unbuilt import build_runner
from avsim.run.verdict import RunVerdict
from avsim.scenario.load import ScenarioError, load_scenario
from avsim.stack import (
    API_VERSION,
    GROUP,
    Indicator,
    Plan,
    StackChoice,
    StackChoiceError,
    by_pedals,
    drive_by_wire,
)
from avsim.stack.choice import resolve, version_of
from control.vehicle_controller import indicator
from perception.perception import Perception
from tests.avsim.stack import user_stacks
from tests.roads import make_map, seg
from vehicle_urdf import read_geometry
from world.ego.body import vehicle_info
from world.frames import GnssFix, SensorKind, SensorSpec

USER = "tests.avsim.stack.user_stacks"
STRAIGHT = """\
format: avsim/1
name: straight
duration: 2
road:
  speed_limit_kph: 50
  segments:
    - straight: 300
ego: {s: 10, speed_kph: 30, set_speed_kph: 30}
"""


@pytest.fixture
def straight(tmp_path: Path) -> Path:
    path = tmp_path / "straight.yaml"
    path.write_text(STRAIGHT, encoding="utf-8")
    return path


def run(path: Path, **stack: str) -> tuple[Runner, RunVerdict]:
    overrides: dict[str, object] = {f"stack.{k}": v for k, v in stack.items()}
    runner = Runner(load_scenario(path, overrides), None, profile=None)
    return runner, runner.run().verdict


# ---- choosing -------------------------------------------------------------------------------


@pytest.mark.parametrize(("choice", "key", "problem"), [
    (dict(stack="not a factory"), "stack", "is not a factory"),
    (dict(planner="a:b:c"), "planner", "is not a factory"),
    (dict(stack=f"{USER}:cruise", planner=f"{USER}:counting_planner"), "stack",
     "not both"),
])
def test_a_malformed_choice_is_refused_by_its_key(choice: dict[str, Any], key: str,
                                                   problem: str) -> None:
    with pytest.raises(StackChoiceError) as err:
        StackChoice(**choice)
    assert err.value.key == key and problem in err.value.problem


def test_the_bundled_choice_is_named_avsim() -> None:
    assert StackChoice().bundled and StackChoice("avsim").bundled
    assert StackChoice(planner=f"{USER}:counting_planner").label() == \
        f"planner {USER}:counting_planner"
    assert StackChoice(f"{USER}:cruise").whole


@pytest.mark.parametrize(("spec", "problem"), [
    ("no_such_package.stacks:make", "cannot import no_such_package.stacks"),
    (f"{USER}:nowhere", "has no nowhere"),
    (f"{USER}:__version__", "is not callable"),
    ("no-such-installed-stack", "no installed stack 'no-such-installed-stack'"),
])
def test_a_factory_that_cannot_be_found_is_refused_in_one_line(spec: str,
                                                               problem: str) -> None:
    with pytest.raises(StackChoiceError) as err:
        resolve("planner", spec)
    assert problem in str(err.value) and "\n" not in str(err.value)


def test_an_installed_stack_is_found_by_its_entry_point_name(
        straight: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """`pip install my-stack` registers `my-stack = "...:cruise"` in the group avsim.stacks;
    `--stack my-stack` then runs it (the group's listing stubbed here)."""
    point = importlib.metadata.EntryPoint("my-stack", f"{USER}:cruise", GROUP)
    real = importlib.metadata.entry_points

    def entry_points(**select: str) -> object:
        if select.get("group") == GROUP:
            return importlib.metadata.EntryPoints([point])
        return real(**select)

    monkeypatch.setattr(importlib.metadata, "entry_points", entry_points)
    assert resolve("stack", "my-stack") is user_stacks.cruise
    assert version_of("my-stack") == "0.0.7"
    runner, verdict = run(straight, stack="my-stack")
    assert verdict is not RunVerdict.ERROR and isinstance(runner.stack, user_stacks.Cruise)


def test_a_stacks_version_is_its_modules() -> None:
    assert version_of(f"{USER}:cruise") == "0.0.7"
    assert version_of("no_such_package:make") == "unknown"


def test_a_scenario_naming_a_missing_stage_is_bad_input(straight: Path) -> None:
    with pytest.raises(ScenarioError) as err:
        load_scenario(straight, {"stack.planner": "no_such_package.stacks:make"})
    assert err.value.key == "stack.planner"
    assert "cannot import no_such_package.stacks" in err.value.problem


def test_the_cli_refuses_a_missing_stack_with_exit_2_and_writes_nothing(
        straight: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(main, ["run", str(straight), "--profile", "none",
                                       "--planner", "no_such_package.stacks:make"])
    assert result.exit_code == 2, result.output
    assert result.stderr.count("\n") == 1 and "stack.planner" in result.stderr
    assert not (tmp_path / "runs").exists()


# ---- driving ------------------------------------------------------------------------------


def test_a_replaced_planner_plans_every_tick_and_the_rest_is_bundled(straight: Path) -> None:
    """A planner stage wrapping the bundled one drives exactly as the bundled stack."""
    user_stacks.COUNTERS.clear()
    runner, verdict = run(straight, planner=f"{USER}:counting_planner")
    bundled, bundled_verdict = run(straight)
    assert verdict is bundled_verdict is not RunVerdict.ERROR
    assert isinstance(runner.stack, ComposedStack)
    assert isinstance(runner.stack.perception, Perception)  # bundled
    (planner,) = user_stacks.COUNTERS
    assert planner.ticks == len(runner.log.t) > 70  # every control tick of 2 s at 40 Hz
    for column in ("x", "y", "speed", "steering", "drive_torque", "target_speed"):
        assert runner.log.array(column).tobytes() == bundled.log.array(column).tobytes()


def test_a_whole_stack_of_ones_own_drives_the_car_without_showing_a_plan(
        straight: Path) -> None:
    runner, verdict = run(straight, stack=f"{USER}:cruise")
    assert verdict is not RunVerdict.ERROR
    stack = runner.stack
    assert isinstance(stack, user_stacks.Cruise)
    assert {"gnss", "odometry"} <= set(stack.names)  # frames by sensor name (no profile)
    log = runner.log
    assert log.station[-1] - log.station[0] > 10.0  # it drove: 2 s at about 30 km/h
    assert all(math.isnan(v) for v in log.target_speed)  # no plan shown: no targets
    assert all(math.isnan(v) for v in log.pose_error)


def test_an_exception_in_a_users_stack_ends_the_run_in_error(straight: Path) -> None:
    runner = Runner(load_scenario(straight, {"stack.stack": f"{USER}:broken"}), None,
                    profile=None)
    result = runner.run()
    assert result.verdict is RunVerdict.ERROR
    assert result.error is not None and "a bug in the user's stack" in result.error.message
    assert 0.5 <= result.sim_time < 0.6


def test_a_stack_reporting_something_else_ends_the_run_saying_so(straight: Path) -> None:
    runner = Runner(load_scenario(straight, {"stack.stack": f"{USER}:chatty"}), None,
                    profile=None)
    result = runner.run()
    assert result.verdict is RunVerdict.ERROR and result.error is not None
    assert "on_frames returned a dict, not a PerceptionReport or None" in result.error.message


def test_a_factory_making_something_else_ends_the_run_in_error(straight: Path) -> None:
    """Found at load, its product checked once it is built (after load: the run's error)."""
    scenario = load_scenario(straight, {"stack.stack": f"{USER}:not_a_stack"})
    result = build_runner(scenario, None, None, "inline")
    assert isinstance(result, RunResult) and result.verdict is RunVerdict.ERROR
    assert result.error is not None and result.error.type == "StackChoiceError"
    assert "made a object, which has no on_frames, tick" in result.error.message


def test_the_result_names_the_stack(straight: Path, tmp_path: Path,
                                    monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(main, ["run", str(straight), "--profile", "none",
                                       "--stack", f"{USER}:cruise", "--out",
                                       str(tmp_path / "x.rrd"), "--no-progress"])
    assert result.exit_code in (0, 1), result.output  # judged (completes fails in 2 s)
    payload = json.loads((tmp_path / "x.json").read_text(encoding="utf-8"))
    assert payload["stack"] == {
        "name": f"{USER}:cruise", "version": "0.0.7", "api": API_VERSION,
        "factories": {"stack": f"{USER}:cruise", "perception": "avsim",
                      "planner": "avsim", "controller": "avsim"}, "privileged": False}
    # the header and the result say the stack localises the car itself (not the bundled way)
    assert payload["localisation"]["source"] == "own"
    assert "the stack localises the car itself, from GNSS and odometry only" in result.output


# ---- perception's front door ----------------------------------------------------------------


def _perception() -> Perception:
    road = make_map(seg(100.0, lanes=1, oncoming=0))
    sensors = (SensorSpec("gnss", SensorKind.GNSS, 10.0, 0.0),)
    return Perception(road, vehicle_info(read_geometry()), sensors, 0)


def test_perception_refuses_a_frame_of_a_sensor_it_was_not_told_of() -> None:
    fix = GnssFix(0.0, 0.0, 0.0, 0.0, 1.0, 0.1)
    with pytest.raises(ValueError, match="sensor 'gps', which the car was not said to have"):
        _perception().on_frames(0.0, {"gps": fix})


def test_perception_refuses_a_frame_of_another_kind_than_its_sensors() -> None:
    fix = GnssFix(0.0, 0.0, 0.0, 0.0, 1.0, 0.1)
    perception = _perception()
    perception._kinds["lidar"] = SensorKind.LIDAR
    with pytest.raises(ValueError, match="'lidar' is a lidar sensor, its frame a GnssFix"):
        perception.on_frames(0.0, {"lidar": fix})


def test_an_acceleration_asked_by_wire_is_what_the_car_does(straight: Path) -> None:
    """1 m/s^2 through the inverse model for 2 s from 30 km/h: the speed grows by about
    2 m/s (open loop: within 15 %)."""
    runner, verdict = run(straight, stack=f"{USER}:accelerate")
    assert verdict is not RunVerdict.ERROR
    speed, t = runner.log.array("speed"), runner.log.array("t")
    gained = (speed[-1] - speed[10]) / (t[-1] - t[10])
    assert gained == pytest.approx(1.0, rel=0.15)


def test_drive_by_wire_brakes_for_a_deceleration_and_drives_against_the_resistances() -> None:
    car = vehicle_info(read_geometry())
    hold = drive_by_wire(0.1, 0.0, 20.0, car)
    assert hold.drive_torque > 0.0 and hold.brake_torque == 0.0  # rolling and air drag
    assert hold.steering_angle == 0.1 and hold.accel_request == 0.0
    stop = drive_by_wire(0.0, -3.0, 20.0, car)
    assert stop.drive_torque == 0.0
    assert stop.brake_torque == pytest.approx(
        (car.mass * 3.0 - hold.drive_torque / car.wheel_radius) * car.wheel_radius)


def test_pedals_and_indicators_reach_the_car(straight: Path) -> None:
    """Half throttle, then full brake: the car speeds up, then brakes hard; the indicators the
    stack switched are the car's (logged)."""
    runner, verdict = run(straight, stack=f"{USER}:pedals")
    assert verdict is not RunVerdict.ERROR
    log = runner.log
    t, speed = log.array("t"), log.array("speed")
    assert speed[t < 1.0][-1] > speed[0] + 0.5  # half of 3000 N m: about 2 m/s^2
    assert speed[t < 1.0][-1] - speed[-1] > 5.0  # 5000 N m: over 5 m/s^2 for its last second
    assert {log.indicator[int(k)] for k in np.flatnonzero(t < 0.95)} == {Indicator.LEFT}
    assert log.indicator[len(log.t) - 1] is Indicator.RIGHT
    assert log.drive_torque[0] == 1500.0 and log.brake_torque[len(log.t) - 1] == 5000.0


def test_the_pedals_are_clamped_and_the_brake_wins() -> None:
    both = by_pedals(0.1, 2.0, 0.5)
    assert (both.drive_torque, both.brake_torque, both.steering_angle) == (0.0, 2500.0, 0.1)
    assert by_pedals(0.0, 2.0, -1.0).drive_torque == 3000.0


def test_the_bundled_controller_indicates_a_lane_change() -> None:
    """Towards a lane of higher index (left), lower or the shoulder (right), else off."""
    plan = cast(Plan, SimpleNamespace(lane=1, origin_lane=0))
    assert indicator(plan) is Indicator.LEFT
    assert indicator(cast(Plan, SimpleNamespace(lane=-1000, origin_lane=0))) is \
        Indicator.RIGHT
    assert indicator(cast(Plan, SimpleNamespace(lane=1, origin_lane=1))) is Indicator.OFF


# ---- diagnostic channels --------------------------------------------------------------------


def test_a_stacks_channels_are_recorded_under_its_name() -> None:
    assert stack_channels({"gap_error": 1.5, "mode": 2}) == {"stack/gap_error": 1.5,
                                                              "stack/mode": 2.0}


@pytest.mark.parametrize(("channels", "problem"), [
    ({f"c{k}": 0.0 for k in range(MAX_CHANNELS + 1)}, "at most 64"),
    ({"has space": 0.0}, "a name is a letter"),
    ({"../up": 0.0}, "a name is a letter"),
    ({"flag": True}, "is not a number"),
    ({"text": "1.0"}, "is not a number"),
])
def test_bad_channels_end_the_run_with_what_is_wrong(channels: dict[str, object],
                                                     problem: str) -> None:
    with pytest.raises(ValueError, match=problem):
        stack_channels(channels)  # type: ignore[arg-type]


def test_a_deterministic_stack_of_ones_own_runs_the_same_twice(straight: Path) -> None:
    first, _ = run(straight, stack=f"{USER}:cruise")
    again, _ = run(straight, stack=f"{USER}:cruise")
    for column in ("x", "y", "speed", "steering", "drive_torque", "brake_torque"):
        assert first.log.array(column).tobytes() == again.log.array(column).tobytes()

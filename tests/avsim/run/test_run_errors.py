"""A run never dies: an exception in any stage after the scenario has loaded (perception,
the planner, control, the storyboard's director, a criterion, the recorder, the world's
step) ends that run with verdict error. Its result keeps the criteria judged so far (what
only the end would settle is not applicable), says ``"passed": false``, ``"verdict":
"error"`` and the error (type, message, traceback, sim time); its recording is closed and
valid, with the error as an event at its sim time."""

from __future__ import annotations

import json
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from avsim.criteria.collision import NoCollision
from avsim.record import blueprint as bp
from avsim.record.recorder import Recorder
from avsim.run.result import dumps, result_json
from avsim.run.runner import Runner
from avsim.run.storyboard.director import Director
from avsim.run.verdict import RunError, RunVerdict
from avsim.scenario.load import load_scenario
from control.vehicle_controller import VehicleController
from perception.perception import Perception
from planner.planner import Planner
from tests.avsim.run.test_runner_criteria import column
from world.world import World

REPO = Path(__file__).resolve().parents[3]
RERUN = Path(sys.executable).parent / "rerun"
CUT_IN = (REPO / "tests" / "data" / "alks" / "logical_scenarios" / "concrete_scenarios"
          / "alks_scenario_4_4_1_cut_in_no_collision_template.xosc")
CALLS = 30  # the injected stage raises on its 30th call: after the run has begun
PLANNER_BUG = "heading error 2.856 rad: the car does not head along the lane"  # the
#   planner's refusal (`planner.lane_change_path`) seen with a front tyre flat in a bend


def raising_on_call(n: int, original: Callable[..., Any], exc: Exception
                    ) -> Callable[..., Any]:
    """`original`, except that its `n`-th call raises `exc`."""
    calls = [0]

    def wrapper(*args: Any, **kwargs: Any) -> Any:
        calls[0] += 1
        if calls[0] == n:
            raise exc
        return original(*args, **kwargs)

    return wrapper


STAGES: dict[str, tuple[type, str, str | Path]] = {  # stage -> (class, method, scenario)
    "perception": (Perception, "on_frames", "normal_driving"),
    "planner": (Planner, "update", "normal_driving"),
    "control": (VehicleController, "update", "normal_driving"),
    "director": (Director, "step", CUT_IN),
    "criterion": (NoCollision, "update", "normal_driving"),
    "recorder": (Recorder, "log_ego_pose", "normal_driving"),
    "world": (World, "step", "normal_driving"),
}


def events(recording: Path) -> list[tuple[int, str, str]]:
    """([ns] sim time, text, level) of each event the recording holds."""
    times, texts = column(recording, bp.EVENTS, "TextLog:text")
    _, levels = column(recording, bp.EVENTS, "TextLog:level")
    return [(t, x[0], lv[0]) for t, x, lv in zip(times, texts, levels, strict=True)]


@pytest.mark.parametrize("stage", list(STAGES))
def test_an_exception_in_a_stage_ends_the_run_in_error(
        stage: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    cls, method, scenario = STAGES[stage]
    bug = ValueError(PLANNER_BUG) if stage == "planner" else RuntimeError(f"a bug in {stage}")
    monkeypatch.setattr(cls, method, raising_on_call(CALLS, getattr(cls, method), bug))
    recording = tmp_path / "run.rrd"
    result = Runner(load_scenario(scenario, {"duration": 3}), recording, profile=None).run()

    assert result.verdict is RunVerdict.ERROR and not result.passed
    error = result.error
    assert error is not None
    assert (error.type, error.message) == (type(bug).__name__, str(bug))
    assert 0.0 <= error.sim_time == result.sim_time < 3.0
    assert error.traceback.startswith("Traceback (most recent call last)")
    assert error.traceback.endswith(f"{error.type}: {error.message}\n")
    assert not result.interrupted
    # judged so far: what only the end settles (the goal, the story) could not be judged
    assert [c.name for c in result.criteria
            if (c.note or "").startswith("not judged: the run ended in error at")]
    assert all(c.first_failure is not None for c in result.criteria if c.passed is False)

    payload = json.loads(dumps(result_json(result, str(scenario), recording, "none")))
    assert (payload["verdict"], payload["passed"], payload["interrupted"]) == (
        "error", False, False)
    assert payload["error"] == {"type": error.type, "message": error.message,
                                "traceback": error.traceback,
                                "sim_time": round(error.sim_time, 4)}

    check = subprocess.run([str(RERUN), "rrd", "verify", str(recording)],
                           capture_output=True, text=True, check=False)
    assert check.returncode == 0, check.stderr
    said = [(t, level) for t, text, level in events(recording) if text == error.line()]
    assert said == [(round(1e9 * error.sim_time), "ERROR")]


def test_an_error_line_is_one_line_with_the_sim_time() -> None:
    error = RunError("ValueError", "first\nsecond  line", "Traceback ...", 12.3456)
    assert error.line() == "run ended in error at t = 12.346 s: ValueError: first second line"
    assert RunError("KeyError", "", "", 0.0).line() == "run ended in error at t = 0.000 s: KeyError"


def test_a_run_without_error_has_its_usual_verdict(tmp_path: Path) -> None:
    result = Runner(load_scenario("normal_driving", {"duration": 1}), None, profile=None).run()
    assert result.error is None and result.verdict is RunVerdict.FAIL  # not completed
    payload = result_json(result, "normal_driving", tmp_path / "x.rrd", "none")
    assert (payload["verdict"], payload["passed"], payload["error"]) == ("fail", False, None)

"""The truth-mode example `examples/stacks/idm_pure_pursuit.py` drives the bundled
sudden_stop and cut_in_out (privileged, profile none) to their verdicts."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from avsim.run.runner import Runner, RunResult
from avsim.run.verdict import RunVerdict
from avsim.scenario.load import load_scenario

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "stacks" / "idm_pure_pursuit.py"


def _run(name: str, actor: int) -> tuple[Runner, RunResult, np.ndarray]:
    """The run, and the actor's (speed [m/s], offset from the ego's lane centre [m]) at
    each progress report."""
    scenario = load_scenario(name, {"stack.stack": f"{EXAMPLE}:make", "stack.privileged": True})
    runner = Runner(scenario, None, profile=None)
    lane = runner.world.road.lane(scenario.world.ego.lane)
    seen: list[tuple[float, float]] = []

    def watch(t: float, duration: float) -> None:
        poses = runner.world.actors.poses
        _, r = lane.local_coordinates(poses.centres[actor, :2])
        seen.append((float(poses.speeds[actor]), float(r)))

    result = runner.run(watch)
    assert type(runner.stack).__name__ == "IdmPurePursuit"
    return runner, result, np.array(seen)


def _passed(result: RunResult, name: str) -> bool | None:
    return next(c.passed for c in result.criteria if c.name == name)


def test_idm_stops_behind_the_sudden_stop_without_contact() -> None:
    runner, result, lead = _run("sudden_stop", 0)
    assert result.verdict is RunVerdict.PASS, [c for c in result.criteria if c.failed]
    assert lead[:, 0].min() < 0.1  # the lead braked to a stop
    assert _passed(result, "no_collision") is True
    assert _passed(result, "standstill_gap") is True  # the car stood behind it
    assert np.nanmin(np.array(runner.log.speed)) < 0.1


def test_idm_follows_the_cutter_in_and_out_without_contact() -> None:
    runner, result, cutter = _run("cut_in_out", 0)
    assert result.verdict is RunVerdict.PASS, [c for c in result.criteria if c.failed]
    assert np.abs(cutter[:, 1]).min() < 0.5  # the cutter entered the car's lane
    assert _passed(result, "no_collision") is True
    assert _passed(result, "min_gap") is True and _passed(result, "max_decel") is True
    gaps = np.array(runner.log.lead_gap)
    assert np.nanmin(gaps) < 30.0  # the car followed it

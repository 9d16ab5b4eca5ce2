"""A run reports where its wall time went, stage by stage (`RunResult.stage_times`)."""

from __future__ import annotations

import dataclasses

import pytest

from avsim.run.runner import Runner, RunResult
from avsim.scenario.load import load_scenario
from world.sensors.setup import Profile

STACK = {"physics", "criteria", "runner", "localisation", "planner", "control",
         "sensor gnss", "sensor odometry"}
PERCEPTION = {"sensor lidar", "perception lanes", "perception lane filter",
              "perception signs", "perception objects", "perception tracking", "scoring"}


def run(profile: Profile | None, sensing: str) -> RunResult:
    scenario = dataclasses.replace(load_scenario("normal_driving"), duration=1.0)
    return Runner(scenario, None, profile=profile, sensing=sensing).run()


@pytest.fixture(scope="module")
def inline() -> RunResult:
    return run(Profile.FAST, "inline")


@pytest.fixture(scope="module")
def process() -> RunResult:
    return run(Profile.FAST, "process")


def main_stages(result: RunResult) -> dict[str, float]:
    return {k: v for k, v in result.stage_times.items() if not k.startswith("worker ")}


def test_inline_times_every_stage_in_this_process(inline: RunResult) -> None:
    stages = set(inline.stage_times)
    assert STACK | PERCEPTION | {"sensor front"} <= stages
    assert not any(s.startswith(("ipc", "worker")) for s in stages)
    assert "recording" not in stages  # nothing recorded
    assert sum(main_stages(inline).values()) <= inline.wall_time


def test_the_render_worker_reports_its_renders_and_the_passing_of_frames(
        process: RunResult) -> None:
    stages = set(process.stage_times)
    assert STACK | PERCEPTION | {"ipc send", "ipc wait", "ipc receive",
                                "worker pose", "worker sensor front"} <= stages
    assert "sensor front" not in stages  # rendered in the worker, not here
    assert sum(main_stages(process).values()) <= process.wall_time
    assert all(v >= 0.0 for v in process.stage_times.values())


def test_timing_changes_nothing_the_run_computes(inline: RunResult,
                                                 process: RunResult) -> None:
    assert inline.log.x == process.log.x and inline.log.steering == process.log.steering
    assert [c.as_json() for c in inline.criteria] == [c.as_json() for c in process.criteria]


def test_a_map_only_run_has_no_sensor_stages_but_its_own() -> None:
    result = run(None, "auto")
    stages = set(result.stage_times)
    assert stages >= STACK
    assert not stages & PERCEPTION

"""A stack in its own process (`avsim.stack.remote`): the example lane keeper of
`examples/stacks/remote/` drives a straight road through the protocol alone, and a child
that crashes, hangs or answers garbage ends the run in error, named, and reaped."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from avsim.run.runner import Runner
from avsim.run.unbuilt import build_runner
from avsim.run.verdict import RunVerdict
from avsim.scenario.load import load_scenario
from avsim.stack.remote import RemoteStack

REPO = Path(__file__).resolve().parents[2]
LAUNCH = REPO / "examples" / "stacks" / "remote" / "launch.py"
FACTORIES = Path(__file__).resolve().with_name("remote_factories.py")

STRAIGHT = """\
format: avsim/1
name: straight_remote
description: a straight two-lane road, nobody else on it
duration: {duration}
seed: 3
road:
  lanes: 2
  oncoming_lanes: 1
  lane_width: 3.5
  shoulder: 2.5
  speed_limit_kph: 60
  segments:
    - straight: 250
ego:
  lane: 0
  s: 20
  speed_kph: 0
  set_speed_kph: 50
sensors:
  gnss: {{preset: rtk}}
"""


def _children() -> set[int]:
    """The pids of this process's children, zombies included."""
    pids = set()
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                stat = (entry / "stat").read_text()
            except OSError:
                continue
            if int(stat.rsplit(")", 1)[1].split()[1]) == os.getpid():
                pids.add(int(entry.name))
    return pids


def _runner(tmp_path: Path, factory: str, duration: float = 30.0) -> Runner:
    path = tmp_path / "straight_remote.yaml"
    path.write_text(STRAIGHT.format(duration=duration))
    return Runner(load_scenario(path, {"stack.stack": factory}), None, profile=None)


def test_the_example_lane_keeper_in_its_own_process_drives_a_straight_road_to_a_pass(
        tmp_path: Path) -> None:
    """From a standstill to the set speed in lane 0 on GNSS (rtk) + odometry and the map
    lines of `hello`: every criterion passes, the car stays near the lane's centre, the
    child's channels reach the log, and it exits of itself on `bye`."""
    runner = _runner(tmp_path, f"{LAUNCH}:make")
    stack = runner.stack
    assert isinstance(stack, RemoteStack)
    assert (stack.name, stack.version, stack.reads) == ("lane-keeper", "1.0",
                                                        frozenset({"gnss", "odometry"}))
    result = runner.run()
    assert result.verdict is RunVerdict.PASS, (result.error, result.criteria)
    speed = np.array(runner.log.speed)
    assert np.max(speed) > 0.9 * 50 / 3.6  # it got near the set speed
    assert result.metrics["max_lateral_error"] < 0.3  # [m]
    assert stack.process.returncode == 0  # it said goodbye and exited, reaped
    assert stack.process.pid not in _children()


@pytest.mark.parametrize(("mode", "said"), [
    ("crash", ["closed its output at tick", "exit status 1",
               "RuntimeError: boom: the remote stack's own bug"]),
    ("hang", ["did not answer tick within 0.5 s", "still running (killed)"]),
    ("huge", ["answered garbage at tick", "a message of 4294967280 bytes (at most 1048576)"]),
    ("notmap", ["answered garbage at tick", "not a map with a string 'type'"]),
    ("nan", ["answered garbage", "command.steering_angle: nan is not a finite number"]),
])
def test_a_child_that_crashes_hangs_or_answers_garbage_ends_the_run_in_error_reaped(
        tmp_path: Path, mode: str, said: list[str]) -> None:
    """The child drives 10 ticks, then fails: the run ends in error at that tick (the
    criteria judged so far), the message names the failure, the child's exit status and
    its stderr, and no process is left behind."""
    runner = _runner(tmp_path, f"{FACTORIES}:{mode}", duration=5.0)
    stack = runner.stack
    assert isinstance(stack, RemoteStack)
    result = runner.run()
    assert result.verdict is RunVerdict.ERROR
    assert result.error is not None and result.error.type == "RemoteStackError"
    for part in said:
        assert part in result.error.message, result.error.message
    assert 0.2 < result.error.sim_time < 0.4  # [s] the 11th tick, 40 Hz
    assert stack.process.returncode is not None
    assert stack.process.pid not in _children()


def test_a_child_that_never_answers_hello_ends_the_run_in_error_before_it_starts(
        tmp_path: Path) -> None:
    path = tmp_path / "straight_remote.yaml"
    path.write_text(STRAIGHT.format(duration=5.0))
    before = _children()
    built = build_runner(load_scenario(path, {"stack.stack": f"{FACTORIES}:silent"}), None,
                         None, "auto")
    assert not isinstance(built, Runner)
    assert built.verdict is RunVerdict.ERROR and built.error is not None
    assert "did not answer hello within 0.5 s" in built.error.message
    assert _children() <= before


def test_an_interrupted_run_still_says_bye_and_reaps_the_child(tmp_path: Path) -> None:
    """A run interrupted (a signal's handler calls `interrupt`) closes its stack: the child
    gets `bye`, exits of itself and is reaped."""
    runner = _runner(tmp_path, f"{LAUNCH}:make")
    stack = runner.stack
    assert isinstance(stack, RemoteStack)
    runner.interrupt()
    result = runner.run()
    assert result.verdict is RunVerdict.INTERRUPTED
    assert stack.process.returncode == 0
    assert stack.process.pid not in _children()


def test_the_remote_lane_keeper_gets_the_bundled_sudden_stops_verdicts() -> None:
    """The bundled `sudden_stop` through the protocol (profile none): the run ends with its
    verdicts, no error; the lead braked to a stop in it. The lane keeper sees no other road
    user, so it does not stop in time (no_collision fails: counted, as for any stack)."""
    scenario = load_scenario("sudden_stop", {"stack.stack": f"{LAUNCH}:make"})
    runner = Runner(scenario, None, profile=None)
    result = runner.run()
    assert result.error is None and result.verdict in (RunVerdict.PASS, RunVerdict.FAIL)
    verdicts = {c.name: c.passed for c in result.criteria}
    assert verdicts["no_collision"] is False and verdicts["speed_limit"] is True
    assert any(e.fired_at is not None for e in result.story)  # the lead's braking started

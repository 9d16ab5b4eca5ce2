"""The result of a run whose world could not be built (an exception while `Runner(...)`
builds the world, the stack or the criteria, after the scenario loaded).

Such a run ends like any run that raised (`avsim.run.verdict`): verdict error at sim time
0 s, the exception's type, message and traceback in its result, no criterion judged (none
was built), and a valid recording that holds the error as an event at t = 0 s, so that the
result file and the recording exist and agree as they do for every other run.
"""

from __future__ import annotations

import time
from contextlib import suppress
from pathlib import Path

from avsim.record.recorder import Recorder
from avsim.run.runner import Runner, RunResult, TrajectoryLog
from avsim.run.verdict import RunError
from avsim.scenario.scenario import Scenario
from world.sensors.setup import Profile


def build_runner(scenario: Scenario, recording: Path | None, profile: Profile | None,
                 sensing: str) -> Runner | RunResult:
    """`Runner(scenario, recording, profile, sensing)`, or, when building it raises, the
    run's result already (`unbuilt_result`): it ended in error at 0 s."""
    started = time.perf_counter()
    try:
        return Runner(scenario, recording, profile, sensing)
    except Exception as exc:  # the world cannot be built: the run ends in error at 0 s
        return unbuilt_result(scenario, exc, recording, profile, started)


def unbuilt_result(scenario: Scenario, exc: Exception, recording: Path | None,
                   profile: Profile | None, started: float) -> RunResult:
    """The result of `scenario`'s run that raised `exc` while its world was built.

    `recording`: the file the run records to (the error written there as an event at
    t = 0 s, then closed whole), None for none; `profile`: the sensor profile asked for
    (None: none); `started`: `time.perf_counter()` when the build began (the result's wall
    time [s] runs from it)."""
    error = RunError.of(exc, 0.0)
    if recording is not None:
        with suppress(Exception):  # the build's error is the news; the recording stays
            _record_error(recording, scenario.name, error)
    return RunResult(
        scenario=scenario, criteria=[], metrics={}, sim_time=0.0,
        wall_time=time.perf_counter() - started, log=TrajectoryLog(), recording=recording,
        profile=profile.value if profile is not None else None, error=error)


def _record_error(recording: Path, name: str, error: RunError) -> None:
    """A recording of the scene set-up and `error` as an ERROR event at t = 0 s."""
    with Recorder(recording, recording_name=name) as recorder:
        recorder.log_event(0.0, error.line(), "ERROR")

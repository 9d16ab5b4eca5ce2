"""Closed-loop scenario runs, shared by the tests of one module (runs are slow)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from avsim.run.runner import Runner, RunResult
from avsim.run.sensor_loop import FrameHook
from avsim.scenario.load import load_scenario
from world.sensors.setup import Profile


@pytest.fixture(scope="module")
def run_scenario(tmp_path_factory: pytest.TempPathFactory) -> Callable[..., RunResult]:
    """`run(name, record=True, profile=Profile.DEFAULT, frame_hook=None, **overrides)`:
    one run per distinct argument set in this module."""
    cache: dict[str, RunResult] = {}

    def run(name: str, record: bool = True, profile: Profile | None = Profile.DEFAULT,
            frame_hook: FrameHook | None = None, **overrides: object) -> RunResult:
        key = repr((name, record, profile, frame_hook, sorted(overrides.items())))
        if key not in cache:
            scenario = load_scenario(name, overrides or None)
            out: Path | None = tmp_path_factory.mktemp("runs") / f"{name}.rrd" if record else None
            cache[key] = Runner(scenario, out, profile=profile, frame_hook=frame_hook).run()
        return cache[key]

    return run

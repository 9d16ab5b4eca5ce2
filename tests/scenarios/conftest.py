"""Closed-loop scenario runs, shared by the tests of one module (runs are slow)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from avsim.run.runner import Runner, RunResult
from avsim.run.sensor_loop import FrameHook
from avsim.scenario.load import load_scenario
from world.sensors.setup import Profile

SENSING = "inline"  # the cameras render in the test's own process: xdist keeps both cores
#   busy, and a render worker (`--sensing auto`) builds the world a second time and passes
#   every frame through shared memory: normal_driving's first 20 s took 22.3 s of CPU over
#   four processes with it, 18.0 s inline. The two give the same run, bit for bit
#   (tests/avsim/run/test_speedups.py, tests/world/sensors/test_pipeline.py).


@pytest.fixture(scope="module")
def run_scenario(tmp_path_factory: pytest.TempPathFactory) -> Callable[..., RunResult]:
    """`run(name, record=True, profile=Profile.DEFAULT, frame_hook=None, criteria=None,
    **overrides)`: one run per distinct argument set in this module (`name` a bundled
    scenario or a file; `criteria` an OpenSCENARIO file's criteria set or sidecar)."""
    cache: dict[str, RunResult] = {}

    def run(name: str, record: bool = True, profile: Profile | None = Profile.DEFAULT,
            frame_hook: FrameHook | None = None, criteria: str | None = None,
            **overrides: object) -> RunResult:
        key = repr((name, record, profile, frame_hook, criteria, sorted(overrides.items())))
        if key not in cache:
            scenario = load_scenario(name, overrides or None,
                                     Path(criteria) if criteria is not None else None)
            out: Path | None = (tmp_path_factory.mktemp("runs") / f"{scenario.name}.rrd"
                                if record else None)
            cache[key] = Runner(scenario, out, profile=profile, frame_hook=frame_hook,
                                sensing=SENSING).run()
        return cache[key]

    return run

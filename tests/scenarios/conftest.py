"""Closed-loop scenario runs, shared by the tests of one module (runs are slow).

A module that judges the planner, control or the storyboard and not perception runs its
scenarios in two stack modes (`mode`): `truth`, the bundled planner and control on the
privileged ground truth (`avsim.stack.bundled:truth_perception`, profile `none`: nothing
rendered) in `make test`; and `sensors`, the whole stack on the `default` profile's cameras
and LiDAR, marked `acceptance` (`make acceptance`)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from avsim.run.runner import Runner, RunResult
from avsim.run.sensor_loop import FrameHook
from avsim.scenario.load import load_scenario
from tests.scenarios.modes import MODES, PROFILES, SENSORS, TRUTH, TRUTH_STACK
from world.sensors.setup import Profile

SENSING = "inline"  # the cameras render in the test's own process: xdist keeps both cores
#   busy, and a render worker (`--sensing auto`) builds the world a second time and passes
#   every frame through shared memory: normal_driving's first 20 s took 22.3 s of CPU over
#   four processes with it, 18.0 s inline. The two give the same run, bit for bit
#   (tests/avsim/run/test_speedups.py, tests/world/sensors/test_pipeline.py).

@pytest.fixture(scope="module", params=MODES)
def mode(request: pytest.FixtureRequest) -> str:
    """The stack mode of a module's runs: `truth` (make test) or `sensors` (acceptance)."""
    out: str = request.param
    return out


@pytest.fixture(scope="module", params=PROFILES)
def sensor_profile(request: pytest.FixtureRequest) -> Profile:
    """The sensor profile of a module's runs that read signs or lights from the camera but
    do not judge perception's figures: `fast` (make test) or `default` (acceptance)."""
    out: Profile = request.param
    return out


@pytest.fixture(scope="module")
def run_scenario(tmp_path_factory: pytest.TempPathFactory) -> Callable[..., RunResult]:
    """`run(name, record=True, profile=Profile.DEFAULT, frame_hook=None, criteria=None,
    stack=SENSORS, **overrides)`: one run per distinct argument set in this module (`name` a
    bundled scenario or a file; `criteria` an OpenSCENARIO file's criteria set or sidecar;
    `stack=TRUTH` the privileged truth stack, which renders nothing: `profile` set aside)."""
    cache: dict[str, RunResult] = {}

    def run(name: str, record: bool = True, profile: Profile | None = Profile.DEFAULT,
            frame_hook: FrameHook | None = None, criteria: str | None = None,
            stack: str = SENSORS, **overrides: object) -> RunResult:
        if stack == TRUTH:
            profile = None
            overrides = {**overrides, **TRUTH_STACK}
        elif stack != SENSORS:
            raise ValueError(f"stack mode {stack!r}: {TRUTH!r} or {SENSORS!r}")
        key = repr((name, record, profile, frame_hook, criteria, sorted(overrides.items())))
        if key not in cache:
            scenario = load_scenario(name, overrides or None,
                                     Path(criteria) if criteria is not None else None)
            assert scenario.stack.privileged == (stack == TRUTH)  # the mode asked is the run's
            out: Path | None = (tmp_path_factory.mktemp("runs") / f"{scenario.name}.rrd"
                                if record else None)
            cache[key] = Runner(scenario, out, profile=profile, frame_hook=frame_hook,
                                sensing=SENSING).run()
        return cache[key]

    return run

"""The example stacks of `examples/stacks/` drive the bundled scenarios through the public
stack API and get their verdicts."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from avsim.run.runner import Runner
from avsim.run.stack import ComposedStack
from avsim.run.verdict import RunVerdict
from avsim.scenario.load import load_scenario
from world.sensors.setup import Profile

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "stacks"


@pytest.mark.slow
def test_a_time_gap_acc_replacing_the_planners_law_follows_the_lead_off_after_its_stop(
) -> None:
    """sudden_stop: the lead brakes from 50 km/h to a stop 12 m ahead, stands 4 s and
    drives off to 40 km/h. The example's law sets the target behind it (the bundled
    planner's emergency answers stay); the car stops short without contact and follows at
    the law's gap, d_0 + T v, once the lead is steady."""
    from examples.stacks import time_gap_acc as example

    scenario = load_scenario("sudden_stop",
                             {"stack.planner": f"{EXAMPLES / 'time_gap_acc.py'}:make"})
    runner = Runner(scenario, None, profile=Profile.FAST)
    result = runner.run()
    assert result.verdict is RunVerdict.PASS, [c for c in result.criteria if c.failed]
    assert isinstance(runner.stack, ComposedStack)
    planner = runner.stack.planner
    assert type(planner).__name__ == "TimeGapAcc"
    assert planner.ticks_in_force > 100  # type: ignore[attr-defined]
    log = runner.log
    gap, speed = np.array(log.lead_gap), np.array(log.speed)
    assert np.nanmin(speed[np.array(log.t) > 8.0]) < 0.5  # it stopped behind the lead
    last = slice(-40, None)  # the last second: the lead steady at 40 km/h
    wanted = example.STANDSTILL + example.TIME_GAP * speed[last]
    assert np.all(np.abs(gap[last] - wanted) < 0.25 * wanted)

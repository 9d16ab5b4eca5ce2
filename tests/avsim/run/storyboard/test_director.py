"""The director on a real world: ALKS 4.4.1 on the map (no camera or LiDAR), twice. The
cut-in starts when the truth says so, its lane change lands in the ego's lane when its
dynamics say, and the same file and seed give the same run bit for bit."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from avsim.run.runner import Runner, RunResult
from avsim.scenario.load import load_scenario

pytestmark = pytest.mark.slow
ALKS = Path(__file__).parents[3] / "data" / "alks" / "logical_scenarios" / "concrete_scenarios"
CUT_IN = ALKS / "alks_scenario_4_4_1_cut_in_no_collision_template.xosc"
SPAN = np.pi * 3.5 / (2 * 2.0)  # [s] a sinusoidal lane change of 3.5 m at a peak of 2 m/s


@pytest.fixture(scope="module")
def runs() -> tuple[RunResult, RunResult]:
    def run() -> RunResult:
        scenario = load_scenario(CUT_IN, {"duration": 14.0})
        return Runner(scenario, None, profile=None).run()
    return run(), run()


def test_the_cut_in_starts_at_its_trigger_and_lands_after_its_span(
        runs: tuple[RunResult, RunResult]) -> None:
    result, _ = runs
    story = {e.element: e.fired_at for e in result.story}
    start = story["CutInAction"]
    assert start is not None and story["CutInAccelerateAction"] == start
    log = result.log
    t = log.array("t")
    offset = np.array(log.actor_offset)[:, 0]
    assert offset[0] == pytest.approx(0.0, abs=1e-9)  # lane 0, right of the ego
    moving = t[np.flatnonzero(np.abs(np.diff(offset)) > 1e-9)]
    assert moving[0] == pytest.approx(start, abs=0.05)
    assert moving[-1] == pytest.approx(start + SPAN, abs=0.1)
    assert offset[-1] == pytest.approx(3.5, abs=1e-6)  # the ego's lane centre
    lateral = np.diff(offset) / np.diff(t)
    assert lateral.max() == pytest.approx(2.0, rel=0.02)  # the file's rate: its peak


def test_the_same_file_and_seed_give_the_same_run(runs: tuple[RunResult, RunResult]) -> None:
    a, b = runs
    for name in ("x", "y", "yaw", "speed", "station"):
        assert np.array_equal(a.log.array(name), b.log.array(name)), name
    assert np.array_equal(np.array(a.log.actor_offset), np.array(b.log.actor_offset))
    assert a.story == b.story

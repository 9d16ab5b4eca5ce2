"""Ctrl-C reaches the whole process group: a sensing worker still starting exits on it before
it can ignore it. A run being interrupted then ends interrupted, not in error; the same
worker's end without an interrupt is the run's error."""

from __future__ import annotations

from typing import Any

import pytest

from avsim.run.runner import Runner
from avsim.run.verdict import RunVerdict
from avsim.scenario.load import load_scenario
from world.sensors.pipeline import SensingError


@pytest.mark.parametrize(("interrupted", "verdict"), [
    (True, RunVerdict.INTERRUPTED), (False, RunVerdict.ERROR)])
def test_a_worker_ended_by_the_interrupt_is_no_error(
        interrupted: bool, verdict: RunVerdict, monkeypatch: pytest.MonkeyPatch) -> None:
    runner = Runner(load_scenario("normal_driving", {"duration": 2}), None, profile=None)
    tick = runner._tick

    def dying(*args: Any) -> None:
        if runner.world.t > 0.5:
            if interrupted:
                runner.interrupt()
            raise SensingError("sensing worker exited (code 1)")
        tick(*args)

    monkeypatch.setattr(runner, "_tick", dying)
    result = runner.run()
    assert result.verdict is verdict
    assert (result.error is None) is interrupted
    assert 0.5 < result.sim_time < 0.6

"""The runner's step-wise form (`start`, `advance`, `finish`) is the loop `run` uses: the
same scenario run either way gives the same log bit for bit; `advance` hands control back
once per control period, says when the run is over, and keeps the "a run never dies"
contract; a run can be driven by a stack given to the runner instead of the scenario's."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from avsim.run.runner import Runner
from avsim.run.verdict import RunVerdict
from avsim.scenario.load import load_scenario
from avsim.stack import StackContext, StackStep, drive_by_wire
from world.core.rates import CONTROL_RATE
from world.frames import Frames

SHORT = """\
format: avsim/1
name: short
duration: 1
road:
  speed_limit_kph: 50
  segments:
    - straight: 200
ego: {s: 10, speed_kph: 20, set_speed_kph: 20}
"""


@pytest.fixture
def short(tmp_path: Path) -> Path:
    path = tmp_path / "short.yaml"
    path.write_text(SHORT, encoding="utf-8")
    return path


class Coast:
    """A stack that holds the wheels straight and asks for `accel` [m/s^2]; raises at its
    `raise_at`-th tick (0: never)."""

    reads = None

    def __init__(self, ctx: StackContext, accel: float = 0.0, raise_at: int = 0) -> None:
        self.ctx, self.accel, self.raise_at, self.ticks = ctx, accel, raise_at, 0

    def on_frames(self, t: float, frames: Frames) -> None:
        return None

    def tick(self, t: float, dt: float) -> StackStep:
        self.ticks += 1
        if self.ticks == self.raise_at:
            raise RuntimeError("the agent's stack broke")
        return StackStep(drive_by_wire(0.0, self.accel, 5.0, self.ctx.vehicle))


def test_stepping_gives_the_run_bit_for_bit(short: Path) -> None:
    whole = Runner(load_scenario(short), None, profile=None).run()
    runner = Runner(load_scenario(short), None, profile=None)
    assert runner.start()
    periods = 1
    while runner.advance():
        periods += 1
    stepped = runner.finish()
    assert periods == round(1.0 / CONTROL_RATE.period)  # one call per control period
    assert not runner.advance()  # over: nothing more happens
    assert runner.finish() is stepped
    for name in ("t", "x", "y", "yaw", "speed", "steering", "drive_torque", "brake_torque"):
        assert np.array_equal(whole.log.array(name), stepped.log.array(name)), name
    assert [c.as_json() for c in whole.criteria] == [c.as_json() for c in stepped.criteria]
    assert whole.metrics.keys() == stepped.metrics.keys()
    assert np.array_equal(np.array(list(whole.metrics.values())),
                          np.array(list(stepped.metrics.values())), equal_nan=True)


def test_a_given_stack_drives_instead_of_the_scenarios(short: Path) -> None:
    made: list[Coast] = []

    def factory(ctx: StackContext) -> Coast:
        made.append(Coast(ctx, accel=2.0))
        return made[0]

    result = Runner(load_scenario(short), None, profile=None, stack=factory).run()
    assert len(made) == 1 and made[0].ticks == len(result.log.t)
    assert np.all(result.log.array("target_speed") != result.log.array("target_speed"))  # NaN:
    #   the given stack shows no plan, the bundled one would


def test_an_exception_while_stepping_ends_the_run_in_error(short: Path) -> None:
    runner = Runner(load_scenario(short), None, profile=None,
                    stack=lambda ctx: Coast(ctx, raise_at=3))
    assert runner.start()
    assert runner.advance() and runner.advance()
    assert not runner.advance()  # the third tick raised
    result = runner.finish()
    assert result.verdict is RunVerdict.ERROR and result.error is not None
    assert "the agent's stack broke" in result.error.line()

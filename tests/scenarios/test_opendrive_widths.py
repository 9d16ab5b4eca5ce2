"""Closed loop on an OpenDRIVE road whose lanes change along it (`widths.xodr`: route lane 0
narrowing 3.75 -> 3.25 m on a line, an arc and a spiral, a lane offset, three lane
sections): the stack reads the HD map built from the file and keeps route lane 0's centre
as it narrows and moves, on the map and an RTK receiver (no perception judged)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from avsim.run.runner import RunResult

XOSC = Path(__file__).parents[1] / "world/map/opendrive/data/widths_drive.xosc"


@pytest.fixture(scope="module")
def drive(run_scenario: Callable[..., RunResult]) -> RunResult:
    return run_scenario(str(XOSC), record=False, profile=None,
                        **{"sensors.gnss": {"preset": "rtk"}})


def test_the_car_keeps_the_narrowing_lane(drive: RunResult) -> None:
    log = drive.log
    assert drive.sim_time == pytest.approx(13.0, abs=0.05)  # the StopTrigger
    station = log.array("station")
    assert station[0] < 12.0 and station[-1] > 180.0  # through the taper and the arc
    assert set(log.lane) == {0}
    assert not any(log.crossing)  # no tyre on a line
    assert np.max(np.abs(log.array("lane_error"))) < 0.25  # [m] from the lane's centre
    failed = [f"{c.name}: {c.note or c.value}" for c in drive.criteria if c.failed]
    assert not failed, failed

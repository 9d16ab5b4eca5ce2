"""ISO 22179 stop and go, varied (`scenarios/acceptance/stop_and_go_variants.yaml`): the
grid's worst points, a lead that brakes to a stop at 1 or 3 m/s^2, stands 5 s, drives off
to 40 km/h at 1 m/s^2 and at once brakes to a stop again. Before the ACC's d_min guard
(`planner.acc_control.guard_decel`) the ego fell 0.40 m (decelerations of 1 m/s^2) and
0.06 m (3 m/s^2) under UN R157's d_min at about 15 km/h in the second stop; the guard
lifts the first to 1.9 m above it, the second is a known failure (`HARD_STOP`). Shown from
the truth: the lead stopped and drove off twice and the ego stood behind it; then `min_gap`
passed with room."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from avsim.run.runner import RunResult
from world.sensors.setup import Profile

pytestmark = [pytest.mark.slow, pytest.mark.acceptance]
FILE = "scenarios/acceptance/stop_and_go_variants.yaml"
STOPPED = 0.1  # [m/s]
ROOM = 0.5  # [m] the least gap - d_min asked of the ACC


def _point(decel: float) -> dict[str, object]:
    """The grid point at 40 km/h, braking at `decel` [m/s^2], standing 5 s, driving off at
    1 m/s^2."""
    accel = 1.0
    return {"ego.speed_kph": 40, "actors.0.speed_kph": 40,
            "actors.0.actions.1.speed.kph": 40, "actors.0.actions.3.speed.kph": 40,
            "actors.0.actions.0.speed.accel": -decel,
            "actors.0.actions.2.speed.accel": -decel,
            "actors.0.actions.1.speed.accel": accel, "actors.0.actions.3.speed.accel": accel,
            "actors.0.actions.1.trigger.delay": 5, "actors.0.actions.3.trigger.delay": 5}


def _starts(mask: np.ndarray) -> int:
    """How many times `mask` turns true after being false."""
    return int(np.count_nonzero(mask[1:] & ~mask[:-1]))


HARD_STOP = ("grid point 013: the lead brakes at 3 m/s^2 (the judge's hard-braking bound, "
             "still judged) from 40 km/h just as it reaches it; the ego, still inside d_des "
             "after the pull-away (16 m, d_des 19.7 m) and at 10.3 m/s, builds its braking "
             "at the comfort jerk to the comfortable cap, 3 m/s^2, and falls under d_min by "
             "about 0.06 m at 16 km/h, with the guard or without it")


@pytest.mark.parametrize("decel", [  # grid points 009 and 013
    1.0, pytest.param(3.0, marks=pytest.mark.xfail(strict=True, reason=HARD_STOP))])
def test_stop_and_go_keeps_d_min_with_room(run_scenario: Callable[..., RunResult],
                                           decel: float) -> None:
    result = run_scenario(FILE, record=False, profile=Profile.FAST, **_point(decel))
    log = result.log
    v, lead_v, gap = log.array("speed"), log.array("lead_speed"), log.array("lead_gap")
    standing = lead_v < STOPPED
    assert _starts(standing) >= 2 and _starts(~standing) >= 2  # stopped and went twice
    ego_stood = standing & (v < STOPPED) & np.isfinite(gap)
    assert _starts(ego_stood) >= 2  # the ego stood behind it in both stops
    c = {r.name: r for r in result.criteria}
    assert not any(r.failed for r in result.criteria), result.criteria
    min_gap = c["min_gap"]
    assert min_gap.value is not None and min_gap.threshold is not None
    assert min_gap.value - min_gap.threshold >= ROOM

"""Honesty: a front camera that goes black must not leave the car driving as before.

The lane estimate loses its confidence, the planner says so (lane source MAP_HOLD), slows to
the hold speed on the map and the odometry, and after `stop_after` seconds stops in its lane.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np
import pytest

from avsim.run.runner import RunResult
from planner.fsm.lane_source import LaneSourceParams
from tests.scenarios import golden
from world.frames import CameraFrame

pytestmark = pytest.mark.slow
BLACK_FROM = 8.0  # [s]


def black_front(frame: CameraFrame) -> CameraFrame:
    if frame.info.name == "front" and frame.t >= BLACK_FROM:
        return replace(frame, rgb=np.zeros_like(frame.rgb))
    return frame


def test_black_camera_slows_then_stops_in_lane(run_scenario: Callable[..., RunResult]) -> None:
    seeing = run_scenario("normal_driving", record=False, duration=30)
    blind = run_scenario("normal_driving", record=False, duration=30, frame_hook=black_front)
    p = LaneSourceParams()
    changes = [(c.t, c.target) for c in blind.state_changes if c.machine == "lane_source"]
    targets = [c for _, c in changes]
    assert targets == ["camera", "map_hold", "stop_in_lane"], changes
    lost_at = changes[1][0]
    assert BLACK_FROM < lost_at < BLACK_FROM + 1.0  # noticed within a second
    assert changes[2][0] == pytest.approx(lost_at + p.stop_after, abs=0.05)
    t, v = blind.log.array("t"), blind.log.array("speed")
    v_seeing = seeing.log.array("speed")
    # before the blackout both runs are the same; after it the blind car slows, then stops
    before = t < BLACK_FROM
    assert np.array_equal(v[before], v_seeing[before])
    # holding: slowing towards the hold speed at a comfortable rate (1.5 m/s^2 planned)
    v_lost = float(np.interp(lost_at, t, v))
    v_later = float(np.interp(lost_at + 4.0, t, v))
    assert v_lost - v_later >= 4.0 * 1.2
    assert v_later > p.hold_speed - 0.3
    holding = (t > lost_at + 4.0) & (t < lost_at + p.stop_after)
    assert np.min(v_seeing[holding]) > 12.0  # the seeing car drives on at ~50 km/h
    assert np.max(v[t > lost_at + p.stop_after + 6.0]) < 0.1  # stopped
    # ... in its lane: the tyres never left it, and the decelerations were comfortable
    tyres = next(c for c in blind.criteria if c.name == "tyres_in_lane")
    assert tyres.passed, tyres
    assert blind.metrics["max_decel"] <= 2.5


def test_results_match_golden(run_scenario: Callable[..., RunResult]) -> None:
    golden.check(run_scenario("normal_driving", record=False, duration=30), "normal_driving.30s")
    golden.check(run_scenario("normal_driving", record=False, duration=30,
                              frame_hook=black_front), "normal_driving.30s_blind_front")

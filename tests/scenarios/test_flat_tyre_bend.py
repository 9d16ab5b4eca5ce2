"""A front tyre goes flat in a bend (`scenarios/acceptance/flat_tyre_bend.yaml`), every point
of its grid: the wheel (each of the four) and the bend's direction (left, right), in a 300 m
bend at 50 km/h in the left lane of two, a car following in the right lane, a 3 m shoulder.

Each test first asserts from the truth that the situation happened: the flat tyre event
fired while the car was in the arc and turning with it (its heading rate near v / R, with
the bend's sign), and the follower was then in the right lane, behind the ego. Then the
stack's answer and the verdicts: no error, no criterion failed, no contact, the tyres in
the lanes (the shoulder counts after the flat), a minimum-risk stop on the shoulder with the
hazard lights on at no more than 4 m/s^2."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from avsim.criteria.route import MRM_DECEL
from avsim.run.runner import RunResult
from avsim.run.verdict import RunVerdict
from world.hdmap import SHOULDER
from world.map.road import build_road_map
from world.sensors.setup import Profile

pytestmark = [pytest.mark.slow, pytest.mark.acceptance]  # the acceptance set: `make acceptance`
FILE = "scenarios/acceptance/flat_tyre_bend.yaml"
WHEEL, ANGLE = "events.0.flat_tire.wheel", "road.segments.1.arc.angle_deg"
ARC_START, RADIUS, ANGLE_DEG = 60.0, 300.0, 60.0  # [m], [m], [deg] the file's bend
ARC_END = ARC_START + RADIUS * np.radians(ANGLE_DEG)  # [m]
EGO = 4.8  # [m] the ego's body
STOPPED = 0.1  # [m/s]
POINTS = [(wheel, angle) for wheel in ("front_left", "front_right", "rear_left", "rear_right")
          for angle in (60, -60)]  # the file's grid, in its order (points 000 to 007)


def _point(run_scenario: Callable[..., RunResult], wheel: str, angle: int) -> RunResult:
    return run_scenario(FILE, record=False, profile=Profile.FAST, **{WHEEL: wheel, ANGLE: angle})


def _fired(result: RunResult) -> float:
    """[s] when the flat tyre event fired (the event's truth)."""
    entry = next(e for e in result.story if e.kind == "flat_tire")
    assert entry.fired_at is not None, "the flat tyre never fired"
    return entry.fired_at


@pytest.mark.parametrize(("wheel", "angle"), POINTS)
def test_the_tyre_went_flat_in_the_bend_with_the_follower_behind_in_the_right_lane(
        run_scenario: Callable[..., RunResult], wheel: str, angle: int) -> None:
    result = _point(run_scenario, wheel, angle)
    log = result.log
    t, s, v, yaw = (log.array(k) for k in ("t", "station", "speed", "yaw"))
    fired = _fired(result)
    i = int(np.searchsorted(t, fired))
    assert ARC_START + EGO < s[i] < ARC_END - EGO  # in the arc
    yaw_rate = np.gradient(np.unwrap(yaw), t)[i - 8:i + 8].mean()  # [rad/s] over 0.4 s
    assert yaw_rate * np.sign(angle) == pytest.approx(v[i] / RADIUS, rel=0.2)
    # the follower: in the right lane (lane 0), behind the ego, when the tyre went
    road = build_road_map(result.scenario.world.road)
    k = [a.id for a in result.scenario.world.actors].index("follower")
    f_s, f_d = float(np.array(log.actor_station)[i, k]), float(np.array(log.actor_offset)[i, k])
    lane0 = road.lane(0)
    assert abs(f_d - float(lane0.offset_at(f_s))) < 0.5 * float(lane0.width_at(f_s))
    assert log.lane[i] == 1 and f_s < s[i] - EGO


@pytest.mark.parametrize(("wheel", "angle"), POINTS)
def test_a_minimum_risk_stop_on_the_shoulder(
        run_scenario: Callable[..., RunResult], wheel: str, angle: int) -> None:
    result = _point(run_scenario, wheel, angle)
    assert result.verdict is RunVerdict.PASS, (result.error, result.criteria)
    log = result.log
    assert log.lane[-1] == SHOULDER and log.array("speed")[-1] < STOPPED and log.hazard[-1]
    c = {r.name: r for r in result.criteria}
    assert c["no_collision"].value == 0 and c["tyres_in_lane"].passed
    assert c["completes"].passed and "minimum-risk" in (c["completes"].note or "")
    mrs = c["minimum_risk_stop"]
    assert mrs.passed and mrs.value is not None and mrs.value <= MRM_DECEL, mrs

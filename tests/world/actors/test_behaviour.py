"""Tests of scripted NPC behaviour (`world.actors.behaviour`): triggers, speed, stop, lateral moves.

Pure kinematics, no PyBullet. The loops follow the world's convention: at step k the clock
reads t = k / 240 s; triggers are checked at t, then the motion is stepped with (t, dt).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field

import pytest

from world.actors.behaviour import LATERAL_ACCEL, NpcMotion, TriggerContext
from world.spec import (
    Action,
    ActionSpec,
    AfterTrigger,
    EgoStationTrigger,
    GapTrigger,
    LaneChangeAction,
    SpeedAction,
    StopAction,
    TimeTrigger,
    Trigger,
)

RATE = 240  # [Hz] physics rate
DT = 1.0 / RATE  # [s]
LANE_WIDTH = 3.5  # [m]
EPS = 1e-9  # [m] or [m/s]: float round-off allowance
ACCEL_TOL = 1e-3  # [m/s^2] round-off allowance on an acceleration from finite differences
FAR = 1e6  # [m] a gap / station that never triggers anything


def lane_offset(lane: int, s: float) -> float:
    """[m] lane centres of a straight road: lane i at 3.5 i left of the reference line."""
    return LANE_WIDTH * lane


def ctx(t: float, ego_s: float = -FAR, gap: float = FAR) -> TriggerContext:
    return TriggerContext(t=t, ego_s=ego_s, gap=gap)


def motion(*actions: tuple[Trigger, Action], speed: float = 10.0, lane: int = 1) -> NpcMotion:
    specs = tuple(ActionSpec(trigger=trigger, action=action) for trigger, action in actions)
    return NpcMotion(s=0.0, offset=lane_offset(lane, 0.0), speed=speed, direction=1,
                     actions=specs)


@dataclass
class Trace:
    """What a run of `simulate` saw: per step (after the step), and the actions started."""

    t: list[float] = field(default_factory=list)  # [s]
    s: list[float] = field(default_factory=list)  # [m]
    offset: list[float] = field(default_factory=list)  # [m]
    speed: list[float] = field(default_factory=list)  # [m/s]
    lateral_speed: list[float] = field(default_factory=list)  # [m/s]
    started: list[tuple[float, int]] = field(default_factory=list)  # (t [s], action index)


def simulate(m: NpcMotion, duration: float, curvature: float = 0.0) -> Trace:
    """Check triggers and step `m` for `duration` [s] of 240 Hz steps (t = k / 240)."""
    trace = Trace()
    for k in range(1, round(duration * RATE) + 1):
        t = k / RATE
        trace.started += [(t, i) for i in m.fire_due(ctx(t), lane_offset)]
        m.step(t, DT, curvature)
        trace.t.append(t)
        trace.s.append(m.s)
        trace.offset.append(m.offset)
        trace.speed.append(m.speed)
        trace.lateral_speed.append(m.lateral_speed)
    return trace


def diffs(values: list[float]) -> list[float]:
    return [b - a for a, b in itertools.pairwise(values)]


# ---------------------------------------------------------------------------------------
# Speed and stop
# ---------------------------------------------------------------------------------------


@pytest.mark.parametrize(("v0", "target", "accel"), [(10.0, 20.0, 2.0), (20.0, 5.0, 3.0)])
def test_speed_action_reaches_target_at_its_accel(v0: float, target: float, accel: float) -> None:
    m = motion((TimeTrigger(1.0), SpeedAction(speed=target, accel=accel)), speed=v0)
    trace = simulate(m, 1.0 + abs(target - v0) / accel + 2.0)

    assert m.fired_at[0] == 1.0
    expected_end = 1.0 + abs(target - v0) / accel  # [s]
    ended = m.ended_at[0]
    assert ended is not None
    assert ended == pytest.approx(expected_end, abs=2 * DT)
    rates = [dv / DT for dv in diffs([v0, *trace.speed])]
    for t, rate in zip(trace.t, rates, strict=True):
        if t < 1.0 or t > ended:
            assert rate == pytest.approx(0.0, abs=ACCEL_TOL), f"speed changed at t = {t}"
        elif t < ended - DT:  # the last step may be partial
            assert abs(rate) == pytest.approx(accel, abs=ACCEL_TOL), f"at t = {t}"
        assert abs(rate) <= accel + ACCEL_TOL
        assert math.copysign(1.0, rate) == math.copysign(1.0, target - v0) or rate == 0.0
    assert trace.speed[-1] == target  # exactly, no overshoot
    i_end = trace.t.index(ended)
    assert trace.speed[i_end] == target
    assert all(v != target for v in trace.speed[:i_end])


def test_stop_brakes_at_6_mps2_to_rest() -> None:
    v0 = 12.0  # [m/s]
    m = motion((TimeTrigger(0.5), StopAction()), speed=v0)
    trace = simulate(m, 4.0)

    rates = [dv / DT for dv in diffs([v0, *trace.speed])]
    braking = [r for t, r in zip(trace.t, rates, strict=True) if 0.5 <= t < 0.5 + v0 / 6.0 - DT]
    assert braking
    assert all(r == pytest.approx(-6.0, abs=ACCEL_TOL) for r in braking)
    assert all(r >= -6.0 - ACCEL_TOL for r in rates)
    assert min(trace.speed) == 0.0  # never negative: it does not reverse
    assert trace.speed[-1] == 0.0
    ended = m.ended_at[0]
    assert ended is not None
    assert ended == pytest.approx(0.5 + v0 / 6.0, abs=2 * DT)
    stopped = trace.t.index(ended)
    assert trace.s[stopped:] == [trace.s[stopped]] * (len(trace.s) - stopped)  # stays put
    # distance braking: v0^2 / (2 a), plus the constant-speed run before the trigger
    travelled = trace.s[-1]
    assert travelled == pytest.approx(v0 * 0.5 + v0**2 / 12.0, abs=v0 * 2 * DT)


# ---------------------------------------------------------------------------------------
# Lane change 1 -> 0 at 2 m/s
# ---------------------------------------------------------------------------------------

LC_START = 0.5  # [s] trigger time
LC_LATERAL = 2.0  # [m/s]
LC_SPEED = 10.0  # [m/s]


@pytest.fixture(scope="module")
def lane_change() -> tuple[NpcMotion, Trace]:
    m = motion((TimeTrigger(LC_START), LaneChangeAction(to_lane=0, lateral_speed=LC_LATERAL)),
               speed=LC_SPEED, lane=1)
    return m, simulate(m, 8.0)


def test_lane_change_offset_moves_monotonically_to_the_target(
    lane_change: tuple[NpcMotion, Trace],
) -> None:
    m, trace = lane_change
    before = [r for t, r in zip(trace.t, trace.offset, strict=True) if t < LC_START]
    assert before == [LANE_WIDTH] * len(before)
    steps = diffs([LANE_WIDTH, *trace.offset])
    assert all(d <= EPS for d in steps), "the offset moved back towards lane 1"
    assert min(trace.offset) >= -EPS, "overshot lane 0's centre"
    assert trace.offset[-1] == pytest.approx(0.0, abs=EPS)
    assert m.lateral_speed == 0.0


def test_lane_change_lateral_speed_is_capped(lane_change: tuple[NpcMotion, Trace]) -> None:
    _, trace = lane_change
    assert max(abs(v) for v in trace.lateral_speed) <= LC_LATERAL + EPS
    assert max(abs(v) for v in trace.lateral_speed) == pytest.approx(LC_LATERAL)  # reaches it


def test_lane_change_lateral_acceleration_is_bounded(lane_change: tuple[NpcMotion, Trace]) -> None:
    _, trace = lane_change
    worst = max(zip(diffs([0.0, *trace.lateral_speed]), trace.t, strict=True),
                key=lambda pair: abs(pair[0]))
    accel, t = abs(worst[0]) / DT, worst[1]
    assert accel <= LATERAL_ACCEL + ACCEL_TOL, (
        f"lateral acceleration {accel:.2f} m/s^2 > {LATERAL_ACCEL} at t = {t:.4f} s"
    )


def test_lane_change_position_never_jumps(lane_change: tuple[NpcMotion, Trace]) -> None:
    _, trace = lane_change
    limit = (LC_SPEED + LC_LATERAL) * DT + EPS  # [m]
    for t, ds, dr in zip(trace.t[1:], diffs(trace.s), diffs(trace.offset), strict=True):
        assert math.hypot(ds, dr) <= limit, f"jump at t = {t}"


def test_lane_change_ends_on_the_target_and_is_marked_ended(
    lane_change: tuple[NpcMotion, Trace],
) -> None:
    m, trace = lane_change
    ended = m.ended_at[0]
    assert ended is not None
    i_end = trace.t.index(ended)
    assert trace.offset[i_end] == pytest.approx(0.0, abs=EPS)  # on the centre when it ends
    assert trace.offset[i_end:] == [trace.offset[i_end]] * (len(trace.offset) - i_end)


def test_lane_change_takes_the_trapezoid_time(lane_change: tuple[NpcMotion, Trace]) -> None:
    m, _ = lane_change
    ended = m.ended_at[0]
    assert ended is not None
    # a trapezoid: ramps of v / a at both ends, the rest at v
    ramp = LC_LATERAL / LATERAL_ACCEL  # [s]
    cruise = (LANE_WIDTH - LC_LATERAL * ramp) / LC_LATERAL  # [s]
    assert ended == pytest.approx(LC_START + 2 * ramp + cruise, abs=0.02)


# ---------------------------------------------------------------------------------------
# Triggers
# ---------------------------------------------------------------------------------------


def run_triggers(m: NpcMotion, contexts: list[TriggerContext]) -> list[tuple[float, int]]:
    """Check triggers at each context in turn, stepping between; (t, index) started."""
    started = []
    for c in contexts:
        started += [(c.t, i) for i in m.fire_due(c, lane_offset)]
        m.step(c.t, DT, 0.0)
    return started


def times(n: int) -> list[float]:
    return [k / RATE for k in range(1, n + 1)]


def test_time_trigger_fires_at_the_first_check_at_or_after_its_time_once() -> None:
    m = motion((TimeTrigger(1.003), SpeedAction(12.0, 1.0)),
               (TimeTrigger(0.5), SpeedAction(12.0, 1.0)))  # t = 0.5 is on the 240 Hz grid
    started = run_triggers(m, [ctx(t) for t in times(3 * RATE)])
    assert started == [(0.5, 1), (math.ceil(1.003 * RATE) / RATE, 0)]
    assert m.fired_at == [math.ceil(1.003 * RATE) / RATE, 0.5]


def test_ego_station_trigger_fires_when_the_ego_reaches_it() -> None:
    m = motion((EgoStationTrigger(100.0), StopAction()))
    stations = [95.0, 99.99, 100.0, 101.0, 200.0]
    started = run_triggers(m, [ctx(t, ego_s=s) for t, s in zip(times(5), stations, strict=True)])
    assert started == [(3 / RATE, 0)]


def test_gap_trigger_fires_when_the_gap_falls_to_it_or_below() -> None:
    m = motion((GapTrigger(20.0), StopAction()))
    gaps = [30.0, 20.001, 20.0, 15.0, 25.0, 10.0]
    started = run_triggers(m, [ctx(t, gap=g) for t, g in zip(times(6), gaps, strict=True)])
    assert started == [(3 / RATE, 0)]

    below = motion((GapTrigger(20.0), StopAction()))
    assert run_triggers(below, [ctx(1 / RATE, gap=5.0)]) == [(1 / RATE, 0)]


def test_after_trigger_fires_delay_after_the_action_ended_and_not_before() -> None:
    m = motion(
        (TimeTrigger(1.0), SpeedAction(speed=15.0, accel=5.0)),  # 10 -> 15 m/s: ends ~2 s
        (AfterTrigger(index=0, delay=2.0), StopAction()),
    )
    trace = simulate(m, 6.0)
    ended = m.ended_at[0]
    assert ended is not None
    assert ended == pytest.approx(2.0, abs=2 * DT)
    due = ended + 2.0
    expected = min(t for t in trace.t if t >= due)
    assert trace.started == [(1.0, 0), (expected, 1)]
    assert m.fired_at[1] == expected
    assert expected - due < DT + EPS


def test_after_trigger_waits_for_an_action_that_never_ends() -> None:
    m = motion(
        (TimeTrigger(0.1), SpeedAction(speed=30.0, accel=0.5)),  # still accelerating at 5 s
        (AfterTrigger(index=0, delay=0.0), StopAction()),
    )
    trace = simulate(m, 5.0)
    assert m.ended_at[0] is None
    assert trace.started == [(0.1, 0)]


# ---------------------------------------------------------------------------------------
# Replacing a running action
# ---------------------------------------------------------------------------------------


def test_second_lateral_action_replaces_and_ends_the_running_one() -> None:
    m = motion(
        (TimeTrigger(1.0), LaneChangeAction(to_lane=0, lateral_speed=2.0)),  # ~3 s long
        (TimeTrigger(2.0), LaneChangeAction(to_lane=2, lateral_speed=2.0)),
        (TimeTrigger(2.5), SpeedAction(speed=12.0, accel=1.0)),  # another kind: no effect
    )
    trace = simulate(m, 12.0)
    assert m.fired_at[:2] == [1.0, 2.0]
    assert m.ended_at[0] == 2.0  # ended by the replacement, when it fired
    i_switch = trace.t.index(2.0)
    assert 0.0 < trace.offset[i_switch] < LANE_WIDTH  # it was mid-move
    ended = m.ended_at[1]
    assert ended is not None and ended > 2.0
    assert trace.offset[-1] == pytest.approx(2 * LANE_WIDTH, abs=EPS)
    assert max(trace.offset) <= 2 * LANE_WIDTH + EPS
    # the lateral speed reverses smoothly, without a jump at the switch
    around = slice(i_switch - 2, i_switch + 3)
    jumps = diffs(trace.lateral_speed[around])
    assert all(abs(j) <= LATERAL_ACCEL * DT + EPS for j in jumps)


def test_stop_replaces_and_ends_a_running_speed_action() -> None:
    m = motion(
        (TimeTrigger(0.5), SpeedAction(speed=30.0, accel=1.0)),
        (TimeTrigger(1.0), StopAction()),
        (TimeTrigger(0.2), LaneChangeAction(to_lane=0, lateral_speed=1.0)),  # still running
    )
    simulate(m, 1.5)
    assert m.ended_at[0] == 1.0
    assert m.ended_at[2] is None  # a longitudinal action does not end a lateral one


# ---------------------------------------------------------------------------------------
# Station rate on a curve
# ---------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("curvature", "offset", "direction"),
    [
        (0.0, 3.5, 1),
        (1 / 50, 3.5, 1),  # left curve, on its inside: more station per metre driven
        (1 / 50, -3.5, 1),  # left curve, outside
        (-1 / 250, 7.0, 1),  # right curve, outside
        (1 / 80, 3.5, -1),  # against the route
    ],
)
def test_station_advances_at_v_over_one_minus_k_r(
    curvature: float, offset: float, direction: int
) -> None:
    v = 12.0  # [m/s]
    m = NpcMotion(s=100.0, offset=offset, speed=v, direction=direction, actions=())
    n = 2 * RATE
    for k in range(1, n + 1):
        m.step(k / RATE, DT, curvature)
    expected = 100.0 + direction * n * v * DT / (1.0 - curvature * offset)
    assert m.s == pytest.approx(expected, rel=1e-12)
    assert m.offset == offset
    assert m.speed == v

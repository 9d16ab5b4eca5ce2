"""The driver's pedal as a speed limiter: the reference never exceeds the envelope, the
feed-forward fades near it, and a release ramps back to the plan."""

from __future__ import annotations

import pytest

from planner.driver_override import DriverOverride, OverrideParams, override_reference
from planner.messages import SpeedSource
from planner.speed import PlannedSpeed, SpeedRef
from planner.speed_planning import Binding, SpeedTarget

P = OverrideParams()
LIMIT = 40 / 3.6


def cap(speed: float = LIMIT, accel: float = 0.0) -> SpeedTarget:
    return SpeedTarget(speed, accel, LIMIT, Binding.LIMIT, 0.0)


def test_full_pedal_far_below_the_limit_asks_for_full_acceleration() -> None:
    out = override_reference(1.0, 5.0, cap(), P)
    assert out.source is SpeedSource.PEDAL  # the pedal, not the limit, sets the speed
    ref = out.ref
    assert ref.accel == pytest.approx(P.a_full)
    assert ref.speed == pytest.approx(5.0 + P.a_full * P.horizon)
    half = override_reference(0.5, 5.0, cap(), P).ref
    assert half.accel == pytest.approx(0.5 * P.a_full)


def test_near_the_limit_the_feed_forward_fades_and_the_speed_is_capped() -> None:
    out = override_reference(1.0, LIMIT - 1.0, cap(), P)
    assert out.source is SpeedSource.LIMIT  # the envelope binds: the posted limit
    ref = out.ref
    assert ref.speed == pytest.approx(LIMIT)
    assert ref.accel == pytest.approx(1.0 / P.tau)
    at = override_reference(1.0, LIMIT + 0.1, cap(), P).ref
    assert at.speed == pytest.approx(LIMIT) and at.accel == 0.0


def test_a_braking_envelope_wins() -> None:
    out = override_reference(1.0, 12.0, cap(8.0, -1.5), P)
    assert out == PlannedSpeed(SpeedRef(8.0, -1.5), SpeedSource.LIMIT)


def test_closed_loop_point_mass_reaches_the_limit_without_overshoot() -> None:
    d, v, dt = DriverOverride(P), 30 / 3.6, 0.025
    plan = PlannedSpeed(SpeedRef(30 / 3.6, 0.0), SpeedSource.SET_SPEED)
    peak = v
    for _ in range(int(5.0 / dt)):  # a perfect speed loop: a = a_ff + (v_ref - v) / 0.8 s
        out, driver = d.update(1.0, v, plan, cap, dt)
        ref = out.ref
        assert driver
        v += (ref.accel + (ref.speed - v) / 0.8) * dt
        peak = max(peak, v)
    assert LIMIT - 0.05 < peak <= LIMIT + 0.01
    # released: back to the plan at a_release, then the plan itself
    out, driver = d.update(0.0, v, plan, cap, dt)
    ref = out.ref
    assert not driver and ref.speed == pytest.approx(max(peak, v) - P.a_release * dt, abs=0.02)
    assert ref.accel == -P.a_release and out.source is SpeedSource.PEDAL  # the ramp back
    for _ in range(int(4.0 / dt)):
        out, _ = d.update(0.0, v, plan, cap, dt)
    assert out == plan


def test_no_pedal_is_the_plan() -> None:
    plan = PlannedSpeed(SpeedRef(8.0, 0.0), SpeedSource.CURVE)
    assert DriverOverride(P).update(0.04, 8.0, plan, cap, 0.025) == (plan, False)

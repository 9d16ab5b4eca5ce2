"""A SpeedAction on a vehicle within its Performance (`Commands.speed`): the target within
its maxSpeed, a transition whose peak acceleration exceeds maxAcceleration (speeding up) or
maxDeceleration (slowing down) stretched in time until its peak is that limit, as esmini
plays it (NCAP CBLA's bicycle asks 2.48 m/s^2 of a vehicle that can do 2)."""

from __future__ import annotations

import math

import pytest

from avsim.run.storyboard.commands import Commands, Limits
from avsim.run.storyboard.snapshot import EntityState, Snapshot
from avsim.scenario.openscenario.actions import (
    AbsoluteTargetSpeed,
    DynamicsDimension,
    DynamicsShape,
    SpeedAction,
    TransitionDynamics,
)

BICYCLE = Limits(max_speed=14.0, max_accel=2.0, max_decel=10.0)


def _span_and_target(start: float, target: float, shape: DynamicsShape,
                     dimension: DynamicsDimension, value: float,
                     limits: Limits | None = BICYCLE) -> tuple[float, float]:
    me = EntityState(name="VRU", x=0.0, y=0.0, heading=0.0, speed=start, s=0.0, offset=0.0,
                     lane=0, route_heading=0.0, length=1.89, width=0.5, centre_ahead=0.605,
                     odometer=0.0, standing_for=0.0, off_road_for=0.0, end_of_road_for=0.0)
    action = SpeedAction(TransitionDynamics(shape, dimension, value, None),
                         AbsoluteTargetSpeed(target))
    commands = Commands.__new__(Commands)  # `speed` reads only the snapshot
    cmd = commands.speed("go", action, me, Snapshot(0.0, {"VRU": me}, {}), limits)
    return cmd.transition.span, cmd.transition.target


def test_a_linear_change_faster_than_max_acceleration_takes_longer() -> None:
    """0 to 15 km/h in 1.68 s asks 2.48 m/s^2; at 2 m/s^2 it takes 2.083 s."""
    v = 15.0 / 3.6
    span, _ = _span_and_target(0.0, v, "linear", "time", 2.0 * 3.5 / v)
    assert span == pytest.approx(v / 2.0)


def test_without_limits_the_change_keeps_its_time() -> None:
    v = 15.0 / 3.6
    span, _ = _span_and_target(0.0, v, "linear", "time", 2.0 * 3.5 / v, limits=None)
    assert span == pytest.approx(2.0 * 3.5 / v)


def test_a_change_within_the_limits_keeps_its_time() -> None:
    """0 to 4 m/s in 4 s is 1 m/s^2: within the bicycle's 2."""
    span, _ = _span_and_target(0.0, 4.0, "linear", "time", 4.0)
    assert span == pytest.approx(4.0)


@pytest.mark.parametrize(("shape", "peak_slope"), [("sinusoidal", 0.5 * math.pi),
                                                   ("cubic", 1.5)])
def test_a_shaped_change_is_stretched_until_its_peak_is_the_limit(
        shape: DynamicsShape, peak_slope: float) -> None:
    """10 to 0 m/s in 0.5 s peaks far beyond 10 m/s^2 of deceleration: stretched until
    its peak (change x peak slope / span) is 10 m/s^2."""
    span, _ = _span_and_target(10.0, 0.0, shape, "time", 0.5)
    assert span == pytest.approx(10.0 * peak_slope / 10.0)


def test_a_rate_beyond_the_limit_is_the_limit() -> None:
    span, _ = _span_and_target(0.0, 4.0, "linear", "rate", 8.0)
    assert span == pytest.approx(4.0 / 2.0)


def test_a_step_changes_at_once() -> None:
    span, target = _span_and_target(0.0, 4.0, "step", "time", 0.0)
    assert (span, target) == (0.0, 4.0)


def test_the_target_is_within_max_speed() -> None:
    """20 m/s asked of a bicycle that rides at most 14 m/s, from 13 m/s at 1 m/s^2: 1 s."""
    span, target = _span_and_target(13.0, 20.0, "linear", "rate", 1.0)
    assert target == 14.0
    assert span == pytest.approx(1.0)

"""The emergency braking's threat from the lead (`planner.control_layer`): the time to
collision at the closing speed, an oncoming car's included."""

from __future__ import annotations

import math

import pytest

from planner.control_layer import ControlLayer, lead_gap_now
from planner.fsm.control import ControlState
from planner.messages import Lead

V60 = 60.0 / 3.6  # [m/s]


@pytest.mark.parametrize(("velocity", "ttc"), [
    (-V60, 1.5),  # head-on at 60 km/h each: the gap closes at 120 km/h
    (0.0, 3.0),  # a standing car
    (0.5 * V60, 6.0),  # a car ahead at 30 km/h
])
def test_the_time_to_collision_closes_at_the_ego_speed_less_the_leads_signed_velocity(
        velocity: float, ttc: float) -> None:
    lead = Lead(1, 0.0, 50.0, max(velocity, 0.0), velocity)
    out, _ = ControlLayer().update(0.0, V60, V60, 0.0, lead, 0.0)
    assert out.ttc == pytest.approx(ttc)


def test_an_oncoming_car_within_the_emergency_ttc_is_an_emergency_and_taken_as_standing_it_is_not(
        ) -> None:
    """38 m apart at 60 km/h each: 1.14 s to collision (ttc_emergency 1.2 s); taken as
    standing, 2.3 s and a deceleration of 3.8 m/s^2 needed: no emergency yet."""
    def state(lead: Lead) -> ControlState:
        layer = ControlLayer()
        layer.update(0.0, V60, V60, 0.0, None, 0.0)  # under way: SPEED_KEEPING
        return layer.update(0.05, V60, V60, 0.0, lead, 0.0)[0].state
    assert state(Lead(1, 0.05, 38.0, 0.0, -V60)) is ControlState.EMERGENCY_STOP
    assert state(Lead(1, 0.05, 38.0, 0.0)) is not ControlState.EMERGENCY_STOP


def test_the_deceleration_needed_takes_an_oncoming_car_as_standing() -> None:
    """Braking sheds only the ego's speed: v^2 / (2 (d - stop_gap))."""
    out, _ = ControlLayer().update(0.0, V60, V60, 0.0, Lead(1, 0.0, 50.0, 0.0, -V60), 0.0)
    assert out.a_required == pytest.approx(V60 ** 2 / (2.0 * 49.0))


@pytest.mark.parametrize(("velocity", "gap"), [(-V60, 50.0 - 2.0 * V60 * 0.1),
                                               (0.0, 50.0 - V60 * 0.1),
                                               (V60, 50.0)])
def test_the_gap_is_carried_over_the_tracks_age_at_the_closing_speed(velocity: float,
                                                                     gap: float) -> None:
    lead = Lead(1, 1.0, 50.0, max(velocity, 0.0), velocity)
    assert lead_gap_now(lead, 1.1, V60) == pytest.approx(gap)
    assert math.isclose(lead_gap_now(lead, 0.9, V60), 50.0)  # a track from the future: as is

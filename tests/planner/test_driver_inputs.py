"""The driver's set speed, held speed and brake override under the stack
(`planner.driver_inputs`)."""

from __future__ import annotations

import pytest

from planner.driver_inputs import DriverInputs, DriverParams
from planner.messages import SpeedSource
from world.frames import DriverControls

P = DriverParams()
DT = 0.025  # [s] a control tick


def test_no_input_keeps_the_configured_set_speed_and_holds_it() -> None:
    d = DriverInputs(20.0, 50.0)
    d.update(DriverControls(), 20.0, DT)
    assert d.set_speed == 20.0 and not d.overridden
    out = d.driving(DriverControls(), 20.0)
    assert (out.ref.speed, out.ref.accel, out.source) == (20.0, 0.0, SpeedSource.DRIVER)


def test_a_chosen_set_speed_is_the_acc_s_target_capped_at_the_maximum() -> None:
    d = DriverInputs(20.0, 30.0)
    d.update(DriverControls(set_speed=25.0), 20.0, DT)
    assert d.set_speed == 25.0
    d.update(DriverControls(set_speed=40.0), 20.0, DT)
    assert d.set_speed == 30.0


def test_off_the_driver_ramps_his_held_speed_at_the_comfortable_rate() -> None:
    d = DriverInputs(20.0, 50.0)
    controls = DriverControls(set_speed=15.0)
    for _ in range(40):  # 1 s
        d.update(controls, 20.0, DT)
    out = d.driving(controls, 20.0)
    assert out.ref.speed == pytest.approx(20.0 - P.rate * 1.0)
    assert out.ref.accel == -P.rate
    for _ in range(400):
        d.update(controls, 20.0, DT)
    assert d.driving(controls, 20.0).ref == d.driving(controls, 15.0).ref
    assert d.held == 15.0


def test_the_brake_overrides_until_the_driver_switches_the_function_on_again() -> None:
    d = DriverInputs(20.0, 50.0)
    pressed = DriverControls(brake=0.5)
    d.update(pressed, 20.0, DT)
    assert d.overridden
    out = d.driving(pressed, 20.0)
    assert out.ref.accel == -0.5 * P.a_full and out.ref.speed < 20.0
    released = DriverControls()
    d.update(released, 12.0, DT)
    assert d.overridden  # still off after the release ...
    assert d.driving(released, 12.0).ref.speed == 12.0  # ... holding the release speed
    d.update(DriverControls(activations=1), 12.0, DT)
    assert not d.overridden  # the switch pressed: on again


def test_a_light_touch_below_the_threshold_does_not_override() -> None:
    d = DriverInputs(20.0, 50.0)
    d.update(DriverControls(brake=P.threshold), 20.0, DT)
    assert not d.overridden


@pytest.mark.parametrize(("lead_speed", "holds"), [
    (0.0, True),  # the car the AEB stopped for still stands there
    (0.5, True),  # creeping: not yet clear
    (-3.0, True),  # coming towards the car
    (P.clear_speed, False),  # moving away
    (None, False),  # no vehicle ahead in the lane
])
def test_after_an_emergency_stop_the_driver_holds_the_car_until_the_way_is_clear(
        lead_speed: float | None, holds: bool) -> None:
    d = DriverInputs(20.0, 50.0)
    d.update(DriverControls(), 0.0, DT)
    d.emergency_stopped()
    assert d.driving(DriverControls(), 0.0).ref.speed == 0.0
    for _ in range(40):  # 1 s
        d.way_clear(lead_speed)
        d.update(DriverControls(), 0.0, DT)
    out = d.driving(DriverControls(), 0.0)
    assert d.aeb_hold is holds
    if holds:
        assert (out.ref.speed, out.ref.accel) == (0.0, 0.0)
    else:  # moving off towards the set speed at the comfortable rate
        assert out.ref.speed == pytest.approx(P.rate * 1.0) and out.ref.accel == P.rate

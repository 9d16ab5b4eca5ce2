"""PID unit behaviour: P, I, D (with low-pass and no kick), clamp, conditional hold, reset."""

from __future__ import annotations

import pytest

from control.pid import Pid, PidParams


def test_proportional_only() -> None:
    pid = Pid(PidParams(kp=3.0))
    assert pid.update(2.0, 0.1) == pytest.approx(6.0)
    assert pid.update(-1.0, 0.1) == pytest.approx(-3.0)


def test_integral_accumulates_error_times_dt() -> None:
    pid = Pid(PidParams(kp=0.0, ki=2.0))
    outputs = [pid.update(1.0, 0.1) for _ in range(5)]
    assert outputs == pytest.approx([0.2, 0.4, 0.6, 0.8, 1.0])
    assert pid.integral_term == pytest.approx(1.0)


def test_integral_term_is_clamped_both_ways_and_recovers_at_once() -> None:
    pid = Pid(PidParams(kp=0.0, ki=1.0, integral_limit=0.3))
    for _ in range(100):
        out = pid.update(1.0, 0.1)
    assert out == pytest.approx(0.3)
    # anti-windup: no stored excess, so one step of opposite error moves the output down now
    assert pid.update(-1.0, 0.1) == pytest.approx(0.2)
    for _ in range(100):
        out = pid.update(-1.0, 0.1)
    assert out == pytest.approx(-0.3)


def test_integrate_false_holds_the_integral() -> None:
    pid = Pid(PidParams(kp=0.0, ki=1.0))
    pid.update(1.0, 0.5)
    assert pid.update(1.0, 0.5, integrate=False) == pytest.approx(0.5)
    assert pid.update(1.0, 0.5) == pytest.approx(1.0)


def test_derivative_has_no_kick_on_first_step_then_backward_difference() -> None:
    pid = Pid(PidParams(kp=0.0, kd=1.0))
    assert pid.update(5.0, 0.1) == 0.0
    assert pid.update(6.0, 0.1) == pytest.approx(10.0)
    assert pid.update(6.0, 0.1) == pytest.approx(0.0)


def test_derivative_low_pass() -> None:
    # tau = dt -> alpha = 1/2: a step in the raw derivative shows half, then decays by half
    pid = Pid(PidParams(kp=0.0, kd=1.0, derivative_tau=0.1))
    pid.update(0.0, 0.1)
    assert pid.update(1.0, 0.1) == pytest.approx(5.0)
    assert pid.update(1.0, 0.1) == pytest.approx(2.5)
    assert pid.update(1.0, 0.1) == pytest.approx(1.25)


def test_reset_clears_integral_and_derivative() -> None:
    pid = Pid(PidParams(kp=1.0, ki=1.0, kd=1.0))
    pid.update(0.0, 0.1)
    pid.update(2.0, 0.1)
    pid.reset()
    assert pid.integral_term == 0.0
    assert pid.derivative == 0.0
    # first step after reset: P plus one step of I, no derivative from the old error
    assert pid.update(1.0, 0.1) == pytest.approx(1.0 + 0.1)


@pytest.mark.parametrize("dt", [0.0, -0.1, float("nan")])
def test_non_positive_dt_is_rejected(dt: float) -> None:
    with pytest.raises(ValueError, match="dt"):
        Pid(PidParams(kp=1.0)).update(1.0, dt)


def test_bad_params_are_rejected() -> None:
    with pytest.raises(ValueError, match="integral_limit"):
        PidParams(kp=1.0, integral_limit=-1.0)
    with pytest.raises(ValueError, match="derivative_tau"):
        PidParams(kp=1.0, derivative_tau=-0.1)

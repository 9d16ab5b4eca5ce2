"""The ACC / event controllers: following, eased hard braking, stopping and passing."""

from __future__ import annotations

import itertools
import math

import pytest

from planner.acc_control import (
    AccControlParams,
    EasedBrake,
    braking_need,
    pass_speed,
    stop_speed,
    trail,
)

P = AccControlParams()


def test_trail_closes_the_gap_error_and_never_exceeds_the_plan() -> None:
    d0 = 4.0
    assert trail(30.0, 40.0, 40.0, 20.0, d0, P).speed == pytest.approx(20.0)  # at d_des: v_l
    assert trail(30.0, 48.0, 40.0, 20.0, d0, P).speed == pytest.approx(22.0)  # far: faster
    assert trail(30.0, 32.0, 40.0, 20.0, d0, P).speed == pytest.approx(18.0)  # close: slower
    assert trail(19.0, 48.0, 40.0, 20.0, d0, P).speed == 19.0  # the map's plan caps it
    assert trail(30.0, 5.0, 40.0, 1.0, d0, P).speed == 0.0  # never backwards
    assert trail(30.0, 40.0, 40.0, 20.0, d0, P).accel == 0.0
    # far behind a moving lead the braking curve to d0 binds
    assert trail(30.0, 60.0, d0, 0.6, d0, P).speed == pytest.approx(
        math.sqrt(0.36 + 3.0 * 56.0))
    # behind a stopped lead: the final approach, to rest 1 m beyond d0
    assert trail(30.0, d0 + 3.0, 5.0, 0.0, d0, P).speed == pytest.approx(math.sqrt(2.0))
    assert trail(30.0, d0 + 1.0, d0, 0.0, d0, P).speed == 0.0
    assert trail(30.0, d0 + 1.0, d0, 1.0, d0, P).speed > 0.0  # it moves off with the lead


def test_braking_need() -> None:
    # 20 -> 10 m/s with 30 m to go to d_stop: (400 - 100) / 60 = 5 m/s^2 (the cap)
    assert braking_need(20.0, 10.0, 32.0, P) == pytest.approx(5.0)
    assert braking_need(15.0, 10.0, 27.0, P) == pytest.approx(125.0 / 50.0)
    assert braking_need(10.0, 12.0, 20.0, P) == 0.0  # the lead is faster: nothing needed
    assert braking_need(30.0, 0.0, 1.0, P) == P.a_hard  # the cap


def test_hard_braking_eases_in_and_releases_at_once() -> None:
    brake, dt, v = EasedBrake(), 0.025, 20.0
    refs = [brake.step(v, 4.0, dt, P) for _ in range(60)]
    decel = [-r.accel for r in refs]
    assert decel[0] == pytest.approx(P.j_in * dt)  # no step: it starts small
    assert all(b - a <= P.j_in * dt + 1e-12 for a, b in itertools.pairwise(decel))
    assert decel[-1] == pytest.approx(4.0)  # and reaches the need within a second
    assert decel.index(4.0) * dt == pytest.approx(4.0 / P.j_in, abs=dt)
    assert refs[-1].speed == pytest.approx(v - 4.0 * dt)  # the reference follows the plan
    assert -brake.step(v, 1.0, dt, P).accel == 1.0  # less needed: at once
    assert -brake.step(v, 9.0, dt, P, cap=3.5).accel <= 3.5  # a mode's own cap


def test_stop_and_pass_speeds() -> None:
    assert stop_speed(0.5, 20.0, P) == 0.0  # within the margin: stopped
    assert stop_speed(P.margin + 0.25, 20.0, P) == 0.0  # within `arrived`: it has arrived
    assert stop_speed(P.margin + 0.35, 20.0, P) == pytest.approx(math.sqrt(2 * 1.5 * 0.35))
    assert stop_speed(P.margin + 30.0, 50.0, P) == pytest.approx(math.sqrt(2 * 1.5 * 30.0))
    assert stop_speed(500.0, 12.0, P) == 12.0  # far away: the plan
    v_pass = 5.0 / 3.6
    assert pass_speed(P.margin, v_pass, 20.0, P) == pytest.approx(v_pass)
    assert pass_speed(P.margin + 20.0, v_pass, 20.0, P) == pytest.approx(
        math.sqrt(v_pass**2 + 60.0))

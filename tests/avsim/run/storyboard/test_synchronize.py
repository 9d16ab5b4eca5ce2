"""The SynchronizeAction speed law on its own: a master at constant speed towards its
target, the actor integrated at the check period; the actor arrives when the master does
(within one check), at the final speed, through each of esmini's profiles."""

from __future__ import annotations

import pytest

from avsim.run.storyboard.synchronize import Mode, Synchronizer, SyncInput

DT = 0.025  # [s] the check period


def play(d0: float, v0: float, master_d0: float, master_v: float, vf: float | None,
         steady: float | None = None, steady_time: float | None = None
         ) -> tuple[float, float, float, set[Mode]]:
    """(the actor's distance left when done [m], the master's [m], the actor's speed then
    [m/s], the modes it went through)."""
    law = Synchronizer(0.0, 0.0, steady, steady_time)
    d, m, v = d0, master_d0, v0
    modes = set()
    for _ in range(100_000):
        v, done = law.step(SyncInput(d, m, v, master_v, vf), DT)
        modes.add(law.mode)
        if done:
            return d, m, v, modes
        d -= v * DT
        m -= master_v * DT
    raise AssertionError("never done")


@pytest.mark.parametrize(("v0", "vf", "mode"), [
    (5.0, 8.0, Mode.NON_LINEAR),  # 90 m in 10 s from 5: rush, then slow to 8
    (12.0, 6.0, Mode.NON_LINEAR),  # from 12 to 6: linger, then speed up
    (12.0, 6.0, Mode.LINEAR),
])
def test_the_actor_arrives_with_the_master_at_the_final_speed(v0: float, vf: float,
                                                              mode: Mode) -> None:
    d, m, v, modes = play(90.0, v0, 150.0, 15.0, vf)
    assert m < 15.0 * DT + 1e-9  # the master arrives within this check
    assert d == pytest.approx(0.0, abs=vf * DT + 0.05)  # and so does the actor, to a check
    assert v == vf
    assert mode in modes


def test_one_that_would_arrive_far_too_early_stops_and_waits() -> None:
    d, _m, v, modes = play(20.0, 10.0, 300.0, 15.0, 5.0)
    assert {Mode.STOPPED} <= modes or {Mode.STOP_IMMEDIATELY} <= modes
    assert d == pytest.approx(0.0, abs=0.3)
    assert v == 5.0


def test_without_a_final_speed_the_average_is_kept() -> None:
    d, _m, _v, modes = play(60.0, 4.0, 150.0, 15.0, None)
    assert d == pytest.approx(0.0, abs=0.1)
    assert modes == {Mode.LINEAR}


def test_a_steady_state_reaches_the_final_speed_that_far_before() -> None:
    law = Synchronizer(0.0, 0.0, 20.0, None)
    d, m, v = 90.0, 150.0, 5.0
    reached_at = None
    while True:
        v, done = law.step(SyncInput(d, m, v, 15.0, 8.0), DT)
        if law.mode is Mode.STEADY_STATE and reached_at is None:
            reached_at = d
        if done:
            break
        d -= v * DT
        m -= 15.0 * DT
    assert reached_at == pytest.approx(20.0, abs=0.5)
    assert d == pytest.approx(0.0, abs=8.0 * DT + 0.05)


def test_the_actor_waits_while_the_master_stands() -> None:
    law = Synchronizer(0.0, 0.0, None, None)
    assert law.step(SyncInput(50.0, 80.0, 6.0, 0.0, 8.0), DT) == (0.0, False)
    assert law.mode is Mode.WAITING


def test_a_standing_master_stops_the_actor_and_the_law_goes_on_from_rest() -> None:
    """With a steady state, the endless master time less the steady state's time is a
    finite one: the profile is chosen in the same check (esmini), not at the next."""
    law = Synchronizer(0.0, 0.0, None, 4.0)
    assert law.step(SyncInput(155.0, 150.0, 19.0, 0.0, 19.0), DT) == (0.0, False)
    assert law.mode is Mode.NON_LINEAR
    assert not law.convex  # against an endless time: concave


def test_an_action_opening_the_storyboard_holds_its_actor_for_the_first_check() -> None:
    """esmini's opening frame (every velocity 0): the actor stands for the first check,
    reaches the apex at once and goes on linear: 2 s / t - vf at the next check, s and t
    less the steady state's share."""
    law = Synchronizer(0.0, 0.0, None, 4.0, opening=True)
    d, m, v, vm, vf = 155.6, 151.9, 19.4, 19.4, 19.4
    assert law.step(SyncInput(d, m, v, vm, vf), DT) == (0.0, False)
    assert law.mode is Mode.LINEAR
    m -= vm * DT
    v, done = law.step(SyncInput(d, m, 0.0, vm, vf), DT)
    s, t = d - 4.0 * vf, m / vm - 4.0
    assert not done
    assert v == pytest.approx(2.0 * s / t - vf)
    assert v > vf


def test_without_the_opening_the_actor_keeps_moving_from_its_speed() -> None:
    law = Synchronizer(0.0, 0.0, None, 4.0)
    v, _ = law.step(SyncInput(155.6, 151.9, 19.4, 19.4, 19.4), DT)
    assert v > 19.4
    assert law.mode is Mode.NON_LINEAR

"""The ICCAS C-FSM: the threat measures, and every transition of its table as a table row,
with rows that must not fire beside them (hysteresis, thresholds, a stopped car)."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

from planner.fsm import control
from planner.fsm.control import (
    EDGES,
    TABLE,
    ControlInput,
    ControlParams,
    ControlState,
    required_deceleration,
    time_to_collision,
    transition,
)
from tests.planner.fsm.tables import doc_shows_table, unwalked_rows

P = ControlParams()
S = ControlState
STOP, ESTOP = S.STOP, S.EMERGENCY_STOP
ACCEL, DECEL, KEEP = S.ACCELERATION, S.DECELERATION, S.SPEED_KEEPING
INF = math.inf


def x(**kw: object) -> ControlInput:
    """Defaults: 10 m/s on a 10 m/s target, a steady plan, no lead."""
    base = ControlInput(v=10.0, v_target=10.0)
    return replace(base, **kw)  # type: ignore[arg-type]


def test_required_deceleration_braking_lead() -> None:
    # 13.9 m/s (50 km/h) 10 m behind a 10 m/s lead braking at 6 m/s^2: it stops in
    # 100 / 12 = 8.33 m, the ego must stop in 10 + 8.33 - 1 = 17.33 m: 193.21 / 34.67
    a = required_deceleration(13.9, 10.0, 10.0, -6.0)
    assert a == pytest.approx(13.9**2 / (2.0 * (10.0 + 100.0 / 12.0 - 1.0)))
    assert a == pytest.approx(5.5734, abs=1e-4)
    assert a > 3.9**2 / 18.0  # the constant-speed term (0.845) is the smaller one
    # same speeds, 30 m: the lead stops in 10 m, the ego within 39 m
    assert required_deceleration(10.0, 30.0, 10.0, -5.0) == pytest.approx(100.0 / 78.0)
    assert required_deceleration(10.0, 30.0, 10.0, -5.0, d_stop=5.0) == pytest.approx(
        100.0 / 70.0)


def test_required_deceleration_closing_at_constant_lead_speed() -> None:
    # 20 m/s, 11 m behind a 15 m/s lead: shed 5 m/s within 10 m, 25 / 20 = 1.25; the lead's
    # 0.6 m/s^2 (it stops in 187.5 m) asks only 400 / 395 = 1.01
    assert required_deceleration(20.0, 11.0, 15.0, -0.6) == pytest.approx(1.25)
    assert required_deceleration(20.0, 11.0, 15.0, 0.0) == pytest.approx(1.25)
    # a gap at or inside d_stop counts as 0.1 m: 2^2 / 0.2
    assert required_deceleration(5.0, 0.5, 3.0, 0.0) == pytest.approx(20.0)
    assert required_deceleration(10.0, 0.5, 0.0, -6.0) == pytest.approx(500.0)


def test_required_deceleration_none() -> None:
    assert required_deceleration(10.0, 20.0, 12.0, 0.0) == 0.0  # opening, the lead steady
    assert required_deceleration(10.0, 20.0, 12.0, -0.4) == 0.0  # easing off is not braking
    assert required_deceleration(10.0, 20.0, 10.0, 1.0) == 0.0  # same speed
    assert required_deceleration(10.0, INF, INF, 0.0) == 0.0  # no lead
    assert required_deceleration(10.0, INF, INF, -6.0) == 0.0
    assert required_deceleration(0.0, 5.0, 0.0, -6.0) == 0.0  # standing still
    # a lead coming towards the ego (v_l < 0): the closing speed is 9 m/s
    assert required_deceleration(8.0, 20.0, -1.0, -2.0) == pytest.approx(81.0 / 38.0)


def test_time_to_collision() -> None:
    assert time_to_collision(10.0, 13.9, 10.0) == pytest.approx(10.0 / 3.9)
    assert time_to_collision(10.0, 13.9, 10.0) == pytest.approx(2.5641, abs=1e-4)
    assert time_to_collision(20.0, 10.0, 0.0) == pytest.approx(2.0)
    assert time_to_collision(20.0, 10.0, 10.0) == INF  # same speed
    assert time_to_collision(20.0, 10.0, 12.0) == INF  # opening
    assert time_to_collision(INF, 10.0, INF) == INF  # no lead
    assert time_to_collision(0.0, 10.0, 5.0) == 0.0  # touching
    assert time_to_collision(-0.5, 10.0, 12.0) == 0.0


def test_params_have_hysteresis() -> None:
    assert P.a_emergency_exit < P.a_emergency_enter
    assert P.v_stopped < P.v_start
    assert P.keep_band < P.speed_band


def test_state_values() -> None:
    assert [s.value for s in S] == ["stop", "emergency_stop", "acceleration", "deceleration",
                                    "speed_keeping"]


# (name, from, input, expected next state or None to stay)
TABLE_CASES = [
    # any but EMERGENCY_STOP -> EMERGENCY_STOP, moving only
    ("stop_estop_a", STOP, x(v=0.3, v_target=0.0, a_required=6.0), ESTOP),
    ("stop_estop_ttc", STOP, x(v=P.v_stopped, v_target=0.0, ttc=0.5), ESTOP),
    ("accel_estop_a_at_threshold", ACCEL, x(a_required=5.0), ESTOP),
    ("accel_estop_ttc", ACCEL, x(v_target=12.0, a_target=1.0, ttc=1.0), ESTOP),
    ("decel_estop_a", DECEL, x(v_target=8.0, a_required=6.0), ESTOP),
    ("decel_estop_ttc", DECEL, x(ttc=1.19), ESTOP),
    ("keep_estop_a", KEEP, x(a_required=5.5), ESTOP),
    ("keep_estop_ttc_touching", KEEP, x(ttc=0.0), ESTOP),
    ("keep_estop_before_speeding_up", KEEP, x(v_target=20.0, a_required=6.0), ESTOP),
    # ... but not below the thresholds (the exit ones included: hysteresis)
    ("keep_no_estop_a_hysteresis", KEEP, x(a_required=3.0), None),
    ("keep_no_estop_a_below", KEEP, x(a_required=4.99), None),
    ("keep_no_estop_ttc_at_threshold", KEEP, x(ttc=1.2), None),
    ("keep_no_estop_ttc_hysteresis", KEEP, x(ttc=2.0), None),
    ("accel_no_estop_hysteresis", ACCEL, x(v_target=12.0, a_target=1.0, a_required=3.0,
                                           ttc=2.0), None),
    ("decel_no_estop_hysteresis", DECEL, x(v_target=8.0, a_required=3.0, ttc=2.0), None),
    # ... and not when stopped: a stopped car has no emergency
    ("keep_stopped_high_a_stops", KEEP, x(v=0.05, v_target=0.0, a_required=8.0, ttc=0.5),
     STOP),
    ("decel_stopped_high_a_stops", DECEL, x(v=0.0, v_target=0.0, a_required=8.0), STOP),
    ("stop_stopped_high_a_stays", STOP, x(v=0.0, v_target=0.0, a_required=8.0, ttc=0.5),
     None),
    ("stop_no_start_under_threat_a", STOP, x(v=0.0, v_target=5.0, a_required=8.0), None),
    ("stop_no_start_under_threat_ttc", STOP, x(v=0.0, v_target=5.0, ttc=0.5), None),
    ("decel_stopped_no_start_under_threat", DECEL, x(v=0.05, v_target=5.0, ttc=0.5), None),
    # EMERGENCY_STOP -> STOP, -> DECELERATION
    ("estop_stop", ESTOP, x(v=0.05, v_target=0.0), STOP),
    ("estop_stop_threat_holds", ESTOP, x(v=0.0, v_target=10.0, a_required=8.0, ttc=0.2),
     STOP),
    ("estop_decel", ESTOP, x(v_target=8.0, a_required=2.0, ttc=math.inf), DECEL),
    ("estop_stays_closing_slowly", ESTOP, x(v_target=8.0, a_required=2.0, ttc=10.0), None),
    ("estop_decel_lead_gone", ESTOP, x(), DECEL),
    ("estop_decel_from_slow", ESTOP, x(v=P.v_stopped, v_target=0.0), DECEL),
    ("estop_stays_threat", ESTOP, x(a_required=6.0, ttc=0.8), None),
    ("estop_stays_a_hysteresis", ESTOP, x(a_required=3.0), None),
    ("estop_stays_a_at_exit", ESTOP, x(a_required=2.5), None),
    ("estop_stays_ttc_hysteresis", ESTOP, x(ttc=2.0), None),
    ("estop_stays_ttc_at_exit", ESTOP, x(ttc=3.0), None),
    # ACCELERATION, DECELERATION, SPEED_KEEPING -> STOP
    ("accel_stop", ACCEL, x(v=0.05, v_target=0.0), STOP),
    ("decel_stop", DECEL, x(v=0.0, v_target=P.v_start, a_target=-1.0), STOP),
    ("keep_stop", KEEP, x(v=0.05, v_target=0.2), STOP),
    ("decel_no_stop_at_v_stopped", DECEL, x(v=P.v_stopped, v_target=0.0, a_target=-0.5),
     None),
    # STOP -> ACCELERATION
    ("stop_accel", STOP, x(v=0.0, v_target=5.0), ACCEL),
    ("stop_accel_just_above_v_start", STOP, x(v=0.0, v_target=0.51), ACCEL),
    ("stop_stays", STOP, x(v=0.0, v_target=0.0), None),
    ("stop_stays_at_v_start", STOP, x(v=0.0, v_target=P.v_start), None),
    ("stop_stays_creeping", STOP, x(v=0.3, v_target=0.0), None),
    # SPEED_KEEPING -> ACCELERATION, -> DECELERATION
    ("keep_accel_speed", KEEP, x(v_target=11.0), ACCEL),
    ("keep_accel_plan", KEEP, x(a_target=0.5), ACCEL),
    ("keep_decel_speed", KEEP, x(v_target=9.0), DECEL),
    ("keep_decel_plan", KEEP, x(a_target=-0.5), DECEL),
    ("keep_decel_wins_disagreement", KEEP, x(v_target=12.0, a_target=-1.0), DECEL),
    ("keep_stays", KEEP, x(), None),
    ("keep_stays_at_bands_above", KEEP, x(v_target=10.5, a_target=0.3), None),
    ("keep_stays_at_bands_below", KEEP, x(v_target=9.6, a_target=-0.3), None),
    # ACCELERATION -> DECELERATION, -> SPEED_KEEPING
    ("accel_decel_speed", ACCEL, x(v_target=9.0), DECEL),
    ("accel_decel_plan", ACCEL, x(a_target=-0.5), DECEL),
    ("accel_decel_wins_disagreement", ACCEL, x(v_target=15.0, a_target=-1.0), DECEL),
    ("accel_keep", ACCEL, x(v_target=10.1, a_target=0.2), KEEP),
    ("accel_keep_exact", ACCEL, x(), KEEP),
    ("accel_stays", ACCEL, x(v_target=12.0, a_target=1.0), None),
    ("accel_stays_outside_keep_band", ACCEL, x(v_target=10.3), None),
    ("accel_stays_plan_accelerating", ACCEL, x(a_target=0.5), None),
    # DECELERATION -> ACCELERATION, -> SPEED_KEEPING
    ("decel_accel_speed", DECEL, x(v_target=11.0), ACCEL),
    ("decel_accel_plan", DECEL, x(a_target=0.5), ACCEL),
    ("decel_accel_from_standstill", DECEL, x(v=0.05, v_target=0.8), ACCEL),
    ("decel_keep", DECEL, x(v_target=9.9, a_target=-0.1), KEEP),
    ("decel_stays", DECEL, x(v_target=8.0, a_target=-2.0), None),
    ("decel_stays_outside_keep_band", DECEL, x(v_target=9.7), None),
    ("decel_stays_target_above_plan_brakes", DECEL, x(v_target=12.0, a_target=-1.0), None),
    ("decel_stays_target_below_plan_accelerates", DECEL, x(v_target=9.0, a_target=1.0),
     None),
]


@pytest.mark.parametrize(("name", "state", "inp", "expected"), TABLE_CASES,
                         ids=[r[0] for r in TABLE_CASES])
def test_transition_table(name: str, state: ControlState, inp: ControlInput,
                          expected: ControlState | None) -> None:
    change = transition(state, inp, P)
    assert (change.to if change else None) is expected, name
    if change is not None:
        assert change.reason


# every (from, to) pair of the module doc's table
EXPECTED_EDGES = {
    (STOP, ESTOP), (ACCEL, ESTOP), (DECEL, ESTOP), (KEEP, ESTOP),
    (ESTOP, STOP), (ESTOP, DECEL),
    (ACCEL, STOP), (DECEL, STOP), (KEEP, STOP),
    (STOP, ACCEL), (KEEP, ACCEL), (KEEP, DECEL), (ACCEL, DECEL), (DECEL, ACCEL),
    (ACCEL, KEEP), (DECEL, KEEP),
}


def test_every_transition_has_a_row() -> None:
    edges = {(row[1], row[3]) for row in TABLE_CASES if row[3] is not None}
    assert edges == EXPECTED_EDGES
    assert EDGES == EXPECTED_EDGES  # the module's rules allow exactly these
    stays = {row[1] for row in TABLE_CASES if row[3] is None}
    assert stays == set(S)  # every state has rows that must not fire


def test_the_cases_walk_every_row_of_the_data() -> None:
    cases = [(state, inp, expected) for _, state, inp, expected in TABLE_CASES]
    assert unwalked_rows(TABLE, cases, lambda _: P) == []


def test_the_module_doc_shows_the_table_of_the_data() -> None:
    assert doc_shows_table(control, TABLE)


def test_no_state_changes_to_itself() -> None:
    assert all(a is not b for a, b in EDGES)


def test_the_estop_hysteresis_holds_over_a_tick_sequence() -> None:
    """A threat rises, peaks and fades: the state enters at 5, holds down to 2.5, leaves to
    DECELERATION and, on target, settles in SPEED_KEEPING; 3 and 4.9 do not enter again."""
    state = KEEP
    seen = []
    for a_req in (1.0, 3.0, 5.0, 4.0, 3.0, 2.6, 2.4, 3.0, 4.9):
        change = transition(state, x(a_required=a_req), P)
        state = change.to if change else state
        seen.append(state)
    assert seen == [KEEP, KEEP, ESTOP, ESTOP, ESTOP, ESTOP, DECEL, KEEP, KEEP]

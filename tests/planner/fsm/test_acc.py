"""The DECS ACC / event layer: the gaps, and every transition of its chart (`TABLE`: Table 2
of the paper and the completions the module doc lists) walked row by row, with inputs that
must not fire beside them; the module doc shows the table as it is in the data."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

from planner.fsm import acc
from planner.fsm.acc import (
    ACC_ACTIVE,
    EDACC,
    EVENT_MODE,
    TABLE,
    AccEvent,
    AccInput,
    AccMode,
    AccParams,
    gaps,
    r157_min_gap,
    sight_speed,
    transition,
)
from planner.fsm.machine import fired_row
from tests.planner.fsm.tables import doc_shows_table

P = AccParams()
M = AccMode
KPH = 1.0 / 3.6
INF = math.inf
V = 12.0  # [m/s] ego speed of the table (43 km/h: d_min < d_des)
VL = 8.0  # [m/s] a slower lead
G = gaps(V, VL, P)  # the gaps behind it


def x(**kw: object) -> AccInput:
    """Defaults: ACC on, 12 m/s, set 15 m/s, limit 20 m/s, no lead, no event; an event by its
    name (`stop_sign=True`)."""
    events = frozenset(e for e in AccEvent if kw.pop(e.value, False))
    base = AccInput(acc_on=True, v=V, v_s=15.0, v_gps=20.0, events=events)
    return replace(base, **kw)  # type: ignore[arg-type]


def test_r157_minimum_gap() -> None:
    assert r157_min_gap(0.0) == 2.0
    assert r157_min_gap(1.0) == 2.0  # below 10 km/h the 2 m floor (1.1 s would be 1.1 m)
    v = 60 * KPH
    assert r157_min_gap(v) == pytest.approx(v * 1.6)
    v = 130 * KPH
    assert r157_min_gap(v) == pytest.approx(v * 2.3)


def test_gaps() -> None:
    assert G.d_min == pytest.approx(r157_min_gap(V))
    assert G.d_des == pytest.approx(max(4.0 + 1.5 * V, G.d_min + 0.2 * V))
    assert G.d_max == pytest.approx(G.d_des + (V**2 - VL**2) / 3.0 + 10.0)
    assert G.d_min < G.d_des < G.d_max
    # at 72 km/h R157's 1.72 s exceeds tau: d_des keeps tau_margin (0.2 s) above d_min
    fast = gaps(20.0, 15.0, P)
    assert fast.d_min == pytest.approx(20.0 * 1.72)
    assert fast.d_des == pytest.approx(20.0 * (1.72 + 0.2))
    slow = gaps(2.0, INF, P)  # crawling: the desired gap is the standstill gap plus tau v
    assert slow.d_des == pytest.approx(7.0) and slow.d_max == pytest.approx(17.0)
    assert gaps(V, 25.0, P).d_max == pytest.approx(gaps(V, 25.0, P).d_des + 10.0)


BETWEEN = 0.5 * (G.d_des + G.d_max)  # a gap inside the following band
CLOSE = G.d_min - 1.0
FAR = G.d_max + 5.0

# (name, from, input, expected next mode or None to stay)
TABLE_CASES = [
    # ACC_OFF <-> ACC_ON
    ("off_on", M.ACC_OFF, x(), M.CRUISE),
    ("off_stays_off", M.ACC_OFF, x(acc_on=False), None),
    ("switched_off_cruise", M.CRUISE, x(acc_on=False), M.ACC_OFF),
    ("switched_off_event", M.STOP_SIGN, x(acc_on=False, stop_sign=True), M.ACC_OFF),
    # Cruise (Table 2: 1 to 2, 1 to 3, 1 to 4)
    ("cruise_trail", M.CRUISE, x(d=BETWEEN, v_l=VL), M.TRAIL),
    ("cruise_no_trail_lead_faster", M.CRUISE, x(d=BETWEEN, v_l=16.0), None),
    ("cruise_no_trail_far", M.CRUISE, x(d=FAR, v_l=VL), None),
    ("cruise_brake", M.CRUISE, x(d=CLOSE, v_l=VL), M.BRAKE),
    # inside d_des but beyond d_min: TRAIL's law opens the gap (*: Table 2 starts at d_des)
    ("cruise_trail_inside_d_des", M.CRUISE, x(d=0.5 * (G.d_min + G.d_des), v_l=VL), M.TRAIL),
    #   standing 3.3 m behind a standing car when the light turns green (issue K 6)
    ("cruise_trail_standing_behind_a_car", M.CRUISE, x(v=0.0, d=3.3, v_l=0.0), M.TRAIL),
    ("cruise_limit_no_lead", M.CRUISE, x(v_gps=13.0), M.SPEED_LIMIT),
    ("cruise_limit_lead_faster", M.CRUISE, x(v_gps=13.0, d=BETWEEN, v_l=14.0), M.SPEED_LIMIT),
    ("cruise_stays", M.CRUISE, x(), None),
    # Trail (2 to 1, 2 to 8, 2 to 9; * to Brake, to SpeedLimit)
    ("trail_cruise_lead_gone", M.TRAIL, x(), M.CRUISE),
    ("trail_cruise_lead_faster", M.TRAIL, x(d=BETWEEN, v_l=16.0), M.CRUISE),
    ("trail_stays", M.TRAIL, x(d=BETWEEN, v_l=VL), None),
    # a lead just beyond d_max is let go only d_let_go beyond it (*: a gap about d_max
    # flicked TRAIL and CRUISE for a tick in town_stop_queue)
    ("trail_stays_just_beyond_d_max", M.TRAIL, x(d=G.d_max + 1.0, v_l=VL), None),
    ("trail_cruise_beyond_d_let_go", M.TRAIL, x(d=G.d_max + P.d_let_go, v_l=VL), M.CRUISE),
    ("trail_limit_waits_just_beyond_d_max", M.TRAIL, x(v_gps=13.0, d=G.d_max + 1.0, v_l=VL),
     None),
    ("cruise_stays_just_beyond_d_max", M.CRUISE, x(d=G.d_max + 1.0, v_l=VL), None),
    ("trail_pedestrian", M.TRAIL, x(d=BETWEEN, v_l=VL, pedestrian=True), M.PEDESTRIAN),
    ("trail_speed_bump", M.TRAIL, x(d=BETWEEN, v_l=VL, speed_bump=True), M.SPEED_BUMP),
    ("trail_brake", M.TRAIL, x(d=CLOSE, v_l=VL), M.BRAKE),
    # no comfortable stop (ISO 15622; *): BRAKE at once, saying so; left once relaxed
    ("trail_brake_no_comfortable_stop", M.TRAIL,
     x(d=BETWEEN, v_l=0.0, a_need=4.2, ttc=2.1, comfortable=False, relaxed=False), M.BRAKE),
    ("cruise_brake_no_comfortable_stop", M.CRUISE,
     x(d=FAR, v_l=0.0, a_need=3.6, ttc=3.0, comfortable=False, relaxed=False), M.BRAKE),
    ("limit_brake_no_comfortable_stop", M.SPEED_LIMIT,
     x(v_gps=13.0, d=FAR, v_l=0.0, a_need=3.6, comfortable=False, relaxed=False), M.BRAKE),
    ("brake_stays_until_relaxed", M.BRAKE,
     x(d=BETWEEN, v_l=VL, a_need=2.8, comfortable=True, relaxed=False), None),
    ("brake_cruise_stays_until_relaxed", M.BRAKE,
     x(d=FAR, v_l=VL, a_need=2.8, comfortable=True, relaxed=False), None),
    # a lead at the set speed or the limit: no flip on its speed's wobble (v_band *)
    ("trail_stays_lead_at_set_speed", M.TRAIL, x(d=G.d_des + 2.0, v_l=15.2), None),
    # a lead just lost: TRAIL holds for lead_hold (the car it hid may become the lead; *)
    ("trail_stays_lead_just_lost", M.TRAIL, x(lead_lost=True), None),
    ("trail_limit_waits_lead_just_lost", M.TRAIL, x(v_gps=13.0, lead_lost=True), None),
    # ... TRAIL only: cruising (an event just over) with a lead lost, the limit binds at once
    ("cruise_limit_lead_just_lost", M.CRUISE, x(v_gps=13.0, lead_lost=True), M.SPEED_LIMIT),
    ("brake_trail_lead_at_set_speed", M.BRAKE, x(d=G.d_min + 1.5, v_l=15.2), M.TRAIL),
    ("limit_stays_lead_at_limit", M.SPEED_LIMIT,
     x(v_s=13.0, v_gps=13.0, d=G.d_des + 2.0, v_l=13.2), None),
    ("trail_limit", M.TRAIL, x(v_gps=13.0), M.SPEED_LIMIT),
    # Brake (3 to 1, 3 to 2, 3 to 4, 3 to 9)
    ("brake_cruise", M.BRAKE, x(d=FAR, v_l=VL), M.CRUISE),
    ("brake_cruise_lead_faster", M.BRAKE, x(d=G.d_min + 1.0, v_l=16.0), M.CRUISE),
    ("brake_trail", M.BRAKE, x(d=BETWEEN, v_l=VL), M.TRAIL),
    ("brake_limit", M.BRAKE, x(v_gps=13.0, d=FAR, v_l=VL), M.SPEED_LIMIT),
    ("brake_stays_close", M.BRAKE, x(d=CLOSE, v_l=VL), None),
    ("brake_stays_below_d_des", M.BRAKE, x(d=0.5 * (G.d_min + G.d_des), v_l=VL), None),
    ("brake_trail_slowed_to_the_lead", M.BRAKE,
     x(d=0.5 * (G.d_min + G.d_des), v=VL + 0.3, v_l=VL), M.TRAIL),
    ("brake_stays_slowed_but_close", M.BRAKE,
     x(d=gaps(VL, VL, P).d_min - 0.5, v=VL, v_l=VL), None),
    ("brake_stays_slowed_just_above_d_min", M.BRAKE,  # d_band: no flip at d_min
     x(d=gaps(VL, VL, P).d_min + 0.5, v=VL, v_l=VL), None),
    ("brake_speed_bump", M.BRAKE, x(d=CLOSE, v_l=VL, speed_bump=True), M.SPEED_BUMP),
    # SpeedLimit (4 to 1, 4 to 2; * to Brake)
    ("limit_cruise", M.SPEED_LIMIT, x(), M.CRUISE),
    ("limit_trail", M.SPEED_LIMIT, x(v_gps=13.0, d=BETWEEN, v_l=VL), M.TRAIL),
    ("limit_trail_inside_d_des", M.SPEED_LIMIT,
     x(v_gps=13.0, d=0.5 * (G.d_min + G.d_des), v_l=VL), M.TRAIL),
    ("limit_stays", M.SPEED_LIMIT, x(v_gps=13.0), None),
    ("limit_brake", M.SPEED_LIMIT, x(v_gps=13.0, d=CLOSE, v_l=VL), M.BRAKE),
    # events from ACC_ACTIVE (* generalised from Table 2's rows)
    ("cruise_off_ramp", M.CRUISE, x(off_ramp=True), M.OFF_RAMP),
    ("cruise_off_ramp_with_its_limit", M.CRUISE, x(off_ramp=True, v_gps=7.0), M.OFF_RAMP),
    #   the ramp's lower limit in force on the tick its event starts (`planner.events`):
    #   one change, straight into OFF_RAMP, not through SPEED_LIMIT (issue K)
    ("limit_stop_sign", M.SPEED_LIMIT, x(v_gps=13.0, stop_sign=True), M.STOP_SIGN),
    ("cruise_pedestrian_first", M.CRUISE, x(pedestrian=True, speed_bump=True), M.PEDESTRIAN),
    # OffRamp (6 to 1, 6 to 7)
    ("ramp_cruise", M.OFF_RAMP, x(), M.CRUISE),
    ("ramp_stop_sign", M.OFF_RAMP, x(off_ramp=True, stop_sign=True), M.STOP_SIGN),
    ("ramp_stays", M.OFF_RAMP, x(off_ramp=True), None),
    ("ramp_stays_at_bump", M.OFF_RAMP, x(off_ramp=True, speed_bump=True), None),
    # Pedestrian (8 to 1)
    ("pedestrian_cruise", M.PEDESTRIAN, x(), M.CRUISE),
    ("pedestrian_stays", M.PEDESTRIAN, x(pedestrian=True, d=CLOSE, v_l=0.0), None),
    # SpeedBump (9 to 1, 9 to 5, 9 to 8)
    ("bump_cruise", M.SPEED_BUMP, x(), M.CRUISE),
    ("bump_flat", M.SPEED_BUMP, x(speed_bump=True, flat=True), M.FLAT),
    ("bump_pedestrian", M.SPEED_BUMP, x(speed_bump=True, pedestrian=True), M.PEDESTRIAN),
    ("bump_stays", M.SPEED_BUMP, x(speed_bump=True), None),
    # StopSign (* to Cruise, * to Pedestrian)
    ("stop_cruise", M.STOP_SIGN, x(), M.CRUISE),
    ("stop_pedestrian", M.STOP_SIGN, x(stop_sign=True, pedestrian=True), M.PEDESTRIAN),
    ("stop_stays", M.STOP_SIGN, x(stop_sign=True), None),
    # town junctions (ours): RedLight, Yield
    ("cruise_red_light", M.CRUISE, x(red_light=True), M.RED_LIGHT),
    ("trail_yield", M.TRAIL, x(give_way=True, d=BETWEEN, v_l=VL), M.YIELD),
    ("red_light_stays", M.RED_LIGHT, x(red_light=True), None),
    ("red_light_cruise", M.RED_LIGHT, x(), M.CRUISE),
    ("red_light_then_yield", M.RED_LIGHT, x(give_way=True), M.YIELD),
    ("red_light_pedestrian", M.RED_LIGHT, x(red_light=True, pedestrian=True), M.PEDESTRIAN),
    ("yield_stays", M.YIELD, x(give_way=True), None),
    ("red_light_outranks_yield", M.RED_LIGHT, x(red_light=True, give_way=True), None),
    ("yield_cruise", M.YIELD, x(), M.CRUISE),
    ("yield_turns_red", M.YIELD, x(give_way=True, red_light=True), M.RED_LIGHT),
    ("stop_sign_then_yield", M.STOP_SIGN, x(give_way=True), M.YIELD),
    ("stop_sign_before_red", M.CRUISE, x(stop_sign=True, red_light=True), M.STOP_SIGN),
    ("red_light_no_bump", M.RED_LIGHT, x(red_light=True, speed_bump=True), None),
    # Flat (5: the end)
    ("cruise_flat", M.CRUISE, x(flat=True), M.FLAT),
    ("flat_stays", M.FLAT, x(), None),
    ("flat_stays_off", M.FLAT, x(acc_on=False), None),
]


@pytest.mark.parametrize(("name", "state", "inp", "expected"), TABLE_CASES,
                         ids=[r[0] for r in TABLE_CASES])
def test_transition_table(name: str, state: AccMode, inp: AccInput,
                          expected: AccMode | None) -> None:
    change = transition(state, inp, P)
    assert (change.to if change else None) is expected, name
    if change is not None:
        assert change.reason


@pytest.mark.parametrize("k", range(len(TABLE.rows)), ids=[f"row_{k + 1}" for k in
                                                            range(len(TABLE.rows))])
def test_every_row_of_the_table_is_walked(k: int) -> None:
    """Each row of the data fires for at least one case above, from a state it leaves, with
    its own target and reason (a row added to the table needs a case here)."""
    row = TABLE.rows[k]
    walked = [name for name, state, inp, _ in TABLE_CASES
              if fired_row(TABLE, state, inp, gaps(inp.v, inp.v_l, P)) is row]
    assert walked, f"no case walks row {k + 1}: {row.when}"
    for name, state, inp, expected in TABLE_CASES:
        if name in walked:
            change = transition(state, inp, P)
            assert change is not None and change.to is row.target is expected
            assert change.reason == row.reason_for(inp, gaps(inp.v, inp.v_l, P))


def test_the_module_doc_shows_the_table_of_the_data() -> None:
    assert doc_shows_table(acc, TABLE, acc.source_names)


def test_each_event_has_its_mode_and_every_event_mode_its_event() -> None:
    assert set(EVENT_MODE) == set(AccEvent)
    assert set(EVENT_MODE.values()) == EDACC


def test_every_state_is_left_and_entered_in_the_table() -> None:
    sources = {row[1] for row in TABLE_CASES}
    targets = {row[3] for row in TABLE_CASES if row[3] is not None}
    assert sources == set(AccMode)
    assert targets == set(AccMode)
    assert ACC_ACTIVE | EDACC | {AccMode.ACC_OFF} == set(AccMode)
    # every edge of Table 2 has a row
    table2 = {(M.CRUISE, M.TRAIL), (M.CRUISE, M.BRAKE), (M.CRUISE, M.SPEED_LIMIT),
              (M.TRAIL, M.CRUISE), (M.TRAIL, M.PEDESTRIAN), (M.TRAIL, M.SPEED_BUMP),
              (M.BRAKE, M.CRUISE), (M.BRAKE, M.TRAIL), (M.BRAKE, M.SPEED_LIMIT),
              (M.BRAKE, M.SPEED_BUMP), (M.SPEED_LIMIT, M.CRUISE), (M.SPEED_LIMIT, M.TRAIL),
              (M.OFF_RAMP, M.CRUISE), (M.OFF_RAMP, M.STOP_SIGN), (M.PEDESTRIAN, M.CRUISE),
              (M.SPEED_BUMP, M.CRUISE), (M.SPEED_BUMP, M.FLAT), (M.SPEED_BUMP, M.PEDESTRIAN)}
    edges = {(row[1], row[3]) for row in TABLE_CASES if row[3] is not None}
    assert table2 <= edges
    assert edges <= TABLE.edges  # every case's change is an edge of the data


SETTLE_CASES = [
    # (name, state, input, mode reached, reason's parts)
    ("switched_on_behind_a_lead", M.ACC_OFF, x(d=0.5 * (G.d_des + G.d_max), v_l=VL),
     M.TRAIL, ("ACC switched on", "a slower vehicle ahead within d_max")),
    ("bump_done_below_the_limit", M.SPEED_BUMP, x(v_gps=10.0), M.SPEED_LIMIT,
     ("speed_bump done", "the posted limit is below the set speed")),
    ("stop_done_too_close", M.STOP_SIGN, x(d=0.5 * G.d_min, v_l=0.0), M.BRAKE,
     ("stop_sign done", "gap at or below d_min")),
    ("bump_done_nothing_else", M.SPEED_BUMP, x(), M.CRUISE, ("speed_bump done",)),
]


@pytest.mark.parametrize(("name", "state", "inp", "expected", "reasons"), SETTLE_CASES,
                         ids=[c[0] for c in SETTLE_CASES])
def test_the_default_state_is_settled_at_once(name: str, state: AccMode, inp: AccInput,
                                              expected: AccMode,
                                              reasons: tuple[str, ...]) -> None:
    """Into CRUISE from outside ACC_ACTIVE, CRUISE's rows are tried on the same input: one
    change, to the mode they reach, with both reasons (no mode held for a single tick)."""
    change = transition(state, inp, P)
    assert change is not None and change.to is expected, name
    assert change.reason == "; ".join(reasons)


def test_sight_speed_keeps_the_gap_and_the_stop_within_the_sensing_range() -> None:
    """Faster than the sight speed, a lead followed at d_des is out of sight, or a car
    standing in the lane is found too late to stop for at 8 m/s^2."""
    v = sight_speed(40.0, P, 8.0)  # following binds: d_des (R157 d_min + 0.2 s) = 40 m
    assert gaps(v, v, P).d_des == pytest.approx(40.0)
    assert v * 0.5 + v * v / 16.0 + 2.5 < 40.0
    v = sight_speed(55.0, P, 8.0)  # the stop binds: 0.5 s, then 8 m/s^2, 2.5 m short
    assert v * 0.5 + v * v / 16.0 + 2.5 == pytest.approx(55.0)
    assert gaps(v, v, P).d_des < 55.0
    assert 88.0 < v / KPH < 93.0
    assert sight_speed(55.0, P, 4.0) < v  # gentler stopping: slower
    assert sight_speed(300.0, P, 8.0) / KPH > 130.0  # a long-range radar: no cap that matters

"""The whole pass against the vehicles coming up behind in the lane moved into
(`planner.rear_pass`): a table of vehicles behind, each either outrun or not, with the
figures of the overtake family's failures (the ego at 50 km/h, a car standing 45 m ahead,
a car at 68 to 80 km/h 50 to 60 m back in the left lane, which UN R157's rule for the move
out lets it pull out in front of)."""

from __future__ import annotations

import pytest

from planner.lane_occupancy import Neighbour, OccupancyParams, rear_decel_needed
from planner.rear_pass import (
    Pass,
    RearPassParams,
    gap_after,
    pass_time,
    rear_catches,
    rear_gap_needed,
    travel,
)

KPH = 1.0 / 3.6  # [m/s] per km/h
OCC, P = OccupancyParams(), RearPassParams()
V = 50.0 * KPH  # [m/s] the ego's speed, and the speed it wants
EGO = 4.8  # [m] the ego's length
STANDING = Neighbour(1, 0.0, 45.0, 0.0, 0.0, 0.9, 4.6)  # a car standing 45 m ahead
SLOW = Neighbour(1, 0.0, 45.0, 20.0 * KPH, 0.0, 0.9, 4.6)  # ... or at 20 km/h
PASS = Pass(V, V, STANDING, EGO, t_out=5.0, t_back=5.0)
FROM_REST = Pass(0.0, V, Neighbour(1, 0.0, 10.0, 0.0, 0.0, 0.9, 4.6), EGO, t_out=4.5,
                 t_back=5.0)  # standing 10 m behind a standing car


def behind(gap: float, kph: float, ident: int = 2) -> Neighbour:
    """A vehicle `gap` [m] behind (bumpers) in the target lane at `kph` [km/h]."""
    return Neighbour(ident, 0.0, gap, kph * KPH)


# (name, the pass, the vehicles behind, the one that catches the car: an index or None)
CASES = [
    # the campaign's failures: the move out's rule holds, the whole pass does not
    ("76_kph_55_m_back", PASS, [behind(55.0, 76.0)], 0),
    ("68_kph_50_m_back", PASS, [behind(50.0, 68.0)], 0),
    ("73_kph_60_m_back", PASS, [behind(60.0, 73.0)], 0),
    # far enough back, or not faster: the pass starts
    ("76_kph_120_m_back", PASS, [behind(120.0, 76.0)], None),
    ("as_fast_20_m_back", PASS, [behind(20.0, 50.0)], None),
    ("slower_15_m_back", PASS, [behind(15.0, 40.0)], None),
    ("standing_behind", PASS, [behind(3.0, 0.0)], None),
    ("going_the_other_way", PASS, [behind(30.0, -50.0)], None),
    ("none_behind", PASS, [], None),
    # every vehicle behind counts, not only the nearest
    ("a_faster_one_behind_a_slow_one", PASS, [behind(15.0, 40.0), behind(55.0, 76.0, 3)], 1),
    ("the_nearest_that_catches_is_named", PASS,
     [behind(80.0, 80.0, 3), behind(55.0, 76.0)], 1),
    # a slow vehicle ahead takes longer to pass than a standing one as near
    ("20_kph_car_ahead_70_kph_90_m_back", Pass(V, V, SLOW, EGO, 5.0, 5.0),
     [behind(90.0, 70.0)], 0),
    ("standing_car_ahead_70_kph_90_m_back", PASS, [behind(90.0, 70.0)], None),
    # from a standstill 10 m behind a standing car the car needs longer still
    ("from_a_standstill_60_kph_90_m_back", FROM_REST, [behind(90.0, 60.0)], 0),
    ("from_a_standstill_60_kph_150_m_back", FROM_REST, [behind(150.0, 60.0)], None),
    # never past it: any moving vehicle behind catches the car
    ("never_past_it", Pass(V, 15.0 * KPH, SLOW, EGO, 5.0, 5.0), [behind(200.0, 30.0)], 0),
]


@pytest.mark.parametrize(("name", "ps", "cars", "caught"), CASES, ids=[c[0] for c in CASES])
def test_rear_catches(name: str, ps: Pass, cars: list[Neighbour], caught: int | None) -> None:
    got = rear_catches(ps, cars, OCC, P)
    assert got == (None if caught is None else cars[caught])


@pytest.mark.parametrize(("gap", "kph"), [(55.0, 76.0), (50.0, 68.0), (60.0, 73.0)])
def test_the_move_out_alone_allows_what_the_whole_pass_does_not(gap: float,
                                                                   kph: float) -> None:
    """The failures' cars behind: UN R157's rule for the move out holds (the car behind
    would brake at under 1 m/s^2), and not braking it is still over 1 s behind when the
    move out (5 s) is over; at the end of the pass (10 s) it is 20 m short of the rear
    distance or has run into the ego."""
    u = kph * KPH
    assert rear_decel_needed(gap, u, V, OCC) < 1.0
    assert gap - (u - V) * PASS.t_out > V * OCC.rear_time_gap
    t = pass_time(PASS, OCC, P)
    assert t is not None and t == pytest.approx(10.0)
    assert gap_after(behind(gap, kph), t, PASS, P) < rear_gap_needed(u, V, OCC) - 15.0


def test_pass_time_phases() -> None:
    """Past the standing car: 45 + 4.6 + 4.8 + 13.9 (1 s at 50 km/h) = 68.3 m at 13.9 m/s,
    4.9 s, under the move out's 5 s; then the 5 s back. Past the 20 km/h car: relative
    8.3 m/s, 8.2 s, then back."""
    assert pass_time(PASS, OCC, P) == pytest.approx(5.0 + 5.0)
    assert pass_time(Pass(V, V, SLOW, EGO, 5.0, 5.0), OCC, P) == pytest.approx(
        (45.0 + 4.6 + EGO + V) / (V - 20.0 * KPH) + 5.0)
    assert pass_time(Pass(V, 15.0 * KPH, SLOW, EGO, 5.0, 5.0), OCC, P) is None


def test_travel_speeds_up_to_the_pass_speed() -> None:
    assert travel(4.0, 0.0, 6.0, 1.5) == pytest.approx(0.5 * 1.5 * 16.0)
    assert travel(6.0, 0.0, 6.0, 1.5) == pytest.approx(12.0 + 6.0 * 2.0)
    assert travel(3.0, 20.0, 10.0, 1.5) == pytest.approx(30.0)  # from above: at the pass speed


def test_rear_gap_needed_is_the_rule_s_limit() -> None:
    """At the gap `rear_gap_needed` the vehicle behind needs exactly ``rear_decel``."""
    for kph in (55.0, 70.0, 80.0):
        gap = rear_gap_needed(kph * KPH, V, OCC)
        assert rear_decel_needed(gap + 1e-9, kph * KPH, V, OCC) <= OCC.rear_decel
        assert rear_decel_needed(gap - 0.01, kph * KPH, V, OCC) > OCC.rear_decel \
            or kph * KPH <= V

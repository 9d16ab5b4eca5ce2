"""Lane occupancy from tracks on the map: neighbours per lane, free and blocked lanes."""

from __future__ import annotations

import pytest

from perception.messages import ObjectClass, Track
from planner.fsm.acc import AccParams, gaps, r157_min_gap
from planner.lane_occupancy import (
    LaneTraffic,
    Neighbour,
    OccupancyParams,
    is_blocked,
    is_free,
    lane_traffic,
    rear_closes,
    rear_decel_needed,
)
from tests.roads import W, make_map, seg
from tests.vehicle import VEHICLE

P = OccupancyParams()
ROAD = make_map(seg(400.0))  # 2 lanes: lane 0 centre y = 0, lane 1 centre y = 3.5
V = 13.9  # [m/s] ego speed
EGO_S = 100.0  # [m] ego centre station (x on this straight road)


def car(x: float, y: float, vx: float, ident: int = 1, t: float = 1.0) -> Track:
    return Track(id=ident, t=t, x=x, y=y, vx=vx, vy=0.0, rel_x=x - EGO_S, rel_y=y,
                 rel_vx=vx - V, rel_vy=0.0, length=4.6, width=1.8, height=1.5, yaw=0.0,
                 cls=ObjectClass.CAR, hits=5, misses=0, position_sigma=0.1)


def traffic(*tracks: Track, t: float = 1.0) -> dict[int, LaneTraffic]:
    return lane_traffic(ROAD, tracks, t, EGO_S, (0, 1), P, VEHICLE)


def test_neighbours_ahead_behind_and_alongside() -> None:
    lt = traffic(car(150.0, 0.1, 8.0, 1), car(130.0, 0.0, 9.0, 2), car(60.0, W, 20.0, 3),
                 car(102.0, W + 0.2, 14.0, 4))
    assert lt[0].ahead == Neighbour(2, 1.0, pytest.approx(30.0 - 2.3 - 2.4), 9.0, 0.0, 0.9,
                                    pytest.approx(4.6))
    assert lt[0].behind is None and not lt[0].alongside
    assert lt[1].behind == Neighbour(3, 1.0, pytest.approx(40.0 - 2.3 - 2.4), 20.0,
                                     pytest.approx(W), 0.9, pytest.approx(4.6))
    assert lt[1].alongside and lt[1].ahead is None


def test_a_straddling_box_counts_in_both_lanes_a_grazing_one_in_neither_other() -> None:
    straddling = traffic(car(140.0, 0.5 * W, 10.0))
    assert straddling[0].ahead is not None and straddling[1].ahead is not None
    # box edge 0.2 m into lane 1 (less than the 0.3 m overlap): lane 0 only
    grazing = traffic(car(140.0, 0.5 * W - 0.9 - 0.2, 10.0))
    assert grazing[0].ahead is not None and grazing[1].ahead is None


def test_gaps_are_carried_to_now() -> None:
    """The track's place is its scan's (0.5 s ago): the car at 8 m/s is 4 m farther on now;
    the ego's station is now's, so its own 0.5 s of driving is not taken off again."""
    lt = traffic(car(140.0, 0.0, 8.0), t=1.5)
    assert lt[0].ahead is not None
    assert lt[0].ahead.gap == pytest.approx(40.0 + 0.5 * 8.0 - 4.7)
    behind = traffic(car(60.0, W, 20.0), t=1.5)[1].behind  # 20 m/s: 10 m nearer now
    assert behind is not None and behind.gap == pytest.approx(40.0 - 10.0 - 4.7)


@pytest.mark.parametrize("age", [0.1, 0.175])
def test_a_standing_cars_gap_is_its_place_whatever_the_tracks_age(age: float) -> None:
    """A standing car's gap is where it stands less the car's front now, however old its
    track (the LiDAR's scans come at 10 Hz and are used a tick or more later): taking the
    car's own speed x the track's age off as well put it 1.2 m nearer (7 m/s, 0.175 s), and
    a pass under way, judging its path at that nearer place, took the car it was clearing
    for a lead and stopped beside it."""
    lt = traffic(car(140.0, 0.0, 0.0), t=1.0 + age)
    assert lt[0].ahead is not None
    assert lt[0].ahead.gap == pytest.approx(40.0 - 4.7)


def test_free_ahead_needs_d_min_plus_closing() -> None:
    need = r157_min_gap(V) + (V - 10.0) * P.front_time
    assert is_free(LaneTraffic(1, ahead=Neighbour(1, 1.0, need + 0.1, 10.0)), V, P)
    assert not is_free(LaneTraffic(1, ahead=Neighbour(1, 1.0, need - 0.1, 10.0)), V, P)
    assert is_free(LaneTraffic(1), V, P)
    assert not is_free(LaneTraffic(1, alongside=True), V, P)


@pytest.mark.parametrize(("v_ahead", "under_way", "free"), [
    (V + 2.7, False, False),  # a start needs d_min(v) even behind a faster vehicle
    (V + 2.7, True, True),  # under way behind one pulling away: the gap only grows
    (V, True, True),  # ... or holding the ego's speed
    (V - 0.5, True, False),  # one the ego closes on gives the change up
])
def test_a_change_under_way_goes_on_behind_a_vehicle_that_is_not_slower(
        v_ahead: float, under_way: bool, free: bool) -> None:
    """A vehicle ahead in the target lane 0.5 m nearer than d_min(v): a pass behind a car
    pulling away (52 km/h, 16.6 m ahead, the ego speeding up through 42 km/h toward its set
    speed) was given up over the line it had crossed as d_min(v) rose past the gap, though
    the gap was growing."""
    lt = LaneTraffic(1, ahead=Neighbour(1, 1.0, r157_min_gap(V) - 0.5, v_ahead))
    assert is_free(lt, V, P, under_way=under_way) is free


def test_free_behind_is_r157s_approaching_vehicle_rule() -> None:
    dv = 25.0 - V
    need = dv * 0.4 + dv**2 / 6.0 + V * 1.0
    assert is_free(LaneTraffic(1, behind=Neighbour(1, 1.0, need + 0.1, 25.0)), V, P)
    assert not is_free(LaneTraffic(1, behind=Neighbour(1, 1.0, need - 0.1, 25.0)), V, P)
    slower = LaneTraffic(1, behind=Neighbour(1, 1.0, V * 1.0 + 0.1, 10.0))  # only t_G counts
    assert is_free(slower, V, P)


@pytest.mark.parametrize(
    ("gap", "v_behind", "v", "decel"),
    [
        # UN R157's rule as the rear vehicle's need: dv^2 / (2 (gap - dv t_B - v t_G))
        (40.0, 25.0, V, (25.0 - V) ** 2 / (2.0 * (40.0 - (25.0 - V) * 0.4 - V))),
        (20.0, 16.7, 0.0, 16.7**2 / (2.0 * (20.0 - 16.7 * 0.4))),  # past a standing car
        (V + 1.0, 10.0, V, 0.0),  # slower behind, beyond t_G: nothing to brake for
        (V, V, V, 0.0),  # just t_G behind at the same speed
        (V - 0.1, V, V, float("inf")),  # inside t_G: no braking keeps it
        (5.0, 25.0, V, float("inf")),  # too near to brake at all
    ],
)
def test_the_rear_vehicles_needed_deceleration(gap: float, v_behind: float, v: float,
                                               decel: float) -> None:
    assert rear_decel_needed(gap, v_behind, v, P) == pytest.approx(decel)


def test_free_behind_means_the_rear_car_brakes_at_most_3_m_s2() -> None:
    def behind(gap: float) -> LaneTraffic:
        return LaneTraffic(1, behind=Neighbour(1, 1.0, gap, 25.0))

    limit = next(g / 10 for g in range(1, 2000) if rear_decel_needed(g / 10, 25.0, V, P) <= 3.0)
    assert is_free(behind(limit), V, P) and not is_free(behind(limit - 0.1), V, P)


def test_the_rear_rule_is_judged_at_the_lowest_speed_planned() -> None:
    """A car slowing while it moves over (a flat tyre) lets the one behind close faster: a
    gap free at its speed now is not at the speed it slows to."""
    lt = LaneTraffic(0, behind=Neighbour(1, 1.0, 30.0, 18.1))
    assert is_free(lt, 16.4, P)  # dv = 1.7 m/s: 18 m would do
    assert not is_free(lt, 16.4, P, v_rear=6.4)  # dv = 11.7 m/s: 34 m needed
    assert is_free(lt, 16.4, P, v_rear=20.0)  # never above the speed now
    # the front rule stays at the speed now
    ahead = LaneTraffic(0, ahead=Neighbour(1, 1.0, r157_min_gap(16.4) + 0.1, 16.4))
    assert is_free(ahead, 16.4, P, v_rear=0.0)


def test_blocked_by_a_slower_lead_within_d_max() -> None:
    acc = AccParams()
    d_max = gaps(V, 5.5, acc).d_max
    slow_near = LaneTraffic(0, ahead=Neighbour(1, 1.0, d_max - 1.0, 5.5))
    assert is_blocked(slow_near, V, V, P, acc)
    assert not is_blocked(LaneTraffic(0, ahead=Neighbour(1, 1.0, d_max + 1.0, 5.5)), V, V, P, acc)
    nearly = LaneTraffic(0, ahead=Neighbour(1, 1.0, 20.0, V - 2.0))  # within the margin
    assert not is_blocked(nearly, V, V, P, acc)
    assert not is_blocked(LaneTraffic(0), V, V, P, acc)


def test_a_change_under_way_goes_on_up_to_the_abort_deceleration() -> None:
    """Started only if the car behind need not brake over 3 m/s^2; given up only once it
    would have to brake over 4 m/s^2 (hysteresis)."""
    def behind(gap: float) -> LaneTraffic:
        return LaneTraffic(1, behind=Neighbour(1, 1.0, gap, 25.0))

    gap = next(g / 10 for g in range(1, 2000)
               if rear_decel_needed(g / 10, 25.0, V, P) <= 3.5)  # needs 3.5 m/s^2
    assert not is_free(behind(gap), V, P)
    assert is_free(behind(gap), V, P, under_way=True)
    worse = next(g / 10 for g in range(2000, 1, -1)
                 if rear_decel_needed(g / 10, 25.0, V, P) > 4.0)
    assert not is_free(behind(worse), V, P, under_way=True)


def test_free_behind_needs_a_car_not_braking_to_stay_t_g_back_through_the_move() -> None:
    """The ego at 20 km/h, a car at 65 km/h 37 m behind: UN R157's rule holds (it would
    brake at 2.9 m/s^2), but not braking it closes 12.5 m/s x 5 s: the lane is not free
    for a 5 s move; it is when the gap covers that and 1 s of the ego's speed."""
    v, fast, t_move = 5.56, 18.06, 5.0
    lt = LaneTraffic(1, behind=Neighbour(1, 1.0, 37.0, fast))
    assert rear_decel_needed(37.0, fast, v, P) < 3.0 and is_free(lt, v, P)
    assert not is_free(lt, v, P, t_move=t_move)
    need = (fast - v) * t_move + v * P.rear_time_gap
    assert is_free(LaneTraffic(1, behind=Neighbour(1, 1.0, need + 0.01, fast)), v, P,
                   t_move=t_move)
    assert not rear_closes(need + 0.01, fast, v, t_move, P)
    assert rear_closes(need - 0.01, fast, v, t_move, P)
    # judged at the lowest speed planned, and never for a car no faster than that
    assert not is_free(LaneTraffic(1, behind=Neighbour(1, 1.0, need + 0.01, fast)), 8.0, P,
                       v_rear=4.0, t_move=t_move)
    assert is_free(LaneTraffic(1, behind=Neighbour(1, 1.0, 6.0, v)), v, P, t_move=t_move)

"""Transitions shaped as OpenSCENARIO's dynamics, and an NPC driven by commands."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from world.actors.behaviour import NpcMotion
from world.actors.profiles import (
    LateralCommand,
    PathCommand,
    Shape,
    SpeedCommand,
    TrackCommand,
    Transition,
    fraction,
    lane_change_step,
    span_by_rate,
    speed_span_by_distance,
)

DT = 1.0 / 120.0  # [s] the actors' step


@pytest.mark.parametrize("shape", [Shape.LINEAR, Shape.SINUSOIDAL, Shape.CUBIC])
def test_each_shape_runs_from_zero_to_one_and_peaks_at_its_slope(shape: Shape) -> None:
    u = np.linspace(0.0, 1.0, 20001)
    values = np.array([fraction(shape, x)[0] for x in u])
    slopes = np.array([fraction(shape, x)[1] for x in u])
    assert values[0] == 0.0 and values[-1] == pytest.approx(1.0)
    assert np.all(np.diff(values) >= 0.0)
    # the slope is the derivative, and its peak is the one `span_by_rate` times by
    assert np.allclose(np.gradient(values, u), slopes, atol=1e-3)
    assert slopes.max() == pytest.approx(span_by_rate(shape, 1.0, 1.0), rel=1e-6)


@given(change=st.floats(0.1, 10.0), rate=st.floats(0.1, 5.0),
       shape=st.sampled_from([Shape.LINEAR, Shape.SINUSOIDAL, Shape.CUBIC]))
def test_a_rate_is_the_transitions_peak_rate(change: float, rate: float, shape: Shape) -> None:
    """A lane change's `rate` is its peak lateral speed (ALKS 4.4: Vy_max)."""
    t = Transition(0.0, change, shape, span_by_rate(shape, change, rate))
    peak = max(t.at(x)[1] for x in np.linspace(0.0, t.span, 2001))
    assert peak == pytest.approx(rate, rel=1e-3)
    assert t.at(t.span)[0] == change and t.at(t.span)[2]


def test_a_sinusoidal_lane_change_of_a_lane_at_two_metres_a_second() -> None:
    """3.5 m at a peak of 2 m/s: T = pi 3.5 / (2 x 2) = 2.75 s."""
    assert span_by_rate(Shape.SINUSOIDAL, 3.5, 2.0) == pytest.approx(math.pi * 3.5 / 4.0)


def test_a_speed_change_by_distance_is_timed_by_the_mean_speed() -> None:
    assert speed_span_by_distance(10.0, 20.0, 150.0) == pytest.approx(10.0)
    with pytest.raises(ValueError, match="positive mean speed"):
        speed_span_by_distance(0.0, 0.0, 10.0)


def test_a_step_is_at_once() -> None:
    assert Transition(3.0, 7.0, Shape.STEP, 5.0).at(0.0) == (7.0, 0.0, True)


def run(motion: NpcMotion, until: float, t0: float = 0.0) -> list[tuple[float, float, float]]:
    """(t, s, offset) after each step up to `until` [s]."""
    out = []
    t = t0
    while t < until - 1e-9:
        motion.step(t, DT, 0.0)
        t += DT
        out.append((t, motion.s, motion.offset))
    return out


def test_a_lateral_command_lands_on_its_target_when_its_span_ends() -> None:
    motion = NpcMotion(0.0, 0.0, 10.0, 1, ())
    span = span_by_rate(Shape.SINUSOIDAL, 3.5, 2.0)
    motion.command(LateralCommand("lc", Transition(0.0, 3.5, Shape.SINUSOIDAL, span), 0.0,
                                  0.0, lane=1))
    trace = run(motion, 4.0)
    done = [t for t, _, o in trace if o == pytest.approx(3.5)]
    assert done and done[0] == pytest.approx(span, abs=DT)
    assert motion.finished == ["lc"] and motion.lane == 1
    speeds = np.diff([o for _, _, o in trace]) / DT
    assert speeds.max() == pytest.approx(2.0, rel=0.01)  # the peak lateral speed
    assert trace[-1][1] == pytest.approx(40.0)  # the speed kept along


def test_a_lateral_command_by_distance_runs_over_the_distance_travelled() -> None:
    motion = NpcMotion(0.0, 0.0, 10.0, 1, ())
    motion.command(LateralCommand("lc", Transition(0.0, -3.5, Shape.CUBIC, 50.0), 0.0, 0.0,
                                  by_distance=True))
    trace = run(motion, 6.0)
    first = next(s for _, s, o in trace if o == pytest.approx(-3.5))
    assert first == pytest.approx(50.0, abs=10.0 * DT)


def test_a_timed_lane_change_moves_across_by_its_shape_and_keeps_the_speed_over_ground(
) -> None:
    """esmini's law: the offset is the shape at x + dt, the progress along the lane is
    what the speed leaves of the step after the shape's slope at x, the heading the step's."""
    transition = Transition(0.0, 3.5, Shape.SINUSOIDAL, 2.0)
    x = 0.0
    for _ in range(120):  # to 1 s, the middle of the move
        rate = 3.5 * 0.5 * math.pi / 2.0 * math.sin(math.pi * x / 2.0)
        step = lane_change_step(transition, x, False, 10.0, DT)
        assert step.offset == pytest.approx(1.75 * (1.0 - math.cos(math.pi * (x + DT) / 2.0)))
        assert step.along == pytest.approx(math.sqrt((10.0 * DT) ** 2 - (rate * DT) ** 2))
        assert step.heading == pytest.approx(math.atan2(rate, step.along / DT))
        x = step.x
    assert x == pytest.approx(1.0)
    assert step.offset == pytest.approx(1.75) and not step.done
    assert step.along < 10.0 * DT  # slower along the lane while it moves across


def test_a_lane_change_by_distance_runs_over_the_progress_along_the_lane() -> None:
    transition = Transition(0.0, -3.5, Shape.CUBIC, 50.0)
    step = lane_change_step(transition, 25.0, True, 10.0, DT)
    slope = -3.5 * 1.5 / 50.0  # the cubic's peak slope d offset / d distance, at mid-way
    assert step.along == pytest.approx(10.0 * DT / math.sqrt(1.0 + slope * slope))
    assert step.x == pytest.approx(25.0 + step.along)
    assert step.heading == pytest.approx(math.atan(slope), abs=1e-6)


def test_a_lane_change_faster_across_than_the_speed_goes_straight_across() -> None:
    transition = Transition(0.0, 3.5, Shape.SINUSOIDAL, 0.5)  # 11 m/s across at 2 m/s
    step = lane_change_step(transition, 0.25, False, 2.0, DT)
    assert step.along == 0.0
    assert step.x == pytest.approx(0.25 + 2.0 * DT * 0.5 / 3.5)
    assert step.offset == pytest.approx(3.5 * step.x / 0.5)  # linear
    assert step.heading == pytest.approx(0.5 * math.pi)


def test_a_lane_change_at_rest_does_not_move() -> None:
    step = lane_change_step(Transition(0.0, 3.5, Shape.LINEAR, 2.0), 0.5, False, 0.0, DT)
    assert (step.x, step.along, step.done) == (0.5, 0.0, False)
    assert step.offset == pytest.approx(0.875)


def test_a_lane_change_moves_the_reference_point_behind_the_body_centre() -> None:
    """With `ahead`, the reference point (the centre `ahead` back along the heading) follows
    the law, the station advances by the progress along the lane, the speed is kept."""
    ahead = 1.4  # [m]
    motion = NpcMotion(0.0, 0.0, 10.0, 1, ())
    span = span_by_rate(Shape.SINUSOIDAL, 3.5, 3.0)
    transition = Transition(0.0, 3.5, Shape.SINUSOIDAL, span)
    motion.command(LateralCommand("lc", transition, 0.0, -ahead, lane=1, ahead=ahead))
    x, s_ref = 0.0, -ahead
    for k in range(120):
        motion.step(k * DT, DT, 0.0)
        step = lane_change_step(transition, x, False, 10.0, DT)
        x, s_ref = step.x, s_ref + step.along
        yaw = motion.heading_offset
        assert yaw == pytest.approx(step.heading)
        assert motion.s - ahead * math.cos(yaw) == pytest.approx(s_ref)
        assert motion.offset - ahead * math.sin(yaw) == pytest.approx(step.offset)
    assert motion.speed == 10.0
    assert s_ref < 10.0 * 1.0 - ahead - 0.1  # behind where the full speed along would be
    run(motion, 3.0, 1.0)
    assert motion.finished == ["lc"] and motion.lane == 1 and motion.heading_offset == 0.0
    assert motion.offset == pytest.approx(3.5)


def test_a_speed_command_then_holds_its_target() -> None:
    motion = NpcMotion(0.0, 0.0, 20.0, 1, ())
    span = span_by_rate(Shape.LINEAR, 10.0, 5.0)
    motion.command(SpeedCommand("brake", Transition(20.0, 10.0, Shape.LINEAR, span), 0.0))
    run(motion, 2.0)
    assert motion.speed == pytest.approx(10.0) and motion.finished == ["brake"]
    run(motion, 5.0, 2.0)
    assert motion.speed == pytest.approx(10.0)


def test_a_continuous_speed_command_never_finishes_and_a_cancel_holds_the_speed() -> None:
    motion = NpcMotion(0.0, 0.0, 20.0, 1, ())
    motion.command(SpeedCommand("follow", Transition(20.0, 15.0, Shape.LINEAR, 1.0), 0.0,
                                continuous=True))
    run(motion, 3.0)
    assert motion.finished == [] and motion.speed == pytest.approx(15.0)
    motion.cancel("follow")
    run(motion, 4.0, 3.0)
    assert motion.speed == pytest.approx(15.0)


def test_a_track_command_keeps_its_acceleration_limits() -> None:
    motion = NpcMotion(0.0, 0.0, 10.0, 1, ())
    motion.command(TrackCommand("gap", 20.0, max_accel=2.0, max_decel=4.0))
    run(motion, 1.0)
    assert motion.speed == pytest.approx(12.0, abs=1e-9)


def test_a_timed_path_is_at_each_vertex_at_its_time() -> None:
    motion = NpcMotion(100.0, -5.0, 0.0, 1, (), pedestrian=True)
    path = PathCommand("walk", (100.0, 100.0, 100.0), (-5.0, 0.0, 5.0), (1.0, 4.0, 7.0))
    motion.command(path)
    trace = run(motion, 8.0)
    at = {round(t, 6): o for t, _, o in trace}
    for t, offset in [(1.0, -5.0), (4.0, 0.0), (7.0, 5.0)]:
        key = min(at, key=lambda x: abs(x - t))
        assert at[key] == pytest.approx(offset, abs=1e-6)
    assert motion.finished == ["walk"]


def test_an_untimed_path_is_walked_at_the_speed_held() -> None:
    """14 m of path at 2 m/s (7 s), its last segment straight across; then on along the
    lane at that speed over ground (as esmini moves an entity on after its trajectory)."""
    motion = NpcMotion(0.0, 0.0, 2.0, 1, ())
    motion.command(PathCommand("p", (10.0, 10.0), (0.0, 4.0), None))
    trace = run(motion, 7.0)
    assert motion.finished == ["p"]
    assert (trace[-1][1], trace[-1][2]) == pytest.approx((10.0, 4.0), abs=0.05)
    trace = run(motion, 8.0, t0=7.0)
    assert (trace[-1][1], trace[-1][2]) == pytest.approx((12.0, 4.0), abs=0.05)
    assert motion.speed == pytest.approx(2.0)


def test_a_pedestrian_starts_facing_as_placed_and_keeps_it_on_along_its_lane() -> None:
    """Placed facing across (a file's orientation), a pedestrian walks a timed path across
    the road and then goes on along its lane at the path's speed over ground, still facing
    across (esmini moves it on along the road keeping its heading)."""
    motion = NpcMotion(100.0, -5.0, 0.0, 1, (), pedestrian=True, facing=math.pi / 2)
    assert motion.heading_offset == pytest.approx(math.pi / 2)
    motion.command(PathCommand("walk", (100.0, 100.0), (-5.0, 5.0), (0.0, 5.0)))
    run(motion, 5.0)
    assert motion.finished == ["walk"]
    assert (motion.s, motion.offset) == pytest.approx((100.0, 5.0), abs=1e-6)
    trace = run(motion, 7.0, t0=5.0)
    assert (trace[-1][1], trace[-1][2]) == pytest.approx((104.0, 5.0), abs=1e-6)
    assert motion.heading_offset == pytest.approx(math.pi / 2)

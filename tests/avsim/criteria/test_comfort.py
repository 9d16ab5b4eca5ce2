"""`comfort` (ISO 15622 / 22179) on synthetic truth: a braking within the limits passes with
its peaks as values, one beyond them fails, the rise of deceleration is judged and its fall
is not, a braking with no comfortable solution by the truth (a car stopped close ahead) is
excused, a run that never braked is not applicable; the run metrics' peaks; the key loads."""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
import yaml

from avsim.criteria.base import TruthSample
from avsim.criteria.comfort import (
    A_ISO,
    J_ISO,
    ComfortDecel,
    ComfortJerk,
    closing_distance,
    comfortable_solution,
    peaks,
)
from avsim.scenario.load import ScenarioError, load_scenario
from tests.avsim.texts import MINIMAL
from tests.roads import make_map, seg
from world.actors.actor_set import ActorPoses
from world.spec import ActorType

RATE = 40  # [Hz] the criteria rate
ROAD = make_map(seg(2000.0))
EGO_LENGTH = 4.8
CAR_HALF = np.array([2.3, 0.9, 0.75])
V0 = 20.0  # [m/s]


def no_actors() -> ActorPoses:
    return ActorPoses(ids=(), kinds=(), centres=np.zeros((0, 3)), yaws=np.zeros(0),
                      half_sizes=np.zeros((0, 3)), stations=np.zeros(0),
                      offsets=np.zeros(0), speeds=np.zeros(0), accels=np.zeros(0))


def stopped_car(station: float) -> ActorPoses:
    return ActorPoses(ids=("stopped",), kinds=(ActorType.CAR,), centres=np.zeros((1, 3)),
                      yaws=np.zeros(1), half_sizes=CAR_HALF[None, :],
                      stations=np.array([station]), offsets=np.zeros(1),
                      speeds=np.zeros(1), accels=np.zeros(1))


def braking(decel: float, jerk: float, t0: float = 2.0, duration: float = 12.0,
            ) -> list[tuple[float, float, float]]:
    """(t, speed, station): V0, then from t0 the deceleration rising at `jerk` to `decel`
    and held to a stop."""
    out, v, s, a = [], V0, 100.0, 0.0
    dt = 1.0 / RATE
    for k in range(round(duration * RATE)):
        t = k * dt
        if t >= t0 and v > 0.0:
            a = min(decel, a + jerk * dt)
        v = max(v - a * dt, 0.0)
        s += v * dt
        out.append((t, v, s))
    return out


def feed(criterion: ComfortDecel | ComfortJerk,
         trace: list[tuple[float, float, float]],
         actors: ActorPoses | Callable[[float], ActorPoses] | None = None,
         ) -> ComfortDecel | ComfortJerk:
    """`criterion` fed the trace, with `actors` (or `actors(t)`) around."""
    for t, v, s in trace:
        criterion.update(TruthSample(
            t=t, speed=v, station=s, front_station=s + 2.4, tyres=np.zeros((4, 2)),
            tyre_stations=np.zeros(4), tyre_offsets=np.zeros(4), touching=frozenset(),
            actors=(actors(t) if callable(actors) else actors) if actors is not None
            else no_actors()))
    return criterion


def test_a_braking_within_the_limits_passes_with_its_peaks() -> None:
    trace = braking(2.0, 1.5)
    decel = feed(ComfortDecel(ROAD, EGO_LENGTH), trace).result()
    jerk = feed(ComfortJerk(ROAD, EGO_LENGTH), trace).result()
    assert decel.passed and jerk.passed
    assert decel.value == pytest.approx(2.0, abs=0.02)  # the 2 s average of a held 2.0
    assert jerk.value == pytest.approx(1.5, abs=0.05)
    assert (decel.threshold, decel.unit, jerk.threshold, jerk.unit) == (
        A_ISO, "m/s^2", J_ISO, "m/s^3")


def test_a_hard_or_sudden_braking_fails() -> None:
    hard = feed(ComfortDecel(ROAD, EGO_LENGTH), braking(4.5, 2.0)).result()
    assert not hard.passed and hard.value is not None and hard.value > A_ISO
    assert hard.first_failure is not None and hard.first_failure > 2.0
    sudden = feed(ComfortJerk(ROAD, EGO_LENGTH), braking(3.0, 8.0)).result()
    assert not sudden.passed and sudden.value == pytest.approx(3.0, abs=0.1)  # over 1 s


def test_the_fall_of_deceleration_is_not_judged() -> None:
    """The car coming to rest from 3 m/s^2 drops its deceleration at once: not a jolt ISO
    limits (the onset of braking is)."""
    jerk = feed(ComfortJerk(ROAD, EGO_LENGTH), braking(3.0, 2.0)).result()
    assert jerk.passed


def test_no_comfortable_solution_by_the_truth_is_excused() -> None:
    """A car stands 30 m ahead of the ego at 20 m/s: stopping 2 m short needs 400 / 56 =
    7.1 m/s^2, so the hard braking that follows is excused, and, the only braking, leaves
    the criterion not applicable."""
    trace = braking(6.0, 20.0, t0=0.5, duration=6.0)
    front = 100.0 + 2.4  # the ego's front at the start
    car = stopped_car(front + 30.0 + CAR_HALF[0])
    assert not comfortable_solution(V0, 30.0, 0.0, 0.0, 0.0)  # needs 400 / 56 m/s^2
    decel = feed(ComfortDecel(ROAD, EGO_LENGTH), trace, car).result()
    assert decel.passed is None and decel.note is not None
    assert "excused" in decel.note
    # the same braking with the car 200 m away is judged, and fails
    far = feed(ComfortDecel(ROAD, EGO_LENGTH), trace, stopped_car(front + 200.0)).result()
    assert far.passed is False


def test_a_car_standing_behind_the_lead_counts_before_the_lead_leaves() -> None:
    """The lead, 20 m ahead at the ego's speed, hides a car standing 45 m ahead in the
    lane: no braking within ISO's limits stops short of that car (V0 needs 2.5 m/s^2
    with a step, 63 m at 2.5 m/s^3), so the braking is excused while the lead is still in
    the lane; the same braking with the standing car 300 m ahead is judged."""
    front = 100.0 + 2.4
    trace = braking(5.0, 8.0, t0=0.5, duration=6.0)

    def lane(standing_gap: float) -> Callable[[float], ActorPoses]:
        def at(t: float) -> ActorPoses:
            lead_s = front + 20.0 + CAR_HALF[0] + V0 * t  # keeps its speed (then leaves)
            return ActorPoses(ids=("lead", "standing"), kinds=(ActorType.CAR,) * 2,
                              centres=np.zeros((2, 3)), yaws=np.zeros(2),
                              half_sizes=np.stack([CAR_HALF, CAR_HALF]),
                              stations=np.array([lead_s, front + standing_gap + CAR_HALF[0]]),
                              offsets=np.zeros(2), speeds=np.array([V0, 0.0]),
                              accels=np.zeros(2))
        return at
    assert not comfortable_solution(V0, 45.0, 0.0, 0.0, 0.0)
    assert comfortable_solution(V0, 20.0, V0, 0.0, 0.0)  # the lead alone needs nothing
    hidden = feed(ComfortJerk(ROAD, EGO_LENGTH), trace, lane(45.0)).result()
    assert hidden.passed is None and hidden.note is not None and "excused" in hidden.note
    far = feed(ComfortJerk(ROAD, EGO_LENGTH), trace, lane(300.0)).result()
    assert far.passed is False


def test_never_braking_is_not_applicable() -> None:
    steady = [(k / RATE, V0, 100.0 + V0 * k / RATE) for k in range(10 * RATE)]
    r = feed(ComfortDecel(ROAD, EGO_LENGTH), steady).result()
    assert r.passed is None and r.note is not None and "never braked" in r.note


def test_a_comfortable_solution_rises_at_the_jerk_bound() -> None:
    """Closing at 5.6 m/s (a cut-in at 40 km/h before a car at 60 km/h): a step to 3.5
    m/s^2 would end it in 4.5 m, but the deceleration rising at 2.5 m/s^3 from coasting
    takes 8.11 m (1.4 s of rise shedding 2.45 m/s, then 3.15 m/s at 3.5 m/s^2); braking at
    3.5 m/s^2 already, the step's distance."""
    assert closing_distance(5.6, 0.0) == pytest.approx(
        5.6 * 1.4 - J_ISO * 1.4**3 / 6 + 3.15**2 / (2 * A_ISO))
    assert closing_distance(5.6, A_ISO) == pytest.approx(5.6**2 / (2 * A_ISO))
    assert closing_distance(5.6, 9.0) == closing_distance(5.6, A_ISO)  # clipped
    t = math.sqrt(2 * 1.0 / J_ISO)  # a small closing ends during the rise
    assert closing_distance(1.0, 0.0) == pytest.approx(1.0 * t - J_ISO * t**3 / 6)
    assert closing_distance(0.0, 0.0) == closing_distance(-3.0, 0.0) == 0.0
    # so 9 m ahead (7 m of room) there is none, though the instant need is 2.24 m/s^2
    assert not comfortable_solution(16.67, 9.0, 11.07, 0.0, 0.0)
    assert comfortable_solution(16.67, 10.2, 11.07, 0.0, 0.0)
    assert comfortable_solution(16.67, 9.0, 11.07, 0.0, 2.5)  # already braking


def test_a_braking_lead_needs_a_stop_behind_where_it_rests() -> None:
    # the closing alone ends in time: 10 m/s in 14.29 m at a step, more at the bound
    assert comfortable_solution(20.0, 22.0, 10.0, 0.0, 0.0) is (closing_distance(10.0, 0.0)
                                                                <= 20.0)
    # the lead brakes at 5 m/s^2 and rests 10 m on: the ego must stop within 30 m
    assert not comfortable_solution(20.0, 22.0, 10.0, -5.0, 0.0)
    assert closing_distance(20.0, A_ISO) > 30.0
    assert comfortable_solution(10.0, 22.0, 12.0, 0.0, 0.0)  # opening
    assert comfortable_solution(10.0, 40.0, 10.0, -2.0, 0.0)  # 63 m to stop in 13.5 m


def test_a_brake_onset_after_a_close_cut_in_is_excused_and_a_far_one_judged() -> None:
    """A car 9 m ahead at 14.4 m/s, the ego at V0 (closing 5.6 m/s), braking at 4 m/s^3:
    no comfortable solution at the start (the instant need, 2.24 m/s^2, is under A_ISO), so
    the jerk is excused; the same braking behind a car 80 m ahead (a comfortable solution
    at hand) fails on the jerk."""
    front = 100.0 + 2.4
    trace = braking(3.0, 4.0, t0=0.5, duration=6.0)

    def ahead_moving(gap: float) -> Callable[[float], ActorPoses]:
        def at(t: float) -> ActorPoses:
            return ActorPoses(ids=("cut",), kinds=(ActorType.CAR,), centres=np.zeros((1, 3)),
                              yaws=np.zeros(1), half_sizes=CAR_HALF[None, :],
                              stations=np.array([front + gap + CAR_HALF[0] + 14.4 * t]),
                              offsets=np.zeros(1), speeds=np.array([14.4]),
                              accels=np.zeros(1))
        return at
    near = feed(ComfortJerk(ROAD, EGO_LENGTH), trace, ahead_moving(9.0)).result()
    assert near.passed is None and near.note is not None and "excused" in near.note
    far = feed(ComfortJerk(ROAD, EGO_LENGTH), trace, ahead_moving(80.0)).result()
    assert far.passed is False


def test_the_run_metrics_are_the_unexcused_peaks() -> None:
    trace = braking(2.0, 1.5)
    t = np.array([x[0] for x in trace])
    v = np.array([x[1] for x in trace])
    m = peaks(t, v)
    assert m["peak_decel_2s"] == pytest.approx(2.0, abs=0.02)
    assert m["peak_braking_jerk"] == pytest.approx(1.5, abs=0.05)


def test_the_scenario_key_loads_and_a_bad_value_is_one_line(tmp_path: Path) -> None:
    doc = yaml.safe_load(MINIMAL)
    doc["criteria"] = {"comfort": "iso15622"}
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump(doc))
    assert load_scenario(str(path)).criteria.get("comfort") == "iso15622"
    doc["criteria"] = {"comfort": "gentle"}
    path.write_text(yaml.safe_dump(doc))
    with pytest.raises(ScenarioError, match="comfort"):
        load_scenario(str(path))

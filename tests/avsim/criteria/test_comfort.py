"""`comfort` (ISO 15622 / 22179) on synthetic truth: a braking within the limits passes with
its peaks as values, one beyond them fails, the rise of deceleration is judged and its fall
is not, a braking with no comfortable solution by the truth (a car stopped close ahead) is
excused, a run that never braked is not applicable; the run metrics' peaks; the key loads."""

from __future__ import annotations

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
    peaks,
    required_decel,
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
         trace: list[tuple[float, float, float]], actors: ActorPoses | None = None,
         ) -> ComfortDecel | ComfortJerk:
    for t, v, s in trace:
        criterion.update(TruthSample(
            t=t, speed=v, station=s, front_station=s + 2.4, tyres=np.zeros((4, 2)),
            tyre_stations=np.zeros(4), tyre_offsets=np.zeros(4), touching=frozenset(),
            actors=actors if actors is not None else no_actors()))
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
    assert required_decel(V0, 30.0, 0.0, 0.0) == pytest.approx(400.0 / 56.0)
    decel = feed(ComfortDecel(ROAD, EGO_LENGTH), trace, car).result()
    assert decel.passed is None and decel.note is not None
    assert "excused" in decel.note
    # the same braking with the car 200 m away is judged, and fails
    far = feed(ComfortDecel(ROAD, EGO_LENGTH), trace, stopped_car(front + 200.0)).result()
    assert far.passed is False


def test_never_braking_is_not_applicable() -> None:
    steady = [(k / RATE, V0, 100.0 + V0 * k / RATE) for k in range(10 * RATE)]
    r = feed(ComfortDecel(ROAD, EGO_LENGTH), steady).result()
    assert r.passed is None and r.note is not None and "never braked" in r.note


def test_required_deceleration_of_a_braking_lead() -> None:
    # closing only: (20 - 10)^2 / (2 (22 - 2))
    assert required_decel(20.0, 22.0, 10.0, 0.0) == pytest.approx(2.5)
    # the lead brakes at 5 m/s^2 to a stop 10 m on: stop within 22 + 10 - 2 m
    assert required_decel(20.0, 22.0, 10.0, -5.0) == pytest.approx(400.0 / 60.0)
    assert required_decel(10.0, 22.0, 12.0, 0.0) == 0.0


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

"""ACC comfort within ISO 15622 / ISO 22179 (issue K, items 1, 3 and 5), on the acceptance
scenarios that reproduced its failures: (a) closing at 15 km/h on a slower lead from 25 m
(braked at 4.4 m/s^2, where about 1 m/s^2 does); (b) a stopped car revealed by the lead's
cut-out about 50 m ahead (braked at 5.9 m/s^2); (c) a stop line, a crossing a pedestrian
walks onto and a speed bump, met at 40 km/h (the crossing braked at 5.9 m/s^2: a pedestrian
is tracked from about 24 m); and pedal pushes while following (never nearer the lead than
UN R157's d_min).

Each test asserts first that its situation happened, from the truth (the lead was slower,
the stopped car was revealed, the line was reached, the pedal was pushed), then the
measured peaks: the 2 s deceleration and the rise of braking deceleration (`comfort_decel`,
`comfort_jerk`, `avsim.criteria.comfort`). The `fast` profile: perception is not judged."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from avsim.run.runner import RunResult
from planner.fsm.acc import r157_min_gap
from world.sensors.setup import Profile

pytestmark = [pytest.mark.slow, pytest.mark.acceptance]  # the acceptance set: `make acceptance`
KPH = 1 / 3.6
DIR = "scenarios/acceptance"


def run(run_scenario: Callable[..., RunResult], name: str) -> RunResult:
    return run_scenario(f"{DIR}/{name}.yaml", record=False, profile=Profile.FAST)


def criteria(result: RunResult) -> dict[str, object]:
    return {c.name: c for c in result.criteria}


def acc_changes(result: RunResult) -> list[tuple[float, str, str]]:
    return [(c.t, c.target, c.reason) for c in result.state_changes if c.machine == "acc"]


@pytest.fixture(scope="module")
def approach(run_scenario: Callable[..., RunResult]) -> RunResult:
    return run(run_scenario, "acc_approach")


@pytest.fixture(scope="module")
def revealed(run_scenario: Callable[..., RunResult]) -> RunResult:
    return run(run_scenario, "revealed_stop")


@pytest.fixture(scope="module")
def city(run_scenario: Callable[..., RunResult]) -> RunResult:
    return run(run_scenario, "city_stop_40")


@pytest.fixture(scope="module")
def pedal(run_scenario: Callable[..., RunResult]) -> RunResult:
    return run(run_scenario, "pedal_push_following")


def test_a_slower_lead_is_approached_at_about_1_m_s2(approach: RunResult) -> None:
    log = approach.log
    gap, lead_v, v = log.array("lead_gap"), log.array("lead_speed"), log.array("speed")
    assert gap[0] == pytest.approx(25.0, abs=0.5)  # the situation: 25 m ahead ...
    assert v[0] - lead_v[0] == pytest.approx(15 * KPH, abs=0.2)  # ... closing at 15 km/h
    assert v[-1] == pytest.approx(25 * KPH, abs=0.3)  # and then it followed
    assert approach.passed, approach.criteria
    c = criteria(approach)
    assert c["comfort_decel"].value < 1.5  # was 1.7 (0.2 s peak 3.5)
    assert c["comfort_jerk"].value < 2.0  # was 2.8
    assert [m for _, m, _ in acc_changes(approach)] == ["cruise", "trail"]


def test_a_stopped_car_revealed_by_a_cut_out_is_stopped_for_comfortably(
        revealed: RunResult) -> None:
    log = revealed.log
    t, gap, lead_v = log.array("t"), log.array("lead_gap"), log.array("lead_speed")
    jump = int(np.argmax(np.diff(gap) > 10.0)) + 1  # the lead left: the stopped car ahead
    assert lead_v[jump] == 0.0 and 40.0 < gap[jump] < 55.0
    assert log.speed[jump] == pytest.approx(50 * KPH, abs=0.3)
    # comfortable by the truth: stopping 2 m short needs under 3.5 m/s^2
    assert log.speed[jump] ** 2 / (2.0 * (gap[jump] - 2.0)) < 3.5
    assert revealed.passed, revealed.criteria
    c = criteria(revealed)
    assert c["comfort_decel"].value < 3.0  # was 3.8 (0.2 s 5.9 m/s^2)
    assert c["comfort_jerk"].value < 2.5  # was 5.7
    # without `overtake` it stands behind the stopped car 2 to 6 m back (UN R157 4.2.1)
    assert 2.0 <= c["standstill_gap"].value <= 6.0
    assert log.speed[-1] < 0.1 and t[-1] > t[jump] + 10.0
    # one clean transition: TRAIL throughout (the lead cut out, the stopped car taken on)
    assert [m for _, m, _ in acc_changes(revealed)] == ["cruise", "trail"]


def test_city_events_at_40_kph_are_taken_within_comfort(city: RunResult) -> None:
    log = city.log
    s, v = log.array("station"), log.array("speed")
    front = s + 2.4
    assert v[0] == pytest.approx(40 * KPH, abs=0.1)
    at_line = (front > 116.0) & (front <= 120.0) & (v < 0.1)
    assert at_line.any()  # it stopped at the line at s 120
    assert v[(s > 150.0) & (s < 190.0)].max() > 38 * KPH  # 40 km/h between the events
    assert v[(s > 260.0) & (s < 300.0)].max() > 38 * KPH
    walker = np.array(log.actor_offset)[:, 0]
    in_lane = np.abs(walker) < 1.75  # the walker in the ego's lane (its centre at offset 0)
    assert in_lane.any() and front[in_lane].max() < 230.0  # it gave way: short of the
    #   crossing (s 230) all the while the walker crossed its lane, ...
    assert v[in_lane & (front > 215.0)].min() < 3.0  # ... at a crawl near it (it came at
    #   the 20 km/h of a crossing where a pedestrian waits: the walker left its lane as it
    #   came to 2.3 m/s, 9 m short of the crossing, before it had to stand)
    modes = [m for _, m, _ in acc_changes(city)]
    assert "stop_sign" in modes and "pedestrian" in modes and "speed_bump" in modes
    assert city.passed, city.criteria
    c = criteria(city)
    assert c["comfort_decel"].value < 3.0  # was 4.2 (0.2 s 5.8) at the crossing
    assert c["comfort_jerk"].value < 2.5  # was 5.5


def test_pedal_pushes_while_following_keep_d_min(pedal: RunResult) -> None:
    log = pedal.log
    t, v, gap = log.array("t"), log.array("speed"), log.array("lead_gap")
    pushed = log.array("pedal") > 0.05
    assert pushed.any() and np.isfinite(gap).all()  # pushed, with the lead ahead throughout
    margin = gap - np.array([r157_min_gap(x) for x in v])
    start = int(np.argmax(pushed))
    end = len(pushed) - 1 - int(np.argmax(pushed[::-1]))
    lead_v = log.array("lead_speed")
    assert v[start:end].max() > lead_v[start] + 0.3  # the push sped it up, closing in ...
    assert gap[start:end].min() < gap[start] - 1.0  # ... on the lead
    around = (t > t[start] - 1.0) & (t < t[end] + 5.0)  # the push, its start and its end
    assert float(margin[around].min()) > 0.0
    assert float(margin[t > 2.0].min()) > 0.0
    assert pedal.passed, pedal.criteria

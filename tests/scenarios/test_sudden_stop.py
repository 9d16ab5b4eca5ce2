"""ICCAS sudden stop: the car ahead brakes at 6 m/s^2 to a stop from 50 km/h, 12 m ahead
(Euro NCAP CCRb) and 1.5 s ahead (UN R157); the ego stops behind it without contact, at
least 0.5 m short, in its lane, and follows it off again.

Each test runs twice (`tests.scenarios.modes`): `[truth]`, the bundled planner and control on
the privileged ground truth (profile `none`), in `make test`; `[sensors]`, the whole stack on
the `default` profile's cameras and LiDAR, in `make acceptance`. Each run has its own
golden file (`NAME.truth`, `NAME`)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from avsim.run.runner import RunResult
from tests.scenarios import golden
from world.actors.catalogue import CATALOGUE, DEFAULT_MODEL

NPC_CAR_LENGTH = CATALOGUE[DEFAULT_MODEL["car"]].length  # [m] a `type: car` actor's body

pytestmark = pytest.mark.slow
KPH = 1 / 3.6
CASES = {"sudden_stop": (1.0, 12.0), "sudden_stop_headway": (3.0, 50 * KPH * 1.5)}


@pytest.fixture(scope="module", params=sorted(CASES))
def result(request: pytest.FixtureRequest, run_scenario: Callable[..., RunResult],
           mode: str) -> RunResult:
    return run_scenario(request.param, record=False, stack=mode)


def _lead(result: RunResult) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    log = result.log
    t = log.array("t")
    k = [a.id for a in result.scenario.world.actors].index("lead")
    lead_s = np.array(log.actor_station)[:, k]
    gap = lead_s - log.array("station") - (NPC_CAR_LENGTH + 4.8) / 2
    return t, lead_s, np.gradient(lead_s, t), gap


def test_the_lead_braked_hard_from_50_close_ahead(result: RunResult) -> None:
    t, _, lead_v, gap = _lead(result)
    t_brake, nominal_gap = CASES[result.scenario.name]
    i = int(np.searchsorted(t, t_brake))
    assert lead_v[i - 1] == pytest.approx(50 * KPH, abs=0.1)
    # the ego keeps its distance until then (it may start to open the gap)
    assert nominal_gap - 0.3 <= gap[i] <= nominal_gap + 1.5
    stopped = np.flatnonzero(lead_v < 0.05)
    t_stop = t[stopped[stopped > i][0]]
    assert t_stop - t_brake == pytest.approx(50 * KPH / 6.0, abs=0.15)  # 6 m/s^2
    assert (lead_v[(t > t_stop) & (t < t_stop + 3.5)] < 0.05).all()  # it stood


def test_no_contact_and_the_ego_stops_short(result: RunResult) -> None:
    assert not any(c.failed for c in result.criteria), result.criteria
    t, _, lead_v, gap = _lead(result)
    v = result.log.array("speed")
    t_brake, _ = CASES[result.scenario.name]
    after = t > t_brake
    assert float(gap.min()) >= 0.5
    standing = after & (v < 0.05) & (lead_v < 0.05)
    assert standing.any()  # it came to rest behind the standing lead
    assert float(gap[standing].min()) >= 0.5
    assert result.metrics["max_lateral_error"] < 0.3  # in its lane while braking


def test_the_control_fsm_brakes_to_a_stop(result: RunResult) -> None:
    control = [c.target for c in result.state_changes if c.machine == "control"]
    assert "stop" in control[control.index("deceleration"):]
    if result.scenario.name == "sudden_stop":  # 12 m at 50 km/h, under d_min from the start:
        # braking beyond ISO's comfort, by the ACC's a_hard (its lead taken at once, braking
        # from 0.3 s) or the emergency stop
        assert result.metrics["max_decel"] > 4.5


def test_result_matches_golden(result: RunResult, mode: str) -> None:
    golden.check(result, golden.label(result.scenario.name, mode))

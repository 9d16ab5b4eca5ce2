"""ICCAS traffic jam: the lead brakes to a stop at 1 m/s^2, waits 10 s and drives off,
twice. The ego stops 2-6 m behind, moves off within 2 s of the lead, keeps UN R157's d_min
while moving, and is back at its set speed when the jam clears.

Each test runs twice (`tests.scenarios.modes`): `[truth]`, the bundled planner and control on
the privileged ground truth (profile `none`), in `make test`; `[sensors]`, the whole stack on
the `default` profile's cameras and LiDAR, in `make acceptance`. Each run has its own
golden file (`traffic_jam.truth`, `traffic_jam`)."""

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


@pytest.fixture(scope="module")
def result(run_scenario: Callable[..., RunResult], mode: str) -> RunResult:
    return run_scenario("traffic_jam", record=False, stack=mode)


def _intervals(mask: np.ndarray, t: np.ndarray) -> list[tuple[float, float]]:
    edges = np.flatnonzero(np.diff(mask.astype(int)))
    starts = [t[i + 1] for i in edges if not mask[i]]
    ends = [t[i] for i in edges if mask[i]]
    return list(zip(starts, ends, strict=False))


def test_stop_and_go_twice(result: RunResult) -> None:
    log = result.log
    t, v, s = log.array("t"), log.array("speed"), log.array("station")
    k = [a.id for a in result.scenario.world.actors].index("lead")
    lead_s = np.array(log.actor_station)[:, k]
    lead_v = np.gradient(lead_s, t)
    gap = lead_s - s - (NPC_CAR_LENGTH + 4.8) / 2
    stops = [(a, b) for a, b in _intervals(lead_v < 0.05, t) if b - a >= 9.0]
    assert len(stops) == 2, stops  # the lead stopped twice, ~10 s each
    for a, b in stops:
        during = (t >= a) & (t <= b)
        standing = during & (v < 0.05)
        assert standing.any()  # the ego came to rest behind it
        assert 2.0 <= float(gap[standing].min()) <= float(gap[standing].max()) <= 6.0
        lead_off = t[np.argmax((t > b) & (lead_v > 0.1))]
        ego_off = t[np.argmax((t > b - 1.0) & (v > 0.1))]
        assert 0.0 <= ego_off - lead_off <= 2.0
    assert float(gap.min()) > 2.0


def test_verdict_and_back_to_set_speed(result: RunResult) -> None:
    assert not any(c.failed for c in result.criteria), result.criteria
    c = {r.name: r for r in result.criteria}
    assert c["min_gap"].value >= c["min_gap"].threshold  # d_min while moving
    assert 2.0 <= c["standstill_gap"].value <= 6.0
    assert c["time_to_resume"].value <= 15.0
    v = result.log.array("speed")
    assert v[-1] == pytest.approx(45 * KPH, abs=1 * KPH)  # the jam cleared: set speed
    modes = [x.target for x in result.state_changes if x.machine == "acc"]
    assert modes == ["cruise", "trail", "cruise"]  # trailed through both stops, no brake


@pytest.mark.xfail(strict=True, reason=(
    "max_decel 1.512 m/s^2: at 54.5 s, trailing the lead braking at 1.0 m/s^2 (a_gentle), "
    "the trail law's d_des'(v) x gap_rate term follows the noise of the lead's estimated "
    "acceleration about the taper at a_gentle and the planned speed dips 0.33 m/s in 0.2 s; "
    "1.481 before the localiser's rear-axle turn and the pull-away feed-forward; 1.534 on "
    "the privileged truth (exact velocities, no estimation noise): the trail law's own"))
def test_the_jam_is_taken_gently(result: RunResult) -> None:
    c = {r.name: r for r in result.criteria}
    assert c["max_decel"].value <= 1.5  # the lead brakes at 1.0 m/s^2


def test_result_matches_golden(result: RunResult, mode: str) -> None:
    golden.check(result, golden.label("traffic_jam", mode))

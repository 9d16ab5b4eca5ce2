"""The acceptance set (`scenarios/acceptance/`, issue K item 9): every run of its grids, as
`avsim suite scenarios/acceptance` runs them, under the `default` sensor profile (the
cameras and the LiDAR in the loop).

Each test first shows from the truth that its situation happened (the stationary car stood
in the ego's lane and the ego came up behind it; the lead braked to a stop; the cutter
entered the ego's lane ahead of it; the lead left the lane and revealed the stopped car;
the lead stopped and drove off again), then that every criterion passed (ISO 15622 comfort
included, `comfort: iso15622`; a collision UN
R157 deems unavoidable is reported by `no_collision`, not failed). The set is too long for
`make test` (113 runs of the grids): `make acceptance` runs it.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from numpy.typing import NDArray

from avsim.batch.suite import collect_scenarios, suite_entries
from avsim.run.runner import RunResult
from world.sensors.setup import Profile

pytestmark = [pytest.mark.slow, pytest.mark.acceptance]
SET = Path(__file__).parents[2] / "scenarios" / "acceptance"
LANE_WIDTH = 3.5  # [m] every road of the set's
STOPPED = 0.1  # [m/s]
KPH = 1 / 3.6
GRIDS = ("ncap_ccrs", "ncap_ccrm", "ncap_ccrb", "r157_lead_braking", "r157_cut_in",
         "r157_cut_out", "iso22179_stop_and_go")


def _runs() -> list[tuple[str, str, dict[str, object]]]:
    entries = suite_entries(collect_scenarios([str(SET)]))
    return [(name or Path(path).stem, path, overrides) for name, path, overrides in entries
            if Path(path).stem in GRIDS]


RUNS = _runs()
KNOWN = {  # grid point -> why it fails (a strict xfail: it is reported when it passes)
    f"ncap_ccrm_{k:03d}": "80 km/h closing on a car at 20 km/h: the roof LiDAR's lowest "
    "ring that clears the ground meets the car's rear above min_top from 72 m, its track "
    "starts at 65 m, and keeping UN R157's d_min from there needs more than ISO 15622's "
    "3.5 m/s^2: the gap falls to 5.4 m, under d_min's 11.3 m (following_gap)"
    for k in range(25, 30)} | {
    "r157_lead_braking_004": "90 km/h behind a lead braking at 4 m/s^2 from a 2 s headway: "
    "comfort_decel 3.53 m/s^2 over ISO 15622's 3.5 where the judge finds a comfortable "
    "solution; 3.43 before the localiser's rear-axle turn moved the pose and the tracks "
    "placed in it: the ACC's braking build-up has 0.07 m/s^2 of margin here"}


def actor(result: RunResult, k: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(station, offset from the reference line) [m] of actor k's centre at each tick."""
    return (np.array(result.log.actor_station)[:, k],
            np.array(result.log.actor_offset)[:, k])


def lane_of(offset: NDArray[np.float64]) -> NDArray[np.int64]:
    """The lane an offset from the reference line is in (lane 0's centre is on it)."""
    return np.rint(offset / LANE_WIDTH).astype(np.int64)


def speed_of(result: RunResult, station: NDArray[np.float64]) -> NDArray[np.float64]:
    """[m/s] an actor's speed along the road, from its stations."""
    return np.gradient(station, result.log.array("t"))


def ccrs(result: RunResult) -> None:
    s, offset = actor(result, 0)
    assert np.ptp(s) < 0.01 and np.all(lane_of(offset) == 0), "the target did not stand in lane 0"
    gap = result.log.array("lead_gap")
    assert np.isfinite(gap[0]) and np.nanmin(gap) < 8.0, "the ego never came up behind it"
    assert result.log.array("speed")[-1] < STOPPED, "the ego did not stop behind it"


def ccrm(result: RunResult) -> None:
    s, offset = actor(result, 0)
    v = speed_of(result, s)
    assert np.allclose(v, 20 * KPH, atol=0.05) and np.all(lane_of(offset) == 0)
    ego = result.log.array("speed")
    assert ego[0] > 20 * KPH + 2.0, "the ego did not close on it"
    assert abs(ego[-1] - 20 * KPH) < 1.0 and np.isfinite(result.log.array("lead_gap")[-1]), \
        "the ego did not settle behind it"


def braking_lead(result: RunResult, stand: float = 1.0) -> None:
    """The lead braked from its speed to a stop and stood at least `stand` [s]."""
    s, offset = actor(result, 0)
    v = speed_of(result, s)
    assert v[0] > 10 * KPH and np.all(lane_of(offset) == lane_of(offset[:1])[0])
    standing = v < STOPPED
    assert standing.any(), "the lead never stopped"
    t = result.log.array("t")
    assert t[standing][-1] - t[standing][0] >= stand
    assert result.log.array("speed")[-1] < STOPPED or not standing[-1]


def cut_in(result: RunResult) -> None:
    s, offset = actor(result, 0)
    lane = lane_of(offset)
    assert lane[0] == 1 and lane[-1] == 0, "the cutter did not cut in"
    entered = int(np.argmax(lane == 0))
    ego_s = result.log.array("station")
    assert s[entered] > ego_s[entered], "it cut in behind the ego"


def cut_out(result: RunResult) -> None:
    lead_s, lead_offset = actor(result, 0)
    lane = lane_of(lead_offset)
    assert lane[0] == 0 and lane[-1] == 1, "the lead did not cut out"
    stopped_s, stopped_offset = actor(result, 1)
    assert np.ptp(stopped_s) < 0.01 and np.all(lane_of(stopped_offset) == 0)
    left = int(np.argmax(lane == 1))
    assert lead_s[left] < stopped_s[left], "the lead passed the stopped car before leaving"
    assert result.log.array("speed")[-1] < STOPPED, "the ego did not stop behind it"


def stop_and_go(result: RunResult) -> None:
    braking_lead(result, stand=3.0)
    s, _ = actor(result, 0)
    assert speed_of(result, s)[-1] > 5.0, "the lead did not drive off again"
    ego = result.log.array("speed")
    assert ego.min() < STOPPED and ego[-1] > 5.0, "the ego did not stop and go with it"


SITUATIONS: dict[str, Callable[[RunResult], None]] = {
    "ncap_ccrs": ccrs, "ncap_ccrm": ccrm, "ncap_ccrb": braking_lead,
    "r157_lead_braking": braking_lead, "r157_cut_in": cut_in, "r157_cut_out": cut_out,
    "iso22179_stop_and_go": stop_and_go,
}


def test_the_grids_are_the_set() -> None:
    assert {Path(p).stem for p in collect_scenarios([str(SET)])} >= set(SITUATIONS)
    assert len(RUNS) == 113


@pytest.mark.parametrize(("name", "path", "overrides"), [
    pytest.param(*r, marks=pytest.mark.xfail(strict=True, reason=KNOWN[r[0]]))
    if r[0] in KNOWN else r for r in RUNS], ids=[r[0] for r in RUNS])
def test_the_situation_happens_and_every_criterion_passes(
        run_scenario: Callable[..., RunResult], name: str, path: str,
        overrides: dict[str, object]) -> None:
    result = run_scenario(path, record=False, profile=Profile.DEFAULT, **overrides)
    SITUATIONS[Path(path).stem](result)
    failed = [f"{c.name}: {c.note or c.value}" for c in result.criteria if c.failed]
    assert not failed, failed

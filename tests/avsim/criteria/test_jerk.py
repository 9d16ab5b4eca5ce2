"""`max_jerk` on synthetic truth: speed ramps of a known jerk pass and fail at the right
threshold and first-failure time, braking counts as much as speeding up, an extra sample off
the criteria rate (a contact onset) does not bend it; and the scenario key loads, or gives a
one-line error naming it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from avsim.criteria.base import TruthSample
from avsim.criteria.declaration import RunInputs
from avsim.criteria.jerk import MaxJerk
from avsim.criteria.registry import build_criteria
from avsim.scenario.load import ScenarioError, load_scenario
from tests.avsim.texts import MINIMAL
from tests.roads import make_map, seg
from vehicle_urdf import read_geometry

RATE = 40  # [Hz] the runner's criteria rate
JERK = 4.0  # [m/s^3]
T1 = 2.0  # [s] the jerk starts (on a sample: 80 / RATE)
V0 = 10.0  # [m/s]


def speed(t: float, jerk: float = JERK) -> float:
    """[m/s] steady V0, then from T1 a constant jerk: v = V0 + jerk (t - T1)^2 / 2."""
    return V0 + 0.5 * jerk * max(0.0, t - T1) ** 2


def sample(t: float, v: float) -> TruthSample:
    return TruthSample(t=t, speed=v, station=10.0 + V0 * t, front_station=12.4 + V0 * t,
                       tyres=np.zeros((4, 2)), tyre_stations=np.zeros(4),
                       tyre_offsets=np.zeros(4), touching=frozenset(), xy=(V0 * t, 0.0))


def run(threshold: float, times: list[float], jerk: float = JERK) -> MaxJerk:
    c = MaxJerk(threshold)
    for t in times:
        c.update(sample(t, speed(t, jerk)))
    return c


GRID = [k / RATE for k in range(4 * RATE)]  # 4 s at the criteria rate


def test_a_known_jerk_passes_just_above_it_and_is_the_value() -> None:
    r = run(JERK * 1.001, GRID).result()
    assert r.passed and r.first_failure is None
    assert r.value == pytest.approx(JERK, rel=1e-9)
    assert (r.name, r.unit, r.threshold) == ("max_jerk", "m/s^3", JERK * 1.001)


@pytest.mark.parametrize(("threshold", "first_failure"), [
    # the 0.2 s average ramps up over 8 samples: (m - 1/2) / 8 of the jerk, m samples in
    (0.999 * JERK, T1 + 9 / RATE),  # only the full jerk, 9 samples in, is over
    (0.9 * JERK, T1 + 8 / RATE),  # 7.5 / 8 = 0.9375 of it, 8 samples in
    (0.5 * JERK, T1 + 5 / RATE),  # 4.5 / 8 = 0.5625
    (0.01 * JERK, T1 + 1 / RATE),  # 0.5 / 8 at the first sample of the jerk
])
def test_a_known_jerk_fails_below_it_at_the_right_time(threshold: float,
                                                       first_failure: float) -> None:
    c = run(threshold, GRID)
    r = c.result()
    assert not r.passed and r.value == pytest.approx(JERK, rel=1e-9)
    assert r.first_failure == first_failure
    (infraction,) = c.take_infractions()  # the first failure only
    assert (infraction.t, infraction.kind) == (first_failure, "max_jerk")
    assert infraction.message.startswith("longitudinal jerk +")
    assert infraction.where == (V0 * first_failure, 0.0)


def test_braking_onset_counts_like_speeding_up() -> None:
    r = run(0.9 * JERK, GRID, jerk=-JERK).result()
    assert not r.passed and r.value == pytest.approx(JERK, rel=1e-9)
    assert r.first_failure == T1 + 8 / RATE


def test_steady_speed_and_a_steady_acceleration_have_no_jerk() -> None:
    c = MaxJerk(0.01)
    for t in GRID:
        c.update(sample(t, V0 + 1.5 * max(0.0, t - T1)))
    r = c.result()
    # the acceleration steps from 0 to 1.5 m/s^2 at T1: 7.5 m/s^3 for 0.2 s, nothing else
    assert r.value == pytest.approx(1.5 / 0.2, rel=1e-9)
    steady = MaxJerk(1e-6)
    for t in GRID:
        steady.update(sample(t, V0 + 0.7 * t))
    assert steady.result().passed and steady.result().value < 1e-6


def test_nothing_is_judged_before_the_window_fills() -> None:
    c = run(1e-9, GRID[:9], jerk=1e3)  # 9 samples: 8 accelerations span 0.175 s only
    assert c.result().passed and c.result().value == 0.0
    c.update(sample(GRID[9], speed(GRID[9], 1e3)))
    assert c.result().value == 0.0  # the 10th: judged, and before T1 there is no jerk


def test_an_extra_sample_off_the_rate_does_not_bend_it() -> None:
    """The runner also samples at each contact onset (at 120 Hz steps): times off the grid."""
    extra = sorted([*GRID, T1 + 0.1 + 1 / 120, T1 + 0.5 + 1 / 240, 3.0 + 1 / 120])
    r = run(JERK * 1.001, extra).result()
    assert r.passed and r.value == pytest.approx(JERK, rel=1e-9)


# -- the scenario key ----------------------------------------------------------------------------


def file_with(tmp_path: Path, criteria: object) -> Path:
    data = yaml.safe_load(MINIMAL)
    data["criteria"] = criteria
    path = tmp_path / "jerk.yaml"
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    return path


def test_max_jerk_is_off_unless_asked_and_builds_when_set(tmp_path: Path) -> None:
    run = RunInputs(road=make_map(seg(100.0)), car=read_geometry(), rate=RATE, signals=(),
                    set_speed=V0, bodies={})
    off = load_scenario(file_with(tmp_path, {})).criteria
    assert "max_jerk" not in [c.name for c in build_criteria(off, run).items]
    on = load_scenario(file_with(tmp_path, {"max_jerk": 10})).criteria
    assert on.get("max_jerk") == 10
    criteria = build_criteria(on, run).items
    assert [c.name for c in criteria][-1] == "max_jerk"  # after the default criteria
    assert criteria[-1].result().threshold == 10


@pytest.mark.parametrize(("criteria", "key", "problem"), [
    ({"max_jerk": 0}, "criteria.max_jerk", "must be > 0, got 0"),
    ({"max_jerk": -2.5}, "criteria.max_jerk", "must be > 0, got -2.5"),
    ({"max_jerk": "10"}, "criteria.max_jerk", "must be a number, got '10'"),
    ({"max_jerk": [10]}, "criteria.max_jerk", "must be a number, got a list"),
    ({"max_jerks": 10}, "criteria.max_jerks", "unknown key (did you mean max_jerk?)"),
    ({"max_jerk_mps3": 10}, "criteria.max_jerk_mps3", "unknown key (did you mean max_jerk?)"),
])
def test_a_bad_or_unknown_max_jerk_is_a_one_line_error(
        criteria: dict[str, object], key: str, problem: str, tmp_path: Path) -> None:
    path = file_with(tmp_path, criteria)
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    assert str(info.value) == f"{path}: {key}: {problem}"

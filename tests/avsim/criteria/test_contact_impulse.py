"""The deceleration and jerk measures leave out a contact's impulse: a gentle braking (1 m/s^2,
its onset at 1 m/s^3) struck at `HIT` by a contact that takes `DROP` of its speed in two
samples (a 0.2 s average of 31 m/s^2). Each measure shows what it shows of the same braking
unstruck, not the blow, and says so; without the contact spans it would show the blow (each
test checks that too).
Then one closed-loop run of an UN R157 cut-in grid point with an unavoidable contact."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TypeVar

import numpy as np
import pytest

from avsim.criteria.base import CriteriaSet, Criterion, CriterionResult, TruthSample, Verdict
from avsim.criteria.comfort import ComfortDecel, ComfortJerk, peaks
from avsim.criteria.impulse import SETTLE, ImpulseSpans, describe, meets
from avsim.criteria.jerk import MaxJerk
from avsim.criteria.speed import MaxDecel
from avsim.run.runner import Runner, _max_decel
from avsim.scenario.load import load_scenario
from tests.roads import make_map, seg
from world.actors.actor_set import ActorPoses
from world.core.rates import CONTROL_RATE

RATE = 40  # [Hz] the criteria rate
ROAD = make_map(seg(2000.0))
EGO_LENGTH = 4.8  # [m]
V0 = 20.0  # [m/s]
DECEL = 1.0  # [m/s^2] the braking held
ONSET = 1.0  # [m/s^3] its rise
HIT = 6.0  # [s] the contact onset
TOUCH = 0.2  # [s] the bodies touch this long
DROP = 6.0  # [m/s] the speed the contact takes, over two samples
BODY = 7
C = TypeVar("C", Criterion, CriteriaSet)


def trace(rate: float = RATE, hit: bool = True) -> list[tuple[float, float, bool]]:
    """(t [s], speed [m/s], touching) at `rate` [Hz] for 12 s."""
    out, v, a = [], V0, 0.0
    dt = 1.0 / rate
    for k in range(round(12.0 * rate)):
        t = k * dt
        if t >= 1.0:
            a = min(DECEL, a + ONSET * dt)
        v -= a * dt
        if hit and HIT <= t < HIT + 2 * dt:
            v -= DROP / 2
        out.append((t, v, hit and HIT <= t < HIT + TOUCH))
    return out


def no_actors() -> ActorPoses:
    return ActorPoses(ids=(), kinds=(), centres=np.zeros((0, 3)), yaws=np.zeros(0),
                      half_sizes=np.zeros((0, 3)), stations=np.zeros(0),
                      offsets=np.zeros(0), speeds=np.zeros(0), accels=np.zeros(0))


def feed(criterion: C, hidden: bool = False, hit: bool = True) -> C:
    """`criterion` fed the struck trace (`hit`: else the same braking unstruck); `hidden`:
    the contact not in the samples (what the measure would show without the contact
    spans)."""
    s = 100.0
    for t, v, touching in trace(hit=hit):
        s += v / RATE
        criterion.update(TruthSample(
            t=t, speed=v, station=s, front_station=s + 2.4, tyres=np.zeros((4, 2)),
            tyre_stations=np.zeros(4), tyre_offsets=np.zeros(4),
            touching=frozenset({BODY}) if touching and not hidden else frozenset(),
            actors=no_actors()))
    return criterion


def sample(t: float, touching: bool) -> TruthSample:
    return TruthSample(t=t, speed=0.0, station=0.0, front_station=0.0,
                       tyres=np.zeros((4, 2)), tyre_stations=np.zeros(4),
                       tyre_offsets=np.zeros(4),
                       touching=frozenset({BODY}) if touching else frozenset())


def test_a_span_runs_from_the_onset_until_settled_after_parting() -> None:
    spans = ImpulseSpans()
    for t, touching in [(1.0, False), (2.0, True), (2.1, True), (2.3, False), (5.0, True)]:
        spans.update(sample(t, touching))
    assert spans.spans == [(2.0, 2.3 + SETTLE), (5.0, math.inf)]  # the last one goes on
    assert not spans.meets(1.5, 1.99) and spans.meets(1.5, 2.0)  # the onset's sample in
    assert spans.meets(2.7, 3.0) and not spans.meets(2.8, 3.0)  # settled at 2.8 s
    assert spans.meets(9.0, 9.2)
    assert describe(spans.spans) == ("contact impulse left out: 2.00-2.80 s, 5.00 s-end "
                                     "(until 0.5 s after parting)")
    assert describe([]) is None and not meets([], 0.0, 1.0)


def test_max_decel_leaves_out_the_impulse_and_says_so() -> None:
    hidden = feed(MaxDecel(5.0, RATE), hidden=True).result()
    assert hidden.passed is False and hidden.value is not None and hidden.value > 30.0
    result = feed(MaxDecel(5.0, RATE)).result()
    assert result.passed and result.value == feed(MaxDecel(5.0, RATE), hit=False).result().value
    assert result.value == pytest.approx(DECEL, abs=0.01)
    assert result.note is not None and result.note.startswith(
        "contact impulse left out: 6.00-6.70 s")


def test_max_jerk_leaves_out_the_impulse_and_says_so() -> None:
    assert feed(MaxJerk(10.0), hidden=True).result().passed is False
    result = feed(MaxJerk(10.0)).result()
    assert result.passed and result.value == feed(MaxJerk(10.0), hit=False).result().value
    assert result.value == pytest.approx(ONSET, abs=0.05)
    assert result.note is not None and "contact impulse left out" in result.note


@pytest.mark.parametrize("kind", [ComfortDecel, ComfortJerk])
def test_the_comfort_criteria_leave_out_the_impulse(
        kind: type[ComfortDecel | ComfortJerk]) -> None:
    assert feed(kind(ROAD, EGO_LENGTH), hidden=True).result().passed is False
    result = feed(kind(ROAD, EGO_LENGTH)).result()
    unstruck = feed(kind(ROAD, EGO_LENGTH), hit=False).result()
    assert result.verdict is Verdict.PASS and unstruck.verdict is Verdict.PASS
    assert result.value == unstruck.value and 0.8 < (result.value or 0.0) < 1.01
    assert result.note is not None and "contact impulse left out" in result.note


def test_the_run_peaks_leave_out_the_impulse() -> None:
    t, v, _ = (np.array(x) for x in zip(*trace(), strict=True))
    raw = peaks(t, v)
    assert raw["peak_decel_2s"] > DECEL + 2.0 and raw["peak_braking_jerk"] > 2.0
    kept = peaks(t, v, [(HIT, HIT + TOUCH + SETTLE)])
    t, v, _ = (np.array(x) for x in zip(*trace(hit=False), strict=True))
    assert kept == peaks(t, v)
    assert kept["peak_decel_2s"] == pytest.approx(DECEL, abs=0.01)


def test_the_max_decel_metric_keeps_the_raw_peak_beside_the_braking() -> None:
    """The metric on the log (the control rate): `max_decel` the braking, the raw peak
    (the blow) beside it."""
    t, v, _ = (np.array(x) for x in zip(*trace(CONTROL_RATE.hz), strict=True))
    raw, braking = _max_decel(t, v, [(HIT, HIT + TOUCH + SETTLE)])
    assert raw > 30.0
    assert braking == pytest.approx(DECEL, abs=0.01)
    assert _max_decel(t, v, []) == (raw, raw)
    assert _max_decel(t[:3], v[:3], []) == (0.0, 0.0)  # no window filled


def test_an_unavoidable_cut_in_contact_is_counted_passed_and_braking_plausible() -> None:
    """The acceptance grid's cutter at 20 km/h entering 15 m ahead at 2 m/s across (its
    TTC at the lane intrusion about 0.5 s, under UN R157's 1.28 s): without sensors the
    stack does not brake and the ego strikes it. The contact is counted, `no_collision`
    passes with the excuse, and the deceleration without the blow is the car's braking
    (with it, tens of m/s^2)."""
    scenario = load_scenario("acceptance/r157_cut_in", {
        "actors.0.speed_kph": 20, "actors.0.actions.0.trigger.gap": 15,
        "actors.0.actions.0.lane_change.lateral_speed": 2.0, "duration": 12})
    result = Runner(scenario, None, profile=None).run()
    assert result.error is None
    assert result.metrics["collisions"] >= 1 and result.metrics["collisions_excused"] >= 1
    assert result.metrics["min_lead_gap"] < 0.0  # the boxes overlapped: it did strike
    contact = next(c for c in result.criteria if c.name == "no_collision")
    assert contact.verdict is Verdict.PASS
    assert contact.note is not None and "unavoidable: r157, actor cutter at" in contact.note
    assert "TTC at lane intrusion" in contact.note and "<= bound 1.28 s" in contact.note
    assert result.metrics["max_decel_with_contact"] > 15.0  # the blow
    assert result.metrics["max_decel"] < 15.0  # the car's own braking


class _Ender(Criterion):
    """Ends the judging at the contact onset (as an excused contact does)."""

    name, unit = "ender", ""

    def update(self, sample: TruthSample) -> None:
        if sample.touching:
            self.ends_judging = "the contact"

    def result(self) -> CriterionResult:
        return CriterionResult(self.name, True, 0.0, None, self.unit)


@pytest.mark.parametrize("make", [lambda: MaxDecel(5.0, RATE), lambda: MaxJerk(10.0),
                                  lambda: ComfortDecel(ROAD, EGO_LENGTH)])
def test_the_span_is_followed_after_the_judging_ended(make: Callable[[], Criterion]) -> None:
    """The judging ends at the onset, the spans are still followed: the note gives where
    the impulse really ended, not the run's end."""
    criterion = make()
    feed(CriteriaSet([_Ender(), criterion]))
    assert (criterion.result().note or "").startswith("contact impulse left out: 6.00-6.70 s")

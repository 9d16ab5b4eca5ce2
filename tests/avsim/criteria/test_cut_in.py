"""UN R157 5.2.5.2 from the truth: a car cutting in from the next lane, slower than the ego;
whether the regulation requires avoiding a collision with it decides, under
`unavoidable: r157`, whether `no_collision` fails or passes with the excuse in its note.
Either way the contact is counted."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from avsim.criteria.base import CriteriaSet, Criterion, CriterionResult, TruthSample, Verdict
from avsim.criteria.collision import NoCollision
from avsim.criteria.cut_in import INTRUSION, R157_VISIBLE, CutInWatch
from tests.roads import make_map, seg
from world.actors.actor_set import ActorPoses
from world.spec import ActorType

ROAD = make_map(seg(2000.0, lanes=2, oncoming=0))
EGO_LENGTH = 4.8  # [m]
HALF = np.array([[2.5, 1.0, 0.9]])  # [m] the cutting-in car's half sizes
DT = 1.0 / 40.0  # [s] the criteria rate
BODY = 7  # the car's body id


def poses(station: float, offset: float, speed: float,
          kind: ActorType = ActorType.CAR) -> ActorPoses:
    return ActorPoses(ids=("cutter",), kinds=(kind,), centres=np.zeros((1, 3)),
                      yaws=np.zeros(1), half_sizes=HALF, stations=np.array([station]),
                      offsets=np.array([offset]), speeds=np.array([speed]),
                      accels=np.zeros(1))


def sample(t: float, ego_s: float, actors: ActorPoses, touching: bool = False) -> TruthSample:
    """The ego in lane 0 (offset 0) at 60 km/h."""
    return TruthSample(t=t, speed=60 / 3.6, station=ego_s, front_station=ego_s + 2.4,
                       tyres=np.zeros((4, 2)), tyre_stations=np.full(4, ego_s),
                       tyre_offsets=np.array([0.7, -0.7, 0.7, -0.7]),
                       touching=frozenset({BODY}) if touching else frozenset(), offset=0.0,
                       actors=actors)


def cut_in(gap: float, lateral: float = 1.0, speed: float = 40 / 3.6,
           kind: ActorType = ActorType.CAR, start_moving: float = 1.0) -> list[TruthSample]:
    """The car in lane 1 (3.5 m left), `gap` [m] ahead of the ego's front when its lateral
    move (at `lateral` m/s from `start_moving` s) starts; the ego closes in; samples until
    it is in the ego's lane, then one touching it."""
    out = []
    ego_v = 60 / 3.6
    t = 0.0
    ego_s = 100.0
    car_s = ego_s + 2.4 + gap + 2.5 + (ego_v - speed) * start_moving
    offset = 3.5
    while offset > 0.2:
        out.append(sample(t, ego_s, poses(car_s, offset, speed, kind)))
        t += DT
        ego_s += ego_v * DT
        car_s += speed * DT
        if t > start_moving:
            offset -= lateral * DT
    out.append(sample(t, ego_s, poses(car_s, offset, speed, kind), touching=True))
    return out


def judge(samples: list[TruthSample]) -> tuple[CutInWatch, NoCollision]:
    watch = CutInWatch(ROAD, EGO_LENGTH)
    criterion = NoCollision({BODY: "actor cutter"}, {BODY: "cutter"}, watch)
    for s in samples:
        criterion.update(s)
    return watch, criterion


def test_a_cut_in_far_enough_ahead_must_be_avoided() -> None:
    """30 m ahead at 20 km/h slower, 1 m/s across: TTC at the intrusion well over
    5.56 / 12 + 0.35 s, its movement seen for more than 0.72 s: the collision fails."""
    watch, criterion = judge(cut_in(30.0))
    (c,) = watch.cut_ins.values()
    assert c.required and c.v_rel == pytest.approx(20 / 3.6)
    assert c.visible_for >= R157_VISIBLE
    # the intrusion: the car's right side INTRUSION inside the lane's left edge (1.75 m)
    assert c.t == pytest.approx(1.0 + (3.5 - 1.0 - 1.75 + INTRUSION) / 1.0, abs=2 * DT)
    result = criterion.result()
    assert result.verdict is Verdict.FAIL and criterion.count == 1


def test_a_cut_in_too_close_is_counted_and_passes_with_its_excuse() -> None:
    """7 m ahead when it starts across at 1 m/s: 1.6 m at the intrusion, TTC 0.3 s, under
    the bound of 0.81 s: unavoidable. The contact is counted (the metric), excused (no
    infraction), and `no_collision` passes with the regulation's figures in its note."""
    samples = cut_in(7.0)
    watch, criterion = judge(samples)
    (c,) = watch.cut_ins.values()
    assert not c.required and "TTC at lane intrusion" in c.reason()
    result = criterion.result()
    assert result.verdict is Verdict.PASS and result.value == 0
    assert criterion.count == 1 and criterion.excused == 1
    assert criterion.take_infractions() == [] and result.first_failure is None
    bound = (20 / 3.6) / 12.0 + 0.35
    assert result.note == (f"1 contact(s) excused: unavoidable: r157, actor cutter at "
                           f"{samples[-1].t:.2f} s: TTC at lane intrusion {c.ttc:.2f} s <= "
                           f"bound {bound:.2f} s")


def test_a_lateral_move_seen_too_briefly_is_unavoidable() -> None:
    """Across at 2 m/s: in the lane 0.49 s after it started moving: seen under 0.72 s."""
    watch, _ = judge(cut_in(30.0, lateral=2.0))
    (c,) = watch.cut_ins.values()
    assert c.visible_for < R157_VISIBLE and not c.required
    assert "visible" in c.reason()


def test_a_pedestrian_is_no_cutting_in_vehicle() -> None:
    watch, criterion = judge(cut_in(7.0, kind=ActorType.PEDESTRIAN))
    assert watch.cut_ins == {}
    assert criterion.result().verdict is Verdict.FAIL  # every collision with it fails


def test_without_the_setting_every_collision_fails() -> None:
    criterion = NoCollision({BODY: "actor cutter"})
    for s in cut_in(7.0):
        criterion.update(s)
    assert criterion.result().verdict is Verdict.FAIL


class _Seen(Criterion):
    """A criterion that counts the samples it saw, and fails at the end unless it saw
    `settles` of them (a verdict only the run's end settles, as `completes`)."""

    name, unit = "seen", "samples"

    def __init__(self, fail_at: float | None = None, settles: int = 10**6) -> None:
        super().__init__()
        self.seen, self.fail_at, self.settles = 0, fail_at, settles

    def update(self, sample: TruthSample) -> None:
        self.seen += 1
        if self.fail_at is not None and sample.t >= self.fail_at:
            self._fail(sample, "failed")

    def result(self) -> CriterionResult:
        return CriterionResult(self.name, self.first_failure is None and
                               self.seen >= self.settles, self.seen, None, self.unit,
                               self.first_failure)


def test_an_unavoidable_collision_ends_the_judging() -> None:
    """After the unavoidable collision no criterion sees a sample; a failure seen before
    it stands, a verdict only the run's end would settle is not applicable, and the
    samples after the collision (the car pushed across the lane) change nothing."""
    samples = cut_in(7.0)
    crash = samples[-1].t
    after = [sample(crash + DT * k, 130.0, samples[-1].actors or poses(0, 0, 0), True)
             for k in range(1, 40)]
    failed_before, unsettled = _Seen(fail_at=samples[5].t), _Seen()
    collision = NoCollision({BODY: "actor cutter"}, {BODY: "cutter"},
                            CutInWatch(ROAD, EGO_LENGTH))
    criteria = CriteriaSet([collision, failed_before, unsettled])
    for s in samples + after:
        criteria.update(s)
    assert criteria.ended is not None and criteria.ended[0] == crash
    assert unsettled.seen == len(samples)  # none after the collision
    results = criteria.results()
    assert results[0].verdict is Verdict.PASS  # the collision: counted, excused
    assert "unavoidable: r157" in (results[0].note or "")
    assert results[1].verdict is Verdict.FAIL and results[1].first_failure == samples[5].t
    assert results[1].note == (f"judged until {crash:.2f} s: judging ended with the "
                               "unavoidable collision with actor cutter")
    assert results[2].verdict is Verdict.NOT_APPLICABLE
    assert "judging ended with the unavoidable collision with actor cutter" in (
        results[2].note or "")


def test_a_pass_judged_until_an_unavoidable_collision_says_so() -> None:
    samples = cut_in(7.0)
    passing = _Seen(settles=1)
    criteria = CriteriaSet([NoCollision({BODY: "actor cutter"}, {BODY: "cutter"},
                                        CutInWatch(ROAD, EGO_LENGTH)), passing])
    for s in samples:
        criteria.update(s)
    result = criteria.results()[1]
    assert result.verdict is Verdict.PASS
    assert result.note == (f"judged until {samples[-1].t:.2f} s: judging ended with the "
                           "unavoidable collision with actor cutter")


def test_contacts_after_the_judging_ended_are_counted_not_judged() -> None:
    """The car pushed on, it parts from the cutter and strikes it again (and a kerb): the
    judging has ended, yet each onset is counted and the note lists them."""
    samples = cut_in(7.0)
    crash, actors = samples[-1].t, samples[-1].actors or poses(0, 0, 0)
    kerb = 9
    after = [sample(crash + DT, 130.0, actors),  # parted
             sample(crash + 2 * DT, 130.0, actors, True),  # the cutter again
             dataclasses.replace(sample(crash + 3 * DT, 130.0, actors),
                                 touching=frozenset({kerb}))]
    collision = NoCollision({BODY: "actor cutter", kerb: "kerb"}, {BODY: "cutter"},
                            CutInWatch(ROAD, EGO_LENGTH))
    criteria = CriteriaSet([collision])
    for s in samples + after:
        criteria.update(s)
    assert collision.count == 3 and collision.excused == 1
    result = criteria.results()[0]
    assert result.verdict is Verdict.PASS and result.value == 0
    assert result.note is not None and result.note.endswith(
        f"2 contact(s) after the judging ended, counted, not judged: actor cutter at "
        f"{crash + 2 * DT:.2f} s, kerb at {crash + 3 * DT:.2f} s")


def test_an_excused_contact_after_one_that_counts_does_not_end_the_judging() -> None:
    """A kerb struck first (a failure), then the unavoidable cut-in: both counted, the
    judging goes on (the run already failed on its own), the verdict a failure."""
    kerb = 9
    samples = cut_in(7.0)
    first = dataclasses.replace(samples[3], touching=frozenset({kerb}))
    collision = NoCollision({BODY: "actor cutter", kerb: "kerb"}, {BODY: "cutter"},
                            CutInWatch(ROAD, EGO_LENGTH))
    criteria = CriteriaSet([collision])
    for s in [*samples[:3], first, *samples[4:]]:
        criteria.update(s)
    assert criteria.ended is None
    assert collision.count == 2 and collision.excused == 1
    result = criteria.results()[0]
    assert result.verdict is Verdict.FAIL and result.value == 1
    assert (result.note or "").startswith(f"kerb at {first.t:.2f} s; 1 contact(s) excused: ")


def test_a_collision_to_avoid_does_not_end_the_judging() -> None:
    unsettled = _Seen()
    criteria = CriteriaSet([NoCollision({BODY: "actor cutter"}, {BODY: "cutter"},
                                        CutInWatch(ROAD, EGO_LENGTH)), unsettled])
    samples = cut_in(30.0)
    for s in samples + samples[-1:] * 5:
        criteria.update(s)
    assert criteria.ended is None and unsettled.seen == len(samples) + 5
    assert criteria.results()[0].verdict is Verdict.FAIL

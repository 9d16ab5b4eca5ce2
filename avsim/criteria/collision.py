"""`no_collision`: the ego touches nothing but the ground and the speed bumps.

Every contact onset with any body is counted (`count`, the run's metric `collisions`),
whether a rule excuses it or not and whether or not the run is still judged then: a contact
is always counted. The verdict rests on the contacts no rule excuses (its value): each is an
infraction and fails it.

With `unavoidable: r157` a collision with a vehicle that cut in where UN R157 5.2.5.2 does
not require the ALKS to avoid it (`avsim.criteria.cut_in`) is excused: counted (and in the
metric `collisions_excused`), no infraction, and the criterion passes with the excuse in
its note, the regulation's figures that made it unavoidable (`unavoidable: r157, actor
cutter at 3.21 s: TTC at lane intrusion 0.80 s <= bound 1.10 s`). Such a collision, when it
is the first, ends the judging of the run (`CriteriaSet`): what follows it (the car pushed
out of its lane, the gap never restored) is the crash's doing, not the stack's, so the
other criteria keep what they judged before it (their notes say until when), and one only
the run's end would have settled is not applicable. The contacts after that are still
counted, and the note lists them as not judged.

It also keeps the run's contact spans (`avsim.criteria.impulse`), which the deceleration
measures leave out.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Literal

from avsim.criteria.base import (
    Criterion,
    CriterionResult,
    Need,
    TruthSample,
)
from avsim.criteria.cut_in import CutInWatch
from avsim.criteria.declaration import Declaration, RunInputs
from avsim.criteria.impulse import ImpulseSpans

R157 = "r157"  # the `unavoidable` setting: UN R157 5.2.5.2's cut-in conditions
NOTE_CONTACTS = 5  # contacts listed by name in a note, at most


@dataclass(frozen=True, slots=True)
class Contact:
    """One contact onset of the ego with a body."""

    t: float  # [s] sim time of the onset
    what: str  # the body (`actor cutter`, `kerb`, `building or sign`)
    excuse: str | None = None  # why a rule excuses it (`unavoidable: r157, ...`), None: none
    judged: bool = True  # it happened while the run was judged (before an excused one
    #   ended the judging)

    @property
    def counts(self) -> bool:
        """It counts against `no_collision`: judged and not excused."""
        return self.judged and self.excuse is None


class NoCollision(Criterion):
    """The ego touches no actor, building or roadside object: counts every contact onset
    (module doc), each one no rule excuses an infraction."""

    name, unit = "no_collision", "contacts"

    def __init__(self, names: Mapping[int, str], actors: Mapping[int, str] | None = None,
                 cut_ins: CutInWatch | None = None) -> None:
        super().__init__()
        self.names = names  # body id -> what it is (for the messages)
        self.actors = actors or {}  # NPC body id -> actor id
        self.cut_ins = cut_ins  # the R157 cut-in judge, None: every collision fails
        self.contacts: list[Contact] = []  # every onset, in order
        self.impulses = ImpulseSpans()  # the contact spans, for the deceleration measures
        self._touching: frozenset[int] = frozenset()

    @property
    def count(self) -> int:
        """Every contact onset of the run, excused or not (the metric `collisions`)."""
        return len(self.contacts)

    @property
    def excused(self) -> int:
        """The contact onsets a rule excused (the metric `collisions_excused`)."""
        return sum(c.excuse is not None for c in self.contacts)

    def update(self, sample: TruthSample) -> None:
        if self.cut_ins is not None:
            self.cut_ins.update(sample)
        for body, what in self._onsets(sample):
            exempt = self._exempt(body)
            if exempt is None:
                self.contacts.append(Contact(sample.t, what))
                self._infraction(sample, f"collision with {what}")
                continue
            if self.ends_judging is None and not any(c.counts for c in self.contacts):
                self.ends_judging = f"the unavoidable collision with {what}"
            self.contacts.append(Contact(
                sample.t, what, f"unavoidable: {R157}, {what} at {sample.t:.2f} s: {exempt}"))

    def after_judging(self, sample: TruthSample) -> None:
        """The judging has ended: a contact onset is still counted, not judged."""
        self.contacts += [Contact(sample.t, what, judged=False)
                          for _, what in self._onsets(sample)]

    def _onsets(self, sample: TruthSample) -> list[tuple[int, str]]:
        """(body id, what it is) of each body the ego touches now and did not before."""
        self.impulses.update(sample)
        new = sorted(sample.touching - self._touching)
        self._touching = sample.touching
        return [(body, self.names.get(body, f"body {body}")) for body in new]

    def _exempt(self, body: int) -> str | None:
        """Why a collision with `body` is one R157 does not require avoiding, else None."""
        actor = self.actors.get(body)
        if self.cut_ins is None or actor is None:
            return None
        cut_in = self.cut_ins.cut_ins.get(actor)
        if cut_in is None or cut_in.required:
            return None
        return cut_in.reason()

    def result(self) -> CriterionResult:
        counted = [c for c in self.contacts if c.counts]
        parts = [f"{c.what} at {c.t:.2f} s" for c in counted[:NOTE_CONTACTS]]
        excused = [c.excuse for c in self.contacts if c.excuse is not None]
        if excused:
            parts.append(f"{len(excused)} contact(s) excused: " + "; ".join(excused))
        later = [c for c in self.contacts if not c.judged]
        if later:
            parts.append(f"{len(later)} contact(s) after the judging ended, counted, not "
                         "judged: " + ", ".join(f"{c.what} at {c.t:.2f} s"
                                                for c in later[:NOTE_CONTACTS]))
        return CriterionResult(self.name, not counted, len(counted), 0, self.unit,
                               self.first_failure, note="; ".join(parts) or None)


def _no_collision(setting: str | None, run: RunInputs) -> list[Criterion]:
    watch = CutInWatch(run.road, run.car.body_length) if setting == R157 else None
    return [NoCollision(run.bodies, run.actor_bodies, watch)]


NO_COLLISION: Declaration[str | None] = Declaration(
    build=_no_collision,
    needs=frozenset({Need.BODIES, Need.ACTOR_BODIES}),
    needs_if_set=frozenset({Need.MAP, Need.CAR, Need.ACTORS}), always=True,
    key="unavoidable", setting=Literal["r157"],
    doc="`r157`: a collision with a vehicle cutting in where UN R157 5.2.5.2 does not "
    "require the ALKS to avoid it is excused: counted (metrics `collisions`, "
    "`collisions_excused`), a pass of `no_collision` with the regulation's figures in its "
    "note, and the end of the run's judging. Default: every collision fails.",
    example=R157)

"""`no_collision`: the ego touches nothing but the ground and the speed bumps.

With `unavoidable: r157` a collision with a vehicle that cut in where UN R157 5.2.5.2 does
not require the ALKS to avoid it (`avsim.criteria.cut_in`) is reported, not failed: the
verdict is not applicable when every collision was such, with a note giving the
regulation's figures. Such a collision, when it is the first, ends the judging of the run
(`CriteriaSet`): what follows it (the car pushed out of its lane, the gap never restored)
is the crash's doing, not the stack's, so the other criteria keep what they judged before
it, and one only the run's end would have settled is not applicable.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Literal

from avsim.criteria.base import (
    Criterion,
    CriterionResult,
    Need,
    TruthSample,
)
from avsim.criteria.cut_in import CutInWatch
from avsim.criteria.declaration import Declaration, RunInputs

R157 = "r157"  # the `unavoidable` setting: UN R157 5.2.5.2's cut-in conditions


class NoCollision(Criterion):
    """The ego touches no actor, building or roadside object: counts contact onsets, each
    an infraction (module doc for the collisions UN R157 labels unavoidable)."""

    name, unit = "no_collision", "contacts"

    def __init__(self, names: Mapping[int, str], actors: Mapping[int, str] | None = None,
                 cut_ins: CutInWatch | None = None) -> None:
        super().__init__()
        self.names = names  # body id -> what it is (for the messages)
        self.actors = actors or {}  # NPC body id -> actor id
        self.cut_ins = cut_ins  # the R157 cut-in judge, None: every collision fails
        self.count = 0
        self.unavoidable: list[str] = []  # what each exempt collision was, and why
        self._touching: frozenset[int] = frozenset()
        self._contacts: list[tuple[float, str]] = []  # ([s], what) of each onset

    def update(self, sample: TruthSample) -> None:
        if self.cut_ins is not None:
            self.cut_ins.update(sample)
        for body in sorted(sample.touching - self._touching):
            what = self.names.get(body, f"body {body}")
            exempt = self._exempt(body)
            if exempt is not None:
                self.unavoidable.append(f"{what} at {sample.t:.2f} s: unavoidable under "
                                        f"UN R157 5.2.5.2 ({exempt})")
                if self.count == 0:
                    self.ends_judging = f"the unavoidable collision with {what}"
                continue
            self.count += 1
            self._contacts.append((sample.t, what))
            self._infraction(sample, f"collision with {what}")
        self._touching = sample.touching

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
        if self.count == 0 and self.unavoidable:
            return CriterionResult.not_applicable(self.name, 0, self.unit,
                                                  "; ".join(self.unavoidable))
        note = "; ".join(f"{what} at {t:.2f} s" for t, what in self._contacts[:5])
        return CriterionResult(self.name, self.count == 0, self.count, 0, self.unit,
                               self.first_failure, note=note or None)


def _no_collision(setting: str | None, run: RunInputs) -> list[Criterion]:
    watch = CutInWatch(run.road, run.car.body_length) if setting == R157 else None
    return [NoCollision(run.bodies, run.actor_bodies, watch)]


NO_COLLISION: Declaration[str | None] = Declaration(
    build=_no_collision,
    needs=frozenset({Need.BODIES, Need.ACTOR_BODIES}),
    needs_if_set=frozenset({Need.MAP, Need.CAR, Need.ACTORS}), always=True,
    key="unavoidable", setting=Literal["r157"],
    doc="`r157`: a collision with a vehicle cutting in where UN R157 5.2.5.2 does not "
    "require the ALKS to avoid it is reported, not failed. Default: every collision fails.",
    example=R157)

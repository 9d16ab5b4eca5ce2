"""`no_collision`: the ego touches nothing but the ground and the speed bumps."""

from __future__ import annotations

from collections.abc import Mapping

from avsim.criteria.base import (
    Criterion,
    CriterionResult,
    Need,
    TruthSample,
)
from avsim.criteria.declaration import Declaration


class NoCollision(Criterion):
    """The ego touches no actor, building or roadside object: counts contact onsets, each
    an infraction."""

    name, unit = "no_collision", "contacts"

    def __init__(self, names: Mapping[int, str]) -> None:
        super().__init__()
        self.names = names  # body id -> what it is (for the messages)
        self.count = 0
        self._touching: frozenset[int] = frozenset()
        self._contacts: list[tuple[float, str]] = []  # ([s], what) of each onset

    def update(self, sample: TruthSample) -> None:
        for body in sorted(sample.touching - self._touching):
            self.count += 1
            what = self.names.get(body, f"body {body}")
            self._contacts.append((sample.t, what))
            self._infraction(sample, f"collision with {what}")
        self._touching = sample.touching

    def result(self) -> CriterionResult:
        note = "; ".join(f"{what} at {t:.2f} s" for t, what in self._contacts[:5])
        return CriterionResult(self.name, self.count == 0, self.count, 0, self.unit,
                               self.first_failure, note=note or None)


NO_COLLISION: Declaration[None] = Declaration(
    build=lambda _, run: [NoCollision(run.bodies)], needs=frozenset({Need.BODIES}),
    always=True)

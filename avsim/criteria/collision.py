"""`no_collision`: the ego touches nothing but the ground and the speed bumps."""

from __future__ import annotations

from avsim.criteria.base import (
    Criterion,
    CriterionResult,
    TruthSample,
)


class NoCollision(Criterion):
    """The ego touches no actor, building or roadside object: counts contact onsets."""

    name, unit = "no_collision", "contacts"

    def __init__(self, names: dict[int, str]) -> None:
        super().__init__()
        self.names = names  # body id -> what it is (for the event log)
        self.count = 0
        self._touching: frozenset[int] = frozenset()
        self.events: list[tuple[float, str]] = []

    def update(self, sample: TruthSample) -> None:
        for body in sorted(sample.touching - self._touching):
            self.count += 1
            self.events.append((sample.t, self.names.get(body, f"body {body}")))
            self._fail(sample.t)
        self._touching = sample.touching

    def result(self) -> CriterionResult:
        note = "; ".join(f"{what} at {t:.2f} s" for t, what in self.events[:5])
        return CriterionResult(self.name, self.count == 0, self.count, 0, self.unit,
                               self.first_failure, note=note)

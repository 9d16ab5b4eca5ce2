"""`avsim campaign --shrink`: a failed run's values moved toward its family's nominal case
while the run still fails the same criterion.

The keys are taken one at a time, in the file's `vary:` order (the scenario `seed` is kept
as drawn, and a key the file leaves out has no nominal value to move to). A key is first
set to its nominal value; if the run still fails, the key stays there. Otherwise, for a
number, the interval between the failing value and the nominal (passing) one is halved: the
midpoint takes the failing side if the run fails there, else the passing side, at most
`MAX_STEPS` runs per key (an integer key stops when the interval has no integer inside).
A choice that passes at its nominal value keeps its drawn value. A failure takes at most
`MAX_RUNS` runs. The smallest failing case is the values where every key ended.

The shrinkers of several failures advance together, one candidate each per round, so that
a round's runs go to the executor at once (`Shrinker.candidate` / `Shrinker.tell`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

from avsim.batch.sampling import SEED_KEY, Law

MAX_STEPS = 8  # runs per key
MAX_RUNS = 40  # runs per failure


@dataclass
class Shrinker:
    """The shrinking of one failed run (module doc)."""

    laws: tuple[Law, ...]
    values: dict[str, object]  # the smallest failing case so far: starts at the run's
    nominal: Mapping[str, object]  # each key's nominal value (absent: none to move to)
    criterion: str  # the criterion the run failed and every candidate must fail too
    runs: int = 0  # candidates run so far
    moved: dict[str, tuple[object, object]] = field(default_factory=dict)  # key ->
    #   (drawn, shrunk) of every key that moved
    _key: int = -1  # the key being shrunk (an index of `laws`)
    _steps: int = 0  # its candidates so far
    _passing: object = None  # its nearest value to the failing one that passed
    _proposal: object = None  # the candidate's value of the key, awaiting its run

    def __post_init__(self) -> None:
        self._next_key()

    @property
    def done(self) -> bool:
        """Whether there is no candidate to run anymore."""
        return self._key >= len(self.laws) or self.runs >= MAX_RUNS

    def candidate(self) -> dict[str, object] | None:
        """The values to run next, None when done."""
        if self.done:
            return None
        return self.values | {self.laws[self._key].key: self._proposal}

    def tell(self, failed: list[str]) -> None:
        """The candidate's run failed the criteria `failed`: the key moves or narrows."""
        law = self.laws[self._key]
        self.runs += 1
        self._steps += 1
        if self.criterion in failed:
            drawn = self.moved.get(law.key, (self.values[law.key], None))[0]
            self.values[law.key] = self._proposal
            self.moved[law.key] = (drawn, self._proposal)
            if self._proposal == self.nominal[law.key]:
                self._next_key()
                return
        else:
            self._passing = self._proposal
        self._propose_midpoint(law)

    def _propose_midpoint(self, law: Law) -> None:
        """The midpoint of the failing value and the passing one, or the next key."""
        if not law.numeric or self._steps >= MAX_STEPS:
            self._next_key()
            return
        low, high = self.values[law.key], self._passing
        assert isinstance(low, (int, float)) and isinstance(high, (int, float))
        middle: object = (low + high) / 2
        if law.kind == "integers":
            middle = round(low + (high - low) / 2)
            if middle in (low, high):
                self._next_key()
                return
        self._proposal = middle

    def _next_key(self) -> None:
        """The next key with a nominal value that differs from its own; its first
        candidate is that nominal value."""
        self._key += 1
        self._steps = 0
        while self._key < len(self.laws):
            key = self.laws[self._key].key
            if (key != SEED_KEY and key in self.nominal
                    and self.nominal[key] != self.values[key]):
                self._proposal = self.nominal[key]
                return
            self._key += 1

"""A campaign's draws: each run's values of the keys its file's `vary:` names.

Run k of the campaign's file number f draws from its own generator,
``Generator(PCG64(SeedSequence([seed, f, k])))``: the same values whatever the number of
runs, workers or executor. The keys are drawn in the file's order, after the run's
scenario `seed` (an integer of 0..`MAX_SEED`), which is drawn first unless `vary:` names
`seed` itself (then by its law, in its place). Values are plain Python numbers and lists,
so that they are written to YAML and JSON as they are: a uniform or normal draw is rounded
to `DECIMALS` decimals, the value the run then uses.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from avsim.scenario.bounds import MAX_SEED
from avsim.scenario.model import DistributionModel, grid_paths

SEED_KEY = "seed"  # the scenario's random seed: drawn for each run unless `vary:` names it
DECIMALS = 6  # of a uniform or normal draw


@dataclass(frozen=True, slots=True)
class Law:
    """One key of `vary:` and its distribution (the file's units)."""

    key: str  # a dotted key path, or several joined by commas (drawn together)
    kind: str  # uniform | normal | integers | choice
    low: float = 0.0  # uniform, integers: the least value; normal: the clip's
    high: float = 0.0  # uniform, integers: the most value (included); normal: the clip's
    mean: float = 0.0  # normal
    sd: float = 0.0  # normal
    values: tuple[object, ...] = ()  # choice
    weights: tuple[float, ...] = ()  # choice: each value's probability (sum 1)

    @property
    def paths(self) -> list[str]:
        """The key paths this law sets."""
        return grid_paths(self.key)

    @property
    def numeric(self) -> bool:
        """Whether the values are numbers on an interval (not a choice)."""
        return self.kind != "choice"

    def draw(self, rng: np.random.Generator) -> object:
        """One value, by the law."""
        if self.kind == "uniform":
            return round(float(rng.uniform(self.low, self.high)), DECIMALS)
        if self.kind == "normal":
            drawn = float(np.clip(rng.normal(self.mean, self.sd), self.low, self.high))
            return round(drawn, DECIMALS)
        if self.kind == "integers":
            return int(rng.integers(int(self.low), int(self.high), endpoint=True))
        return self.values[int(rng.choice(len(self.values), p=self.weights))]


def law_of(key: str, model: DistributionModel) -> Law:
    """The `Law` of one validated key of `vary:`."""
    if model.uniform is not None:
        return Law(key, "uniform", low=model.uniform[0], high=model.uniform[1])
    if model.normal is not None:
        n = model.normal
        return Law(key, "normal", low=n.min, high=n.max, mean=n.mean, sd=n.sd)
    if model.integers is not None:
        return Law(key, "integers", low=model.integers[0], high=model.integers[1])
    assert model.choice is not None  # the model demands exactly one law
    weights = model.weights or [1.0] * len(model.choice)
    total = sum(weights)
    return Law(key, "choice", values=tuple(model.choice),
               weights=tuple(w / total for w in weights))


def laws_of(vary: Mapping[str, DistributionModel]) -> tuple[Law, ...]:
    """Every key of a validated `vary:`, in the file's order."""
    return tuple(law_of(key, model) for key, model in vary.items())


def generator(seed: int, *stream: int) -> np.random.Generator:
    """The generator of one stream of draws: `seed` (the campaign's `--seed`) and the
    stream's numbers (the file's index, the run's ...)."""
    return np.random.Generator(np.random.PCG64(np.random.SeedSequence([seed, *stream])))


def draw_run(laws: Sequence[Law], seed: int, family: int, run: int) -> dict[str, object]:
    """Run `run` of family `family`: each law's key -> its value (a key of several paths
    keeps its list), the scenario `seed` first unless a law sets it (module doc)."""
    rng = generator(seed, family, run)
    values: dict[str, object] = {}
    if not any(SEED_KEY in law.paths for law in laws):
        values[SEED_KEY] = int(rng.integers(0, MAX_SEED, endpoint=True))
    for law in laws:
        values[law.key] = law.draw(rng)
    return values

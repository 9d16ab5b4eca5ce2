"""`avsim campaign --search METRIC`: the cross-entropy method, minimising a metric of the
result over a family's laws.

Iteration 0 draws `population` runs from the file's own laws; each next iteration keeps the
elite (the `ELITE` fraction of the runs so far measured lowest, at least 2), refits a
sampling law to it and draws `population` more. A number's law is a normal clipped to the
key's interval (a uniform's [lo, hi], a normal's [min, max], an integer's, rounded), its
mean and standard deviation the elite's, blended with the previous ones by `SMOOTHING`;
a choice's is the elite's frequencies so blended. The sd never falls below `MIN_SD` of the
interval, so that the search keeps looking. A run that did not measure the metric (NaN) or
did not finish counts as +inf. The scenario `seed` is held at the file's own unless `vary:`
names it, so that the metric depends on the varied values only. Run k of iteration i of
family f draws from ``SeedSequence([seed, f, i, k, SEARCH_STREAM])``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from avsim.batch.sampling import DECIMALS, Law, generator

ELITE = 0.25  # of the runs so far, refitted to
SMOOTHING = 0.7  # weight of the elite's fit against the previous law's
MIN_SD = 0.02  # of a number's interval: the least sd of its sampling law
SEARCH_STREAM = 7  # tells the search's draws from the campaign's (`sampling.draw_run`)
MAX_ITERATIONS = 20
MAX_POPULATION = 200


@dataclass(frozen=True, slots=True)
class Belief:
    """The sampling law of one key in a search: a clipped normal or a categorical."""

    law: Law
    mean: float = 0.0
    sd: float = 0.0
    probabilities: tuple[float, ...] = ()  # a choice's

    def draw(self, rng: np.random.Generator) -> object:
        """One value."""
        if not self.law.numeric:
            return self.law.values[int(rng.choice(len(self.law.values),
                                                  p=self.probabilities))]
        drawn = float(np.clip(rng.normal(self.mean, self.sd), self.law.low, self.law.high))
        if self.law.kind == "integers":
            return round(drawn)
        return round(drawn, DECIMALS)

    def refit(self, elite: Sequence[object]) -> Belief:
        """The law refitted to the elite's values of the key (module doc)."""
        if not self.law.numeric:
            counts = [sum(v == value for v in elite) for value in self.law.values]
            fitted = np.array(counts, dtype=float) / len(elite)
            blended = SMOOTHING * fitted + (1 - SMOOTHING) * np.array(self.probabilities)
            return Belief(self.law, probabilities=tuple(float(p) for p in blended))
        numbers = np.array(elite, dtype=float)
        floor = MIN_SD * (self.law.high - self.law.low)
        mean = SMOOTHING * float(numbers.mean()) + (1 - SMOOTHING) * self.mean
        sd = SMOOTHING * float(numbers.std()) + (1 - SMOOTHING) * self.sd
        return Belief(self.law, mean, max(sd, floor))


def first_belief(law: Law) -> Belief:
    """The law of iteration 0: the file's own (a uniform or integer key's mean and sd
    those of its interval; a choice's its weights)."""
    if not law.numeric:
        return Belief(law, probabilities=law.weights)
    if law.kind == "normal":
        return Belief(law, law.mean, law.sd)
    return Belief(law, (law.low + law.high) / 2, (law.high - law.low) / math.sqrt(12))


@dataclass
class Search:
    """The cross-entropy search over one family's laws (module doc)."""

    laws: tuple[Law, ...]
    seed: int  # the campaign's `--seed`
    family: int  # the family's index (a stream of the draws)
    population: int
    tried: list[tuple[dict[str, object], float]]  # values, metric (+inf if unmeasured)
    beliefs: tuple[Belief, ...] = ()
    iteration: int = 0

    def __post_init__(self) -> None:
        if not self.beliefs:
            self.beliefs = tuple(first_belief(law) for law in self.laws)

    def draws(self) -> list[dict[str, object]]:
        """This iteration's values, one mapping (`vary:` key -> value) per run."""
        runs = []
        for k in range(self.population):
            rng = generator(self.seed, self.family, self.iteration, k, SEARCH_STREAM)
            runs.append({b.law.key: b.draw(rng) for b in self.beliefs})
        return runs

    def tell(self, values: Sequence[dict[str, object]], metrics: Sequence[float]) -> None:
        """This iteration's runs measured `metrics`: refit to the elite, next iteration."""
        self.tried += [(v, m if math.isfinite(m) else math.inf)
                       for v, m in zip(values, metrics, strict=True)]
        ranked = sorted(self.tried, key=lambda pair: pair[1])
        elite = [v for v, _ in ranked[: max(2, int(ELITE * len(ranked)))]]
        self.beliefs = tuple(b.refit([v[b.law.key] for v in elite]) for b in self.beliefs)
        self.iteration += 1

    def best(self) -> tuple[dict[str, object], float] | None:
        """The values that measured the least metric, and it; None if none measured it."""
        measured = [pair for pair in self.tried if math.isfinite(pair[1])]
        return min(measured, key=lambda pair: pair[1]) if measured else None

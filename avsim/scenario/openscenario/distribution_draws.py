"""The runs of a `Stochastic` ParameterValueDistribution: `numberOfTestRuns` runs, each
drawing one value of every `StochasticDistribution` in the file's order, from one numpy
`Generator` (PCG64) seeded with the file's `randomSeed` (an integer 0 <= seed < 2**32;
0 when the file gives none). Same file, same runs, bit for bit. esmini 3.6 plays no
stochastic distribution (it runs the scenario once with its defaults), so there is no
reference to match; another player's draws differ.

- `ProbabilityDistributionSet`: an `Element value` chosen with probability weight / sum.
- `NormalDistribution expectedValue variance` (the normal's mean and variance).
- `LogNormalDistribution expectedValue variance`: the mean and variance of the log-normal
  value itself (> 0), i.e. the underlying normal has sigma^2 = ln(1 + variance / mean^2)
  and mu = ln(mean) - sigma^2 / 2.
- `PoissonDistribution expectedValue`: an integer count.
- `UniformDistribution / Range lowerLimit upperLimit`: uniform in [lower, upper).
- `Histogram / Bin weight / Range`: a bin chosen with probability weight / sum, then
  uniform in its range.

A `Range` inside a normal, log-normal or Poisson distribution truncates it: a value outside
[lower, upper] is drawn again (the distribution conditioned on the range, not clipped
onto its ends), at most `MAX_REDRAWS` times, after which the file is refused (its range
holds almost none of the distribution). `UserDefinedDistribution` is refused: its
semantics are the tool's own.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from avsim.scenario.bounds import MAX_SEED
from avsim.scenario.openscenario.distribution_values import (
    MAX_RUNS,
    Assignments,
    number,
    optional_number,
    text,
)
from avsim.scenario.openscenario.xmlread import Node

MAX_REDRAWS = 10_000  # draws of one value inside its Range before the file is refused

Draw = Callable[[np.random.Generator], str]  # one value of a distribution, as text


def stochastic_runs(node: Node) -> list[Assignments]:
    """The runs of a Stochastic element (module doc)."""
    count = number(node, "numberOfTestRuns")
    if count != int(count) or not 1 <= count <= MAX_RUNS:
        raise node.error(f"numberOfTestRuns must be an integer from 1 to {MAX_RUNS}, got "
                         f"{text(node.attrs['numberOfTestRuns'])}")
    seed = optional_number(node, "randomSeed", 0.0)
    if seed != int(seed) or not 0 <= seed <= MAX_SEED:
        raise node.error(f"randomSeed must be an integer from 0 to {MAX_SEED}, got "
                         f"{text(node.attrs['randomSeed'])}")
    draws: list[tuple[str, Draw]] = []
    for child in node.children:
        if child.tag != "StochasticDistribution":
            raise child.error(f"not supported yet ({child.tag})")
        name = child.attrs.get("parameterName")
        if not name:
            raise child.error("missing attribute parameterName")
        draws.append((name, _draw(child.only_child())))
    if not draws:
        raise node.error("no StochasticDistribution: the distribution would describe no run")
    rng = np.random.Generator(np.random.PCG64(int(seed)))
    return [tuple((name, draw(rng)) for name, draw in draws) for _ in range(int(count))]


def _draw(node: Node) -> Draw:
    """How to draw a value of the distribution element `node`."""
    maker = DRAWS.get(node.tag)
    if maker is None:
        raise node.error(f"not supported yet ({node.tag})")
    return maker(node)


def _weights(node: Node, items: list[Node]) -> np.ndarray:
    """The probabilities of `items` (their `weight`s, each >= 0, summing to > 0)."""
    if not items:
        raise node.error("no elements to choose from")
    weights = np.array([number(item, "weight") for item in items])
    if (weights < 0).any() or weights.sum() <= 0:
        raise node.error("weights must be >= 0 and not all 0")
    probabilities: np.ndarray = weights / weights.sum()
    return probabilities


def _weighted_set(node: Node) -> Draw:
    elements = node.all("Element")
    p = _weights(node, elements)
    values = []
    for element in elements:
        if "value" not in element.attrs:
            raise element.error("missing attribute value")
        values.append(element.attrs["value"])
    return lambda rng: values[int(rng.choice(len(values), p=p))]


def _limits(node: Node) -> tuple[float, float]:
    """A Range's (lower, upper), refused when reversed."""
    low, high = number(node, "lowerLimit"), number(node, "upperLimit")
    if high < low:
        raise node.error(f"upperLimit {high:g} is below lowerLimit {low:g}")
    return low, high


def _truncated(node: Node, sample: Callable[[np.random.Generator], float],
               as_text: Callable[[float], str] = repr) -> Draw:
    """Draws of `sample`, redrawn while outside the node's optional Range."""
    bounds = node.child("Range")
    if bounds is None:
        return lambda rng: as_text(sample(rng))
    low, high = _limits(bounds)

    def draw(rng: np.random.Generator) -> str:
        for _ in range(MAX_REDRAWS):
            value = sample(rng)
            if low <= value <= high:
                return as_text(value)
        raise bounds.error(f"no value inside the range in {MAX_REDRAWS} draws")

    return draw


def _spread(node: Node) -> tuple[float, float]:
    """(expectedValue, variance >= 0)."""
    mean, variance = number(node, "expectedValue"), number(node, "variance")
    if variance < 0:
        raise node.error(f"variance must be >= 0, got {variance:g}")
    return mean, variance


def _normal(node: Node) -> Draw:
    mean, variance = _spread(node)
    sigma = math.sqrt(variance)
    return _truncated(node, lambda rng: float(rng.normal(mean, sigma)))


def _log_normal(node: Node) -> Draw:
    mean, variance = _spread(node)
    if mean <= 0:
        raise node.error(f"expectedValue must be > 0, got {mean:g}")
    s2 = math.log1p(variance / mean**2)
    mu, sigma = math.log(mean) - s2 / 2, math.sqrt(s2)
    return _truncated(node, lambda rng: float(rng.lognormal(mu, sigma)))


def _poisson(node: Node) -> Draw:
    mean = number(node, "expectedValue")
    if not 0 <= mean <= 1e9:
        raise node.error(f"expectedValue must be from 0 to 1e9, got {mean:g}")
    return _truncated(node, lambda rng: float(rng.poisson(mean)), lambda v: str(int(v)))


def _uniform(node: Node) -> Draw:
    low, high = _limits(node.need("Range"))
    return lambda rng: repr(float(rng.uniform(low, high)))


def _histogram(node: Node) -> Draw:
    bins = node.all("Bin")
    p = _weights(node, bins)
    limits = [_limits(b.need("Range")) for b in bins]

    def draw(rng: np.random.Generator) -> str:
        low, high = limits[int(rng.choice(len(limits), p=p))]
        return repr(float(rng.uniform(low, high)))

    return draw


DRAWS: dict[str, Callable[[Node], Draw]] = {  # a StochasticDistribution's kinds
    "ProbabilityDistributionSet": _weighted_set,
    "NormalDistribution": _normal,
    "LogNormalDistribution": _log_normal,
    "PoissonDistribution": _poisson,
    "UniformDistribution": _uniform,
    "Histogram": _histogram,
}

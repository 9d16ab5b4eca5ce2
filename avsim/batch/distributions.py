"""The runs of an OpenSCENARIO ParameterValueDistribution file as batch entries: one per
concrete run (`avsim.scenario.openscenario.distribution`), named
``<distribution file's name>_p<k>`` (k: esmini's 0-based permutation), running the file's
ScenarioFile with that run's parameters (`parameters.NAME` overrides) besides the batch's
own overrides. `avsim run`, `suite` and `sweep` take a distribution file through these
entries and the one batch engine (`avsim.batch.suite.plan`, the executors)."""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from pathlib import Path

from avsim.scenario.openscenario.distribution import (
    Distribution,
    is_distribution,
    load_distribution,
)

Entry = tuple[str | None, str, dict[str, object]]  # (job name, scenario, overrides): `plan`'s


class DistributionError(ValueError):
    """A batch override that the distribution also sets (one line)."""


def is_distribution_file(scenario: str) -> bool:
    """Whether `scenario` (a path or a bundled name) is a ParameterValueDistribution file."""
    path = Path(scenario)
    return path.suffix == ".xosc" and path.is_file() and is_distribution(path)


def run_name(dist: Distribution, index: int) -> str:
    """The job name of run `index`: the file's stem in [a-z0-9_], then ``_p<index>``."""
    stem = re.sub(r"[^a-z0-9_]+", "_", dist.path.stem.lower()).strip("_") or "distribution"
    return f"{stem}_p{index}"


def distribution_entries(scenario: str, overrides: Mapping[str, object] | None = None,
                         search_paths: Sequence[Path] = ()) -> list[Entry]:
    """The entries of the distribution file `scenario` (module doc); `ScenarioError` for a
    bad file, `DistributionError` for an override of a parameter the distribution sets
    (every run would be the same)."""
    dist = load_distribution(Path(scenario), search_paths)
    given = dict(overrides or {})
    entries: list[Entry] = []
    for run in dist.runs:
        own = run.overrides()
        both = sorted(set(own) & set(given))
        if both:
            raise DistributionError(f"{scenario}: {both[0]}: the distribution sets this "
                                    "parameter (--set / --param would replace its values)")
        entries.append((run_name(dist, run.index), str(dist.scenario), given | own))
    return entries

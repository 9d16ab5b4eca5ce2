"""The runs a campaign adds after its own: shrinking each failure (`--shrink`,
`avsim.batch.shrink`) and searching each family for its worst case (`--search`,
`avsim.batch.search`). Both go through the campaign's executor in rounds (`Execute`) and
write their runs into `shrink/` and `search/` below the campaign's folder (result JSON
only: their recordings are deleted, a repro file remakes any of them).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

from avsim.batch.campaign import (
    MISSING,
    DrawnRun,
    Family,
    Settings,
    jobs_of,
    run_overrides,
)
from avsim.batch.jobs import RunJob, RunOutcome, Status
from avsim.batch.search import Search
from avsim.batch.shrink import Shrinker
from avsim.scenario.load import ScenarioError

Execute = Callable[[list[RunJob]], list[RunOutcome]]  # runs jobs, outcomes in job order
SHRINK_DIR, SEARCH_DIR = "shrink", "search"  # below the campaign's folder


@dataclass(frozen=True)
class Shrunk:
    """A failed run shrunk toward its family's nominal case."""

    run: DrawnRun
    criterion: str  # the criterion every shrunk candidate failed too
    values: Mapping[str, object]  # the smallest failing case
    moved: Mapping[str, tuple[object, object]]  # key -> (drawn, shrunk) of the keys moved
    runs: int  # candidates run


@dataclass(frozen=True)
class Worst:
    """A family's search result: the least metric found."""

    family: Family
    metric: str
    nominal: float  # the metric of the file's own case (NaN when unmeasured)
    value: float  # the least found (NaN when no run measured it)
    values: Mapping[str, object]  # the values that gave it (empty when none did)
    runs: int  # search runs, the nominal's included


def _finished(outcomes: Sequence[RunOutcome]) -> list[RunOutcome]:
    """The outcomes, their recordings deleted (a repro file remakes a run)."""
    for outcome in outcomes:
        outcome.job.recording.unlink(missing_ok=True)
    return list(outcomes)


def _interrupted(outcomes: Sequence[RunOutcome]) -> bool:
    """Whether the campaign was interrupted (Ctrl-C, SIGTERM) during these runs: no more
    rounds start, what was found so far is reported."""
    return any(o.status is Status.INTERRUPTED for o in outcomes)


def _job(name: str, family: Family, values: Mapping[str, object], settings: Settings,
         folder: str) -> RunJob | None:
    """A checked job of values, None when they do not load (never for values inside the
    laws: a law may still reach a value the file's other keys refuse)."""
    entry = (name, family.file, run_overrides(values, settings))
    try:
        return jobs_of([entry], settings, settings.out_dir / folder)[0]
    except ScenarioError:
        return None


def _failed(outcome: RunOutcome) -> list[str]:
    """The criteria a run failed."""
    if outcome.status is not Status.FAILED:
        return []
    return [str(c["name"]) for c in outcome.criteria() if c["passed"] is False]


def shrink(failures: Sequence[DrawnRun], settings: Settings, execute: Execute) -> list[Shrunk]:
    """Each failure shrunk (`avsim.batch.shrink`), the shrinkers' candidates run in rounds."""
    shrinkers = [_shrinker(run) for run in failures]
    while True:
        pending: list[tuple[Shrinker, RunJob | None]] = []
        for run, shrinker in zip(failures, shrinkers, strict=True):
            values = shrinker.candidate()
            if values is not None:
                name = f"{run.outcome.job.name}_shrink_{shrinker.runs:02d}"
                pending.append((shrinker, _job(name, run.family, values, settings,
                                               SHRINK_DIR)))
        if not pending:
            break
        jobs = [job for _, job in pending if job is not None]
        done = _finished(execute(jobs))
        if _interrupted(done):
            break
        outcomes = iter(done)
        for shrinker, job in pending:
            shrinker.tell(_failed(next(outcomes)) if job is not None else [])
    return [Shrunk(run, s.criterion, dict(s.values), dict(s.moved), s.runs)
            for run, s in zip(failures, shrinkers, strict=True)]


def _shrinker(run: DrawnRun) -> Shrinker:
    """The shrinker of a failed run: toward its family's nominal values (the keys the file
    writes)."""
    family = run.family
    nominal = {law.key: family.nominal(law.key) for law in family.laws}
    written = {key: value for key, value in nominal.items() if value is not MISSING}
    return Shrinker(family.laws, dict(run.values), written, run.failed_criteria[0])


def search(families: Sequence[Family], settings: Settings, metric: str, iterations: int,
           population: int, execute: Execute) -> list[Worst]:
    """Each family's least `metric` (`avsim.batch.search`), the families' runs in rounds;
    the first round also runs each family's nominal case."""
    searches = [Search(f.laws, settings.seed, f.index, population, []) for f in families]
    nominal_jobs = [_job(f"{f.name}_nominal", f, {}, settings, SEARCH_DIR) for f in families]
    nominals = _metrics(_finished(execute([j for j in nominal_jobs if j is not None])),
                        nominal_jobs, metric)
    for _ in range(iterations):
        draws = [s.draws() for s in searches]
        jobs = [_job(f"{f.name}_search_{s.iteration:02d}_{k:03d}", f, values, settings,
                     SEARCH_DIR)
                for f, s, runs in zip(families, searches, draws, strict=True)
                for k, values in enumerate(runs)]
        done = _finished(execute([j for j in jobs if j is not None]))
        if _interrupted(done):
            break
        measured = iter(_metrics(done, jobs, metric))
        for s, runs in zip(searches, draws, strict=True):
            s.tell(runs, [next(measured) for _ in runs])
    worst = []
    for family, s, nominal in zip(families, searches, nominals, strict=True):
        best = s.best()
        values, value = best if best is not None else ({}, math.nan)
        worst.append(Worst(family, metric, nominal, value, values, len(s.tried) + 1))
    return worst


def _metrics(outcomes: Sequence[RunOutcome], jobs: Sequence[RunJob | None],
             metric: str) -> list[float]:
    """Each job's metric (NaN for a job that could not be made), in job order."""
    found = iter(outcomes)
    return [math.nan if job is None else next(found).metric(metric) for job in jobs]


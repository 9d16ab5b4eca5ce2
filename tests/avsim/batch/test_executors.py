"""Executors without running a scenario: the order runs start in, and Ray's absence."""

from __future__ import annotations

import os
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from avsim.batch.executors import ExecutorError, LocalExecutor, RayExecutor, longest_first
from avsim.batch.jobs import RunJob, RunOutcome, Status


def job(name: str, duration: float) -> RunJob:
    return RunJob(name, f"{name}.yaml", Path("out"), duration=duration)


def test_the_longest_runs_start_first_and_ties_keep_their_order() -> None:
    jobs = [job("a", 10.0), job("b", 180.0), job("c", 45.0), job("d", 45.0), job("e", 0.0)]
    assert [j.name for j in longest_first(jobs)] == ["b", "c", "d", "a", "e"]


def test_without_ray_the_ray_executor_says_how_to_get_it(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setitem(sys.modules, "ray", None)  # `import ray` raises ImportError
    with pytest.raises(ExecutorError) as err:
        RayExecutor().run([job("a", 1.0)])
    assert str(err.value) == ("--executor ray: Ray is not installed "
                              "(pip install 'avsim[ray]')")


def _dies(job: RunJob, messages: Any) -> RunOutcome:
    """A worker task that says it started (as the real one does), then, for the job named
    `crashes`, ends its process as a crash in native code would."""
    messages.put(job.name)
    if job.name == "crashes":
        os._exit(3)
    return RunOutcome(job, Status.PASSED, {"criteria": [], "metrics": {}, "sim_time": 1.0})


def _dies_at_once(job: RunJob, messages: Any) -> RunOutcome:
    """As `_dies`, but the crash comes before the worker could say it started."""
    if job.name == "crashes":
        os._exit(3)
    return _dies(job, messages)


@pytest.mark.parametrize("task", [_dies, _dies_at_once])
@pytest.mark.parametrize("workers", [1, 2])
def test_a_worker_that_dies_is_that_runs_error_not_the_batchs(
    task: Callable[[RunJob, Any], RunOutcome], workers: int,
) -> None:
    """The crashing run is the longest: it starts first and breaks the pool while the others
    wait or run; they finish all the same."""
    jobs = [job("fine", 1.0), job("crashes", 2.0), job("later", 0.5), job("last", 0.1)]
    outcomes = LocalExecutor(workers, task=task).run(jobs)
    assert [o.job.name for o in outcomes] == ["fine", "crashes", "later", "last"]
    assert [o.status for o in outcomes] == [Status.PASSED, Status.ERROR, Status.PASSED,
                                            Status.PASSED]
    crashed = outcomes[1]
    assert crashed.result is None and crashed.error is not None
    assert crashed.error.startswith("crashes: the worker died")
    assert "\n" not in crashed.error

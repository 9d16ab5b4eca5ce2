"""Executors without running a scenario: the order runs start in, and Ray's absence."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from avsim.executors import ExecutorError, RayExecutor, longest_first
from avsim.jobs import RunJob


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

"""Closed-loop scenario runs, shared by the tests of one module (runs are slow)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from avsim.runner import Runner, RunResult
from avsim.scenario import load_scenario


@pytest.fixture(scope="module")
def run_scenario(tmp_path_factory: pytest.TempPathFactory) -> Callable[..., RunResult]:
    cache: dict[tuple[str, bool], RunResult] = {}

    def run(name: str, record: bool = True, **overrides: object) -> RunResult:
        key = (name + repr(sorted(overrides.items())), record)
        if key not in cache:
            spec = load_scenario(name, overrides or None)
            out: Path | None = tmp_path_factory.mktemp("runs") / f"{name}.rrd" if record else None
            cache[key] = Runner(spec, out).run()
        return cache[key]

    return run

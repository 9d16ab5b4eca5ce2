"""A run's sensing worker starts before the world is built, and a failure while building
leaves no worker process and no shared-memory file behind."""

from __future__ import annotations

import multiprocessing as mp
import tempfile
from pathlib import Path
from typing import Any

import pytest

from avsim.run import runner as runner_module
from avsim.run.runner import Runner
from avsim.scenario.load import load_scenario
from world.sensors.setup import Profile


def test_a_failed_build_stops_the_sensing_worker(monkeypatch: pytest.MonkeyPatch) -> None:
    made: list[Path] = []  # this run's shared-memory files (other tests' may come and go)

    original = tempfile.mkstemp

    def mkstemp(*args: Any, **kwargs: Any) -> Any:
        fd, name = original(*args, **kwargs)
        made.append(Path(name))
        return fd, name

    monkeypatch.setattr(tempfile, "mkstemp", mkstemp)  # the module the pipeline uses

    def broken_world(*args: object, **kwargs: object) -> None:
        assert any(p.name == "avsim-sensing" for p in mp.active_children())  # started first
        raise RuntimeError("the world cannot be built")

    monkeypatch.setattr(runner_module, "World", broken_world)
    with pytest.raises(RuntimeError, match="cannot be built"):
        Runner(load_scenario("normal_driving"), None, profile=Profile.FAST, sensing="process")
    assert not any(p.name == "avsim-sensing" for p in mp.active_children())
    assert made and not any(path.exists() for path in made)

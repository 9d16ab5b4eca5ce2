"""`avsim` with a test's hook, for tests that run the command line in a subprocess:
``python -m tests.avsim.run.cli_hooks HOOK MARK GO avsim-arguments...``.

The hooks let a test act at a known moment without guessing times: each creates the file
MARK when the moment comes, then waits (at most `WAIT`) until the test creates the file GO.

- ``import``: while the run's heavy modules are imported (`avsim.run.runner`);
- ``build``: while the world is built (`world.world.World`'s constructor);
- ``after``: after the run's last tick, before its files are written (`Runner.run`);
- ``world``: no waiting: building the world raises a RuntimeError;
- ``planner``: no waiting: the planner's 30th update raises the ValueError the planner
  raises when the car does not head along the lane (MARK and GO unused).
"""

from __future__ import annotations

import importlib.abc
import sys
import time
from collections.abc import Callable, Sequence
from importlib.machinery import ModuleSpec
from pathlib import Path
from types import ModuleType
from typing import Any

WAIT = 60.0  # [s] the longest a hook waits for GO
HEAVY = "avsim.run.runner"  # the module the `import` hook slows


def pause(mark: Path, go: Path) -> None:
    """Create `mark`, then wait until `go` exists (at most `WAIT`)."""
    mark.touch()
    deadline = time.monotonic() + WAIT
    while not go.exists() and time.monotonic() < deadline:
        time.sleep(0.01)


class SlowImport(importlib.abc.MetaPathFinder):
    """Pauses once, as `HEAVY` starts to be imported; finds nothing itself."""

    def __init__(self, mark: Path, go: Path) -> None:
        self.mark, self.go, self.done = mark, go, False

    def find_spec(self, name: str, path: Sequence[str] | None,
                  target: ModuleType | None = None) -> ModuleSpec | None:
        if name == HEAVY and not self.done:
            self.done = True
            pause(self.mark, self.go)
        return None


def wrap(cls: type, method: str, around: Callable[[Callable[..., Any], Any], Any]) -> None:
    """Replace `cls.method` by `around(original, *args)`."""
    original = getattr(cls, method)

    def wrapper(*args: Any, **kwargs: Any) -> Any:
        return around(lambda: original(*args, **kwargs), args[0])

    setattr(cls, method, wrapper)


def install(hook: str, mark: Path, go: Path) -> None:
    """Install `hook` (module doc)."""
    if hook == "import":
        sys.meta_path.insert(0, SlowImport(mark, go))
    elif hook == "build":
        from world.world import World

        def paused_build(call: Callable[[], Any], _self: Any) -> Any:
            pause(mark, go)
            return call()

        wrap(World, "__init__", paused_build)
    elif hook == "after":
        from avsim.run.runner import Runner

        def paused_end(call: Callable[[], Any], _self: Any) -> Any:
            result = call()
            pause(mark, go)
            return result

        wrap(Runner, "run", paused_end)
    else:
        install_fault(hook)


def install_fault(hook: str) -> None:
    """Install the `world` or `planner` hook (module doc)."""
    if hook == "world":
        from world.world import World

        def broken_build(_call: Callable[[], Any], _self: Any) -> Any:
            raise RuntimeError("the world cannot be built")

        wrap(World, "__init__", broken_build)
    elif hook == "planner":
        from planner.planner import Planner

        calls = [0]

        def planner_bug(call: Callable[[], Any], _self: Any) -> Any:
            calls[0] += 1
            if calls[0] == 30:
                raise ValueError("heading error 2.856 rad: the car does not head along "
                                 "the lane")
            return call()

        wrap(Planner, "update", planner_bug)
    else:
        raise SystemExit(f"unknown hook {hook!r}")


if __name__ == "__main__":
    install(sys.argv[1], Path(sys.argv[2]), Path(sys.argv[3]))
    from avsim.cli import main

    main(sys.argv[4:], prog_name="avsim")

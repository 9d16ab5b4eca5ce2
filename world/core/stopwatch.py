"""Wall time per named stage of a run: where each simulated second goes.

A `Stopwatch` belongs to one run (the runner makes it and hands it to the parts it times).
`with watch("physics"): ...` adds the span's `time.perf_counter()` seconds to the stage
"physics"; `watch.add(stage, seconds)` adds a span measured elsewhere (another process's).
Only leaf stages are timed, never one inside another, so the stages of one process add up to
its wall time less the untimed rest. A span costs about a microsecond; nothing the run
computes depends on the figures, so a run is the same with or without anyone reading them.

The stage names the runner uses (`bench/bench_stages.py` prints them per profile):
physics, criteria, runner, scoring, recording, sensor <name> (a capture in this process),
localisation, perception <stage>, planner, control, ipc send / ipc wait / ipc receive (the
frames passed to and from the render worker) and worker <stage> (time spent in the render
worker, beside the main process's).
"""

from __future__ import annotations

import time
from collections.abc import Iterator, Mapping
from contextlib import contextmanager


class Stopwatch:
    """Seconds and span counts per stage name, summed over a run."""

    __slots__ = ("seconds", "spans")

    def __init__(self) -> None:
        self.seconds: dict[str, float] = {}  # [s] per stage
        self.spans: dict[str, int] = {}  # spans per stage

    @contextmanager
    def __call__(self, stage: str) -> Iterator[None]:
        start = time.perf_counter()
        try:
            yield
        finally:
            self.add(stage, time.perf_counter() - start)

    def add(self, stage: str, seconds: float) -> None:
        self.seconds[stage] = self.seconds.get(stage, 0.0) + seconds
        self.spans[stage] = self.spans.get(stage, 0) + 1

    def add_all(self, seconds: Mapping[str, float], prefix: str = "") -> None:
        """Add one span per stage of `seconds`, each named `prefix + stage`."""
        for stage, value in seconds.items():
            self.add(prefix + stage, value)

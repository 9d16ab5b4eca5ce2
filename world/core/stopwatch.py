"""Wall time per named stage of a run: where each simulated second goes.

A `Stopwatch` belongs to one run (the runner makes it and hands it to the parts it times).
`with watch("physics"): ...` adds the span's `time.perf_counter()` seconds to the stage
"physics"; `watch.add(stage, seconds)` adds a span measured elsewhere (another process's).
Only leaf stages are timed, never one inside another, so the stages of one process add up to
its wall time less the untimed rest. A span costs a few microseconds (the physics step
opens one every step); nothing the run computes depends on the figures, so a run is the
same with or without anyone reading them.

The stage names the runner uses (`bench/bench_stages.py` prints them per profile):
physics, criteria, runner, scoring, recording, sensor <name> (a capture in this process),
localisation, perception <stage>, planner, control, ipc send / ipc wait / ipc receive (the
frames passed to and from the render worker) and worker <stage> (time spent in the render
worker, beside the main process's).
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from types import TracebackType


class Stopwatch:
    """Seconds and span counts per stage name, summed over a run."""

    __slots__ = ("seconds", "spans")

    def __init__(self) -> None:
        self.seconds: dict[str, float] = {}  # [s] per stage
        self.spans: dict[str, int] = {}  # spans per stage

    def __call__(self, stage: str) -> _Span:
        """A context manager timing one span of `stage` (an exception's span included)."""
        return _Span(self, stage)

    def add(self, stage: str, seconds: float) -> None:
        self.seconds[stage] = self.seconds.get(stage, 0.0) + seconds
        self.spans[stage] = self.spans.get(stage, 0) + 1

    def add_all(self, seconds: Mapping[str, float], prefix: str = "") -> None:
        """Add one span per stage of `seconds`, each named `prefix + stage`."""
        for stage, value in seconds.items():
            self.add(prefix + stage, value)


class _Span:
    """One timed span (a plain class, cheaper than a generator-based context manager)."""

    __slots__ = ("_stage", "_start", "_watch")

    def __init__(self, watch: Stopwatch, stage: str) -> None:
        self._watch, self._stage, self._start = watch, stage, 0.0

    def __enter__(self) -> None:
        self._start = time.perf_counter()

    def __exit__(self, kind: type[BaseException] | None, error: BaseException | None,
                 trace: TracebackType | None) -> None:
        self._watch.add(self._stage, time.perf_counter() - self._start)

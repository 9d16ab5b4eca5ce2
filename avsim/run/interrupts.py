"""Ending a run or a batch cleanly on SIGINT (Ctrl-C) or SIGTERM.

While an `Interrupts` block is active, either signal is recorded instead of raising
`KeyboardInterrupt` or killing the process, and the callbacks registered with `on_signal` are
called (a `Runner`'s `interrupt`: the run ends at its current tick, its recording is closed
and valid, its result says ``"interrupted": true``). The caller writes what it has and exits
with `exit_status`: 128 + the signal's number, as a shell reports a process a signal ended
(130 for SIGINT, 143 for SIGTERM). The handlers before the block are restored after it.

Before such a block, while a command starts (loading, the heavy imports: nothing written
yet), `ExitAtOnce` makes either signal end the process at once with that status, without a
traceback or click's "Aborted!" (exit 1).

A run's exit status is its verdict's (`avsim.run.verdict`): a signal that comes after the
run's last tick changes nothing (the run is whole, its files are written, its result says
``"interrupted": false``), and the exit status is that of its verdict.
"""

from __future__ import annotations

import signal
from collections.abc import Callable
from types import FrameType, TracebackType
from typing import NoReturn

SIGNALS = (signal.SIGINT, signal.SIGTERM)


class Interrupts:
    """A context manager that turns SIGINT and SIGTERM into a recorded request to stop."""

    def __init__(self) -> None:
        self.received: int | None = None  # the first signal's number, once one came
        self._callbacks: list[Callable[[], None]] = []
        self._previous: dict[int, object] = {}

    def on_signal(self, callback: Callable[[], None]) -> None:
        """Call `callback` when a signal comes (at once if one already has)."""
        self._callbacks.append(callback)
        if self.received is not None:
            callback()

    def __enter__(self) -> Interrupts:
        for sig in SIGNALS:
            self._previous[sig] = signal.signal(sig, self._handle)
        return self

    def __exit__(self, kind: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        for sig, handler in self._previous.items():
            signal.signal(sig, handler)  # type: ignore[arg-type]

    def _handle(self, signum: int, _frame: FrameType | None) -> None:
        if self.received is None:
            self.received = signum
        for callback in self._callbacks:
            callback()

    @property
    def exit_status(self) -> int | None:
        """128 + the signal's number once one came (130 SIGINT, 143 SIGTERM), else None."""
        return None if self.received is None else 128 + self.received


def _exit(signum: int, _frame: FrameType | None) -> NoReturn:
    """End the process with 128 + the signal's number (no traceback: SystemExit)."""
    raise SystemExit(128 + signum)


class ExitAtOnce:
    """A context manager during which SIGINT and SIGTERM end the process at once, with
    130 / 143 (module doc); the handlers before it are restored after it."""

    def __init__(self) -> None:
        self._previous: dict[int, object] = {}

    def __enter__(self) -> ExitAtOnce:
        for sig in SIGNALS:
            self._previous[sig] = signal.signal(sig, _exit)
        return self

    def __exit__(self, kind: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        for sig, handler in self._previous.items():
            signal.signal(sig, handler)  # type: ignore[arg-type]

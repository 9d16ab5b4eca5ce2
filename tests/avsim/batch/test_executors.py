"""Executors without running a scenario: the order runs start in, and Ray's absence."""

from __future__ import annotations

import os
import signal
import sys
import threading
import time
from collections.abc import Callable
from pathlib import Path

import pytest

from avsim.batch.executors import (
    Channel,
    ExecutorError,
    LocalExecutor,
    Progress,
    RayExecutor,
    _QueueProgress,
    longest_first,
)
from avsim.batch.jobs import RunJob, RunOutcome, Status, not_run
from avsim.run.interrupts import Interrupts


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


def _dies(job: RunJob, channel: Channel) -> RunOutcome:
    """A worker task that says it started (as the real one does), then, for the job named
    `crashes`, ends its process as a crash in native code would."""
    channel.messages.put((job.name, os.getpid()))
    if job.name == "crashes":
        os._exit(3)
    return RunOutcome(job, Status.PASSED, {"criteria": [], "metrics": {}, "sim_time": 1.0})


def _dies_at_once(job: RunJob, channel: Channel) -> RunOutcome:
    """As `_dies`, but the crash comes before the worker could say it started."""
    if job.name == "crashes":
        os._exit(3)
    return _dies(job, channel)


@pytest.mark.parametrize("task", [_dies, _dies_at_once])
@pytest.mark.parametrize("workers", [1, 2])
def test_a_worker_that_dies_is_that_runs_error_not_the_batchs(
    task: Callable[[RunJob, Channel], RunOutcome], workers: int,
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


def _slow(job: RunJob, channel: Channel) -> RunOutcome:
    """A worker task that says it started, then "runs" for up to 30 s, ending early (at its
    tick, as a run does) when its worker is told to stop; `quick` ends at once."""
    if channel.stopping.is_set():
        return not_run(job)
    with Interrupts() as stop:
        channel.messages.put((job.name, os.getpid()))
        end = time.monotonic() + (0.0 if job.name == "quick" else 30.0)
        while time.monotonic() < end and stop.received is None:
            time.sleep(0.02)
        interrupted = stop.received is not None
        return RunOutcome(job, Status.INTERRUPTED if interrupted else Status.PASSED,
                          {"criteria": [], "metrics": {}, "sim_time": 1.0,
                           "interrupted": interrupted})


def test_a_stopped_batch_ends_its_runs_at_their_tick_and_starts_no_more() -> None:
    """A signal caught by the batch's `Interrupts` (set here from a timer, as its handler
    would): the runs under way end early with their results, the waiting ones never start,
    the finished one stands."""
    jobs = [job("quick", 3.0), job("slow", 2.0), job("slower", 1.0), job("never", 0.5),
            job("nor", 0.4)]
    stop = Interrupts()

    class StopOnceSlowStarts:  # the batch's sink: the signal comes 1 s after `slow` began
        def started(self, job: RunJob) -> None:
            if job.name == "slow":
                threading.Timer(1.0, setattr, (stop, "received", signal.SIGTERM)).start()

        def advanced(self, progress: Progress) -> None:
            pass

        def finished(self, outcome: RunOutcome) -> None:
            pass

    start = time.monotonic()
    outcomes = LocalExecutor(2, task=_slow).run(jobs, StopOnceSlowStarts(), stop)
    assert time.monotonic() - start < 25.0  # no run went its 30 s
    assert [o.job.name for o in outcomes] == [j.name for j in jobs]
    assert outcomes[0].status is Status.PASSED
    assert all(o.status is Status.INTERRUPTED for o in outcomes[1:])
    assert outcomes[1].result is not None and outcomes[1].result["interrupted"] is True
    not_started = [o for o in outcomes[1:] if o.result is None]
    assert not_started and all(o.error is not None and o.error.endswith(
        "not run (the batch was interrupted)") for o in not_started)


class _GoneSink:
    """A manager queue proxy whose manager process has ended."""

    def __init__(self) -> None:
        self.puts = 0

    def put(self, _item: object) -> None:
        self.puts += 1
        raise BrokenPipeError(32, "Broken pipe")


def test_a_progress_sink_that_is_gone_stops_the_messages_not_the_run() -> None:
    """A campaign stopped from outside ends its manager process while the workers still run:
    the progress message raised BrokenPipeError inside the run's loop, and the run was
    written as an `error`."""
    sink = _GoneSink()
    progress = _QueueProgress("run", sink)
    for k in range(50):
        progress(0.1 * k, 5.0)  # no exception
    assert sink.puts == 1  # the first failure ends the messages

"""Where the runs of a suite or a sweep execute: worker processes here, or Ray tasks.

Each run is independent, seeded and deterministic (`avsim.batch.jobs.run_job`), so neither the
executor nor the number of workers changes a result; only the order in which outcomes
arrive does, and the batch sorts them back into job order.

- `LocalExecutor`: a pool of ``jobs`` worker processes, one run per worker process
  (``max_tasks_per_child=1``: nothing carries over from one run to the next, and each
  run's memory is given back). Workers are forked from a ``forkserver`` that has done what
  every run needs first (`PRELOAD`: `avsim.run.warm`, 4-5 s of imports) and nothing
  else: no PyBullet client, no GL context, no run's state to inherit. (Workers started
  with ``spawn`` paid those seconds in every run: a 3 x 3 sweep of 3 s runs took 66 s on
  two workers, 30 s now.) The workers send their simulated time through a queue for the
  live progress display.
- `RayExecutor`: one Ray task per run (``num_cpus=1``) on the cluster at ``address`` (or
  ``RAY_ADDRESS``), or on a local Ray instance started for the batch. A task runs in a
  scratch folder on its node and returns its files' bytes, which are written here: the
  cluster's nodes need not share a file system with this machine. Ray is an optional extra
  (``pip install 'avsim[ray]'``).

Both submit the longest runs first (their scenario duration), which keeps the last worker
from starting a long run while the others idle.
"""

from __future__ import annotations

import contextlib
import math
import multiprocessing as mp
import os
import queue
import signal
import tempfile
from collections.abc import Callable, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

from avsim.batch.jobs import RunJob, RunOutcome, Status, not_run, run_job
from avsim.files import write_atomic
from avsim.run.interrupts import Interrupts

POLL = 0.2  # [s] how often the display is refreshed while runs are under way
PROGRESS_EVERY = 1.0  # [s] of simulated time between a worker's progress messages
RAY_EXTRA = "pip install 'avsim[ray]'"  # how to get Ray, for the error message


PRELOAD = ["avsim.run.warm"]  # what the local workers' forkserver imports once (module doc)


class ExecutorError(Exception):
    """The executor cannot start (bad input: exit status 2)."""


@dataclass(frozen=True, slots=True)
class Progress:
    """A running job's simulated time, as a worker reports it."""

    name: str  # the job's name
    sim_time: float  # [s] simulated so far
    duration: float  # [s] the scenario's duration


class ProgressSink(Protocol):
    """Receives what the executor knows while runs are under way (the live display)."""

    def started(self, job: RunJob) -> None: ...
    def advanced(self, progress: Progress) -> None: ...
    def finished(self, outcome: RunOutcome) -> None: ...


class Executor(Protocol):
    """Runs a batch's jobs somewhere."""

    name: str  # as `--executor` names it

    def run(self, jobs: Sequence[RunJob], sink: ProgressSink | None = None,
            stop: Interrupts | None = None) -> list[RunOutcome]:
        """Run every job; the outcomes in job order (after a signal caught by `stop`: the
        finished runs', the interrupted ones' and `not_run` for the rest)."""
        ...


def longest_first(jobs: Sequence[RunJob]) -> list[RunJob]:
    """The jobs ordered by falling duration (stable: ties keep their order)."""
    return sorted(jobs, key=lambda job: -job.duration)


def _in_job_order(jobs: Sequence[RunJob], outcomes: Sequence[RunOutcome]) -> list[RunOutcome]:
    """The outcomes sorted back into the order of `jobs`."""
    by_name = {o.job.name: o for o in outcomes}
    return [by_name[j.name] for j in jobs]


# ---- local worker processes ----------------------------------------------------------------


class _QueueProgress:
    """A worker's progress callback: a message per `PROGRESS_EVERY` of simulated time.
    Progress is for the display only: a sink that is gone (the batch's manager process
    ended: a pipe broken, a connection reset or closed) stops the messages, never the run."""

    def __init__(self, name: str, sink: Any) -> None:
        self.name, self.sink, self.next = name, sink, 0.0

    def __call__(self, t: float, duration: float) -> None:
        if t >= self.next:
            self.next = t + PROGRESS_EVERY
            try:
                self.sink.put(Progress(self.name, t, duration))
            except (OSError, EOFError):
                self.next = math.inf


def _ignore_sigint() -> None:
    """A pool worker's initializer: Ctrl-C (which reaches the whole process group) is for
    the main process to handle; a worker running a job catches it itself (`_local_task`)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


@dataclass(frozen=True)
class Channel:
    """What a local worker's task shares with the batch (manager proxies: picklable)."""

    messages: Any  # a queue: (job name, worker process id) when a run starts, `Progress`
    stopping: Any  # an event: set once the batch stops (a task taken after it does not run)


def _local_task(job: RunJob, channel: Channel) -> RunOutcome:
    """A worker's task: unless the batch is stopping, say the job started (its name and
    this process's id on the queue), then run it; SIGINT or SIGTERM meanwhile end the run at
    its tick, files kept."""
    if channel.stopping.is_set():
        return not_run(job)
    with Interrupts() as stop:
        channel.messages.put((job.name, os.getpid()))  # started
        return run_job(job, progress=_QueueProgress(job.name, channel.messages),
                       interrupts=stop)


def died(job: RunJob, exc: BaseException) -> RunOutcome:
    """The outcome of a job whose worker process died (a crash in native code, killed):
    `run_job` catches what Python raises, not that."""
    what = type(exc).__name__ + (f": {exc}" if str(exc) else "")
    return RunOutcome(job, Status.ERROR, error=f"{job.name}: the worker died ({what})")


@dataclass
class LocalExecutor:
    """Worker processes on this machine (module doc).

    A worker that dies (a crash in native code, the OOM killer) breaks the whole pool: every
    run under way or waiting fails with it. The runs that were under way (all that were
    lost, if none had reported starting) are suspects: each runs again alone, and one that
    dies again is reported as died (runs are deterministic: that is the one that crashed);
    the others go to a fresh pool. Every round removes its suspects, so it ends."""

    jobs: int = 1  # worker processes
    name: str = "local"
    task: Callable[[RunJob, Channel], RunOutcome] = _local_task  # what a worker runs (tests)

    def run(self, jobs: Sequence[RunJob], sink: ProgressSink | None = None,
            stop: Interrupts | None = None) -> list[RunOutcome]:
        """Run every job, longest first, in rounds of pools (class doc); outcomes in job
        order. Once `stop` has caught a signal, no run starts, the runs under way end at
        their tick (their workers get SIGINT; their files are written) and the rest are
        `not_run`."""
        ctx = mp.get_context("forkserver")
        ctx.set_forkserver_preload(PRELOAD)
        outcomes: list[RunOutcome] = []
        todo = longest_first(jobs)
        with ctx.Manager() as manager:
            messages = Channel(manager.Queue(), manager.Event())
            while todo and not _stopped(stop):
                started: dict[str, int] = {}
                done, lost = self._pool(ctx, todo, self.jobs, messages, started, sink, stop)
                outcomes += done
                if _stopped(stop):  # a pool broken while stopping: its runs are not rerun
                    outcomes += [_tell(sink, not_run(j)) for j, _ in lost]
                    todo = []
                    break
                suspects = [j for j, _ in lost if j.name in started] or [j for j, _ in lost]
                todo = [j for j, _ in lost if j not in suspects]
                for job in suspects:
                    outcomes.append(self._alone(ctx, job, messages, sink, stop))
            outcomes += [_tell(sink, not_run(j)) for j in todo]
        return _in_job_order(jobs, outcomes)

    def _alone(self, ctx: Any, job: RunJob, messages: Channel, sink: ProgressSink | None,
               stop: Interrupts | None) -> RunOutcome:
        """Run `job` in a pool of its own: its outcome, or `died` if it breaks this one too."""
        if _stopped(stop):
            return _tell(sink, not_run(job))
        done, lost = self._pool(ctx, [job], 1, messages, {}, sink, stop)
        if done:
            return done[0]
        return _tell(sink, not_run(job) if _stopped(stop) else died(job, lost[0][1]))

    def _pool(self, ctx: Any, jobs: Sequence[RunJob], workers: int, messages: Channel,
              started: dict[str, int], sink: ProgressSink | None, stop: Interrupts | None,
              ) -> tuple[list[RunOutcome], list[tuple[RunJob, BaseException]]]:
        """Run `jobs` in one pool: the outcomes, and the jobs lost when a worker died (with
        the error). `started` collects the runs that began: name -> worker process id."""
        outcomes: list[RunOutcome] = []
        lost: list[tuple[RunJob, BaseException]] = []
        by_name = {j.name: j for j in jobs}
        signalled: set[str] = set()  # the runs told to end (stopping)
        with ProcessPoolExecutor(max_workers=min(workers, len(jobs)), mp_context=ctx,
                                 max_tasks_per_child=1, initializer=_ignore_sigint) as pool:
            futures = {pool.submit(self.task, job, messages): job for job in jobs}
            pending: set[Future[RunOutcome]] = set(futures)
            while pending:
                done, pending = wait(pending, timeout=POLL, return_when=FIRST_COMPLETED)
                _drain(messages.messages, by_name, sink, started)
                if _stopped(stop):
                    messages.stopping.set()  # the tasks already queued to workers
                    for future in pending:
                        future.cancel()  # those not yet under way
                    _end_runs(started, signalled)
                for future in done:
                    job = futures[future]
                    if future.cancelled():
                        outcomes.append(_tell(sink, not_run(job)))
                    elif (exc := future.exception()) is not None:
                        lost.append((job, exc))
                    else:
                        outcomes.append(_tell(sink, future.result()))
        _drain(messages.messages, by_name, sink, started)
        return outcomes, lost


def _stopped(stop: Interrupts | None) -> bool:
    """A signal has asked the batch to stop."""
    return stop is not None and stop.received is not None


def _end_runs(started: dict[str, int], signalled: set[str]) -> None:
    """SIGINT to the worker of each run under way not yet told: it ends at its tick."""
    for name, pid in started.items():
        if name not in signalled:
            signalled.add(name)
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGINT)


def _tell(sink: ProgressSink | None, outcome: RunOutcome) -> RunOutcome:
    """Report a finished outcome to the sink; the outcome."""
    if sink is not None:
        sink.finished(outcome)
    return outcome


def _drain(messages: Any, jobs: dict[str, RunJob], sink: ProgressSink | None,
           started: dict[str, int]) -> None:
    """Pass the queued messages on to the sink: a (job name, worker process id) is a start
    (also noted in `started`), a `Progress` an advance."""
    while True:
        try:
            message = messages.get_nowait()
        except queue.Empty:
            return
        if isinstance(message, Progress):
            if sink is not None:
                sink.advanced(message)
            continue
        name, pid = message
        started[name] = pid
        if sink is not None:
            sink.started(jobs[name])


# ---- Ray -----------------------------------------------------------------------------------


def _ray_task(job: RunJob) -> tuple[RunOutcome, dict[str, bytes]]:
    """A Ray task: run the job in a scratch folder, return the outcome and its files."""
    with tempfile.TemporaryDirectory(prefix="avsim-") as scratch:
        outcome = run_job(job, into=Path(scratch))
        files = {p.name: p.read_bytes() for p in Path(scratch).iterdir()
                 if p.is_file() and not p.name.startswith(".")}
    return outcome, files


@dataclass
class RayExecutor:
    """Ray tasks on a cluster, or on a local Ray instance (module doc)."""

    address: str | None = None  # a cluster ("ray://host:10001", "auto"); None: RAY_ADDRESS
    #   or else a local instance started for this batch
    jobs: int | None = None  # CPUs of the local instance (None: all of this machine's)
    name: str = "ray"

    def run(self, jobs: Sequence[RunJob], sink: ProgressSink | None = None,
            stop: Interrupts | None = None) -> list[RunOutcome]:
        """Run every job as a Ray task (starting and stopping Ray if it is not running);
        outcomes in job order. Once `stop` has caught a signal the tasks not finished are
        cancelled (`not_run`; a task's files come back only when it finishes)."""
        ray = _import_ray()
        address = self.address or os.environ.get("RAY_ADDRESS") or None
        started_here = not ray.is_initialized()
        if started_here:
            _ray_init(ray, address, self.jobs)
        try:
            return self._run(ray, jobs, sink, stop)
        finally:
            if started_here:
                ray.shutdown()

    def _run(self, ray: Any, jobs: Sequence[RunJob], sink: ProgressSink | None,
             stop: Interrupts | None) -> list[RunOutcome]:
        """Submit every task, longest first; write each one's files here as it returns."""
        task = ray.remote(num_cpus=1, max_retries=0)(_ray_task)
        order = longest_first(jobs)
        refs = {task.remote(job): job for job in order}
        if sink is not None:
            for job in order:
                sink.started(job)
        outcomes: list[RunOutcome] = []
        pending = list(refs)
        cancelled = False
        while pending:
            if _stopped(stop) and not cancelled:
                cancelled = True
                for ref in pending:
                    ray.cancel(ref, force=True)
            done, pending = ray.wait(pending, num_returns=1, timeout=POLL)
            if not done:
                continue
            job = refs[done[0]]
            try:
                outcome, files = ray.get(done[0])
            except ray.exceptions.TaskCancelledError:
                outcome, files = not_run(job), {}
            except ray.exceptions.RayError as exc:  # the task's worker or node died
                outcome, files = (not_run(job) if cancelled else died(job, exc)), {}
            _write_files(job.out_dir, files)
            outcomes.append(_tell(sink, outcome))
        return _in_job_order(jobs, outcomes)


def _import_ray() -> Any:
    """The `ray` module, or an `ExecutorError` saying how to install it."""
    try:
        import ray
    except ImportError:
        raise ExecutorError(f"--executor ray: Ray is not installed ({RAY_EXTRA})") from None
    return ray


def _ray_init(ray: Any, address: str | None, cpus: int | None) -> None:
    """Connect to the cluster at `address`, or start a local instance of `cpus` CPUs."""
    # the workers import avsim from wherever this process does (an editable install or a
    # checkout on the cluster's nodes); they do not need the driver's working directory
    options: dict[str, Any] = {"include_dashboard": False, "log_to_driver": False,
                               "configure_logging": False}
    if address is None and cpus is not None:
        options["num_cpus"] = cpus
    try:
        ray.init(address=address, **options)
    except (ConnectionError, RuntimeError, ValueError) as exc:
        where = address or "a local instance"
        raise ExecutorError(f"--executor ray: cannot connect to {where}: {exc}") from None


def _write_files(out_dir: Path, files: dict[str, bytes]) -> None:
    """Write a task's returned files (name -> bytes) into `out_dir`, each whole."""
    for name, data in files.items():
        write_atomic(out_dir / name, data)

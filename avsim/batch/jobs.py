"""One run of a suite or a sweep: what to run (`RunJob`) and what came of it (`RunOutcome`).

A job is plain data, so that it pickles to a worker process or a Ray task; `run_job` is the
worker's whole work: load the scenario with the job's overrides, run it headless, write its
recording, result JSON and speed-profile plot into the job's folder, and return the
outcome. A job never raises: bad input and crashes come back as outcomes with a one-line
`error`, so that one bad run cannot take a suite down.
"""

from __future__ import annotations

import math
import time
import traceback
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from enum import Enum
from pathlib import Path
from typing import TYPE_CHECKING

from avsim.files import publish, temporary_beside, write_atomic
from avsim.run.verdict import RunError, RunVerdict
from avsim.scenario.load import ScenarioError, load_scenario
from avsim.scenario.profile_fit import check_profile

if TYPE_CHECKING:
    from avsim.run.interrupts import Interrupts
    from avsim.scenario.scenario import Scenario


KEY_SUFFIX = ".key"  # a campaign run's key file, beside its result JSON (`resume_key`)
STACK, SCRIPTED = "stack", "scripted"  # what drives the car under test (`RunJob.ego`)
EGO_MODES = (STACK, SCRIPTED)
NO_SENSORS = "none"  # the profile of a scripted car under test: it reads no sensors


def ego_profile(ego: str, profile: str) -> str:
    """The sensor profile a run of `ego` has: `NO_SENSORS` when the file's actions move the
    car under test (`SCRIPTED`), else `profile`."""
    return NO_SENSORS if ego == SCRIPTED else profile


class Status(Enum):
    """How a run ended, as the CLI's exit status says it."""

    PASSED = "passed"  # every criterion passed (exit 0)
    FAILED = "failed"  # a criterion failed (exit 1)
    BAD_INPUT = "bad_input"  # the scenario or an override is invalid (exit 2)
    ERROR = "error"  # the run ended in error (exit 3): an exception in a stage (its result
    #   judged so far, the error line `avsim.run.verdict.RunError.line`), or the run could
    #   not start or its worker died (no result: the exception's last line)
    INTERRUPTED = "interrupted"  # the batch was interrupted (SIGINT / SIGTERM): the run
    #   ended at its tick, its result judged so far, or it never started (no result)


@dataclass(frozen=True, slots=True)
class RunJob:
    """A scenario to run, with its key overrides, into its own folder."""

    name: str  # unique within the batch: [a-z0-9_]+ (the scenario's name, + sweep values)
    scenario: str  # a file path or a bundled scenario's name, as the user gave it
    out_dir: Path  # the run writes <out_dir>/<name>.rrd, .json, .png here
    overrides: Mapping[str, object] = field(default_factory=dict)  # dotted key -> value
    profile: str = "default"  # sensor profile: fast | default | paper | none
    sensing: str = "inline"  # cameras render in this process (workers run in parallel)
    plot: bool = True  # also write the speed-profile PNG
    duration: float = 0.0  # [s] the scenario's simulated time: its cost, longest run first
    search_paths: tuple[Path, ...] = ()  # folders an OpenSCENARIO file's references may be in
    criteria: Path | None = None  # an OpenSCENARIO file's sidecar (`--criteria`), else None
    resume_key: str | None = None  # a campaign run's key (`avsim.batch.resume.run_key`),
    #   written to <out_dir>/<name>.key once its result JSON is (None: no key file)
    ego: str = STACK  # what drives the car under test: avsim's stack, or (`SCRIPTED`, an
    #   OpenSCENARIO file) the file's own actions, no sensors (`EgoSpec.scripted`)
    stack_code: str = ""  # a digest of the code of the user's stack or stages that drive it
    #   ("" for the bundled stack: `avsim.stack.choice.code_digest`)

    @property
    def scripted(self) -> bool:
        """Whether the file's own actions move the car under test (`ego` is `SCRIPTED`)."""
        return self.ego == SCRIPTED

    @property
    def recording(self) -> Path:
        """The run's `.rrd`."""
        return self.out_dir / f"{self.name}.rrd"

    @property
    def result_file(self) -> Path:
        """The run's result JSON."""
        return self.out_dir / f"{self.name}.json"

    @property
    def key_file(self) -> Path:
        """The run's key (`resume_key`), beside its result JSON."""
        return self.out_dir / f"{self.name}{KEY_SUFFIX}"

    @property
    def plot_file(self) -> Path:
        """The run's speed-profile PNG."""
        return self.out_dir / f"{self.name}.png"


@dataclass(frozen=True, slots=True)
class RunOutcome:
    """What one job gave. `result` is the run's result JSON (`avsim.run.result.result_json`)."""

    job: RunJob
    status: Status
    result: dict[str, object] | None = None  # None when the run did not finish
    error: str | None = None  # one line, for BAD_INPUT and ERROR
    wall_time: float = 0.0  # [s] the job's whole time in its worker, loading included

    @property
    def passed(self) -> bool:
        """Whether every criterion passed."""
        return self.status is Status.PASSED

    @property
    def sim_time(self) -> float:
        """[s] simulated (0 when the run did not finish)."""
        return self._number("sim_time")

    @property
    def run_time(self) -> float:
        """[s] the simulation's own wall time (the result's; `wall_time` adds loading)."""
        return self._number("wall_time")

    def _number(self, key: str) -> float:
        """The result's number at `key`, 0 when absent."""
        value = None if self.result is None else self.result.get(key)
        return float(value) if isinstance(value, (int, float)) else 0.0

    def criteria(self) -> list[dict[str, object]]:
        """The result's criteria (name, passed, value, threshold, unit, first_failure?)."""
        if self.result is None:
            return []
        criteria = self.result["criteria"]
        assert isinstance(criteria, list)
        return criteria

    def metric(self, name: str) -> float:
        """A metric of the result, or a criterion's value by its name; NaN if absent."""
        if self.result is None:
            return math.nan
        metrics = self.result["metrics"]
        assert isinstance(metrics, dict)
        value = metrics.get(name)
        if value is None:
            value = next((c["value"] for c in self.criteria() if c["name"] == name), None)
        return float(value) if isinstance(value, (int, float)) else math.nan

    def first_failure(self) -> float | None:
        """[s] the earliest time a criterion failed, if one did and said when."""
        times = [float(t) for c in self.criteria()
                 if c["passed"] is False and isinstance(t := c.get("first_failure"), (int, float))]
        return min(times) if times else None

    def failure_time(self) -> float | None:
        """[s] the moment to look at a failed run: its first failure, or its end when the
        failed criteria are judged at the end (`completes`); None if it did not fail."""
        if self.status is not Status.FAILED or self.result is None:
            return None
        first = self.first_failure()
        return first if first is not None else self.sim_time


ProgressCallback = Callable[[float, float], None]  # (sim time, duration) [s]
VERDICT_STATUS = {  # a result's verdict (`avsim.run.verdict`) -> the run's status
    RunVerdict.PASS.value: Status.PASSED, RunVerdict.FAIL.value: Status.FAILED,
    RunVerdict.ERROR.value: Status.ERROR, RunVerdict.INTERRUPTED.value: Status.INTERRUPTED,
}


def not_run(job: RunJob) -> RunOutcome:
    """The outcome of a job the batch's interruption kept from starting."""
    return RunOutcome(job, Status.INTERRUPTED,
                      error=f"{job.name}: not run (the batch was interrupted)")


def run_job(job: RunJob, into: Path | None = None,
            progress: ProgressCallback | None = None,
            interrupts: Interrupts | None = None) -> RunOutcome:
    """Run one job in this process (the worker's entry point); never raises.

    The files go to `into` when given (a worker's scratch folder on a cluster node, whose
    files the caller moves to ``job.out_dir``), else to ``job.out_dir``; the result names
    the job's own paths either way. `progress` is called as the simulation advances; a
    signal caught by `interrupts` ends the run at its tick (`Status.INTERRUPTED`, its files
    written)."""
    start = time.perf_counter()
    try:
        scenario = load_scenario(job.scenario, dict(job.overrides), job.criteria,
                                 search_paths=job.search_paths, scripted_ego=job.scripted)
        check_profile(scenario, job.profile, job.scenario)
    except ScenarioError as exc:
        return RunOutcome(job, Status.BAD_INPUT, error=str(exc),
                          wall_time=time.perf_counter() - start)
    try:
        result = _simulate(job, scenario, into or job.out_dir, progress, interrupts)
    except Exception as exc:  # a crash is this run's outcome, not the batch's
        last = traceback.format_exception_only(exc)[-1].strip()
        return RunOutcome(job, Status.ERROR, error=f"{job.name}: {last}",
                          wall_time=time.perf_counter() - start)
    if job.resume_key is not None:  # after the result: a run cut off before has no key
        write_atomic((into or job.out_dir) / job.key_file.name, job.resume_key.encode())
    return outcome_of(job, result, time.perf_counter() - start)


def outcome_of(job: RunJob, result: dict[str, object], wall_time: float) -> RunOutcome:
    """The outcome of `job` whose run gave `result` (its result JSON) in `wall_time` [s]."""
    status = VERDICT_STATUS[str(result["verdict"])]
    error = None
    if isinstance(fault := result.get("error"), dict):
        error = f"{job.name}: {RunError(**fault).line()}"
    return RunOutcome(job, status, result, error, wall_time=wall_time)


def _simulate(job: RunJob, scenario: Scenario, into: Path, progress: ProgressCallback | None,
              interrupts: Interrupts | None) -> dict[str, object]:
    """Run the loaded scenario into `into`: the recording (renamed whole at the end), the
    result JSON and the plot; returns the result JSON."""
    from world.core.quiet import quiet_c_output

    with quiet_c_output():  # PyBullet's build banner
        from avsim.report.speed_plot import plot_speed_profile
        from avsim.run.result import dumps, result_json
        from avsim.run.runner import RunResult
        from avsim.run.unbuilt import build_runner
        from world.sensors.setup import Profile

    recording = into / job.recording.name
    partial = temporary_beside(recording)  # created exclusively, an unpredictable name
    try:
        profile = None if job.profile == "none" else Profile(job.profile)
        built = build_runner(scenario, partial, profile, job.sensing)
        if isinstance(built, RunResult):  # the world could not be built: its result
            result = built
        else:
            if interrupts is not None:
                interrupts.on_signal(built.interrupt)
            result = built.run(progress)
        publish(partial, recording)
    finally:
        partial.unlink(missing_ok=True)
    payload = result_json(result, job.scenario, job.recording, job.profile)
    write_atomic(into / job.result_file.name, dumps(payload))
    if job.plot and not isinstance(built, RunResult):  # a run that never started: nothing to plot
        plot_speed_profile(result, into / job.plot_file.name)
    return payload

"""A run that ends in error is that run's outcome, not the batch's: the other runs go on,
the reports show it as an error (JUnit `<error>` with the traceback, beside its criteria
judged so far; the summary's error line) and the batch exits 3 (`exit_status`, whose order
is: the batch's signal, error, bad input, failed, passed)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
from junitparser import Error, JUnitXml

from avsim.batch import suite as batch
from avsim.batch.executors import Channel, LocalExecutor, _local_task
from avsim.batch.jobs import RunJob, RunOutcome, Status, run_job
from avsim.report.suite import summary_table

HERE = Path(__file__).parents[1]
FOLLOW = HERE / "batch_scenarios" / "follow.yaml"
RERUN = Path(sys.executable).parent / "rerun"
BUG = "heading error 2.856 rad: the car does not head along the lane"


def _planner_bug_in_broken(job: RunJob, channel: Channel) -> RunOutcome:
    """A worker's task: the real one, with the planner raising on its 30th update in the
    run named `broken`."""
    if job.name == "broken":
        from planner.planner import Planner

        update, calls = Planner.update, [0]

        def failing(self: Planner, *args: object) -> object:
            calls[0] += 1
            if calls[0] == 30:
                raise ValueError(BUG)
            return update(self, *args)  # type: ignore[arg-type]

        Planner.update = failing  # type: ignore[assignment,method-assign]
    return _local_task(job, channel)


def test_a_suite_goes_on_past_a_run_that_ends_in_error(tmp_path: Path) -> None:
    jobs = [RunJob(name, str(FOLLOW), tmp_path, {"duration": 2.0}, "none", duration=2.0)
            for name in ("broken", "fine")]
    outcomes = LocalExecutor(1, task=_planner_bug_in_broken).run(jobs)
    broken, fine = outcomes
    assert (broken.status, fine.status) == (Status.ERROR, Status.FAILED)  # fine: 2 s is
    #   too short to complete, so it fails on its own
    assert broken.result is not None and broken.result["verdict"] == "error"
    assert broken.error is not None and "\n" not in broken.error
    assert broken.error.startswith("broken: run ended in error at t = ")
    assert broken.error.endswith(f"ValueError: {BUG}")
    assert fine.result is not None and fine.result["verdict"] == "fail"
    assert batch.exit_status(outcomes) == 3

    batch.write_reports(outcomes, tmp_path, "errors", {})
    xml = JUnitXml.fromfile(str(tmp_path / "junit.xml"))
    suites = {s.name: s for s in xml}
    assert (suites["broken"].errors, suites["fine"].errors) == (1, 0)
    run_case = next(c for c in suites["broken"] if c.name == "run")
    error = run_case.result[0]
    assert isinstance(error, Error) and error.message == broken.error
    assert error.text is not None and "Traceback (most recent call last)" in error.text
    assert len(list(suites["broken"])) == len(broken.criteria()) + 1  # judged so far, kept
    summary = (tmp_path / "summary.md").read_text(encoding="utf-8")
    assert "## broken: ERROR" in summary and "run ended in error at t =" in summary
    assert "1 failed, 1 errors" in summary
    runs = json.loads((tmp_path / "results.json").read_text(encoding="utf-8"))
    assert [r["status"] for r in runs] == ["error", "failed"]
    assert summary_table(outcomes).title == "0 passed, 1 failed, 1 errors"


def outcome(status: Status) -> RunOutcome:
    return RunOutcome(RunJob(status.value, "x.yaml", Path("out")), status)


def test_the_batch_status_follows_its_order() -> None:
    def of(*statuses: Status, signalled: int | None = None) -> int:
        return batch.exit_status([outcome(s) for s in statuses], signalled)

    assert of(Status.PASSED, Status.PASSED) == 0
    assert of(Status.PASSED, Status.FAILED) == 1
    assert of(Status.FAILED, Status.BAD_INPUT) == 2
    assert of(Status.FAILED, Status.BAD_INPUT, Status.ERROR) == 3
    assert of(Status.ERROR, Status.INTERRUPTED, signalled=143) == 143
    assert of(Status.PASSED, Status.INTERRUPTED, signalled=130) == 130
    assert of(Status.PASSED, Status.FAILED, signalled=130) == 1  # every run had finished
    assert of(Status.PASSED, Status.INTERRUPTED) == 3  # only its worker got a signal


def test_a_run_whose_world_cannot_be_built_ends_in_error_with_its_files(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The worker (`run_job`): verdict error at 0 s, the traceback in the result, a valid
    recording, no criterion judged; the batch's outcome is that run's error."""
    from world.world import World

    def broken(*_args: object, **_kwargs: object) -> None:
        raise RuntimeError("the world cannot be built")

    monkeypatch.setattr(World, "__init__", broken)
    job = RunJob("unbuilt", str(FOLLOW), tmp_path, {"duration": 2.0}, "none", duration=2.0)
    outcome = run_job(job)
    assert outcome.status is Status.ERROR
    assert outcome.error == ("unbuilt: run ended in error at t = 0.000 s: RuntimeError: the "
                             "world cannot be built")
    result = json.loads(job.result_file.read_text(encoding="utf-8"))
    assert result == outcome.result
    assert (result["verdict"], result["sim_time"], result["criteria"]) == ("error", 0.0, [])
    assert "Traceback (most recent call last)" in result["error"]["traceback"]
    check = subprocess.run([str(RERUN), "rrd", "verify", str(job.recording)],
                           capture_output=True, text=True, check=False)
    assert check.returncode == 0, check.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["unbuilt.json", "unbuilt.rrd"]

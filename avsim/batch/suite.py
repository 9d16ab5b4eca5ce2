"""A batch of runs (`avsim suite`, `avsim sweep`): which jobs, run where, what is written.

1. The jobs are built and every scenario is loaded with its overrides before anything runs:
   a bad file or value stops the batch with its one-line message (exit 2), nothing written.
2. An executor (`avsim.batch.executors`) runs them, while a live display shows the batch and
   each run's simulated time.
3. The reports go into the batch's folder beside the runs' own files: ``junit.xml``,
   ``summary.md`` (with a snapshot of each failed run at its first failing moment, or at
   its end when it failed only there, in ``snapshots/``) and ``results.json`` (every run's
   result, in job order).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from rich.console import Console
from rich.progress import BarColumn, TaskID, TextColumn, TimeElapsedColumn
from rich.progress import Progress as RichProgress

from avsim.batch.executors import Executor, Progress
from avsim.batch.jobs import RunJob, RunOutcome, Status
from avsim.files import write_atomic
from avsim.run.interrupts import Interrupts
from avsim.run.result import dumps
from avsim.scenario.load import bundled_scenarios, load_scenario
from avsim.scenario.model import grid_paths
from avsim.scenario.openscenario.sidecar import SUFFIX as SIDECAR_SUFFIX
from avsim.scenario.profile_fit import check_profile

SNAPSHOT_DIR = "snapshots"  # the failed runs' pictures, below the batch's folder


class BatchError(ValueError):
    """A batch that cannot start (bad input, exit status 2): the message is one line."""


def collect_scenarios(args: Sequence[str]) -> list[str]:
    """The scenarios a suite runs: each argument a file, a folder (its ``*.yaml`` and
    ``*.xosc`` files, sorted; OpenSCENARIO catalogs are not scenarios and are left out) or a
    bundled scenario's name; none: every bundled scenario."""
    if not args:
        return [str(p) for p in bundled_scenarios()]
    found: list[str] = []
    for arg in args:
        path = Path(arg)
        if path.is_dir():
            files = sorted(p for p in path.iterdir()
                           if p.suffix in {".yaml", ".yml", ".xosc"}
                           and not p.name.endswith(SIDECAR_SUFFIX))
            if not files:
                raise BatchError(f"{arg}: no scenario files (*.yaml, *.xosc) in this folder")
            found += [str(p) for p in files]
        else:
            found.append(arg)  # a file or a bundled name: load_scenario says if neither
    return found


def suite_entries(scenarios: Sequence[str], search_paths: Sequence[Path] = (),
                  ) -> list[tuple[str | None, str, dict[str, object]]]:
    """The runs of a suite over `scenarios` (`plan`'s entries): one per scenario, or one per
    point of its file's `grid` (named ``<name>_<k:03d>``, as a sweep names its runs);
    `search_paths` as `load_scenario` takes them."""
    from avsim.batch.sweep import Axis, grid

    entries: list[tuple[str | None, str, dict[str, object]]] = []
    for scenario in scenarios:
        loaded = load_scenario(scenario, search_paths=search_paths)
        if not loaded.grid:
            entries.append((None, scenario, {}))
            continue
        points = grid([Axis(key, values) for key, values in loaded.grid])
        entries += [(f"{loaded.name}_{k:03d}", scenario, overrides_of(point))
                    for k, point in enumerate(points)]
    return entries


def overrides_of(point: Mapping[str, object]) -> dict[str, object]:
    """A grid point's overrides: a key of several comma-joined paths gives each its item."""
    overrides: dict[str, object] = {}
    for key, value in point.items():
        paths = grid_paths(key)
        if len(paths) == 1:
            overrides[key] = value
        else:
            assert isinstance(value, list)  # the model checked it: one item per path
            overrides.update(zip(paths, value, strict=True))
    return overrides


def plan(entries: Sequence[tuple[str | None, str, Mapping[str, object]]], out_dir: Path,
         profile: str, search_paths: Sequence[Path] = ()) -> list[RunJob]:
    """Validate each (job name or None for the scenario's own, scenario, overrides) and make
    its job, which carries `search_paths` to its worker. Raises `ScenarioError` for the
    first bad one, `BatchError` for two runs that would write the same files."""
    planned: list[RunJob] = []
    names: dict[str, str] = {}
    for name, scenario, overrides in entries:
        loaded = load_scenario(scenario, dict(overrides), search_paths=search_paths)
        check_profile(loaded, profile, scenario)
        job_name = name or loaded.name
        if job_name in names:
            raise BatchError(f"{scenario}: name: {job_name!r} is also the name of "
                             f"{names[job_name]} (their files would collide in {out_dir})")
        names[job_name] = scenario
        planned.append(RunJob(job_name, scenario, out_dir, dict(overrides), profile,
                              duration=loaded.duration, search_paths=tuple(search_paths)))
    return planned


def validate_out_dir(out_dir: Path) -> None:
    """`BatchError` unless `out_dir` is a folder or can be made: its nearest existing
    ancestor is a directory."""
    if out_dir.exists() and not out_dir.is_dir():
        raise BatchError(f"{out_dir}: --out: not a directory")
    for ancestor in out_dir.absolute().parents:
        if ancestor.exists():
            if not ancestor.is_dir():
                raise BatchError(f"{out_dir}: --out: {ancestor} is not a directory")
            return


# ---- the live display ----------------------------------------------------------------------


@dataclass
class LiveDisplay:
    """A bar for the batch and one per run under way (rich), on stderr."""

    total: int  # runs in the batch
    console: Console = field(default_factory=lambda: Console(stderr=True))
    _bar: RichProgress | None = None  # None off a terminal: one line per finished run only
    _batch: TaskID | None = None
    _runs: dict[str, TaskID] = field(default_factory=dict)  # job name -> its bar
    _failed: int = 0  # runs finished without passing

    def __enter__(self) -> LiveDisplay:
        if self.console.is_terminal:
            columns = (TextColumn("[bold]{task.description}"), BarColumn(),
                       TextColumn("{task.fields[detail]}"), TimeElapsedColumn())
            self._bar = RichProgress(*columns, console=self.console)
            self._bar.start()
            self._batch = self._bar.add_task("batch", total=self.total, detail="")
        return self

    def __exit__(self, *exc: object) -> None:
        if self._bar is not None:
            self._bar.stop()

    def started(self, job: RunJob) -> None:
        """A bar for the run."""
        if self._bar is not None:
            self._runs[job.name] = self._bar.add_task(job.name, total=None, detail="starting")

    def advanced(self, progress: Progress) -> None:
        """The run's bar to its simulated time."""
        task = self._runs.get(progress.name)
        if self._bar is not None and task is not None:
            self._bar.update(task, completed=progress.sim_time, total=progress.duration,
                             detail=f"{progress.sim_time:.0f}/{progress.duration:.0f} s sim")

    def finished(self, outcome: RunOutcome) -> None:
        """The run's verdict as a line; its bar goes, the batch's advances."""
        self._failed += not outcome.passed
        verdict = outcome.status.value.upper() if not outcome.passed else "pass"
        line = f"{outcome.job.name}: {verdict}"
        if outcome.error:
            line += f" ({outcome.error})"
        if self._bar is None:
            self.console.print(line, highlight=False)
            return
        task = self._runs.pop(outcome.job.name, None)
        if task is not None:
            self._bar.remove_task(task)
        self._bar.console.print(line, highlight=False)
        assert self._batch is not None
        self._bar.update(self._batch, advance=1, detail=f"{self._failed} not passed")


def execute(jobs: Sequence[RunJob], executor: Executor,
            stop: Interrupts | None = None) -> list[RunOutcome]:
    """Run the jobs (longest first) with the live display; outcomes in job order (`stop`:
    see `Executor.run`)."""
    with LiveDisplay(len(jobs)) as display:
        return executor.run(jobs, display, stop)


# ---- reports -------------------------------------------------------------------------------


def snapshots_of_failures(outcomes: Sequence[RunOutcome], out_dir: Path,
                          console: Console) -> dict[str, Path]:
    """A PNG of each failed run's recording at `RunOutcome.failure_time` (job name -> PNG).
    A snapshot that cannot be made is reported in one line and left out."""
    from avsim.record.snapshot import SnapshotError, render_snapshot

    pictures: dict[str, Path] = {}
    for outcome in outcomes:
        t = outcome.failure_time()
        if t is None:
            continue
        png = out_dir / SNAPSHOT_DIR / f"{outcome.job.name}.png"
        try:
            render_snapshot(outcome.job.recording, t, png)
        except SnapshotError as exc:
            console.print(f"snapshot of {outcome.job.name} at {t:.2f} s: {exc}", highlight=False)
            continue
        pictures[outcome.job.name] = png
    return pictures


def write_reports(outcomes: Sequence[RunOutcome], out_dir: Path, title: str,
                  snapshots: Mapping[str, Path]) -> None:
    """``junit.xml``, ``summary.md`` and ``results.json`` in `out_dir`."""
    from avsim.report.suite import junit_xml, summary_markdown

    write_atomic(out_dir / "junit.xml", junit_xml(outcomes, title))
    write_atomic(out_dir / "summary.md",
                 summary_markdown(outcomes, title=title, out_dir=out_dir, snapshots=snapshots))
    write_atomic(out_dir / "results.json", dumps(results_json(outcomes)))


def results_json(outcomes: Sequence[RunOutcome]) -> list[dict[str, object]]:
    """Every run of the batch: its name, overrides, status, error and result."""
    return [{"name": o.job.name, "scenario": o.job.scenario,
             "overrides": dict(o.job.overrides), "status": o.status.value, "error": o.error,
             "result": o.result} for o in outcomes]


def comparable(outcome: RunOutcome) -> dict[str, object]:
    """What must not depend on the executor or the number of workers: the verdicts, the
    criteria and the metrics (not the wall time)."""
    result = outcome.result or {}
    same = {
        "name": outcome.job.name, "status": outcome.status.value, "error": outcome.error,
        "criteria": result.get("criteria"), "metrics": result.get("metrics"),
        "sim_time": result.get("sim_time"), "state_changes": result.get("state_changes"),
    }
    return {k: _canonical(v) for k, v in same.items()}


def _canonical(value: object) -> object:
    """`value` with non-finite numbers as their names (NaN is never equal to itself)."""
    if isinstance(value, float) and not math.isfinite(value):
        return repr(value)
    if isinstance(value, dict):
        return {k: _canonical(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_canonical(v) for v in value]
    return value


def exit_status(outcomes: Sequence[RunOutcome], signalled: int | None = None) -> int:
    """The batch's exit status (the CLI's statuses, `avsim.cli`), the first that applies:
    `signalled` (128 + the number of the signal the batch caught: 130, 143) when a run
    was interrupted or never started for it; 3 when a run ended in error (or was
    interrupted by a signal only its worker got); 2 when a run had bad input; 1 when one
    failed; else 0. A signal caught after every run had finished changes nothing."""
    statuses = {o.status for o in outcomes}
    if Status.INTERRUPTED in statuses and signalled is not None:
        return signalled
    if statuses & {Status.ERROR, Status.INTERRUPTED}:
        return 3
    if Status.BAD_INPUT in statuses:
        return 2
    return 0 if statuses <= {Status.PASSED} else 1


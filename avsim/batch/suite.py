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

import json
import math
import shlex
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
from avsim.scenario.load import ScenarioError, bundled_scenarios, load_scenario, scenario_path
from avsim.scenario.model import grid_paths
from avsim.scenario.openscenario.sidecar import SUFFIX as SIDECAR_SUFFIX
from avsim.scenario.profile_fit import check_profile

OVERRIDES_FILE = "(overrides)"  # the file a sidecar's override problem names
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


def suite_entries(scenarios: Sequence[str], overrides: Mapping[str, object] | None = None,
                  ) -> list[tuple[str | None, str, dict[str, object]]]:
    """The runs of a suite over `scenarios` (`plan`'s entries): one per scenario, or one per
    point of its file's `grid` (named ``<name>_<k:03d>``, as a sweep names its runs), each
    with `overrides` (`--set`, `--param`) besides its point. A key both set and swept by the
    file's grid is a `BatchError`: the grid's points would all be the same run."""
    from avsim.batch.sweep import Axis, grid

    given = dict(overrides or {})
    entries: list[tuple[str | None, str, dict[str, object]]] = []
    for scenario in scenarios:
        loaded = load_scenario(scenario)
        if not loaded.grid:
            entries.append((None, scenario, dict(given)))
            continue
        swept = {path for key, _ in loaded.grid for path in grid_paths(key)}
        both = sorted(swept & set(given))
        if both:
            raise BatchError(f"{scenario}: {both[0]}: the file's grid sweeps this key "
                             "(--set would make its points one run)")
        points = grid([Axis(key, values) for key, values in loaded.grid])
        entries += [(f"{loaded.name}_{k:03d}", scenario, given | overrides_of(point))
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
         profile: str, criteria: Path | None = None) -> list[RunJob]:
    """Validate each (job name or None for the scenario's own, scenario, overrides) and make
    its job; `criteria` is the sidecar of the OpenSCENARIO files among them (`--criteria`).
    Raises `ScenarioError` (naming the scenario) for the first bad one, `BatchError` for two
    runs that would write the same files."""
    planned: list[RunJob] = []
    names: dict[str, str] = {}
    for name, scenario, overrides in entries:
        sidecar = criteria if scenario_path(scenario).suffix == ".xosc" else None
        try:
            loaded = load_scenario(scenario, dict(overrides), sidecar)
        except ScenarioError as exc:  # a sidecar's override problem names no file
            if exc.file != OVERRIDES_FILE:
                raise
            raise ScenarioError(scenario, exc.key, exc.problem) from None
        check_profile(loaded, profile, scenario)
        job_name = name or loaded.name
        if job_name in names:
            raise BatchError(f"{scenario}: name: {job_name!r} is also the name of "
                             f"{names[job_name]} (their files would collide in {out_dir})")
        names[job_name] = scenario
        planned.append(RunJob(job_name, scenario, out_dir, dict(overrides), profile,
                              duration=loaded.duration, criteria=sidecar))
    return planned


def run_command(job: RunJob) -> str:
    """The `avsim run` command line that makes `job`'s run (`--dry-run` prints them): its
    scenario, overrides as `--set PATH=VALUE` (JSON, which YAML reads the same), sidecar,
    profile and files, quoted for a POSIX shell."""
    words = ["avsim", "run", job.scenario]
    for key, value in job.overrides.items():
        words += ["--set", f"{key}={json.dumps(value)}"]
    if job.criteria is not None:
        words += ["--criteria", str(job.criteria)]
    words += ["--profile", job.profile, "--out", str(job.recording)]
    return shlex.join(words)


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


def exit_status(outcomes: Sequence[RunOutcome]) -> int:
    """0 all passed; 2 when a run had bad input; else 1 when any failed or crashed."""
    if any(o.status is Status.BAD_INPUT for o in outcomes):
        return 2
    return 0 if all(o.passed for o in outcomes) else 1


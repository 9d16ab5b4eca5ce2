"""A batch of runs (`avsim suite`, `avsim sweep`): which jobs, run where, what is written.

1. The jobs are built and every scenario is loaded with its overrides before anything runs:
   a bad file or value stops the batch with its one-line message (exit 2), nothing written.
2. An executor (`avsim.batch.executors`) runs them, while a live display shows the batch and
   each run's simulated time.
3. The reports go into the batch's folder beside the runs' own files: ``junit.xml``,
   ``summary.md`` (with a snapshot of each failed run at its first failing moment, or at
   its end when it failed only there, in ``snapshots/``) and ``results.json`` (every run's
   result, in job order). A run's name is never a report's (`REPORT_NAMES`), and no run's
   file is an input of the batch: both are refused in step 1.
"""

from __future__ import annotations

import json
import math
import shlex
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from rich.console import Console
from rich.progress import BarColumn, TaskID, TextColumn, TimeElapsedColumn
from rich.progress import Progress as RichProgress

from avsim.batch.executors import Executor, Progress
from avsim.batch.jobs import SCRIPTED, STACK, RunJob, RunOutcome, Status, ego_profile
from avsim.files import write_atomic
from avsim.outputs import (
    Output,
    OutputError,
    check_outputs,
    identity,
    keep_result,
    same_file,
)
from avsim.run.interrupts import Interrupts
from avsim.run.result import dumps
from avsim.scenario.load import ScenarioError, bundled_scenarios, load_scenario, scenario_path
from avsim.scenario.model import grid_paths
from avsim.scenario.openscenario.sidecar import SUFFIX as SIDECAR_SUFFIX
from avsim.scenario.profile_fit import check_profile
from avsim.stack.choice import code_digest

OVERRIDES_FILE = "(overrides)"  # the file a sidecar's override problem names
SNAPSHOT_DIR = "snapshots"  # the failed runs' pictures, below the batch's folder
JUNIT, SUMMARY, RESULTS = "junit.xml", "summary.md", "results.json"  # every batch's reports
SWEEP_CSV, SWEEP_MD, HEAT_MAP = "sweep.csv", "sweep.md", "heatmap.png"  # a sweep's reports
REPORT_NAMES = frozenset(Path(f).stem for f in (JUNIT, SUMMARY, RESULTS, SWEEP_CSV, SWEEP_MD,
                                                HEAT_MAP, SNAPSHOT_DIR))  # no run's name
#   (a run writes NAME.rrd, NAME.json, NAME.png beside the reports: `results` and `heatmap`
#   would be overwritten by a report, the others are refused too so that one rule holds)


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
                  search_paths: Sequence[Path] = (), ego: str = STACK,
                  ) -> list[tuple[str | None, str, dict[str, object]]]:
    """The runs of a suite over `scenarios` (`plan`'s entries): one per scenario, one per
    point of its file's `grid` (named ``<name>_<k:03d>``, as a sweep names its runs), or one
    per concrete run of an OpenSCENARIO distribution file (`avsim.batch.distributions`), each
    with `overrides` (`--set`, `--param`) besides its point; `search_paths` as
    `load_scenario` takes them, each file loaded for `ego` (`RunJob.ego`). A key both set
    and swept by the file's grid is a `BatchError`: the grid's points would all be the
    same run."""
    from avsim.batch.distributions import (
        DistributionError,
        distribution_entries,
        is_distribution_file,
    )
    from avsim.batch.sweep import Axis, grid

    given = dict(overrides or {})
    entries: list[tuple[str | None, str, dict[str, object]]] = []
    for scenario in scenarios:
        if is_distribution_file(scenario):
            try:
                entries += distribution_entries(scenario, given, search_paths)
            except DistributionError as exc:
                raise BatchError(str(exc)) from None
            continue
        loaded = load_scenario(scenario, search_paths=search_paths,
                               scripted_ego=ego == SCRIPTED)
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
         profile: str, criteria: Path | None = None, search_paths: Sequence[Path] = (),
         ego: str = STACK) -> list[RunJob]:
    """Validate each (job name or None for the scenario's own, scenario, overrides) and make
    its job, which carries `search_paths` and `ego` (`RunJob.ego`: a scripted car under
    test runs at profile none, `ego_profile`) to its worker; `criteria` is the sidecar of
    the OpenSCENARIO files among them (`--criteria`). Raises `ScenarioError` (naming the
    scenario) for the first bad one, `BatchError` for two runs that would write the same
    files, a run named like a report (`REPORT_NAMES`) or a run's file that is an input of the
    batch (a scenario file, an OpenSCENARIO file's road or sidecar)."""
    planned: list[RunJob] = []
    names: dict[str, str] = {}
    sources: set[Path] = set()
    profile = ego_profile(ego, profile)
    for name, scenario, overrides in entries:
        sidecar = criteria if scenario_path(scenario).suffix == ".xosc" else None
        try:
            loaded = load_scenario(scenario, dict(overrides), sidecar, search_paths=search_paths,
                                   scripted_ego=ego == SCRIPTED)
        except ScenarioError as exc:  # a sidecar's override problem names no file
            if exc.file != OVERRIDES_FILE:
                raise
            raise ScenarioError(scenario, exc.key, exc.problem) from None
        check_profile(loaded, profile, scenario)
        job_name = name or loaded.name
        if job_name in names:
            raise BatchError(f"{scenario}: name: {job_name!r} is also the name of "
                             f"{names[job_name]} (their files would collide in {out_dir})")
        if job_name in REPORT_NAMES:
            raise BatchError(f"{scenario}: name: {job_name!r} is the name of a report of the "
                             f"batch (runs may not be named {', '.join(sorted(REPORT_NAMES))})")
        names[job_name] = scenario
        sources.update(loaded.sources)
        planned.append(RunJob(job_name, scenario, out_dir, dict(overrides), profile,
                              duration=loaded.duration, criteria=sidecar,
                              search_paths=tuple(search_paths), ego=ego,
                              stack_code=code_digest(loaded.stack)))
    _check_not_inputs(planned, sorted(sources))
    return planned


def _check_not_inputs(jobs: Sequence[RunJob], sources: Sequence[Path]) -> None:
    """`BatchError` when a run's file would be one of the batch's input files."""
    inputs = [(source, identity(source)) for source in sources]
    for job in jobs:
        for file in (job.recording, job.result_file, job.plot_file):
            try:
                ident = identity(file)
            except OSError as exc:
                raise BatchError(f"{file}: --out: cannot be resolved ({exc})") from None
            for source, source_ident in inputs:
                if same_file(ident, source_ident):
                    raise BatchError(f"{file}: --out: is an input of the batch ({source}): "
                                     "avsim never writes over its inputs")


def run_command(job: RunJob) -> str:
    """The `avsim run` command line that makes `job`'s run (`--dry-run` prints them): its
    scenario, overrides as `--set PATH=VALUE` (JSON, which YAML reads the same), sidecar,
    search paths, car under test (`--ego scripted`), profile and files, quoted for a POSIX
    shell."""
    words = ["avsim", "run", job.scenario]
    for key, value in job.overrides.items():
        words += ["--set", f"{key}={json.dumps(value)}"]
    if job.criteria is not None:
        words += ["--criteria", str(job.criteria)]
    for folder in job.search_paths:
        words += ["--search-path", str(folder)]
    if job.scripted:
        words += ["--ego", SCRIPTED]
    words += ["--profile", job.profile, "--out", str(job.recording)]
    return shlex.join(words)


def validate_out_dir(out_dir: Path) -> None:
    """`BatchError` unless `out_dir` is a folder or can be made: its nearest existing
    ancestor is a directory, where a file can be written."""
    if out_dir.exists() and not out_dir.is_dir():
        raise BatchError(f"{out_dir}: --out: not a directory")
    try:
        check_outputs([Output("--out", out_dir / RESULTS)], [])
    except OutputError as exc:
        raise BatchError(f"{out_dir}: --out: {exc.problem}") from None


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

    write_atomic(out_dir / JUNIT, junit_xml(outcomes, title))
    write_atomic(out_dir / SUMMARY,
                 summary_markdown(outcomes, title=title, out_dir=out_dir, snapshots=snapshots))
    write_atomic(out_dir / RESULTS, dumps(results_json(outcomes)))


def reports_written(outcomes: Sequence[RunOutcome], out_dir: Path,
                    write: Callable[[], object]) -> str | None:
    """Call `write` (the batch's reports); None when it wrote them. When a write fails
    (a read-only or removed folder, a full disk) one line instead: what failed and where
    every run's result is kept (`avsim.outputs.keep_result`), for exit status 4."""
    try:
        write()
    except OSError as exc:
        line = f"{exc.filename or out_dir}: --out: could not be written ({exc.strerror or exc})"
        try:
            kept = keep_result("batch", dumps(results_json(outcomes)))
        except OSError as again:
            return f"{line}; the results could not be kept either ({again.strerror or again})"
        return f"{line}; the results are kept in {kept}"
    return None


def results_json(outcomes: Sequence[RunOutcome]) -> list[dict[str, object]]:
    """Every run of the batch: its name, overrides, car under test (`RunJob.ego`), status,
    error and result."""
    return [{"name": o.job.name, "scenario": o.job.scenario,
             "overrides": dict(o.job.overrides), "ego": o.job.ego, "status": o.status.value,
             "error": o.error, "result": o.result} for o in outcomes]


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


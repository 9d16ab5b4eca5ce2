"""The `avsim` command line (SCENARIO_FORMAT.md, "Command line").

Exit status: 0 every criterion passed, 1 one failed, 2 bad input (one line on stderr naming
the file, the key and the problem; no traceback; no output file written), 3 the run ended in
error (an exception in a stage: one line on stderr, the traceback in the result file),
4 an output could not be written (docs/cli.md, "Outputs"), 130 / 143 interrupted by SIGINT /
SIGTERM (`avsim.run.interrupts`). A run's status is its verdict's (`avsim.run.verdict`); a
batch's is `avsim.batch.suite.exit_status`.
"""

from __future__ import annotations

import functools
import json
import os
import re
import subprocess
import sys
import time
import warnings
from collections.abc import Callable, Sequence
from contextlib import AbstractContextManager, ExitStack
from pathlib import Path
from typing import TYPE_CHECKING, Any, NoReturn

import click
from rich.console import Console
from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn
from rich.table import Table

from avsim.files import write_atomic
from avsim.outputs import (
    Output,
    OutputError,
    RunFiles,
    batch_lock,
    check_outputs,
    claim_outputs,
    deliver,
    output_lock,
)
from avsim.run.interrupts import ExitAtOnce, Interrupts
from avsim.run.result import dumps, headline, result_json
from avsim.run.verdict import RunVerdict
from avsim.scenario.bounds import MAX_SEED
from avsim.scenario.load import ScenarioError, load_scenario
from avsim.scenario.profile_fit import check_profile
from avsim.scenario.schema import scenario_json_schema

if TYPE_CHECKING:
    from avsim.batch.jobs import RunJob, RunOutcome
    from avsim.run.runner import Runner, RunResult

PROFILES = ("fast", "default", "paper", "none")  # sensor profiles (`world.sensors.setup`)
EGO_MODES = ("stack", "scripted")  # what drives the car under test (`EgoSpec.scripted`)
SENSING = ("auto", "inline", "process")  # where the cameras render
EXIT_FAILED, EXIT_BAD_INPUT = 1, 2  # exit statuses (module doc)
EXIT_ERROR = 3  # the run ended in `error`
EXIT_OUTPUT = 4  # an output could not be written (docs/cli.md, "Outputs")
EXIT_SIGNAL_BASE = 128  # interrupted: 128 + the signal's number (`avsim.run.interrupts`)
PARAMETER_PREFIX = "parameters."  # `--param NAME=V` is `--set parameters.NAME=V`
PLOT_NEXT_TO_RECORDING = "\0next-to-recording"  # `--plot` given without a file name


def _bad_input(message: str) -> NoReturn:
    """Print `message` as one error line on stderr and exit with `EXIT_BAD_INPUT`."""
    click.echo(f"avsim: error: {message}", err=True)
    sys.exit(EXIT_BAD_INPUT)


def _output_failed(message: str) -> NoReturn:
    """Print `message` as one error line on stderr and exit with `EXIT_OUTPUT`."""
    click.echo(f"avsim: error: {message}", err=True)
    sys.exit(EXIT_OUTPUT)


def _exit(unwritten: str | None, status: int) -> NoReturn:
    """End a command that ran with `status`: the line of an output that could not be
    written (if any) on stderr, and `EXIT_OUTPUT` for it unless `status` is an interrupt's
    (130 / 143), which comes first."""
    if unwritten is not None:
        click.echo(f"avsim: error: {unwritten}", err=True)
    interrupted = status > EXIT_SIGNAL_BASE
    sys.exit(EXIT_OUTPUT if unwritten is not None and not interrupted else status)


def _writable(outputs: Sequence[Output], inputs: Sequence[Path]) -> None:
    """Bad input unless every output can be written (`avsim.outputs.check_outputs`)."""
    try:
        check_outputs(outputs, inputs)
    except OutputError as exc:
        _bad_input(str(exc))


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.pass_context
def main(ctx: click.Context) -> None:
    """avsim: a headless 3D driving sandbox for classical autonomous-driving stacks."""
    ctx.with_resource(ExitAtOnce())  # a signal while a command starts: exit 130 / 143
    warnings.showwarning = _show_warning


def _show_warning(message: Warning | str, category: type[Warning], filename: str,
                  lineno: int, file: Any = None, line: str | None = None) -> None:
    """A scenario's load warning as one line `avsim: warning: <file>: <key>: <problem>` on
    stderr; any other warning as Python shows it."""
    from avsim.scenario.openscenario.parameters import DeclarationWarning

    if issubclass(category, DeclarationWarning):
        click.echo(f"avsim: warning: {message}", err=True)
    else:
        _SHOW_WARNING(message, category, filename, lineno, file, line)


_SHOW_WARNING = warnings.showwarning  # Python's own


search_path_option = click.option(
    "--search-path", "search_paths", type=click.Path(path_type=Path), multiple=True,
    metavar="DIR", help="A folder an OpenSCENARIO file's road, catalogs and sidecar may be "
    "in, besides the file's own folder tree (repeatable; tried in order).")


ego_option = click.option(
    "--ego", type=click.Choice(EGO_MODES), default="stack", show_default=True,
    help="What drives the car under test: avsim's stack, or (scripted, OpenSCENARIO files) "
         "the file's own actions as esmini plays them, its controllers not simulated, no "
         "sensors (the profile is none).")


_STACK_OPTIONS = (
    ("stack", "A whole stack of one's own: package.module:factory, or an installed stack's "
              "name (entry point group avsim.stacks); `avsim`: the bundled one."),
    ("perception", "Replace the bundled perception stage (frames in, PlannerInput out)."),
    ("planner", "Replace the bundled planner stage (PlannerInput in, Plan out)."),
    ("controller", "Replace the bundled controller stage (Plan in, VehicleCommand out)."),
)


def stack_options(f: Callable[..., None]) -> Callable[..., None]:
    """`--stack`, `--perception`, `--planner`, `--controller`, `--privileged`
    (docs/stack-api.md): each given one is the scenario file's `stack.<key>` set for every
    run (`--set stack.<key>=FACTORY`, `--set stack.privileged=true`), so batches pass it to
    their runs and repro files keep it."""
    @functools.wraps(f)
    def command(*args: Any, **kwargs: Any) -> None:
        chosen = tuple(f"stack.{key}={kwargs.pop(key)}" for key, _ in _STACK_OPTIONS
                       if kwargs.get(key) is not None)
        for key, _ in _STACK_OPTIONS:
            kwargs.pop(key, None)
        privileged = ("stack.privileged=true",) if kwargs.pop("privileged") else ()
        kwargs["sets"] = tuple(kwargs["sets"]) + chosen + privileged
        f(*args, **kwargs)

    command = click.option(
        "--privileged", is_flag=True, default=False,
        help="Privileged truth mode: the stack is also given the ground truth (the truth "
             "sensor: pose and objects); every result says so.")(command)
    for key, text in reversed(_STACK_OPTIONS):
        command = click.option(f"--{key}", key, default=None, metavar="FACTORY",
                               help=text)(command)
    return command


class SeedType(click.IntRange):
    """`--seed`: an integer in 0..MAX_SEED (numpy's seed range); a text too long to be one
    is refused by its length, not echoed back."""

    def __init__(self) -> None:
        super().__init__(0, MAX_SEED)

    def convert(self, value: Any, param: click.Parameter | None,
                ctx: click.Context | None) -> int:
        """The seed, or click's usage error (exit 2)."""
        if isinstance(value, str) and len(value) > len(str(MAX_SEED)):
            self.fail(f"{len(value)} characters: a seed is at most {MAX_SEED}", param, ctx)
        return super().convert(value, param, ctx)


@main.command()
@click.argument("scenario")
@click.option("--out", "out", type=click.Path(path_type=Path), default=None,
              help="Recording (.rrd). Default: runs/<name>.rrd")
@click.option("--json", "json_path", type=click.Path(path_type=Path), default=None,
              help="Result file. Default: next to the recording, <name>.json")
@click.option("--profile", type=click.Choice(PROFILES), default="default", show_default=True,
              help="Sensor profile: cameras and LiDAR (none: GNSS + odometry on the map).")
@click.option("--sensing", type=click.Choice(SENSING), default="auto", show_default=True,
              help="Where cameras render: a worker process (auto on 2+ cores) or inline.")
@click.option("--seed", type=SeedType(), default=None,
              help="Override the scenario's seed.")
@click.option("--plot", "plot", is_flag=False, flag_value=PLOT_NEXT_TO_RECORDING, default=None,
              metavar="[PNG]",
              help="Also write the speed profile (ego, lead, limit and set speed over time, "
                   "ACC / event mode as bands; the DECS paper's Fig. 3) and the margins "
                   "under it (manoeuvres, gap and time to collision to the lead, lateral "
                   "offset) as a 1600x1200 PNG. "
                   "Without a value: next to the recording, <name>.png")
@click.option("--set", "sets", multiple=True, metavar="PATH=VALUE",
              help="Set a key of the file before validation, as sweep does (one value).")
@click.option("--param", "params", multiple=True, metavar="NAME=VALUE",
              help="An OpenSCENARIO file's parameter (short for --set parameters.NAME=VALUE).")
@click.option("--criteria", "criteria", type=click.Path(path_type=Path), default=None,
              help="An OpenSCENARIO file's criteria (default: NAME.criteria.yaml beside it).")
@click.option("--no-progress", is_flag=True, help="No progress bar.")
@ego_option
@click.option("--permutation", type=click.IntRange(min=0), default=None, metavar="K",
              help="An OpenSCENARIO ParameterValueDistribution file's run K (0-based, as "
                   "esmini's --param_permutation); without it every run, into the folder "
                   "--out (default runs/<name>), as a suite.")
@search_path_option
@click.pass_context
@stack_options
def run(ctx: click.Context, scenario: str, out: Path | None, json_path: Path | None,
        profile: str, sensing: str, seed: int | None, sets: tuple[str, ...], plot: str | None,
        params: tuple[str, ...], criteria: Path | None, no_progress: bool, ego: str,
        permutation: int | None, search_paths: tuple[Path, ...]) -> None:
    """Run SCENARIO (a YAML or OpenSCENARIO file, or a bundled name) and judge it."""
    from avsim.batch.distributions import is_distribution_file
    from avsim.batch.sweep import SweepError

    scripted = ego == "scripted"
    profile = "none" if scripted else profile  # a scripted ego reads no sensors

    if is_distribution_file(scenario) and permutation is None:
        _run_distribution(ctx, scenario, out, json_path is not None or plot is not None)
    try:
        chosen: dict[str, object] = {}
        if permutation is not None:
            scenario, chosen = _permutation(scenario, permutation, search_paths)
        overrides = chosen | _run_overrides(sets + tuple(PARAMETER_PREFIX + p for p in params),
                                            seed)
        loaded = load_scenario(scenario, overrides, criteria, search_paths, scripted)
        check_profile(loaded, profile, scenario)
    except (ScenarioError, SweepError) as exc:
        _bad_input(str(exc))
    out = out if out is not None else Path("runs") / f"{loaded.name}.rrd"
    json_path = json_path if json_path is not None else out.with_suffix(".json")
    plot_path = None if plot is None else (
        out.with_suffix(".png") if plot == PLOT_NEXT_TO_RECORDING else Path(plot))
    files = RunFiles(out, json_path, plot_path)
    _writable(files.outputs(), (*loaded.sources, *([criteria] if criteria else [])))
    from world.core.quiet import quiet_c_output

    with quiet_c_output():  # PyBullet's build banner
        from avsim.run.runner import RunResult  # heavy: only once the input is known good
        from avsim.run.unbuilt import build_runner
        from world.sensors.setup import Profile, localisation

    try:  # held from before the run until its files are written: one writer per file
        claim = claim_outputs(files)
    except OutputError as exc:
        _output_failed(str(exc))
    with claim, Interrupts() as stop:  # Ctrl-C / SIGTERM end the run at its tick, files kept
        setup = None if profile == "none" else Profile(profile)
        built = build_runner(loaded, claim.partial, setup, sensing)
        if isinstance(built, RunResult):  # the world could not be built: its result
            result = built
        else:
            note = "the car under test is scripted (the file's actions move it)" if scripted \
                else localisation(setup, loaded.world.sensors.gnss, loaded.stack.privileged,
                                  loaded.stack.own_perception).note
            click.echo(f"{loaded.name}: {note}")
            stop.on_signal(built.interrupt)
            result = _run_with_progress(built, loaded.duration, not no_progress)
        payload = result_json(result, scenario, out, profile)
        from avsim.report.speed_plot import plot_speed_profile

        unwritten = deliver(files, claim, loaded.name, dumps(payload),
                            None if isinstance(built, RunResult) else  # no run: no plot
                            lambda path: plot_speed_profile(result, path))
        _print_verdict(payload)
        if result.error is not None:
            click.echo(f"avsim: {result.error.line()}", err=True)
    status = _exit_status(result, stop)
    _exit(unwritten, status)


def _run_overrides(texts: Sequence[str], seed: int | None) -> dict[str, object]:
    """`run`'s `PATH=VALUE` texts (one value each) and `--seed` as overrides."""
    from avsim.batch.sweep import SweepError, parse_set

    overrides: dict[str, object] = {}
    for text in texts:
        axis = parse_set(text)
        if len(axis.values) != 1:
            raise SweepError(f"--set {text}: run takes one value (sweep takes several)")
        overrides[axis.path] = axis.values[0]
    if seed is not None:
        overrides["seed"] = seed
    return overrides


def _permutation(scenario: str, k: int,
                 search_paths: Sequence[Path]) -> tuple[str, dict[str, object]]:
    """`run --permutation K`: the distribution file's scenario file and its run K's
    parameters as overrides (the user's own --set / --param replace them)."""
    from avsim.batch.distributions import is_distribution_file
    from avsim.scenario.openscenario.distribution import load_distribution

    if not is_distribution_file(scenario):
        raise ScenarioError(scenario, "--permutation", "is for a ParameterValueDistribution "
                            "file (this is not one)")
    dist = load_distribution(Path(scenario), search_paths)
    if k >= len(dist.runs):
        raise ScenarioError(scenario, "--permutation",
                            f"{k}: the file describes {len(dist.runs)} runs (0 to "
                            f"{len(dist.runs) - 1})")
    click.echo(f"{scenario}: run {k} of {len(dist.runs)}: {dist.runs[k].label()}", err=True)
    return str(dist.scenario), dist.runs[k].overrides()


def _run_distribution(ctx: click.Context, scenario: str, out: Path | None,
                      single_files: bool) -> NoReturn:
    """`run DIST.xosc` without --permutation: every run of the distribution, as `suite`
    runs it (same options), into the folder `out` (default runs/<name>)."""
    if single_files:
        _bad_input(f"{scenario}: --json / --plot: a distribution file makes several runs "
                   "(each writes its own into --out; --permutation K runs one)")
    name = re.sub(r"[^a-z0-9_]+", "_", Path(scenario).stem.lower()).strip("_")
    options = ctx.params
    ctx.invoke(suite, paths=(scenario,), out=out or Path("runs") / name, sets=options["sets"],
               params=options["params"], criteria=options["criteria"],
               profile=options["profile"], search_paths=options["search_paths"],
               ego=options["ego"])
    sys.exit(0)  # pragma: no cover - suite exits with the batch's status


def _exit_status(result: RunResult, stop: Interrupts) -> int:
    """The run's exit status (module doc): its verdict's; an interrupted run's is the
    signal's."""
    if result.verdict is RunVerdict.INTERRUPTED and stop.exit_status is not None:
        return stop.exit_status
    return {RunVerdict.PASS: 0, RunVerdict.FAIL: EXIT_FAILED}.get(result.verdict, EXIT_ERROR)


def _run_with_progress(runner: Runner, duration: float, show: bool) -> RunResult:
    """Run, with a progress line on stderr when `show` and it is a terminal (quiet when
    piped): simulated time, the real-time factor so far and the wall time to go."""
    console = Console(stderr=True)
    if not show or not console.is_terminal:
        return runner.run()
    columns = (TextColumn("[bold]{task.description}"), BarColumn(),
               TextColumn("{task.completed:.0f}/{task.total:.0f} s sim"),
               TextColumn("{task.fields[pace]}"), TimeElapsedColumn())
    with Progress(*columns, console=console, transient=True) as bar:
        task = bar.add_task(runner.scenario.name, total=duration, pace="")
        start = time.perf_counter()

        def advance(t: float, _duration: float) -> None:
            bar.update(task, completed=t, pace=pace(t, duration, time.perf_counter() - start))

        return runner.run(advance)


def pace(sim: float, duration: float, wall: float) -> str:
    """`RTF x.xx, n s to go`: the real-time factor so far (simulated over wall time) and
    the wall time the rest of the run takes at it; empty before there is a rate."""
    if sim <= 0.0 or wall <= 0.0:
        return ""
    rtf = sim / wall
    return f"RTF {rtf:.2f}, {max(duration - sim, 0.0) / rtf:.0f} s to go"


def _print_verdict(payload: dict[str, object]) -> None:
    """The result file's verdict as a table of criteria, then the run's times and files."""
    console = Console()
    table = Table(title=f"{payload['scenario']}: {headline(payload)}")
    for column in ("criterion", "verdict", "value", "threshold", "unit"):
        table.add_column(column)
    criteria = payload["criteria"]
    assert isinstance(criteria, list)
    for c in criteria:
        verdict = ("n/a" if c["passed"] is None else "pass" if c["passed"]
                   else "[red]FAIL[/red]")
        value = "-" if c["value"] is None else f"{c['value']:.3f}"
        threshold = "-" if c["threshold"] is None else f"{c['threshold']}"
        table.add_row(c["name"], verdict, value, threshold, c["unit"])
    console.print(table)
    renderer = f", cameras by {payload['renderer']}" if payload.get("renderer") else ""
    console.print(f"sim {payload['sim_time']:.1f} s in {payload['wall_time']:.1f} s wall "
                  f"(profile {payload['profile']}{renderer}); recording {payload['recording']}")


@main.command()
@click.argument("recording", type=click.Path(path_type=Path))
@click.option("--web", is_flag=True, help="Open the web viewer (served on port 9090) instead "
              "of the native one.")
def view(recording: Path, web: bool) -> None:
    """Open a run's recording (.rrd) in the Rerun viewer (the one that came with avsim)."""
    if not recording.is_file():
        _bad_input(f"{recording}: (file): no such recording")
    viewer = Path(sys.executable).parent / "rerun"
    if not viewer.is_file():
        _bad_input(f"{recording}: (file): the Rerun viewer is not installed ({viewer})")
    command = [str(viewer), *(["--web-viewer"] if web else []), str(recording)]
    sys.exit(subprocess.call(command))


@main.command(name="list")
def list_scenarios() -> None:
    """Bundled scenarios by folder: a heading line per folder, then one line per scenario,
    tab-separated: the name to give `avsim run`, situation, description."""
    from avsim.scenario.files import REPO_ROOT, bundled_groups

    for number, group in enumerate(bundled_groups()):
        folder = group.folder.relative_to(REPO_ROOT).as_posix() + "/"
        note = f" ({group.note})" if group.note else ""
        click.echo(("\n" if number else "") + f"{folder}{note}")
        for path in group.files():
            name = group.name_of(path)
            try:
                loaded = load_scenario(path)
            except ScenarioError as exc:
                click.echo(f"{name}\t(invalid)\t{exc}")
                continue
            click.echo(f"{name}\t{loaded.situation}\t{loaded.description}")


@main.command()
def schema() -> None:
    """Print the JSON Schema of the scenario format."""
    click.echo(json.dumps(scenario_json_schema(), indent=2))


# ---- batches: suite and sweep ---------------------------------------------------------------

EXECUTORS = ("local", "ray")
_batch_options = [
    click.option("--jobs", "-j", type=click.IntRange(min=1), default=None,
                 help="Runs at a time. Default: this machine's cores."),
    click.option("--executor", type=click.Choice(EXECUTORS), default="local",
                 show_default=True, help="Worker processes here, or Ray tasks."),
    click.option("--address", default=None,
                 help="Ray cluster address (default: RAY_ADDRESS, else a local Ray)."),
    click.option("--profile", type=click.Choice(PROFILES), default="default",
                 show_default=True, help="Sensor profile of every run."),
    click.option("--snapshots/--no-snapshots", default=True, show_default=True,
                 help="A picture of each failed run at its first failing moment."),
    click.option("--dry-run", is_flag=True,
                 help="Load and check every run, print each as its `avsim run` command "
                      "line, and run none."),
    ego_option,
]


def batch_options(f: Callable[..., None]) -> Callable[..., None]:
    """Decorate a batch command with the options suite and sweep share."""
    for option in reversed(_batch_options):
        f = option(f)
    return f


@main.command()
@click.argument("paths", nargs=-1)
@click.option("--out", "out", type=click.Path(path_type=Path), default=Path("runs/suite"),
              show_default=True, help="Folder for the runs' files and the reports.")
@click.option("--set", "sets", multiple=True, metavar="PATH=VALUE",
              help="Set a key of every file before validation (one value; a file without "
                   "the key is refused).")
@click.option("--param", "params", multiple=True, metavar="NAME=VALUE",
              help="A parameter of every OpenSCENARIO file (short for --set "
                   "parameters.NAME=VALUE).")
@click.option("--criteria", "criteria", type=click.Path(path_type=Path), default=None,
              help="The OpenSCENARIO files' criteria: a sidecar file or a bundled set "
                   "(default: each file's NAME.criteria.yaml beside it).")
@batch_options
@search_path_option
@stack_options
def suite(paths: tuple[str, ...], out: Path, sets: tuple[str, ...], params: tuple[str, ...],
          criteria: Path | None, jobs: int | None, executor: str, address: str | None,
          profile: str, snapshots: bool, dry_run: bool, ego: str,
          search_paths: tuple[Path, ...]) -> None:
    """Run scenarios in parallel: files, folders or bundled names (default: every scenario
    in scenarios/). Writes each run's .rrd, .json and .png, junit.xml, summary.md."""
    from avsim.batch import suite as batch
    from avsim.batch.sweep import SweepError

    try:
        overrides = _one_value_each(sets + tuple(PARAMETER_PREFIX + p for p in params))
        batch.validate_out_dir(out)
        entries = batch.suite_entries(batch.collect_scenarios(paths), overrides, search_paths,
                                      ego)
        planned = batch.plan(entries, out, profile, criteria, search_paths, ego)
    except (ScenarioError, SweepError, batch.BatchError) as exc:
        _bad_input(str(exc))
    if dry_run:
        _print_plan(planned)
    with _held(batch_lock(out)), Interrupts() as stop:  # Ctrl-C / SIGTERM: what finished is kept
        outcomes = _execute(planned, executor, jobs, address, stop)
        unwritten = batch.reports_written(outcomes, out, lambda: _report(
            outcomes, out, f"avsim suite ({len(outcomes)} runs{_ego_note(ego)})", snapshots))
    status = batch.exit_status(outcomes, stop.exit_status)
    _exit(unwritten, status)


def _ego_note(ego: str) -> str:
    """A batch's title's note of what drove the car under test: none for the stack."""
    return "" if ego == "stack" else f", ego {ego}"


def _held(lock: AbstractContextManager[None]) -> ExitStack:
    """`lock` entered, held until the returned stack closes; exit 4 with its one line when
    it cannot be (`avsim.outputs.OutputError`: another command holds it, a folder that
    cannot be made)."""
    held = ExitStack()
    try:
        held.enter_context(lock)
    except OutputError as exc:
        _output_failed(str(exc))
    return held


def _one_value_each(texts: Sequence[str]) -> dict[str, object]:
    """`PATH=VALUE` texts as overrides; `SweepError` for a malformed one or several values."""
    from avsim.batch.sweep import SweepError, parse_set

    overrides: dict[str, object] = {}
    for text in texts:
        axis = parse_set(text)
        if len(axis.values) != 1:
            raise SweepError(f"--set {text}: suite takes one value (sweep takes several)")
        overrides[axis.path] = axis.values[0]
    return overrides


def _print_plan(planned: Sequence[RunJob]) -> NoReturn:
    """`--dry-run`: every planned run as the `avsim run` command that makes it, then exit 0
    (nothing run, nothing written)."""
    from avsim.batch.suite import run_command

    for job in planned:
        click.echo(run_command(job))
    click.echo(f"# {len(planned)} runs planned, none run (--dry-run)", err=True)
    sys.exit(0)


@main.command()
@click.argument("scenario")
@click.option("--set", "sets", multiple=True, metavar="PATH=V1,V2,...",
              help="A key path and its values; several --set make a grid.")
@click.option("--param", "params", multiple=True, metavar="NAME=V1,V2,...",
              help="An OpenSCENARIO file's parameter and its values (checked against the "
              "file's constraint groups); short for --set parameters.NAME=...")
@click.option("--out", "out", type=click.Path(path_type=Path), default=None,
              help="Folder for the runs and the reports. Default: runs/sweep_<name>")
@click.option("--metric", default="min_gap", show_default=True,
              help="The heat map's metric (a metric or a criterion of the result).")
@batch_options
@search_path_option
@stack_options
def sweep(scenario: str, sets: tuple[str, ...], params: tuple[str, ...], out: Path | None,
          metric: str, jobs: int | None, executor: str, address: str | None, profile: str,
          snapshots: bool, dry_run: bool, ego: str, search_paths: tuple[Path, ...]) -> None:
    """Run SCENARIO over the grid of --set values (default: the file's own `grid`), like a
    suite; write sweep.csv, sweep.md and, over two swept keys, heatmap.png of --metric."""
    from avsim.batch import suite as batch
    from avsim.batch.sweep import Axis, SweepError, grid, parse_set

    try:
        axes = [parse_set(s) for s in sets + tuple(PARAMETER_PREFIX + p for p in params)]
        loaded = load_scenario(scenario, search_paths=search_paths,
                               scripted_ego=ego == "scripted")
        axes = axes or [Axis(path, values) for path, values in loaded.grid]
        if not axes:
            raise SweepError("give at least one --set or --param to sweep (the file has "
                             "no grid)")
        runs = [batch.overrides_of(point) for point in grid(axes)]
        name = loaded.name
        out = out if out is not None else Path("runs") / f"sweep_{name}"
        batch.validate_out_dir(out)
        entries = [(f"{name}_{k:03d}", scenario, overrides) for k, overrides in enumerate(runs)]
        planned = batch.plan(entries, out, profile, search_paths=search_paths, ego=ego)
    except (ScenarioError, SweepError, batch.BatchError) as exc:
        _bad_input(str(exc))
    if dry_run:
        _print_plan(planned)
    with _held(batch_lock(out)), Interrupts() as stop:  # Ctrl-C / SIGTERM: what finished is kept
        outcomes = _execute(planned, executor, jobs, address, stop)

        def reports() -> None:
            _report(outcomes, out, f"avsim sweep {name} ({len(outcomes)} runs{_ego_note(ego)})",
                    snapshots)
            _sweep_report(outcomes, out, [a.path for a in axes if len(a.values) > 1],
                          [a.path for a in axes], metric, name)

        unwritten = batch.reports_written(outcomes, out, reports)
    status = batch.exit_status(outcomes, stop.exit_status)
    _exit(unwritten, status)


def _execute(planned: Sequence[RunJob], executor: str, jobs: int | None,
             address: str | None, stop: Interrupts) -> list[RunOutcome]:
    """Run the planned jobs on the chosen executor (`--jobs` default: this machine's cores)."""
    from avsim.batch import suite as batch
    from avsim.batch.executors import ExecutorError, LocalExecutor, RayExecutor

    workers = jobs if jobs is not None else (os.cpu_count() or 1)
    runner: LocalExecutor | RayExecutor = (
        LocalExecutor(workers) if executor == "local" else RayExecutor(address, jobs))
    try:
        return batch.execute(planned, runner, stop)
    except ExecutorError as exc:
        _bad_input(str(exc))


def _report(outcomes: Sequence[RunOutcome], out: Path, title: str, snapshots: bool) -> None:
    """Snapshots of the failed runs (if asked), junit.xml and summary.md; the table printed."""
    from avsim.batch import suite as batch
    from avsim.report.suite import summary_table

    console = Console()
    pictures = batch.snapshots_of_failures(outcomes, out, console) if snapshots else {}
    batch.write_reports(outcomes, out, title, pictures)
    console.print(summary_table(outcomes))
    console.print(f"reports: {out / 'summary.md'}, {out / 'junit.xml'}", highlight=False)


def _sweep_report(outcomes: Sequence[RunOutcome], out: Path, swept: list[str],
                  params: list[str], metric: str, name: str) -> None:
    """sweep.csv and sweep.md over every parameter; heatmap.png when two keys were swept."""
    from avsim.report.sweep import heat_map, sweep_csv, sweep_markdown, sweep_rows

    metrics = sorted({metric, "min_gap", "max_decel", "collisions", "collisions_excused"})
    rows = sweep_rows(outcomes, params, metrics)
    write_atomic(out / "sweep.csv", sweep_csv(rows))
    write_atomic(out / "sweep.md", sweep_markdown(rows))
    console = Console()
    if len(swept) == 2:
        heat_map(outcomes, swept[0], swept[1], metric, out / "heatmap.png",
                 title=f"{name}: {metric}")
        console.print(f"heat map: {out / 'heatmap.png'}", highlight=False)
    else:
        console.print(f"no heat map: it needs two swept keys, {len(swept)} were swept",
                      highlight=False)


# ---- campaigns --------------------------------------------------------------------------

def _options(options: Sequence[Callable[..., Any]]) -> Callable[..., Any]:
    """Decorate a command with `options`, in their order."""
    def decorate(f: Callable[..., None]) -> Callable[..., None]:
        for option in reversed(options):
            f = option(f)
        return f
    return decorate


_campaign_options = [_batch_options[k] for k in (0, 1, 2, 3, 5, 6)]  # no snapshots


@main.command()
@click.argument("files", nargs=-1, required=True)
@click.option("--n", "n", type=click.IntRange(0, 10_000), default=20, show_default=True,
              help="Runs drawn from each file.")
@click.option("--seed", type=SeedType(), default=0, show_default=True,
              help="The campaign's seed: run k of a file draws the same values whatever "
                   "--n, --jobs or the executor.")
@click.option("--out", "out", type=click.Path(path_type=Path), default=None,
              help="Folder for the runs and the reports. Default: runs/campaign_<name>")
@click.option("--set", "sets", multiple=True, metavar="PATH=VALUE",
              help="Set a key of every run (one value), besides the drawn ones.")
@click.option("--record", type=click.Choice(("failures", "all")), default="failures",
              show_default=True, help="Keep the recordings of the failed runs, or of all.")
@click.option("--shrink", is_flag=True,
              help="Move each failure's values toward the file's own while it still fails "
                   "the same criterion; write repro/<run>_shrunk.yaml.")
@click.option("--search", "metric", default=None, metavar="METRIC",
              help="Minimise METRIC (a metric or a criterion of the result) over the laws "
                   "by the cross-entropy method; write repro/worst.yaml.")
@click.option("--iterations", type=click.IntRange(1, 20), default=4, show_default=True,
              help="--search: iterations.")
@click.option("--population", type=click.IntRange(2, 200), default=8, show_default=True,
              help="--search: runs per iteration and file.")
@click.option("--resume", is_flag=True,
              help="Take the result of each run that already finished in --out on the same "
                   "file, values, profile and code; run the others.")
@_options(_campaign_options)
@stack_options
def campaign(files: tuple[str, ...], n: int, seed: int, out: Path | None,
             sets: tuple[str, ...], record: str, shrink: bool, metric: str | None,
             iterations: int, population: int, resume: bool, jobs: int | None,
             executor: str, address: str | None, profile: str, dry_run: bool,
             ego: str) -> None:
    """Run N scenarios drawn from each campaign FILE (a scenario file with a `vary:`
    section) like a suite; write a repro file of each failure, campaign.json, summary.md,
    junit.xml (docs/cli.md, "Campaigns")."""
    from avsim.batch import campaign as c
    from avsim.batch import refine
    from avsim.batch import suite as batch
    from avsim.batch.sweep import SweepError

    try:
        settings, families, planned, drawn = _campaign_plan(files, n, seed, out, sets,
                                                            metric, profile, ego)
    except (ScenarioError, SweepError, batch.BatchError) as exc:
        _bad_input(str(exc))
    if dry_run:
        _print_plan(planned)
    with Interrupts() as stop:  # Ctrl-C / SIGTERM: finished runs and reports are kept

        def execute(todo: list[RunJob]) -> list[RunOutcome]:
            return _execute(todo, executor, jobs, address, stop) if todo else []

        outcomes = _campaign_runs(planned, resume, execute)
        runs = [c.DrawnRun(families[k // n], values, outcome)
                for k, (values, outcome) in enumerate(zip(drawn, outcomes, strict=True))]
        c.keep_recordings(runs, record == "all")
        going = stop.exit_status is None
        refined = c.Refined(
            refine.shrink(c.failed(runs), settings, execute) if shrink and going else (),
            refine.search(families, settings, metric, iterations, population, execute)
            if metric is not None and going else ())
        title = f"avsim campaign {' '.join(files)} ({len(runs)} runs)"
        unwritten = batch.reports_written(outcomes, settings.out_dir, lambda: _campaign_report(
            runs, refined, settings, n, title))
    _exit(unwritten, batch.exit_status(outcomes, stop.exit_status))


def _campaign_runs(planned: list[RunJob], resume: bool,
                   execute: Callable[[list[RunJob]], list[RunOutcome]]) -> list[RunOutcome]:
    """Each planned run's outcome, in plan order: with `resume`, those that finished before
    (`avsim.batch.resume`) taken from their files, the others run."""
    from avsim.batch.resume import keyed, resumed

    planned = keyed(planned)  # each run writes its key: any campaign can be resumed
    done = resumed(planned) if resume else {}
    if resume:
        click.echo(f"resumed: {len(done)} of {len(planned)} runs had finished; "
                   f"{len(planned) - len(done)} to run", err=True)
    ran = {o.job.name: o for o in execute([job for job in planned if job.name not in done])}
    return [done.get(job.name) or ran[job.name] for job in planned]


def _campaign_plan(files: Sequence[str], n: int, seed: int, out: Path | None,
                   sets: Sequence[str], metric: str | None, profile: str,
                   ego: str) -> tuple[Any, ...]:
    """The campaign's settings, families, checked jobs and drawn values (bad input raises)."""
    import re

    from avsim.batch import campaign as c
    from avsim.batch import suite as batch
    from avsim.batch.jobs import ego_profile

    fixed = _one_value_each(sets)
    families = [c.load_family(file, index, ego) for index, file in enumerate(files)]
    if metric is not None and not re.fullmatch(r"[a-z0-9_]{1,64}", metric):
        raise batch.BatchError(f"--search: {metric[:64]!r} is not a metric's name ([a-z0-9_]+)")
    name = families[0].name if len(families) == 1 else "all"
    out = out if out is not None else Path("runs") / f"campaign_{name}"
    batch.validate_out_dir(out)
    settings = c.Settings(out, ego_profile(ego, profile), fixed, seed, ego)
    planned, drawn = c.draw_plan(families, n, settings)
    return settings, families, planned, drawn


def _campaign_report(runs: Sequence[Any], refined: Any, settings: Any, n: int,
                     title: str) -> None:
    """The campaign's reports and repro files; the verdicts table printed."""
    from avsim.batch.campaign import write_reports
    from avsim.report.suite import summary_table

    write_reports(runs, refined, settings, n, title)
    console = Console()
    console.print(summary_table([r.outcome for r in runs]))
    console.print(f"reports: {settings.out_dir / 'summary.md'}, "
                  f"{settings.out_dir / 'campaign.json'}", highlight=False)


@main.command("convert")
@click.argument("file", type=click.Path(path_type=Path))
@click.option("--criteria", "criteria", type=click.Path(path_type=Path), default=None,
              help="The file's criteria (default: NAME.criteria.yaml beside it).")
@search_path_option
def convert_command(file: Path, criteria: Path | None, search_paths: tuple[Path, ...]) -> None:
    """Print the avsim/1 YAML of an OpenSCENARIO FILE where it fits that format; what does
    not fit is listed at its top (and counted on stderr)."""
    import yaml

    from avsim.scenario.openscenario.to_yaml import convert_xosc

    if file.suffix != ".xosc":
        _bad_input(f"{file}: (file): convert takes an OpenSCENARIO file (.xosc)")
    try:
        conversion = convert_xosc(file, criteria, search_paths)
    except ScenarioError as exc:
        _bad_input(str(exc))
    head = [f"# avsim/1, converted from {file}"]
    if conversion.misfits:
        head.append("# does not fit the format (approximated or left out):")
        head += [f"#   - {m}" for m in conversion.misfits]
    click.echo("\n".join(head))
    click.echo(yaml.safe_dump(conversion.document, sort_keys=False), nl=False)
    if conversion.misfits:
        click.echo(f"avsim: {len(conversion.misfits)} thing(s) do not fit the avsim/1 format: "
                   "listed at the top", err=True)


@main.command()
@click.argument("recording", type=click.Path(path_type=Path))
@click.option("--at", "at", type=float, required=True, help="[s] simulated time.")
@click.option("--out", "out", type=click.Path(path_type=Path), default=None,
              help="PNG. Default: next to the recording, <name>_<T>s.png")
@click.option("--size", type=(click.IntRange(min=64), click.IntRange(min=64)),
              default=(1600, 900), show_default=True, help="[px] width and height.")
def snapshot(recording: Path, at: float, out: Path | None, size: tuple[int, int]) -> None:
    """A picture of RECORDING (.rrd) at simulated time --at, as its default blueprint shows
    it (Rerun's own viewer, headless)."""
    from avsim.record.snapshot import SnapshotError, render_snapshot

    out = out if out is not None else recording.with_name(f"{recording.stem}_{at:g}s.png")
    _writable([Output("--out", out)], [recording])
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        _output_failed(f"{out}: --out: its folder cannot be made ({exc.strerror})")
    with _held(output_lock([Output("--out", out)])):  # one writer of the picture at a time
        try:
            render_snapshot(recording, at, out, width=size[0], height=size[1])
        except SnapshotError as exc:
            _bad_input(f"{recording}: {exc.key}: {exc}")
    click.echo(str(out))


@main.command()
@click.argument("recording", type=click.Path(path_type=Path))
@click.option("--csv", "fmt", flag_value="csv", help="Write CSV.")
@click.option("--parquet", "fmt", flag_value="parquet", help="Write Parquet.")
@click.option("--out", "out", type=click.Path(path_type=Path), default=None,
              help="The table's file. Default: RECORDING's name with .csv / .parquet.")
@click.option("--force", is_flag=True, help="Overwrite --out if it exists.")
def export(recording: Path, fmt: str | None, out: Path | None, force: bool) -> None:
    """Write the time series of RECORDING (.rrd of `avsim run`) as one table, a row per
    recorded ego pose: time, the ego, the margins (gap, TTC, d_min), the plan's states, the
    actors (docs/cli.md, "Exporting a run")."""
    from avsim.report.export import ExportError, default_out, export_run

    if fmt not in ("csv", "parquet"):
        _bad_input(f"{recording}: --csv|--parquet: give the table's format")
    out = out if out is not None else default_out(recording, "csv" if fmt == "csv" else "parquet")
    _writable([Output("--out", out)], [recording])  # never the recording, even with --force
    if out.exists() and not force:
        _bad_input(f"{out}: --out: exists (--force overwrites it)")
    try:
        table = export_run(recording, out, "csv" if fmt == "csv" else "parquet")
    except ExportError as exc:
        _bad_input(f"{recording}: (file): {exc}")
    click.echo(f"{out}: {table.num_rows} rows, {table.num_columns} columns")


if __name__ == "__main__":
    main()

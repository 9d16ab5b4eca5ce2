"""The `avsim` command line (SCENARIO_FORMAT.md, "Command line").

Exit status: 0 every criterion passed, 1 one failed, 2 bad input (one line on stderr naming
the file, the key and the problem; no traceback; no output file written).
"""

from __future__ import annotations

import json
import os
import sys
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING, NoReturn

import click
from rich.console import Console
from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn
from rich.table import Table

from avsim.result import result_json
from avsim.scenario import ScenarioError, bundled_scenarios, load_scenario
from avsim.schema import scenario_json_schema

if TYPE_CHECKING:
    from avsim.runner import Runner, RunResult

PROFILES = ("fast", "default", "paper", "none")
SENSING = ("auto", "inline", "process")
EXIT_FAILED, EXIT_BAD_INPUT = 1, 2
PLOT_NEXT_TO_RECORDING = "\0next-to-recording"  # `--plot` given without a file name


def _bad_input(message: str) -> NoReturn:
    click.echo(f"avsim: error: {message}", err=True)
    sys.exit(EXIT_BAD_INPUT)


def _writable(path: Path, what: str) -> None:
    """Bad input unless `path` can be created: its nearest existing ancestor is a directory."""
    if path.is_dir():
        _bad_input(f"{path}: {what}: is a directory")
    for ancestor in path.absolute().parents:
        if ancestor.exists():
            if not ancestor.is_dir():
                _bad_input(f"{path}: {what}: {ancestor} is not a directory")
            return


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
def main() -> None:
    """avsim: a headless 3D driving sandbox for classical autonomous-driving stacks."""


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
@click.option("--seed", type=int, default=None, help="Override the scenario's seed.")
@click.option("--plot", "plot", is_flag=False, flag_value=PLOT_NEXT_TO_RECORDING, default=None,
              metavar="[PNG]",
              help="Also write the speed profile (ego, lead, limit and set speed over time, "
                   "ACC / event mode as bands; the DECS paper's Fig. 3) as a 1600x700 PNG. "
                   "Without a value: next to the recording, <name>.png")
@click.option("--no-progress", is_flag=True, help="No progress bar.")
def run(scenario: str, out: Path | None, json_path: Path | None, profile: str, sensing: str,
        seed: int | None, plot: str | None, no_progress: bool) -> None:
    """Run SCENARIO (a file or a bundled name) and judge it."""
    overrides = {"seed": seed} if seed is not None else None
    try:
        spec = load_scenario(scenario, overrides)
    except ScenarioError as exc:
        _bad_input(str(exc))
    out = out if out is not None else Path("runs") / f"{spec.name}.rrd"
    json_path = json_path if json_path is not None else out.with_suffix(".json")
    _writable(out, "--out")
    _writable(json_path, "--json")
    plot_path = None if plot is None else (
        out.with_suffix(".png") if plot == PLOT_NEXT_TO_RECORDING else Path(plot))
    if plot_path is not None:
        _writable(plot_path, "--plot")
    from world.quiet import quiet_c_output

    with quiet_c_output():  # PyBullet's build banner
        from avsim.runner import Runner  # heavy: only once the input is known good
        from world.sensor_setup import Profile

    out.parent.mkdir(parents=True, exist_ok=True)
    partial = out.with_name(f".{out.name}.partial")
    runner = Runner(spec, partial, None if profile == "none" else Profile(profile), sensing)
    result = _run_with_progress(runner, spec.duration, not no_progress)
    partial.replace(out)
    payload = result_json(result, scenario, out, profile)
    _write_atomic(json_path, json.dumps(payload, indent=2) + "\n")
    if plot_path is not None:
        from avsim.plot import plot_speed_profile

        plot_speed_profile(result, plot_path)
    _print_verdict(payload)
    sys.exit(0 if result.passed else EXIT_FAILED)


def _run_with_progress(runner: Runner, duration: float, show: bool) -> RunResult:
    console = Console(stderr=True)
    if not show or not console.is_terminal:
        return runner.run()
    columns = (TextColumn("[bold]{task.description}"), BarColumn(),
               TextColumn("{task.completed:.0f}/{task.total:.0f} s sim"), TimeElapsedColumn())
    with Progress(*columns, console=console, transient=True) as bar:
        task = bar.add_task(runner.spec.name, total=duration)
        return runner.run(lambda t, _d: bar.update(task, completed=t))


def _write_atomic(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.")
    with os.fdopen(fd, "w") as f:
        f.write(text)
    Path(tmp).replace(path)


def _print_verdict(payload: dict[str, object]) -> None:
    console = Console()
    table = Table(title=f"{payload['scenario']}: {'PASS' if payload['passed'] else 'FAIL'}")
    for column in ("criterion", "verdict", "value", "threshold", "unit"):
        table.add_column(column)
    criteria = payload["criteria"]
    assert isinstance(criteria, list)
    for c in criteria:
        table.add_row(c["name"], "pass" if c["passed"] else "[red]FAIL[/red]",
                      f"{c['value']:.3f}", f"{c['threshold']}", c["unit"])
    console.print(table)
    renderer = f", cameras by {payload['renderer']}" if payload.get("renderer") else ""
    console.print(f"sim {payload['sim_time']:.1f} s in {payload['wall_time']:.1f} s wall "
                  f"(profile {payload['profile']}{renderer}); recording {payload['recording']}")


@main.command(name="list")
def list_scenarios() -> None:
    """Bundled scenarios, one per line: name, situation, description."""
    for path in bundled_scenarios():
        try:
            spec = load_scenario(path)
        except ScenarioError as exc:
            click.echo(f"{path.stem}\t(invalid)\t{exc}")
            continue
        click.echo(f"{spec.name}\t{spec.situation}\t{spec.description}")


@main.command()
def schema() -> None:
    """Print the JSON Schema of the scenario format."""
    click.echo(json.dumps(scenario_json_schema(), indent=2))


def _not_yet(what: str, issue: str) -> NoReturn:
    _bad_input(f"{what}: not supported yet (comes with issue {issue})")


@main.command(context_settings={"ignore_unknown_options": True})
@click.argument("args", nargs=-1, type=click.UNPROCESSED)
def suite(args: tuple[str, ...]) -> None:
    """Run many scenarios in parallel (issue F)."""
    _not_yet("avsim suite", "F")


@main.command(context_settings={"ignore_unknown_options": True})
@click.argument("args", nargs=-1, type=click.UNPROCESSED)
def sweep(args: tuple[str, ...]) -> None:
    """Run a parameter grid (issue F)."""
    _not_yet("avsim sweep", "F")


@main.command(context_settings={"ignore_unknown_options": True})
@click.argument("args", nargs=-1, type=click.UNPROCESSED)
def snapshot(args: tuple[str, ...]) -> None:
    """Render a recording at a time to PNG (issue F)."""
    _not_yet("avsim snapshot", "F")


if __name__ == "__main__":
    main()

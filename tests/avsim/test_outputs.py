"""Output files that cannot destroy data, be hijacked or be lost (`avsim.outputs`,
`avsim.files`, the `run` / `snapshot` / `suite` commands; docs/cli.md, "Outputs").

Refusals run in-process through click's runner and stop before the simulator starts. The
few real runs are 0.3 s of simulated time without sensors (`--profile none`). Failures after
a run are injected by replacing the write (the tests run as root in CI, where `chmod` does
not stop a write): `ENOSPC` for a full disk, `EROFS` for a read-only folder.
"""

from __future__ import annotations

import errno
import json
import os
import shutil
import stat
import tempfile
from collections.abc import Callable
from pathlib import Path

import pytest
from click.testing import CliRunner, Result

import avsim.outputs
from avsim.batch import suite as batch
from avsim.batch.jobs import RunJob, RunOutcome, Status
from avsim.cli import EXIT_BAD_INPUT, EXIT_OUTPUT, main
from avsim.files import NAME_MAX, temporary_beside, write_atomic
from avsim.outputs import (
    BATCH_LOCK,
    Output,
    OutputBusyError,
    OutputError,
    batch_lock,
    check_outputs,
    lock_path,
    output_lock,
)
from avsim.scenario.load import load_scenario
from tests.avsim.texts import MINIMAL

HERE = Path(__file__).parent
ALKS = HERE.parent / "data" / "alks" / "logical_scenarios" / "concrete_scenarios"
CUT_IN = "alks_scenario_4_4_1_cut_in_no_collision_template.xosc"
R157 = HERE.parents[1] / "avsim" / "scenario" / "openscenario" / "sets" / "r157.criteria.yaml"
SHORT = ("--profile", "none", "--set", "duration=0.3", "--no-progress")  # a cheap real run


def _scenario(folder: Path, name: str = "minimal") -> Path:
    path = folder / f"{name}.yaml"
    path.write_text(MINIMAL.replace("name: minimal", f"name: {name}"), encoding="utf-8")
    return path


def _invoke(*args: str | Path) -> Result:
    return CliRunner().invoke(main, [str(a) for a in args])


def _one_line_error(result: Result, status: int) -> str:
    assert result.exit_code == status, (result.exit_code, result.output, result.exception)
    assert result.exception is None or isinstance(result.exception, SystemExit)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("avsim: error: "), result.stderr
    return lines[0]


def _tree(folder: Path) -> dict[str, bytes]:
    """Every file below `folder` with its bytes (what a refusal must leave as it was)."""
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*"))
            if p.is_file() and not p.is_symlink()}


# ---- data destroyed: outputs equal to inputs or to each other -------------------------------


@pytest.mark.parametrize("option", ["--out", "--json", "--plot"])
@pytest.mark.parametrize("spelling", ["same", "dotdot", "symlink", "hardlink"])
def test_an_output_that_is_the_scenario_is_refused(tmp_path: Path, option: str,
                                                   spelling: str) -> None:
    scenario = _scenario(tmp_path)
    (tmp_path / "sub").mkdir()
    named = {"same": scenario, "dotdot": tmp_path / "sub" / ".." / scenario.name,
             "symlink": tmp_path / "link.rrd", "hardlink": tmp_path / "hard.png"}[spelling]
    if spelling == "symlink":
        named.symlink_to(scenario)
    if spelling == "hardlink":
        os.link(scenario, named)
    before = _tree(tmp_path)
    outputs = {"--out": tmp_path / "x.rrd", "--json": tmp_path / "x.json",
               "--plot": tmp_path / "x.png", option: named}
    args = [a for opt, path in outputs.items() for a in (opt, path)]
    line = _one_line_error(_invoke("run", scenario, *args, *SHORT), EXIT_BAD_INPUT)
    assert f"{option}: is an input of the run" in line
    assert _tree(tmp_path) == before


def _xosc_tree(folder: Path) -> Path:
    """The cut-in file with its road, catalogs and a sidecar, copied into `folder`."""
    shutil.copy(ALKS / CUT_IN, folder / CUT_IN)
    shutil.copytree(ALKS / "catalogs", folder / "catalogs")
    shutil.copytree(ALKS / "road_networks", folder / "road_networks")
    shutil.copy(R157, folder / CUT_IN.replace(".xosc", ".criteria.yaml"))
    return folder / CUT_IN


@pytest.mark.parametrize("victim", [CUT_IN, "road_networks/alks_road_straight.xodr",
                                    CUT_IN.replace(".xosc", ".criteria.yaml"),
                                    "catalogs/vehicles/vehicle_catalog.xosc"])
def test_no_input_file_of_an_openscenario_run_is_written_over(tmp_path: Path,
                                                              victim: str) -> None:
    xosc = _xosc_tree(tmp_path)
    assert (tmp_path / victim).is_file()
    before = _tree(tmp_path)
    line = _one_line_error(_invoke("run", xosc, "--out", tmp_path / "x.rrd", "--json",
                                   tmp_path / victim, *SHORT), EXIT_BAD_INPUT)
    assert "--json" in line and ("input" in line or "OpenSCENARIO" in line), line
    assert _tree(tmp_path) == before


def test_the_sources_of_a_scenario_are_its_files(tmp_path: Path) -> None:
    yaml_file = _scenario(tmp_path)
    assert load_scenario(yaml_file).sources == (yaml_file,)
    xosc = _xosc_tree(tmp_path)
    sources = {p.resolve() for p in load_scenario(xosc).sources}
    assert sources == {xosc.resolve(), (tmp_path / "road_networks/alks_road_straight.xodr"),
                       xosc.with_name(CUT_IN.replace(".xosc", ".criteria.yaml")).resolve()}


@pytest.mark.parametrize(("first", "second"), [("--out", "--json"), ("--out", "--plot"),
                                                ("--json", "--plot")])
def test_two_outputs_that_are_one_file_are_refused(tmp_path: Path, first: str,
                                                   second: str) -> None:
    scenario = _scenario(tmp_path)
    same = tmp_path / "same.out"
    outputs = {"--out": tmp_path / "x.rrd", "--json": tmp_path / "x.json",
               "--plot": tmp_path / "x.png", first: same, second: tmp_path / "." / same.name}
    args = [a for opt, path in outputs.items() for a in (opt, path)]
    line = _one_line_error(_invoke("run", scenario, *args, *SHORT), EXIT_BAD_INPUT)
    assert f"{second}: the same file as {first}" in line
    assert _tree(tmp_path) == {scenario.name: scenario.read_bytes()}


def test_snapshot_out_equal_to_its_recording_is_refused(tmp_path: Path) -> None:
    recording = tmp_path / "run.rrd"
    recording.write_bytes(b"a recording")
    line = _one_line_error(_invoke("snapshot", recording, "--at", "1", "--out",
                                   tmp_path / "." / "run.rrd"), EXIT_BAD_INPUT)
    assert "--out: is an input of the run" in line
    assert recording.read_bytes() == b"a recording"


# ---- checked before the run ------------------------------------------------------------------


@pytest.mark.parametrize("target", ["device", "fifo", "directory"])
@pytest.mark.parametrize("option", ["--out", "--json"])
def test_an_output_that_is_not_a_regular_file_is_refused(tmp_path: Path, target: str,
                                                         option: str) -> None:
    """Nodes made here (a copy of /dev/null's device, a FIFO, a folder): the command is not
    pointed at the real /dev/null, which a regression would replace with a file."""
    scenario = _scenario(tmp_path)
    path = tmp_path / target
    if target == "device":
        try:
            os.mknod(path, 0o666 | stat.S_IFCHR, os.stat("/dev/null").st_rdev)
        except PermissionError:
            pytest.skip("making a device node needs CAP_MKNOD")
    if target == "fifo":
        os.mkfifo(path)
    if target == "directory":
        path.mkdir()
    mode = path.stat().st_mode
    outputs = {"--out": tmp_path / "x.rrd", "--json": tmp_path / "x.json", option: path}
    args = [a for opt, p in outputs.items() for a in (opt, p)]
    line = _one_line_error(_invoke("run", scenario, *args, *SHORT), EXIT_BAD_INPUT)
    assert option in line and ("regular file" in line or "directory" in line), line
    assert path.stat().st_mode == mode  # still the device, FIFO or directory


@pytest.mark.parametrize("device", ["/dev/null", "/dev/full", "/dev/zero"])
def test_the_system_devices_are_refused_as_outputs(device: str) -> None:
    with pytest.raises(OutputError, match="not a regular file"):
        check_outputs([Output("--json", Path(device))], [])


def test_a_folder_that_cannot_be_written_is_refused_before_the_run(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """`os.access` says yes to root: the real check (a file created there) says no."""
    scenario = _scenario(tmp_path)
    real = tempfile.mkstemp

    def read_only(suffix: str | None = None, prefix: str | None = None,
                  dir: str | Path | None = None) -> tuple[int, str]:
        if dir is not None and Path(dir).resolve() == (tmp_path / "ro").resolve():
            raise OSError(errno.EROFS, os.strerror(errno.EROFS))
        return real(suffix, prefix, dir)

    (tmp_path / "ro").mkdir()
    monkeypatch.setattr(tempfile, "mkstemp", read_only)
    line = _one_line_error(_invoke("run", scenario, "--out", tmp_path / "ro" / "x.rrd", *SHORT),
                           EXIT_BAD_INPUT)
    assert "--out: cannot write in" in line
    assert list((tmp_path / "ro").iterdir()) == []


def test_a_name_longer_than_the_limit_is_refused_before_the_run(tmp_path: Path) -> None:
    scenario = _scenario(tmp_path)
    long = tmp_path / ("n" * (NAME_MAX + 1))
    line = _one_line_error(_invoke("run", scenario, "--out", tmp_path / "x.rrd", "--json",
                                   long, *SHORT), EXIT_BAD_INPUT)
    assert f"longer than {NAME_MAX} bytes" in line


def test_the_folder_check_leaves_nothing_behind(tmp_path: Path) -> None:
    check_outputs([Output("--out", tmp_path / "a" / "b.rrd"), Output("--json",
                                                                     tmp_path / "b.json")], [])
    assert list(tmp_path.iterdir()) == []


def test_an_output_below_a_file_is_refused(tmp_path: Path) -> None:
    (tmp_path / "file").write_text("x")
    with pytest.raises(OutputError, match="is not a directory"):
        check_outputs([Output("--out", tmp_path / "file" / "x.rrd")], [])


# ---- locks -------------------------------------------------------------------------------


def test_a_second_command_writing_the_same_output_is_refused(tmp_path: Path) -> None:
    """While a run holds its outputs' locks, a second `run` to the same --json (named
    another way) is refused with exit 4 before it runs; the first run's files untouched."""
    scenario = _scenario(tmp_path)
    out = tmp_path / "x.json"
    with output_lock([Output("--json", out)]):  # as the first run holds it
        assert lock_path(out).is_file()
        line = _one_line_error(_invoke("run", scenario, "--out", tmp_path / "y.rrd", "--json",
                                       tmp_path / "." / "x.json", *SHORT), EXIT_OUTPUT)
        assert "another avsim command is writing this file" in line
        assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
            [scenario.name, lock_path(out).name])
    assert not lock_path(out).exists()  # removed by its holder


def test_a_lock_is_exclusive_and_its_file_is_never_followed(tmp_path: Path) -> None:
    out = Output("--out", tmp_path / "x.rrd")
    again = Output("--out", tmp_path / "sub" / ".." / "x.rrd")
    with output_lock([out]), pytest.raises(OutputBusyError), output_lock([again]):
        pass  # pragma: no cover
    victim = tmp_path / "victim"
    victim.write_text("precious")
    lock_path(out.path).symlink_to(victim)
    with pytest.raises(OutputError, match="lock file"), output_lock([out]):
        pass  # pragma: no cover
    assert victim.read_text() == "precious"


# ---- temporary files ---------------------------------------------------------------------


def test_temporary_files_are_new_unpredictable_and_fit_the_name_limit(tmp_path: Path) -> None:
    target = tmp_path / ("r" * 246 + ".rrd")  # a 250-character name
    first, second = temporary_beside(target), temporary_beside(target)
    assert first != second and first.parent == second.parent == tmp_path
    assert all(len(os.fsencode(p.name)) <= NAME_MAX for p in (first, second))
    write_atomic(target, "whole")
    assert target.read_text() == "whole"


def test_a_run_never_writes_through_a_link_planted_beside_its_output(tmp_path: Path) -> None:
    """The old temporary name `.x.rrd.partial` (and `.x.json.partial`) planted as symlinks to
    a victim: the run records elsewhere and the victim keeps its bytes."""
    scenario = _scenario(tmp_path)
    victim = tmp_path / "victim"
    victim.write_text("precious")
    for name in (".x.rrd.partial", ".x.json.partial", ".x.png.partial"):
        (tmp_path / name).symlink_to(victim)
    result = _invoke("run", scenario, "--out", tmp_path / "x.rrd", "--plot", *SHORT)
    assert result.exit_code == 1, (result.output, result.exception)  # 0.3 s: not completed
    assert victim.read_text() == "precious"
    assert (tmp_path / "x.rrd").stat().st_size > 0 and (tmp_path / "x.png").is_file()
    assert json.loads((tmp_path / "x.json").read_text())["sim_time"] == 0.3
    leftovers = {p.name for p in tmp_path.iterdir()} - {scenario.name, "victim", "x.rrd",
                                                        "x.json", "x.png"}
    assert leftovers == {".x.rrd.partial", ".x.json.partial", ".x.png.partial"}  # planted


def test_a_250_character_output_name_runs(tmp_path: Path) -> None:
    scenario = _scenario(tmp_path)
    out = tmp_path / ("r" * 246 + ".rrd")
    result = _invoke("run", scenario, "--out", out, *SHORT)
    assert result.exit_code == 1, (result.output, result.exception)
    assert out.stat().st_size > 0 and out.with_suffix(".json").is_file()
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        [scenario.name, out.name, out.with_suffix(".json").name])


# ---- a write that fails after the run -----------------------------------------------------


def _failing(code: int) -> Callable[..., None]:
    def fail(*_args: object) -> None:
        raise OSError(code, os.strerror(code))
    return fail


def test_a_full_disk_after_the_run_keeps_the_result_and_exits_4(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    scenario = _scenario(tmp_path)
    monkeypatch.setattr(avsim.outputs, "write_atomic", _failing(errno.ENOSPC))
    line = _one_line_error(_invoke("run", scenario, "--out", tmp_path / "x.rrd", *SHORT),
                           EXIT_OUTPUT)
    assert f"{tmp_path / 'x.json'}: --json: could not be written (No space left" in line
    kept = Path(line.split("the result is kept in ")[1].split(";")[0])
    try:
        assert kept.name.startswith("avsim-result-minimal-") and kept.suffix == ".json"
        assert json.loads(kept.read_text())["sim_time"] == 0.3
    finally:
        kept.unlink()
    assert (tmp_path / "x.rrd").stat().st_size > 0  # the recording was renamed into place


def test_a_read_only_folder_after_the_run_keeps_the_recording_and_exits_4(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    scenario = _scenario(tmp_path)
    monkeypatch.setattr(avsim.outputs, "publish", _failing(errno.EROFS))
    line = _one_line_error(_invoke("run", scenario, "--out", tmp_path / "x.rrd", *SHORT),
                           EXIT_OUTPUT)
    assert "--out: could not be written (Read-only file system)" in line
    assert f"the result is in {tmp_path / 'x.json'}" in line
    partial = Path(line.split("the recording so far is in ")[1])
    assert partial.parent == tmp_path and partial.stat().st_size > 0
    assert not (tmp_path / "x.rrd").exists()
    assert json.loads((tmp_path / "x.json").read_text())["sim_time"] == 0.3


# ---- batches -------------------------------------------------------------------------------


@pytest.mark.parametrize("name", sorted(batch.REPORT_NAMES))
def test_a_run_named_like_a_report_is_refused_at_plan_time(tmp_path: Path, name: str) -> None:
    scenario = _scenario(tmp_path, name)
    with pytest.raises(batch.BatchError, match="is the name of a report"):
        batch.plan([(None, str(scenario), {})], tmp_path / "out", "none")


def test_a_batch_into_its_scenarios_folder_never_writes_over_one(tmp_path: Path) -> None:
    scenario = tmp_path / "x.json"  # a scenario file whose name a run's result would take
    scenario.write_text(MINIMAL.replace("name: minimal", "name: x"), encoding="utf-8")
    with pytest.raises(batch.BatchError, match="is an input of the batch"):
        batch.plan([(None, str(scenario), {})], tmp_path, "none")
    assert batch.plan([(None, str(scenario), {})], tmp_path / "out", "none")


def test_reports_that_cannot_be_written_keep_the_results(tmp_path: Path,
                                                        monkeypatch: pytest.MonkeyPatch) -> None:
    """A full disk when a batch writes its reports: one line and every run's result kept."""
    monkeypatch.setattr(batch, "write_atomic", _failing(errno.ENOSPC))
    job = RunJob("a", "a.yaml", tmp_path)
    outcomes = [RunOutcome(job, Status.BAD_INPUT, error="a.yaml: x: bad")]
    line = batch.reports_written(outcomes, tmp_path,
                                 lambda: batch.write_reports(outcomes, tmp_path, "t", {}))
    assert line is not None and "--out: could not be written (No space left" in line
    kept = Path(line.split("the results are kept in ")[1])
    try:
        assert json.loads(kept.read_text())[0]["error"] == "a.yaml: x: bad"
    finally:
        kept.unlink()
    assert batch.reports_written(outcomes, tmp_path, lambda: None) is None


@pytest.mark.parametrize("command", ["suite", "sweep"])
def test_a_second_batch_into_the_same_folder_is_refused(tmp_path: Path, command: str) -> None:
    """While a batch holds its --out folder (`batch_lock`, as a suite or sweep does from
    before its first run until its reports are written), another suite or sweep into that
    folder, named another way, exits 4 with one line before it runs anything."""
    scenario = _scenario(tmp_path)
    out = tmp_path / "batch"
    values = "0.3" if command == "suite" else "0.3,0.4"  # a sweep sweeps
    args: list[str | Path] = [command, scenario, "--set", f"duration={values}"]
    with batch_lock(out):
        assert sorted(p.name for p in out.iterdir()) == [BATCH_LOCK]
        line = _one_line_error(_invoke(*args, "--out", tmp_path / "x" / ".." / "batch",
                                       "--profile", "none", "--no-snapshots"), EXIT_OUTPUT)
        assert "--out: another avsim command is writing into this folder" in line
        assert sorted(p.name for p in out.iterdir()) == [BATCH_LOCK]
        dry = _invoke(*args, "--out", out, "--profile", "none", "--dry-run")
        assert dry.exit_code == 0, dry.output  # a dry run writes nothing: no lock needed
    assert list(out.iterdir()) == []  # the lock file is removed by its holder


def test_a_batch_lock_is_exclusive_and_its_file_is_never_followed(tmp_path: Path) -> None:
    out = tmp_path / "batch"
    with batch_lock(out), pytest.raises(OutputBusyError), batch_lock(tmp_path / "." / "batch"):
        pass  # pragma: no cover
    with batch_lock(out):  # free again once its holder ended
        pass
    victim = tmp_path / "victim"
    victim.write_text("precious")
    (out / BATCH_LOCK).symlink_to(victim)
    with pytest.raises(OutputError, match="lock file"), batch_lock(out):
        pass  # pragma: no cover
    assert victim.read_text() == "precious"


def test_a_second_snapshot_to_the_same_picture_is_refused(tmp_path: Path) -> None:
    recording = tmp_path / "run.rrd"
    recording.write_bytes(b"a recording")
    png = tmp_path / "pics" / "at_1s.png"
    png.parent.mkdir()
    with output_lock([Output("--out", png)]):  # as the first snapshot holds it
        line = _one_line_error(_invoke("snapshot", recording, "--at", "1", "--out",
                                       tmp_path / "pics" / "." / "at_1s.png"), EXIT_OUTPUT)
        assert "--out: another avsim command is writing this file" in line
        assert sorted(p.name for p in png.parent.iterdir()) == [lock_path(png).name]
    assert list(png.parent.iterdir()) == []

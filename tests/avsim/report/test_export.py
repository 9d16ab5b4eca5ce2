"""`avsim export RUN.rrd --csv|--parquet` (`avsim.report.export`) on a short real run: the
bundled cut_in_out scenario for 3 s without sensors (`--profile none`), recorded by
`avsim run`, read back with Rerun's reader. Columns and row counts, both formats, bad input
(one line, exit 2, nothing written) and no file overwritten unless asked."""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

import numpy as np
import pyarrow as pa  # type: ignore[import-untyped]
import pyarrow.csv as pa_csv  # type: ignore[import-untyped]
import pyarrow.parquet as pq  # type: ignore[import-untyped]
import pytest
from click.testing import CliRunner, Result
from numpy.typing import NDArray

from avsim.cli import main
from world.core.rates import RECORD_RATE

REPO = Path(__file__).parents[3]
SCENARIO = REPO / "scenarios" / "cut_in_out.yaml"
DURATION = 3.0  # [s]
EGO_START = 60 / 3.6  # [m/s] the scenario's initial speed
ACTORS = ("cutter", "oncoming")
EXIT_BAD_INPUT = 2


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("export")
    result = CliRunner().invoke(main, [
        "run", str(SCENARIO), "--profile", "none", "--set", f"duration={DURATION:g}",
        "--out", str(out / "run.rrd"), "--no-progress"])
    assert (out / "run.rrd").is_file(), (result.output, result.exception)
    return out


def _export(*args: str) -> Result:
    return CliRunner().invoke(main, ["export", *args])


def _floats(table: pa.Table, name: str) -> NDArray[np.float64]:
    """A column as floats, an empty cell (CSV) NaN."""
    return np.array([math.nan if x is None else x for x in table.column(name).to_pylist()],
                    dtype=np.float64)


def _files(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir()) if p.is_file()}


def test_csv_has_the_columns_and_a_row_per_recorded_pose(run_dir: Path, tmp_path: Path) -> None:
    out = tmp_path / "deep" / "run.csv"
    result = _export(str(run_dir / "run.rrd"), "--csv", "--out", str(out))
    assert result.exit_code == 0, (result.output, result.exception)
    table = pa_csv.read_csv(out)
    sim_time = json.loads((run_dir / "run.json").read_text())["sim_time"]
    assert table.num_rows == pytest.approx(sim_time * RECORD_RATE.hz, abs=1)
    assert result.output == f"{out}: {table.num_rows} rows, {table.num_columns} columns\n"
    names = table.column_names
    assert names[:11] == ["t", "ego_x", "ego_y", "ego_z", "ego_yaw", "ego_speed", "ego_accel",
                          "ego_lateral_offset", "target_speed", "speed_limit", "steering"]
    assert names[11:15] == ["lead_gap", "lead_speed", "ttc", "d_min"]
    fsm = [n for n in names if n.startswith("fsm_")]
    assert {"fsm_acc", "fsm_motion", "fsm_control", "fsm_speed_source"} <= set(fsm)
    groups = [f"{a}.{c}" for a in ACTORS for c in ("x", "y", "z", "yaw", "kind")]
    assert names[15 + len(fsm):] == groups
    t = table.column("t").to_numpy()
    np.testing.assert_allclose(np.diff(t), 1.0 / RECORD_RATE.hz, atol=1e-9)
    speed = table.column("ego_speed").to_numpy()
    assert speed[0] == pytest.approx(EGO_START, abs=0.5)
    assert set(table.column("cutter.kind").to_pylist()) <= {"car", None}
    assert table.column("fsm_acc").to_pylist()[-1] in {"cruise", "trail", "brake"}
    d_min = table.column("d_min").to_numpy()
    assert np.all(d_min >= 2.0) and np.all(np.isfinite(d_min))


def test_parquet_holds_the_same_table(run_dir: Path, tmp_path: Path) -> None:
    csv, parquet = tmp_path / "a.csv", tmp_path / "a.parquet"
    assert _export(str(run_dir / "run.rrd"), "--csv", "--out", str(csv)).exit_code == 0
    assert _export(str(run_dir / "run.rrd"), "--parquet", "--out", str(parquet)).exit_code == 0
    a, b = pa_csv.read_csv(csv), pq.read_table(parquet)
    assert a.column_names == b.column_names and a.num_rows == b.num_rows
    for name in ("t", "ego_x", "ego_speed", "lead_gap"):
        x, y = _floats(a, name), _floats(b, name)
        np.testing.assert_allclose(x, y, rtol=1e-12, equal_nan=True)
    assert a.column("fsm_motion").to_pylist() == b.column("fsm_motion").to_pylist()


def test_the_default_out_is_beside_the_recording_and_never_overwritten(run_dir: Path,
                                                                       tmp_path: Path) -> None:
    rrd = tmp_path / "r.rrd"
    rrd.write_bytes((run_dir / "run.rrd").read_bytes())
    first = _export(str(rrd), "--parquet")
    assert first.exit_code == 0, first.output
    assert (tmp_path / "r.parquet").is_file()
    before = _files(tmp_path)
    again = _export(str(rrd), "--parquet")  # exists: refused, unchanged
    assert again.exit_code == EXIT_BAD_INPUT and "--force" in again.stderr
    assert _files(tmp_path) == before
    forced = _export(str(rrd), "--parquet", "--force")
    assert forced.exit_code == 0 and sorted(_files(tmp_path)) == sorted(before)
    for out in (str(rrd), str(tmp_path / "." / "r.rrd")):  # the recording itself, even forced
        bad = _export(str(rrd), "--csv", "--out", out, "--force")
        assert bad.exit_code == EXIT_BAD_INPUT and "is an input" in bad.stderr
    assert rrd.read_bytes() == (run_dir / "run.rrd").read_bytes()


@pytest.mark.parametrize("kind", ["missing", "text", "empty", "directory", "fifo"])
def test_bad_input_is_one_line_and_writes_nothing(tmp_path: Path, kind: str) -> None:
    bad = tmp_path / "bad.rrd"
    if kind == "text":
        bad.write_text("not a recording\n", encoding="utf-8")
    elif kind == "empty":
        bad.write_bytes(b"")
    elif kind == "directory":
        bad.mkdir()
    elif kind == "fifo":
        os.mkfifo(bad)
    before = sorted(p.name for p in tmp_path.iterdir())
    result = _export(str(bad), "--csv")
    assert result.exit_code == EXIT_BAD_INPUT, (result.output, result.exception)
    assert result.stdout == ""
    assert result.stderr.count("\n") == 1 and "Traceback" not in result.stderr
    assert result.stderr.startswith(f"avsim: error: {bad}: ")
    assert sorted(p.name for p in tmp_path.iterdir()) == before


def test_a_format_is_required(run_dir: Path) -> None:
    result = _export(str(run_dir / "run.rrd"))
    assert result.exit_code == EXIT_BAD_INPUT and "--csv|--parquet" in result.stderr
    assert result.stderr.count("\n") == 1


def test_time_to_collision_needs_a_closing_lead(run_dir: Path, tmp_path: Path) -> None:
    out = tmp_path / "x.csv"
    assert _export(str(run_dir / "run.rrd"), "--csv", "--out", str(out)).exit_code == 0
    table = pa_csv.read_csv(out)
    gap, ttc = _floats(table, "lead_gap"), _floats(table, "ttc")
    assert all(math.isnan(x) for x in ttc[np.isnan(gap)])  # no lead: no TTC


def test_a_stacks_own_channels_are_columns(tmp_path: Path) -> None:
    """A stack of one's own shows `speed_error` as a channel: the export has it as
    `stack_speed_error` (NaN-free once the stack has ticked), after the other columns."""
    result = CliRunner().invoke(main, [
        "run", str(SCENARIO), "--profile", "none", "--set", f"duration={DURATION:g}",
        "--stack", "tests.avsim.stack.user_stacks:cruise",
        "--out", str(tmp_path / "run.rrd"), "--no-progress"])
    assert (tmp_path / "run.rrd").is_file(), (result.output, result.exception)
    done = _export(str(tmp_path / "run.rrd"), "--csv", "--out", str(tmp_path / "run.csv"))
    assert done.exit_code == 0, done.output
    table = pa_csv.read_csv(tmp_path / "run.csv")
    assert table.column_names[-1] == "stack_speed_error"
    error = _floats(table, "stack_speed_error")
    assert np.isfinite(error[1:]).all() and error[1] == pytest.approx(0.0, abs=1.0)

"""A run's time series as one table (`avsim export RUN.rrd --csv|--parquet`), read back from
its Rerun recording with Rerun's own reader (`rerun.chunk.RrdReader`), for pandas or a
spreadsheet.

One row per recorded ego pose (the recording's rate, `world.core.rates.RECORD_RATE`), in
time order; every other series is the value it held at that row's time (its latest sample at
or before it; empty / NaN before its first). The columns, in this order:

- `t` [s]: sim time.
- The ego, true: `ego_x`, `ego_y`, `ego_z` [m] (map frame, car centre), `ego_yaw` [rad]
  (from its recorded quaternion), `ego_speed` [m/s], `ego_accel` [m/s^2] (0.25 s mean of
  dv/dt, `avsim.report.dynamics`), `ego_lateral_offset` [m] (from the centre of the lane
  the stack keeps, left +), and the plan's `target_speed`, `speed_limit` [m/s] and the
  commanded `steering` [rad].
- The margins the criteria judge: `lead_gap` [m] (bumper gap to the vehicle ahead in the
  ego's lane, from the truth and the map; NaN: none), `lead_speed` [m/s], `ttc` [s] (gap /
  closing speed while the ego closes on it, `world.truth.time_to_collision`), `d_min` [m]
  (UN R157's minimum following distance at the ego's speed). A recording made before these
  were recorded has no lead columns.
- The plan's states: `fsm_<machine>` per recorded state machine (`acc`, `motion`,
  `control`, `speed_source`, ...), the state's name.
- The actors, one column group per actor in the order they first appear, wide: `<id>.x`,
  `<id>.y`, `<id>.z` [m] (box centre, map frame), `<id>.yaw` [rad], `<id>.kind`; empty
  where the actor is not in the world at that time.
- A stack's own diagnostic channels (`avsim.stack.StackStep.channels`, recorded as
  `metrics/stack/<name>`): `stack_<name>`, by name, in the stack's units.

Bounds: at most `MAX_ROWS` rows and `MAX_ACTORS` actors (refused beyond them). A file that
is missing, not a regular file or not a readable recording, or one without the ego's poses,
raises `ExportError(problem)`; nothing is written then. The output is written whole through
a temporary file beside it (`avsim.files.write_atomic`).
"""

from __future__ import annotations

import io
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

import numpy as np
import pyarrow as pa  # type: ignore[import-untyped]
import pyarrow.csv as pa_csv  # type: ignore[import-untyped]
import pyarrow.parquet as pq  # type: ignore[import-untyped]
from numpy.typing import NDArray
from rerun.chunk import RrdReader

from avsim.files import write_atomic
from avsim.record.recorder import ACTOR_CLASSES
from avsim.report import dynamics, margins
from world.truth import time_to_collision

Format = Literal["csv", "parquet"]
TIMELINE = "sim_time"
EGO = "/world/ego"
ACTORS = "/world/actors"
STACK_CHANNELS = "stack/"  # a stack's diagnostic channels under METRICS
METRICS = "/metrics/"
FSM = "/fsm/"
MAX_ROWS = 2_000_000  # rows: a 27-hour run at 20 Hz
MAX_ACTORS = 500  # actors (column groups of five)
METRIC_COLUMNS = {  # recorded metric -> column
    "speed": "ego_speed", "cross_track_error": "ego_lateral_offset",
    "target_speed": "target_speed", "speed_limit": "speed_limit", "steering": "steering",
    "lead_gap": "lead_gap", "lead_speed": "lead_speed",
}
KIND_NAMES = {class_id: kind for kind, (class_id, _) in ACTOR_CLASSES.items()}

FloatArray = NDArray[np.float64]


class ExportError(Exception):
    """The recording cannot be exported: the message says why."""


@dataclass
class Series:
    """Rows of one entity on the `sim_time` timeline: times [ns] and their rows (as dicts of
    the components), in the order the recording has them."""

    times: list[int] = field(default_factory=list)
    rows: list[dict[str, object]] = field(default_factory=list)

    def sorted(self) -> Series:
        order = sorted(range(len(self.times)), key=lambda i: self.times[i])  # stable
        return Series([self.times[i] for i in order], [self.rows[i] for i in order])


def read_series(recording: Path) -> dict[str, Series]:
    """Every entity's rows on the `sim_time` timeline, by entity path, sorted by time."""
    if not recording.exists():
        raise ExportError("no such file")
    if not recording.is_file():
        raise ExportError("not a regular file")
    found: dict[str, Series] = {}
    try:
        for chunk in RrdReader(recording).stream().to_chunks():
            _add_chunk(found, chunk.to_record_batch())
    except (ValueError, RuntimeError, OSError) as err:
        text = str(err).strip().splitlines()
        raise ExportError(f"not a readable Rerun recording: "
                          f"{text[0] if text else type(err).__name__}") from err
    return {path: series.sorted() for path, series in found.items()}


def _add_chunk(found: dict[str, Series], batch: pa.RecordBatch) -> None:
    meta = batch.schema.metadata or {}
    path = meta.get(b"rerun:entity_path", b"").decode()
    if TIMELINE not in batch.schema.names or not path:
        return
    times = batch.column(TIMELINE).cast(pa.int64()).to_pylist()
    names = [n for n in batch.schema.names if ":" in n]
    columns = {n: batch.column(n).to_pylist() for n in names}
    series = found.setdefault(path, Series())
    for i, t in enumerate(times):
        if t is None:
            continue
        series.times.append(int(t))
        series.rows.append({n: columns[n][i] for n in names})
        if len(series.times) > MAX_ROWS:
            raise ExportError(f"{path}: more than {MAX_ROWS} rows")


def _held(times: list[int], grid: NDArray[np.int64]) -> NDArray[np.int64]:
    """Per grid time, the index of the latest sample at or before it (-1: none yet)."""
    out: NDArray[np.int64] = np.searchsorted(np.asarray(times, dtype=np.int64), grid,
                                             side="right") - 1
    return out


def _first(row: dict[str, object], component: str) -> object:
    values = row.get(component)
    return values[0] if isinstance(values, list) and values else None


def _scalar_column(series: Series, grid: NDArray[np.int64]) -> FloatArray:
    idx = _held(series.times, grid)
    values = np.array([_float(_first(r, "Scalars:scalars")) for r in series.rows] + [math.nan])
    out: FloatArray = values[idx]  # -1 picks the trailing NaN
    return out


def _float(x: object) -> float:
    return float(x) if isinstance(x, int | float) else math.nan


def _yaw(q: object) -> float:
    """[rad] the heading of a quaternion (x, y, z, w)."""
    if not isinstance(q, list | tuple) or len(q) != 4:
        return math.nan
    x, y, z, w = (float(c) for c in q)
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def _ego_columns(ego: Series) -> dict[str, FloatArray]:
    xyz = np.array([_first(r, "Transform3D:translation") or [math.nan] * 3 for r in ego.rows],
                   dtype=np.float64).reshape(-1, 3)
    yaw = np.array([_yaw(_first(r, "Transform3D:quaternion")) for r in ego.rows])
    return {"ego_x": xyz[:, 0], "ego_y": xyz[:, 1], "ego_z": xyz[:, 2], "ego_yaw": yaw}


def _state_column(series: Series, grid: NDArray[np.int64]) -> list[str]:
    states = [str(_first(r, "StateChange:state") or "") for r in series.rows]
    return [states[i] if i >= 0 else "" for i in _held(series.times, grid)]


def _actor_ids(actors: Series) -> list[str]:
    ids: dict[str, None] = {}
    for row in actors.rows:
        labels = row.get("Boxes3D:labels") or []
        assert isinstance(labels, list)
        for label in labels:
            ids.setdefault(str(label), None)
            if len(ids) > MAX_ACTORS:
                raise ExportError(f"more than {MAX_ACTORS} actors")
    return list(ids)


def _actor_columns(actors: Series, grid: NDArray[np.int64]) -> dict[str, pa.Array]:
    """Five columns per actor (module doc), from the latest actors' row at each time."""
    ids = _actor_ids(actors)
    n = len(grid)
    xyzw = {a: np.full((n, 4), math.nan) for a in ids}
    kinds: dict[str, list[str | None]] = {a: [None] * n for a in ids}
    for k, i in enumerate(_held(actors.times, grid)):
        if i < 0:
            continue
        row = actors.rows[i]
        labels = row.get("Boxes3D:labels") or []
        centres = row.get("Boxes3D:centers") or []
        quats = row.get("Boxes3D:quaternions") or []
        classes = row.get("Boxes3D:class_ids") or []
        assert isinstance(labels, list) and isinstance(centres, list)
        assert isinstance(quats, list) and isinstance(classes, list)
        for j, label in enumerate(labels):
            a = str(label)
            xyzw[a][k, :3] = centres[j]
            xyzw[a][k, 3] = _yaw(quats[j]) if j < len(quats) else math.nan
            kinds[a][k] = KIND_NAMES.get(int(classes[j]), "other") if j < len(classes) \
                else None
    out: dict[str, pa.Array] = {}
    for a in ids:
        for c, name in enumerate(("x", "y", "z", "yaw")):
            out[f"{a}.{name}"] = pa.array(xyzw[a][:, c], type=pa.float64())
        out[f"{a}.kind"] = pa.array(kinds[a], type=pa.string())
    return out


def run_table(series: dict[str, Series]) -> pa.Table:
    """The table of the module doc from a recording's series (`read_series`)."""
    ego = series.get(EGO)
    if ego is None or not ego.times:
        raise ExportError("no ego poses in the recording (not an avsim run?)")
    grid = np.asarray(ego.times, dtype=np.int64)
    t = grid.astype(np.float64) / 1e9
    columns: dict[str, pa.Array | FloatArray | list[str]] = {"t": t, **_ego_columns(ego)}
    metrics = {path.removeprefix(METRICS): s for path, s in series.items()
               if path.startswith(METRICS)}
    values = {METRIC_COLUMNS[m]: _scalar_column(s, grid) for m, s in metrics.items()
              if m in METRIC_COLUMNS}
    speed = values.get("ego_speed", np.full(len(t), math.nan))
    columns["ego_speed"] = speed
    columns["ego_accel"] = dynamics.acceleration(t, speed)
    for name in ("ego_lateral_offset", "target_speed", "speed_limit", "steering"):
        if name in values:
            columns[name] = values[name]
    if "lead_gap" in values and "lead_speed" in values:
        columns["lead_gap"], columns["lead_speed"] = values["lead_gap"], values["lead_speed"]
        columns["ttc"] = time_to_collision(values["lead_gap"], speed, values["lead_speed"])
    columns["d_min"] = margins.min_gap(np.nan_to_num(speed))
    for path in sorted(p for p in series if p.startswith(FSM)):
        columns[f"fsm_{path.removeprefix(FSM)}"] = _state_column(series[path], grid)
    actors = series.get(ACTORS)
    table = pa.table({k: pa.array(v) if not isinstance(v, pa.Array) else v
                      for k, v in columns.items()})
    if actors is not None and actors.times:
        for name, column in _actor_columns(actors, grid).items():
            table = table.append_column(name, column)
    for m in sorted(m for m in metrics if m.startswith(STACK_CHANNELS)):
        table = table.append_column(f"stack_{m.removeprefix(STACK_CHANNELS)}",
                                    pa.array(_scalar_column(metrics[m], grid)))
    return table


def encode(table: pa.Table, fmt: Format) -> bytes:
    """The table as CSV (a header row, then one line per row; empty cells for none) or
    Parquet."""
    sink = io.BytesIO()
    if fmt == "csv":
        pa_csv.write_csv(table, sink)
    else:
        pq.write_table(table, sink)
    return sink.getvalue()


def export_run(recording: Path, out: Path, fmt: Format) -> pa.Table:
    """Read `recording`, write its table to `out` whole (`write_atomic`); returns the
    table."""
    table = run_table(read_series(recording))
    write_atomic(out, encode(table, fmt))
    return table


def default_out(recording: Path, fmt: Format) -> Path:
    """`RUN.rrd` -> `RUN.csv` / `RUN.parquet` beside it."""
    return recording.with_suffix(f".{fmt}")

"""The recorder writes a valid, complete, reproducible `.rrd`, cheaply.

No PyBullet: a synthetic run (40 Hz, 10 s) logs every kind of data, then the file is checked
with the `rerun` CLI (`rrd verify`, `rrd compare`) and read back with `RrdReader`.
"""

from __future__ import annotations

import math
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
import pytest
from rerun.chunk import RrdReader

from avsim import blueprint as bp
from avsim.recorder import ACTOR_CLASSES, Recorder

RATE = 40.0  # [Hz] logging rate of the synthetic run
N_TICKS = 400  # 10 s at 40 Hz: five 2 s flushes and a final one at close
EVENT_EVERY = 40  # ticks: two events between two flushes
ACTOR_IDS = ("npc_0", "npc_1", "ped_0")
ACTOR_KINDS = ("car", "truck", "pedestrian")
ACTOR_HALF_SIZES = np.array([[2.4, 0.9, 0.75], [4.0, 1.2, 1.5], [0.3, 0.3, 0.9]])  # [m]
LANES = [[[0.0, 1.75, 0.01], [200.0, 1.75, 0.01]], [[0.0, -1.75, 0.01], [200.0, -1.75, 0.01]]]
WHEEL_CENTERS = [[1.35, 0.8, 0.0], [1.35, -0.8, 0.0], [-1.35, 0.8, 0.0], [-1.35, -0.8, 0.0]]


@dataclass(frozen=True)
class FakeMesh:
    """Satisfies `avsim.recorder.MeshLike`, like `world.road_mesh.TexturedMesh`."""

    name: str
    vertices: npt.NDArray[np.float64]
    indices: npt.NDArray[np.int32]
    uvs: npt.NDArray[np.float64]
    normals: npt.NDArray[np.float64]
    texture: npt.NDArray[np.uint8]


@dataclass(frozen=True)
class Logged:
    """What the synthetic run logged, for comparison with what the file holds."""

    times: npt.NDArray[np.float64]  # (n,) [s]
    speed: npt.NDArray[np.float64]  # (n,) [m/s]
    ego_xyz: npt.NDArray[np.float64]  # (n, 3) [m]
    mesh: FakeMesh
    building_centers: npt.NDArray[np.float64]  # (2, 3) [m]


def _road_mesh() -> FakeMesh:
    rng = np.random.default_rng(7)
    return FakeMesh(
        name="road_surface_0_0",
        vertices=np.array([[0, -5, 0.005], [200, -5, 0.005], [200, 5, 0.005], [0, 5, 0.005]]),
        indices=np.array([[0, 1, 2], [0, 2, 3]], dtype=np.int32),
        uvs=np.array([[0.0, 0.0], [0.0, 16.7], [1.0, 16.7], [1.0, 0.0]]),
        normals=np.tile([0.0, 0.0, 1.0], (4, 1)),
        texture=rng.integers(0, 256, size=(24, 40, 3), dtype=np.uint8),
    )


def _ego_xyz(t: float) -> tuple[float, float, float]:
    return (12.0 * t, 0.4 * math.sin(0.5 * t), 0.33)


def write_run(
    path: Path, recording_id: str, speed_bump_at: int | None = None, wall_pause: float = 0.0
) -> Logged:
    """A 10 s synthetic run; `speed_bump_at` changes one speed sample (by 1 mm/s);
    `wall_pause` [s] of wall time is spent after each event, as a slow simulation would."""
    mesh = _road_mesh()
    building_centers = np.array([[30.0, 20.0, 6.0], [80.0, -22.0, 9.0]])
    times = np.array([i / RATE for i in range(N_TICKS)])
    speed = 12.0 + np.sin(times) / 3.0
    if speed_bump_at is not None:
        speed[speed_bump_at] += 1e-3
    with Recorder(path, recording_name="test run", recording_id=recording_id) as rec:
        rec.log_road_meshes([mesh])
        rec.log_static_boxes(
            "/world/buildings",
            building_centers,
            [[5.0, 5.0, 6.0], [6.0, 7.0, 9.0]],
            [[0.0, 0.0, 0.0, 1.0]] * 2,
            [[180, 170, 160]] * 2,
        )
        rec.log_static_lines("/world/map/lanes", LANES, color=(250, 250, 250), radius=0.05)
        rec.log_ego_body(
            body_half_size=(2.4, 0.8, 0.45),
            body_center=(0.0, 0.0, 0.3),
            wheel_centers=WHEEL_CENTERS,
            wheel_radius=0.33,
            wheel_half_width=0.11,
        )
        for i in range(N_TICKS):
            t = i / RATE
            yaw = 0.02 * t
            rec.log_ego_pose(t, _ego_xyz(t), (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)))
            rec.log_scalars(
                t,
                {
                    "speed": float(speed[i]),
                    "target_speed": 12.0,
                    "speed_limit": 13.9,
                    "steering": 0.01 * math.cos(t),
                    "cross_track_error": 0.05 * math.sin(t),
                },
            )
            if i % 4 == 0:
                offsets = ((20.0, 0.0), (45.0, 3.5), (30.0, -6.0))  # [m] ahead, left
                centers = np.array([[12 * t + d, y, 0.8] for d, y in offsets])
                rec.log_actors(
                    t, ACTOR_IDS, centers, ACTOR_HALF_SIZES, np.tile([0, 0, 0, 1.0], (3, 1)),
                    ACTOR_KINDS,
                )  # fmt: skip
                rec.log_path(t, np.column_stack([np.linspace(12 * t, 12 * t + 40, 9), np.zeros(9)]))
            if i % EVENT_EVERY == 0:
                rec.log_event(t, f"tick {i}", "WARN" if i == 200 else "INFO")
                time.sleep(wall_pause)
    ego_xyz = np.array([_ego_xyz(float(t)) for t in times])
    return Logged(times, speed, ego_xyz, mesh, building_centers)


def rerun_cli() -> str:
    """The `rerun` CLI of the interpreter's environment (it matches the SDK version)."""
    beside = Path(sys.executable).parent / "rerun"
    found = str(beside) if beside.exists() else shutil.which("rerun")
    if found is None:
        pytest.fail("the `rerun` CLI (rerun-sdk) is not installed")
    return found


def rrd(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [rerun_cli(), "rrd", *args], capture_output=True, text=True, timeout=120, check=False
    )


@dataclass(frozen=True)
class Column:
    """One component of one entity across all its chunks, in sim_time order."""

    times: npt.NDArray[np.int64] | None  # (n,) [ns] sim_time, None if static
    values: list[Any]  # (n,) one batch (a list) per row
    arrow_type: str  # the stored Arrow type, e.g. "list<item: double>"


def column(path: Path, entity: str, component: str) -> Column:
    chunks = (
        RrdReader(path).store().stream().filter(content=entity, components=component).to_chunks()
    )
    assert chunks, f"no {component} at {entity}"
    batches = [c.to_record_batch() for c in chunks]
    values = [v for b in batches for v in b.column(component).to_pylist()]
    arrow_type = str(batches[0].schema.field(component).type)
    if bp.TIMELINE not in batches[0].schema.names:
        return Column(None, values, arrow_type)
    times = np.concatenate([b.column(bp.TIMELINE).to_numpy().astype(np.int64) for b in batches])
    order = np.argsort(times, kind="stable")
    return Column(times[order], [values[i] for i in order], arrow_type)


def nanos(times: npt.NDArray[np.float64]) -> npt.NDArray[np.int64]:
    """[s] -> [ns] as `RecordingStream.set_time(duration=t)` converts: round(1e9 * t)."""
    return np.array([round(1e9 * float(t)) for t in times], dtype=np.int64)


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Logged]:
    path = tmp_path_factory.mktemp("rec") / "run.rrd"
    return path, write_run(path, recording_id="test-recorder-0")


def test_file_verifies(run: tuple[Path, Logged]) -> None:
    path, _ = run
    result = rrd("verify", str(path))
    assert result.returncode == 0, result.stderr


def test_speed_series_reads_back_exactly(run: tuple[Path, Logged]) -> None:
    path, logged = run
    # Precondition that makes the time check sharp: for some ticks, truncating 1e9 * t (what
    # rr.TimeColumn does with a float array) differs from rounding it.
    truncated = (logged.times * 1e9).astype(np.int64)
    assert np.any(truncated != nanos(logged.times))

    speed = column(path, f"{bp.METRICS}/speed", "Scalars:scalars")
    assert speed.arrow_type == "list<item: double>"  # float64 stored: values compare exactly
    assert speed.times is not None
    np.testing.assert_array_equal(speed.times, nanos(logged.times))
    np.testing.assert_array_equal(np.array([row[0] for row in speed.values]), logged.speed)


def test_ego_pose_reads_back_as_float32(run: tuple[Path, Logged]) -> None:
    path, logged = run
    pose = column(path, bp.EGO, "Transform3D:translation")
    assert pose.times is not None
    np.testing.assert_array_equal(pose.times, nanos(logged.times))
    xyz = np.array([row[0] for row in pose.values])
    np.testing.assert_array_equal(xyz, logged.ego_xyz.astype(np.float32))


def test_static_world_is_present(run: tuple[Path, Logged]) -> None:
    path, logged = run
    mesh = logged.mesh
    road = f"{bp.ROAD}/{mesh.name}"
    vertices = column(path, road, "Mesh3D:vertex_positions")
    assert vertices.times is None  # static
    np.testing.assert_array_equal(vertices.values[0], mesh.vertices.astype(np.float32))
    texcoords = column(path, road, "Mesh3D:vertex_texcoords")
    np.testing.assert_array_equal(texcoords.values[0], mesh.uvs.astype(np.float32))
    texture = column(path, road, "Mesh3D:albedo_texture_buffer")
    assert bytes(texture.values[0][0]) == mesh.texture.tobytes()

    buildings = column(path, "/world/buildings", "Boxes3D:centers")
    assert buildings.times is None
    np.testing.assert_array_equal(buildings.values[0], logged.building_centers.astype(np.float32))
    wheels = column(path, bp.EGO_WHEELS, "Boxes3D:centers")
    assert wheels.times is None
    np.testing.assert_array_equal(wheels.values[0], np.array(WHEEL_CENTERS, np.float32))
    lanes = column(path, "/world/map/lanes", "LineStrips3D:strips")
    assert lanes.times is None
    np.testing.assert_array_equal(lanes.values[0], np.array(LANES, np.float32))
    style = column(path, f"{bp.METRICS}/speed", "SeriesLines:names")
    assert style.times is None
    assert style.values == [["speed [m/s]"]]


def test_actors_path_and_events(run: tuple[Path, Logged]) -> None:
    path, _ = run
    labels = column(path, bp.ACTORS, "Boxes3D:labels")
    assert len(labels.values) == N_TICKS // 4
    assert labels.values[0] == list(ACTOR_IDS)
    class_ids = column(path, bp.ACTORS, "Boxes3D:class_ids")
    assert class_ids.values[-1] == [ACTOR_CLASSES[kind][0] for kind in ACTOR_KINDS]
    strips = column(path, bp.PLAN_PATH, "LineStrips3D:strips")
    assert len(strips.values) == N_TICKS // 4
    assert len(strips.values[0][0]) == 9  # one strip of 9 points per row
    events = column(path, bp.EVENTS, "TextLog:text")
    ticks = range(0, N_TICKS, EVENT_EVERY)
    assert events.values == [[f"tick {i}"] for i in ticks]
    assert events.times is not None
    np.testing.assert_array_equal(events.times, nanos(np.array([i / RATE for i in ticks])))
    levels = column(path, bp.EVENTS, "TextLog:level")
    assert levels.values == [["WARN" if i == 200 else "INFO"] for i in ticks]


def test_default_blueprint_tracks_the_chase_camera(run: tuple[Path, Logged]) -> None:
    path, _ = run
    reader = RrdReader(path)
    (blueprint,) = reader.blueprints()
    tracked = [
        value
        for chunk in reader.stream(store=blueprint).to_chunks()
        if chunk.entity_path.endswith("/EyeControls3D")
        for value in chunk.to_record_batch().column("EyeControls3D:tracking_entity").to_pylist()
    ]
    assert tracked == [[bp.CHASE_CAMERA]]
    pinhole = column(path, bp.CHASE_CAMERA, "Pinhole:image_from_camera")
    assert pinhole.times is None  # static, rigidly attached to the car


def chunk_layout(path: Path) -> list[tuple[str, int]]:
    """(entity path, rows) of every chunk of the recording, in file order."""
    return [(c.entity_path, c.num_rows) for c in RrdReader(path).stream().to_chunks()]


def test_same_inputs_same_recording(run: tuple[Path, Logged], tmp_path: Path) -> None:
    path, _ = run
    # A slower run (wall-clock pauses longer than the SDK's default 200 ms batching tick)
    # must give the same data in the same chunks: the recorder batches by sim time only.
    again = tmp_path / "again.rrd"
    write_run(again, recording_id="test-recorder-0", wall_pause=0.25)
    result = rrd("compare", str(path), str(again))
    assert result.returncode == 0, result.stderr[-2000:]
    assert chunk_layout(again) == chunk_layout(path)

    # ... and the comparison can fail: one speed sample 1 mm/s off.
    bumped = tmp_path / "bumped.rrd"
    write_run(bumped, recording_id="test-recorder-0", speed_bump_at=123)
    assert rrd("compare", str(path), str(bumped)).returncode != 0


def test_close_is_idempotent_and_exceptions_still_give_a_valid_file(tmp_path: Path) -> None:
    path = tmp_path / "crashed.rrd"

    class BoomError(Exception):
        pass

    with pytest.raises(BoomError), Recorder(path, recording_id="crash") as rec:
        for i in range(30):
            rec.log_scalars(i / RATE, {"speed": float(i)})
        raise BoomError  # buffered samples (all 30: no 2 s flush yet) must still reach the file
    assert rec.closed
    rec.close()  # again: no error
    with pytest.raises(RuntimeError):
        rec.log_scalars(1.0, {"speed": 1.0})
    assert rrd("verify", str(path)).returncode == 0
    speed = column(path, f"{bp.METRICS}/speed", "Scalars:scalars")
    assert [row[0] for row in speed.values] == list(range(30))

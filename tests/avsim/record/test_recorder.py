"""The recorder writes a valid, complete, reproducible `.rrd`, cheaply.

No PyBullet: a synthetic run (40 Hz, 10 s) logs the world, ego and plan data, and a synthetic
minute of the `default` sensor profile (camera JPEGs, LiDAR, tracks, detections, lane lines,
FSM states) checks the sensor and perception data and the file size (<= 10 MB a simulated
minute). The files are checked with the `rerun` CLI (`rrd verify`, `rrd compare`) and read
back with `RrdReader`.
"""

from __future__ import annotations

import io
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
import PIL.Image
import pytest
from rerun.chunk import RrdReader

from avsim.record import blueprint as bp
from avsim.record.recorder import (
    ACTOR_CLASSES,
    TRACK_CLASSES,
    VELOCITY_HORIZON,
    Recorder,
    _rpy_quaternion,
)

RATE = 40.0  # [Hz] logging rate of the synthetic run
FLUSH = 2.0  # [s] the recorder's flush interval here (not its default): several flushes
N_TICKS = 400  # 10 s at 40 Hz: five 2 s flushes and a final one at close
EVENT_EVERY = 40  # ticks: two events between two flushes
ACTOR_IDS = ("npc_0", "npc_1", "ped_0")
ACTOR_KINDS = ("car", "truck", "pedestrian")
ACTOR_HALF_SIZES = np.array([[2.4, 0.9, 0.75], [4.0, 1.2, 1.5], [0.3, 0.3, 0.9]])  # [m]
LANES = [[[0.0, 1.75, 0.01], [200.0, 1.75, 0.01]], [[0.0, -1.75, 0.01], [200.0, -1.75, 0.01]]]
WHEEL_CENTERS = [[1.35, 0.8, 0.0], [1.35, -0.8, 0.0], [-1.35, 0.8, 0.0], [-1.35, -0.8, 0.0]]


@dataclass(frozen=True)
class FakeMesh:
    """Satisfies `avsim.record.recorder.MeshLike`, like `world.scene.road_mesh.TexturedMesh`."""

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
    with Recorder(path, recording_name="test run", recording_id=recording_id,
                  flush_interval=FLUSH) as rec:
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
        raise BoomError  # buffered samples (all 30: no flush yet) must still reach the file
    assert rec.closed
    rec.close()  # again: no error
    with pytest.raises(RuntimeError):
        rec.log_scalars(1.0, {"speed": 1.0})
    assert rrd("verify", str(path)).returncode == 0
    speed = column(path, f"{bp.METRICS}/speed", "Scalars:scalars")
    assert [row[0] for row in speed.values] == list(range(30))


# -- sensors, perception and FSM: a synthetic minute of the `default` sensor profile ---------

PROFILE_SECONDS = 60  # [s] simulated
PROFILE_RATE = 20  # [Hz] pose and scalars; actors, path, tracks, detections, lanes at half
CAMERAS = {  # name -> ((H, W) [px], logging period [s])
    "front": ((480, 640), 0.5),
    "left": ((240, 320), 2.0),
    "right": ((240, 320), 2.0),
}
MOUNTS = {  # name -> (xyz [m] vehicle frame, z from the ground; roll, pitch, yaw [rad])
    "front": ((1.9, 0.0, 1.45), (0.0, 0.08, 0.0)),
    "left": ((0.6, 0.9, 1.3), (0.0, 0.1, math.pi / 2)),
    "right": ((0.6, -0.9, 1.3), (0.0, 0.1, -math.pi / 2)),
}
RIDE_HEIGHT = 0.33  # [m] base link origin above the ground
LIDAR_PERIOD = 1.0  # [s]
LIDAR_RINGS, LIDAR_COLUMNS = 16, 313  # 5,008 points a scan
N_TRACKS = 6  # at every perception tick but the first (no tracks: the clear case)
TRACK_KINDS = ("car", "truck", "pedestrian", "car", "cyclist", "bus")  # "bus": unknown kind
MAX_BYTES_PER_MINUTE = 10_000_000  # acceptance: a default recording is <= 10 MB a sim minute
STATES = (  # (t [s], machine, state, reason)
    (0.0, "lane_source", "ACQUIRING", None),
    (1.5, "lane_source", "CAMERA", "both boundaries seen"),
    (20.0, "acc", "FOLLOW", "lead at 35 m"),
    (41.0, "lane_source", "MAP", "camera lost the lane"),
)


@dataclass(frozen=True)
class ProfileLogged:
    """What the synthetic profile run logged, for comparison with what the file holds."""

    images: dict[str, int]  # camera name -> images logged
    lidar_scans: int
    lidar_first: tuple[npt.NDArray[np.float64], npt.NDArray[np.uint8]]  # points, colours
    perception_ticks: int  # tracks, detections, lanes
    tracks_last: tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]  # centres, velocity


class ImageSource:
    """Smooth synthetic camera images: a colour gradient plus sensor-like noise (sigma 6 grey
    levels; a fresh window of a noise bank each frame, so no two frames are equal)."""

    PAD = 64  # [px] margin of the noise bank: the range of the windows' offsets

    def __init__(self, height: int, width: int, seed: int) -> None:
        rng = np.random.default_rng(seed)
        noise = rng.normal(0.0, 6.0, (height + self.PAD, width + self.PAD, 3))
        self.noise = np.round(noise).astype(np.int16)
        v, u = np.mgrid[0:height, 0:width] / np.array([height, width])[:, None, None]
        wave = 0.5 + 0.5 * np.sin(2.0 * np.pi * u)
        base = np.stack([90 + 120 * v, 100 + 80 * wave, 200 - 120 * v], axis=-1)
        self.base = np.round(base).astype(np.int16)
        self.frames = 0

    def frame(self) -> npt.NDArray[np.uint8]:
        h, w, _ = self.base.shape
        dy, dx = (7 * self.frames) % self.PAD, (13 * self.frames) % self.PAD
        self.frames += 1
        return np.clip(self.base + self.noise[dy : dy + h, dx : dx + w], 0, 255).astype(np.uint8)


def lidar_scan(
    t: float, rng: np.random.Generator
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.uint8]]:
    """A VLP-16-like scan in the map frame: rings on the ground and on walls 20 m to either
    side of the road (2 cm range noise), coloured by height."""
    elevations = np.radians(np.arange(-15, 16, 2))[:, None]  # (16, 1) [rad]
    azimuths = np.linspace(-np.pi, np.pi, LIDAR_COLUMNS, endpoint=False)[None, :]
    height = 1.8  # [m] of the sensor above the ground
    down = np.minimum(elevations, -1e-3)
    ground = np.where(elevations < 0, height / np.tan(-down), np.inf)
    wall = 20.0 / np.maximum(np.abs(np.sin(azimuths)), 1e-3) / np.cos(elevations)
    ranges = np.minimum(np.minimum(ground, wall), 100.0) + rng.normal(0.0, 0.02, (16, 313))
    flat = ranges * np.cos(elevations)
    x, y = flat * np.cos(azimuths) + 12.0 * t, flat * np.sin(azimuths)
    points = np.stack([x, y, height + ranges * np.sin(elevations)], axis=-1).reshape(-1, 3)
    red = np.clip(points[:, 2] * 60.0, 0, 255)
    colors = np.column_stack([red, np.full(len(points), 128), 255 - red]).astype(np.uint8)
    return points, colors


def track_state(t: float) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Centres (N_TRACKS, 3) [m] and velocities (N_TRACKS, 2) [m/s] of the synthetic tracks."""
    k = np.arange(N_TRACKS)
    velocity = np.column_stack([10.0 + k, 0.2 * np.sin(0.3 * t + k)])
    x = 12.0 * t + 15.0 + 8.0 * k
    centers = np.column_stack([x, 3.5 * (k % 3 - 1), np.full(N_TRACKS, 0.8)])
    return centers, velocity


def log_perception(rec: Recorder, t: float, first: bool) -> None:
    """Tracks (none if `first`), detections and three lane lines of one perception tick."""
    n = 0 if first else N_TRACKS
    centers, velocity = track_state(t)
    half_sizes = np.tile([2.3, 0.9, 0.75], (n, 1))
    yaws = np.full(n, 0.01 * t)
    kinds = TRACK_KINDS[:n]
    rec.log_tracks(t, range(1, n + 1), centers[:n], half_sizes, yaws, velocity[:n], kinds)
    rec.log_detections(t, centers[:n] + 0.1, half_sizes, yaws, kinds)
    x = np.linspace(12.0 * t, 12.0 * t + 40.0, 20)
    strips = [np.column_stack([x, np.full(20, y), np.full(20, 0.02)]) for y in (1.75, 0, -1.75)]
    rec.log_lane_lines(t, strips, [(255, 255, 255), (0, 200, 255), (255, 255, 255)])


def log_camera(rec: Recorder, t: float, name: str, source: ImageSource) -> None:
    (height, width), _ = CAMERAS[name]
    f = 0.5 * width / math.tan(math.radians(40.0))  # [px]: 80 deg horizontal field of view
    xyz, rpy = MOUNTS[name]
    rec.log_camera_image(
        t, name, source.frame(), f, f, 0.5 * width, 0.5 * height,
        mount_xyz=xyz, mount_rpy=rpy, ride_height=RIDE_HEIGHT,
    )  # fmt: skip


def log_vehicle(rec: Recorder, tick: int) -> None:
    """Pose and scalars at every tick; actors and the path at every second one."""
    t = tick / PROFILE_RATE
    rec.log_ego_pose(t, _ego_xyz(t), (0.0, 0.0, 0.0, 1.0))
    speed = {"speed": 12.0 + math.sin(t), "target_speed": 12.0, "speed_limit": 13.9}
    rec.log_scalars(t, {**speed, "steering": 0.01 * math.cos(t), "cross_track_error": 0.1})
    if tick % 2 == 0:
        centers = np.array([[12 * t + 20.0, 0.0, 0.8], [12 * t + 45, 3.5, 0.8]])
        quaternions = np.tile([0, 0, 0, 1.0], (2, 1))
        rec.log_actors(t, ["a", "b"], centers, ACTOR_HALF_SIZES[:2], quaternions, ["car"] * 2)
        rec.log_path(t, np.column_stack([np.linspace(12 * t, 12 * t + 40, 9), np.zeros(9)]))


def due(tick: int, period: float) -> bool:
    """Whether something logged every `period` [s] is due at `tick` of PROFILE_RATE."""
    return tick % round(period * PROFILE_RATE) == 0


def write_profile_run(path: Path) -> ProfileLogged:
    """A 60 s synthetic run of the `default` profile (see the constants above)."""
    sources = {
        name: ImageSource(*size, seed=seed)
        for seed, (name, (size, _)) in enumerate(CAMERAS.items())
    }
    states = {round(t * PROFILE_RATE): (machine, state, why) for t, machine, state, why in STATES}
    rng = np.random.default_rng(11)
    first_scan = lidar_scan(0.0, rng)
    with Recorder(path, recording_name="profile", recording_id="test-profile") as rec:
        rec.log_state_machine("lane_source", ["ACQUIRING", "CAMERA", "MAP"])
        for tick in range(PROFILE_SECONDS * PROFILE_RATE):
            t = tick / PROFILE_RATE
            log_vehicle(rec, tick)
            if due(tick, 0.1):
                log_perception(rec, t, first=tick == 0)
            for name, (_, period) in CAMERAS.items():
                if due(tick, period):
                    log_camera(rec, t, name, sources[name])
            if due(tick, LIDAR_PERIOD):
                rec.log_lidar(t, *(first_scan if tick == 0 else lidar_scan(t, rng)))
            if tick in states:
                rec.log_state(t, *states[tick])
    last_t = (PROFILE_SECONDS * PROFILE_RATE - 2) / PROFILE_RATE
    return ProfileLogged(
        images={name: source.frames for name, source in sources.items()},
        lidar_scans=round(PROFILE_SECONDS / LIDAR_PERIOD),
        lidar_first=first_scan,
        perception_ticks=PROFILE_SECONDS * 10,
        tracks_last=track_state(last_t),
    )


@pytest.fixture(scope="module")
def profile_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, ProfileLogged]:
    path = tmp_path_factory.mktemp("profile") / "profile.rrd"
    return path, write_profile_run(path)


def test_profile_file_verifies_and_is_small(profile_run: tuple[Path, ProfileLogged]) -> None:
    path, _ = profile_run
    result = rrd("verify", str(path))
    assert result.returncode == 0, result.stderr
    size = path.stat().st_size  # [bytes] for PROFILE_SECONDS of simulated time
    per_minute = size * 60 / PROFILE_SECONDS
    assert per_minute <= MAX_BYTES_PER_MINUTE, f"{per_minute:,.0f} bytes per simulated minute"


def test_camera_images_read_back(profile_run: tuple[Path, ProfileLogged]) -> None:
    path, logged = profile_run
    for name, ((height, width), period) in CAMERAS.items():
        entity = bp.camera_entity(name)
        blobs = column(path, entity, "EncodedImage:blob")
        assert len(blobs.values) == logged.images[name] == PROFILE_SECONDS / period
        assert blobs.times is not None
        np.testing.assert_array_equal(blobs.times, nanos(np.arange(len(blobs.values)) * period))
        media = column(path, entity, "EncodedImage:media_type")
        assert {row[0] for row in media.values} == {"image/jpeg"}
        with PIL.Image.open(io.BytesIO(bytes(blobs.values[-1][0]))) as image:
            assert (image.format, image.size, image.mode) == ("JPEG", (width, height), "RGB")

        pinhole = column(path, entity, "Pinhole:image_from_camera")
        assert pinhole.times is None  # static, logged once
        matrix = np.array(pinhole.values[0][0]).reshape(3, 3).T  # stored column-major
        f = 0.5 * width / math.tan(math.radians(40.0))
        np.testing.assert_allclose(matrix, [[f, 0, width / 2], [0, f, height / 2], [0, 0, 1]])
        resolution = column(path, entity, "Pinhole:resolution")
        assert resolution.values == [[[width, height]]]
        mount = column(path, entity, "Transform3D:translation")
        assert mount.times is None
        xyz, _ = MOUNTS[name]
        np.testing.assert_allclose(mount.values[0][0], [*xyz[:2], xyz[2] - RIDE_HEIGHT], 1e-6)


def test_camera_mount_rotation() -> None:
    """The mount quaternion turns the camera's x axis (its optical axis) like the URDF's
    R = Rz(yaw) Ry(pitch) Rx(roll): the left camera looks left and a little down."""
    x, y, z, w = _rpy_quaternion(0.0, 0.1, math.pi / 2)
    axis = np.array([1 - 2 * (y * y + z * z), 2 * (x * y + z * w), 2 * (x * z - y * w)])
    np.testing.assert_allclose(axis, [0.0, math.cos(0.1), -math.sin(0.1)], atol=1e-12)


def test_lidar_reads_back(profile_run: tuple[Path, ProfileLogged]) -> None:
    path, logged = profile_run
    positions = column(path, bp.LIDAR, "Points3D:positions")
    assert len(positions.values) == logged.lidar_scans
    points, colors = logged.lidar_first
    assert len(points) == LIDAR_RINGS * LIDAR_COLUMNS
    np.testing.assert_array_equal(positions.values[0], points.astype(np.float32))
    stored_colors = column(path, bp.LIDAR, "Points3D:colors")
    rgba = np.array(stored_colors.values[0], dtype=np.uint32)  # 0xRRGGBBAA
    np.testing.assert_array_equal(rgba >> 24, colors[:, 0])


def test_tracks_read_back(profile_run: tuple[Path, ProfileLogged]) -> None:
    path, logged = profile_run
    labels = column(path, bp.TRACK_BOXES, "Boxes3D:labels")
    centers = column(path, bp.TRACK_BOXES, "Boxes3D:centers")
    assert len(centers.values) == logged.perception_ticks
    assert centers.values[0] == []  # the first tick had no tracks: the view is cleared
    assert labels.values[-1] == [f"id {k}" for k in range(1, N_TRACKS + 1)]
    class_ids = column(path, bp.TRACK_BOXES, "Boxes3D:class_ids")
    other = TRACK_CLASSES["other"][0]
    assert class_ids.values[-1] == [TRACK_CLASSES.get(k, (other,))[0] for k in TRACK_KINDS]
    last_centers, last_velocity = logged.tracks_last
    np.testing.assert_allclose(centers.values[-1], last_centers, rtol=1e-6)

    vectors = column(path, bp.TRACK_VELOCITY, "Arrows3D:vectors")
    assert len(vectors.values) == logged.perception_ticks
    expected = np.column_stack([last_velocity * VELOCITY_HORIZON, np.zeros(N_TRACKS)])
    np.testing.assert_allclose(vectors.values[-1], expected, rtol=1e-6, atol=1e-6)
    origins = column(path, bp.TRACK_VELOCITY, "Arrows3D:origins")
    np.testing.assert_allclose(origins.values[-1], last_centers, rtol=1e-6)


def test_detections_and_lane_lines_read_back(profile_run: tuple[Path, ProfileLogged]) -> None:
    path, logged = profile_run
    detections = column(path, bp.DETECTIONS, "Boxes3D:centers")
    assert len(detections.values) == logged.perception_ticks
    assert detections.values[0] == []
    assert len(detections.values[-1]) == N_TRACKS
    lanes = column(path, bp.LANE_LINES, "LineStrips3D:strips")
    assert len(lanes.values) == logged.perception_ticks
    assert all(len(row) == 3 and len(row[0]) == 20 for row in lanes.values)
    colors = column(path, bp.LANE_LINES, "LineStrips3D:colors")
    assert colors.values[0] == [0xFFFFFFFF, 0x00C8FFFF, 0xFFFFFFFF]


def test_states_read_back_in_order(profile_run: tuple[Path, ProfileLogged]) -> None:
    path, _ = profile_run
    for machine in ("lane_source", "acc"):
        changes = column(path, f"{bp.FSM_ROOT}/{machine}", "StateChange:state")
        expected = [(t, state) for t, m, state, _ in STATES if m == machine]
        assert changes.values == [[state] for _, state in expected]
        assert changes.times is not None
        np.testing.assert_array_equal(changes.times, nanos(np.array([t for t, _ in expected])))
    config = column(path, f"{bp.FSM_ROOT}/lane_source", "StateConfiguration:values")
    assert config.times is None
    assert config.values == [["ACQUIRING", "CAMERA", "MAP"]]
    events = column(path, bp.EVENTS, "TextLog:text")
    assert [row[0] for row in events.values] == [
        "lane_source: ACQUIRING",
        "lane_source: CAMERA (both boundaries seen)",
        "acc: FOLLOW (lead at 35 m)",
        "lane_source: MAP (camera lost the lane)",
    ]


def test_bad_sensor_input_is_rejected(tmp_path: Path) -> None:
    with Recorder(tmp_path / "bad.rrd", recording_id="bad") as rec:
        with pytest.raises(ValueError, match="rgb"):
            rec.log_camera_image(0.0, "front", np.zeros((4, 4, 3)), 1.0, 1.0, 2.0, 2.0)  # float
        with pytest.raises(ValueError, match="colors"):
            rec.log_lidar(0.0, np.zeros((5, 3)), np.zeros((4, 3), np.uint8))
        with pytest.raises(ValueError, match="velocities"):
            rec.log_tracks(0.0, [1], [[0, 0, 0]], [[1, 1, 1]], [0.0], [[1, 2, 3, 4]], ["car"])
        with pytest.raises(ValueError, match="kinds"):
            rec.log_tracks(0.0, [1], [[0, 0, 0]], [[1, 1, 1]], [0.0], [[1, 2]], [])
        with pytest.raises(ValueError, match="colors"):
            rec.log_lane_lines(0.0, [np.zeros((2, 3))] * 2, [(1, 2, 3)] * 3)
        with pytest.raises(ValueError, match="machine"):
            rec.log_state(0.0, "a/b", "X")


def test_infractions_are_logged_at_their_time_and_place(tmp_path: Path) -> None:
    """Each infraction is an ERROR line at /events at its sim time; one with a place adds a
    marker at /world/infractions, which then shows every infraction placed so far."""
    path = tmp_path / "infractions.rrd"
    with Recorder(path, recording_id="infractions") as rec:
        rec.log_event(0.5, "an ordinary event")
        rec.log_infraction(1.25, "speed_limit", "speed 55.0 km/h over the limit", (12.0, -1.5))
        rec.log_infraction(2.0, "completes", "nowhere in particular", None)
        rec.log_infraction(3.5, "no_collision", "collision with actor lead", (40.0, 0.25))
    events = column(path, bp.EVENTS, "TextLog:text")
    assert [row[0] for row in events.values] == [
        "an ordinary event", "speed_limit: speed 55.0 km/h over the limit",
        "completes: nowhere in particular", "no_collision: collision with actor lead"]
    assert events.times is not None
    np.testing.assert_array_equal(events.times, nanos(np.array([0.5, 1.25, 2.0, 3.5])))
    levels = column(path, bp.EVENTS, "TextLog:level")
    assert [row[0] for row in levels.values] == ["INFO", "ERROR", "ERROR", "ERROR"]
    markers = column(path, bp.INFRACTIONS, "Points3D:positions")
    assert markers.times is not None
    np.testing.assert_array_equal(markers.times, nanos(np.array([1.25, 3.5])))
    first, both = (np.array(row) for row in markers.values)
    np.testing.assert_allclose(first[:, :2], [[12.0, -1.5]])
    np.testing.assert_allclose(both[:, :2], [[12.0, -1.5], [40.0, 0.25]])
    labels = column(path, bp.INFRACTIONS, "Points3D:labels")
    assert labels.values == [["speed_limit"], ["speed_limit", "no_collision"]]

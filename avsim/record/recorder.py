"""One Rerun `.rrd` per run, written cheaply.

A `rerun` log call costs too much to make on every physics or control tick at the real-time
factors a run needs. So the time series (ego pose, scalars, actor boxes, planned path) are
*buffered* in numpy arrays and sent as columns (`RecordingStream.send_columns`) every
`FLUSH_INTERVAL` of simulated time and at `close()`; so are the perception outputs (tracks,
detections, lane lines). Static things (road meshes, buildings, the ego's body, series
styles, camera intrinsics and mounts) are logged once. Events, FSM state changes, camera
images and LiDAR scans come at low rates and are logged directly.

The flush interval sets the number of chunks, and the SDK keeps ~2-3 kB of metadata per
chunk in memory until `close()` (the manifest it writes in the file's footer, which viewers
need for random access): at a 2 s interval the town loop's ~10 entities made 300 chunks a
simulated minute, ~1 MB a minute of memory that never came back. Every 30 s it is ~20 chunks
a minute (~4 MB over an hour's run), and what waits for a flush stays small: 30 s
of camera images and scans is a few MB at the `fast` profile's rates.

Size is the caller's to choose, by its rates and point counts: camera images are
JPEG-compressed (`JPEG_QUALITY`), and a LiDAR point costs 12 bytes (float32 x, y, z; 16 with
a colour).

All temporal data sits on one duration timeline, `sim_time` [s] (converted to integer
nanoseconds by rounding, exactly like `RecordingStream.set_time(duration=...)`).

Reproducible files: log time is disabled, and the SDK's chunk batcher never flushes on its
own (`ChunkBatcherConfig.NEVER`); the recorder flushes it at the same sim-time points as the
columns. So chunk boundaries depend on sim time only, never on wall-clock speed, and two runs
with the same inputs and recording id give recordings that `rerun rrd compare` finds equal.

Entity paths (constants in `avsim.record.blueprint`), map frame z up, SI units:

| path | archetype | when |
|---|---|---|
| `/world` | ViewCoordinates RIGHT_HAND_Z_UP | static |
| `/world/road/<name>` | Mesh3D, textured (albedo texture + texcoords) | static |
| caller's path, e.g. `/world/buildings` | Boxes3D, solid | static |
| `/world/ego` | Transform3D: car frame in map frame | buffered, every call |
| `/world/ego/body`, `/world/ego/wheels` | Boxes3D in the car frame | static |
| `/world/ego/chase_camera` | Transform3D + invisible Pinhole: the chase view's eye | static |
| `/world/ego/camera_<name>` | Transform3D (mount) + Pinhole; EncodedImage (JPEG) | static; direct |
| `/world/actors` | Boxes3D, labels = ids, class (colour) = kind | buffered |
| `/world/plan/path` | LineStrips3D | buffered |
| `/world/lidar` | Points3D, map frame | direct |
| `/world/tracks` | AnnotationContext: track class colours | static |
| `/world/tracks/boxes` | Boxes3D, labels "id <n>", class = kind, transparent fill | buffered |
| `/world/tracks/velocity` | Arrows3D from box centres, `VELOCITY_HORIZON` of motion | buffered |
| `/world/perception/lanes` | LineStrips3D: detected lane lines | buffered |
| `/world/perception/detections` | Boxes3D wireframes, class = kind | buffered |
| `/world/infractions` | Points3D: every infraction so far where it was, label = kind | direct |
| `/metrics/<name>` | Scalars; SeriesLines (name, colour) | buffered; style static |
| `/fsm/<machine>` | StateChange; StateConfiguration (optional) | direct; static |
| `/events` | TextLog: events, FSM state changes, infractions (ERROR) | direct |

"Direct" data is logged with `RecordingStream.log` but, like all batched log calls, only
becomes chunks at the sim-time flushes.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import TracebackType
from typing import Any, NamedTuple, Protocol, Self
from uuid import uuid4

import numpy as np
import numpy.typing as npt
import rerun as rr

from avsim.record import blueprint as bp
from avsim.record.blueprint import default_blueprint

FloatArray = npt.NDArray[np.float64]
Rgb = tuple[int, int, int]  # [0..255]

FLUSH_INTERVAL = 30.0  # [s] of sim time between sends of the buffered columns (and the
#   SDK's batched log calls): the chunks' length, their count sets the SDK's memory
NANOS_PER_SECOND = 1e9  # [ns/s]
INITIAL_ROWS = 256  # [-] rows a buffer holds before it first grows (it doubles)

# -- the chase camera: rigidly attached to the car, looking forward and down ----------------
CHASE_OFFSET = (-12.0, 0.0, 5.0)  # [m] car frame: behind and above the car origin
CHASE_PITCH = math.radians(15.0)  # [rad] nose down
CHASE_FOV_Y = math.radians(50.0)  # [rad] vertical field of view
CHASE_ASPECT = 4.0  # [-] wider than any view, so the frustum's sides fall outside it

# -- styles ---------------------------------------------------------------------------------
ACTOR_CLASSES: dict[str, tuple[int, Rgb]] = {  # kind -> (class id, colour)
    "other": (0, (150, 150, 150)),
    "car": (1, (66, 135, 245)),
    "truck": (2, (40, 80, 200)),
    "pedestrian": (3, (245, 180, 30)),
    "cyclist": (4, (240, 120, 40)),
    "obstacle": (5, (200, 60, 60)),
    "motorcycle": (6, (120, 200, 250)),
}
SERIES_STYLES: dict[str, tuple[str, Rgb]] = {  # metric -> (label with unit, colour)
    "speed": ("speed [m/s]", (31, 119, 180)),
    "target_speed": ("target speed [m/s]", (44, 160, 44)),
    "speed_limit": ("speed limit [m/s]", (214, 39, 40)),
    "steering": ("steering [rad]", (255, 127, 14)),
    "cross_track_error": ("cross-track error [m]", (148, 103, 189)),
    "gap": ("gap [m]", (140, 86, 75)),
    "lead_gap": ("gap to the lead [m]", (140, 86, 75)),
    "lead_speed": ("lead speed [m/s]", (26, 35, 126)),
    "lane_offset_error": ("camera lane offset error [m]", (23, 190, 207)),
    "lane_heading_error": ("camera lane heading error [rad]", (188, 189, 34)),
    "lane_confidence": ("camera lane confidence [-]", (127, 127, 127)),
    "tracks": ("confirmed tracks [-]", (227, 119, 194)),
}
SERIES_PALETTE: tuple[Rgb, ...] = (  # for metrics not in SERIES_STYLES, in order of appearance
    (227, 119, 194),
    (127, 127, 127),
    (188, 189, 34),
    (23, 190, 207),
)
EGO_BODY_RGB: Rgb = (230, 230, 235)  # [0..255]
EGO_WHEEL_RGB: Rgb = (30, 30, 30)  # [0..255]
PATH_RGB: Rgb = (0, 220, 120)  # [0..255] the planned path
PATH_RADIUS = 0.08  # [m] line half-width of the planned path
TRACK_CLASSES: dict[str, tuple[int, Rgb]] = {  # kind -> (class id as ACTOR_CLASSES, colour)
    "other": (0, (255, 255, 255)),
    "car": (1, (255, 0, 200)),
    "truck": (2, (170, 60, 255)),
    "pedestrian": (3, (0, 230, 230)),
    "cyclist": (4, (0, 200, 130)),
    "obstacle": (5, (255, 240, 0)),
    "motorcycle": (6, (255, 120, 220)),
}
DETECTION_RGB: Rgb = (255, 200, 0)  # every raw detection, whatever its kind
VELOCITY_HORIZON = 1.0  # [s] a track's velocity arrow shows this much motion
LANE_RADIUS = 0.06  # [m] line half-width of the detected lane lines
LIDAR_RADIUS = 0.05  # [m] default point radius of the LiDAR scan
JPEG_QUALITY = 75  # [-] default JPEG quality of the camera images (1..100)
RIDE_HEIGHT = 0.33  # [m] default height of the base link (`/world/ego`) over the ground
IMAGE_PLANE_DISTANCE = 0.5  # [m] distance of a camera's image plane in the 3D views
TEXT_LOG_LEVELS = frozenset({"TRACE", "DEBUG", "INFO", "WARN", "ERROR", "CRITICAL"})
INFRACTION_HEIGHT = 2.5  # [m] of an infraction's marker over the ground: above the car's
#   roof, which would hide a marker at the car's centre
INFRACTION_RADIUS = 0.5  # [m] an infraction marker's radius
INFRACTION_RGB = (230, 30, 30)  # [0..255]


class MeshLike(Protocol):
    """A textured triangle mesh in the map frame (e.g. `world.scene.road_mesh.TexturedMesh`)."""

    @property
    def name(self) -> str: ...  # a valid entity path part
    @property
    def vertices(self) -> npt.NDArray[Any]: ...  # (N, 3) [m] map frame
    @property
    def indices(self) -> npt.NDArray[Any]: ...  # (M, 3) int, vertex indices
    @property
    def uvs(self) -> npt.NDArray[Any]: ...  # (N, 2) [-]; (0, 0) = texture row 0, column 0
    @property
    def normals(self) -> npt.NDArray[Any]: ...  # (N, 3) unit
    @property
    def texture(self) -> npt.NDArray[Any]: ...  # (H, W, 3) uint8 RGB


def _time_column(times: FloatArray) -> rr.TimeColumn:
    """`sim_time` column for times [s], rounded to [ns] as `set_time(duration=t)` does.

    (`rr.TimeColumn(duration=float_array)` truncates instead of rounding, which would put
    some buffered samples 1 ns away from a directly logged one at the same tick.)
    """
    nanos = np.round(times * NANOS_PER_SECOND).astype(np.int64)
    return rr.TimeColumn(bp.TIMELINE, duration=nanos.astype("timedelta64[ns]"))


class _RowBuffer:
    """Growable rows of `width` float64 values, each with a time [s]; emptied by `take()`."""

    def __init__(self, width: int) -> None:
        self._times = np.empty(INITIAL_ROWS)
        self._rows = np.empty((INITIAL_ROWS, width))
        self._n = 0

    def __len__(self) -> int:
        return self._n

    def append(self, t: float, row: npt.ArrayLike) -> None:
        """One row (width,) at time t [s]; the arrays double when full."""
        if self._n == len(self._times):
            self._times = np.concatenate([self._times, np.empty_like(self._times)])
            self._rows = np.concatenate([self._rows, np.empty_like(self._rows)])
        self._times[self._n] = t
        self._rows[self._n] = row
        self._n += 1

    def take(self) -> tuple[FloatArray, FloatArray]:
        """(times (n,) [s], rows (n, width)) appended since the last take."""
        n, self._n = self._n, 0
        return self._times[:n].copy(), self._rows[:n].copy()


@dataclass
class _BoxBuffer:
    """Boxes of several ticks, a variable number per tick (actors, tracks, detections)."""

    times: list[float] = field(default_factory=list)  # [s]
    counts: list[int] = field(default_factory=list)  # boxes per tick
    centers: list[FloatArray] = field(default_factory=list)  # each (n, 3) [m]
    half_sizes: list[FloatArray] = field(default_factory=list)  # each (n, 3) [m]
    quaternions: list[FloatArray] = field(default_factory=list)  # each (n, 4) xyzw
    labels: list[str] = field(default_factory=list)  # empty if the boxes have none
    class_ids: list[int] = field(default_factory=list)  # one per box, as the classes' map
    vectors: list[FloatArray] = field(default_factory=list)  # each (n, 3) [m]; tracks only

    def append(
        self,
        t: float,
        boxes: tuple[FloatArray, FloatArray, FloatArray],
        labels: Sequence[str],
        class_ids: Sequence[int],
    ) -> None:
        """One tick's boxes: (centers, half_sizes, quaternions) as checked (n, k) rows."""
        centers, half_sizes, quaternions = boxes
        self.times.append(t)
        self.counts.append(len(centers))
        self.centers.append(centers)
        self.half_sizes.append(half_sizes)
        self.quaternions.append(quaternions)
        self.labels.extend(labels)
        self.class_ids.extend(class_ids)

    def box_columns(self) -> rr.ComponentColumnList:
        """The buffered boxes as Boxes3D columns, one row per tick."""
        columns = rr.Boxes3D.columns(
            centers=np.concatenate(self.centers),
            half_sizes=np.concatenate(self.half_sizes),
            quaternions=np.concatenate(self.quaternions),
            labels=self.labels or None,  # None: unlabelled boxes (detections), or no boxes
            class_ids=np.asarray(self.class_ids, dtype=np.uint16),
        )
        return columns.partition(self.counts)

    def arrow_columns(self) -> rr.ComponentColumnList:
        """Arrows from the box centres along `vectors`, one row per tick."""
        columns = rr.Arrows3D.columns(
            origins=np.concatenate(self.centers),
            vectors=np.concatenate(self.vectors),
            class_ids=np.asarray(self.class_ids, dtype=np.uint16),
        )
        return columns.partition(self.counts)


class _CameraSetup(NamedTuple):
    """A camera's static data as last logged (see `Recorder.log_camera_image`)."""

    fx: float  # [px]
    fy: float  # [px]
    cx: float  # [px]
    cy: float  # [px]
    width: int  # [px]
    height: int  # [px]
    mount_xyz: tuple[float, float, float] | None  # [m] vehicle frame, z from the ground
    mount_rpy: tuple[float, float, float]  # [rad] roll, pitch, yaw (as `SensorMount`)
    ride_height: float  # [m] base link origin above the ground


@dataclass
class _StripBuffer:
    """Line strips of several ticks, a variable number per tick, one colour per strip."""

    times: list[float] = field(default_factory=list)  # [s]
    counts: list[int] = field(default_factory=list)  # strips per tick
    strips: list[FloatArray] = field(default_factory=list)  # each (m, 3) [m]
    colors: list[npt.NDArray[np.uint8]] = field(default_factory=list)  # each (n, 3) RGB


@dataclass
class _PathBuffer:
    """Planned paths of several ticks, one strip per tick."""

    times: list[float] = field(default_factory=list)  # [s]
    strips: list[FloatArray] = field(default_factory=list)  # each (n, 3) [m]


def _class_ids(classes: Mapping[str, tuple[int, Rgb]], kinds: Sequence[str]) -> list[int]:
    """Class ids of the kinds; a kind not in `classes` is "other"."""
    other = classes["other"][0]
    return [classes.get(kind, (other,))[0] for kind in kinds]


def _yaw_quaternions(yaws: npt.ArrayLike, n: int) -> FloatArray:
    """(n, 4) xyzw quaternions of rotations by yaws (n,) [rad] about z."""
    half = 0.5 * np.asarray(yaws, dtype=np.float64).reshape(-1)
    if len(half) != n:
        raise ValueError(f"yaws: expected shape ({n},), got {half.shape}")
    zeros = np.zeros(n)
    return np.column_stack([zeros, zeros, np.sin(half), np.cos(half)])


def _rpy_quaternion(roll: float, pitch: float, yaw: float) -> list[float]:
    """xyzw quaternion of R = Rz(yaw) Ry(pitch) Rx(roll) (as `world.frames.SensorMount`)."""
    cr, sr = math.cos(0.5 * roll), math.sin(0.5 * roll)
    cp, sp = math.cos(0.5 * pitch), math.sin(0.5 * pitch)
    cy, sy = math.cos(0.5 * yaw), math.sin(0.5 * yaw)
    return [
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
        cr * cp * cy + sr * sp * sy,
    ]


def _rgb_image(rgb: npt.ArrayLike) -> npt.NDArray[np.uint8]:
    """An (H, W, 3) uint8 image (an alpha channel is dropped), or ValueError."""
    image = np.asarray(rgb)
    if image.dtype != np.uint8 or image.ndim != 3 or image.shape[2] not in (3, 4):
        raise ValueError(f"rgb: expected (H, W, 3) uint8, got {image.shape} {image.dtype}")
    return np.ascontiguousarray(image[..., :3])


def _rows(values: npt.ArrayLike, width: int, what: str, n: int | None = None) -> FloatArray:
    """`values` as an (n, width) float64 array (a single (width,) row is accepted), or
    ValueError naming `what`. With `n` given, the row count must be n (0 rows allowed)."""
    array = np.asarray(values, dtype=np.float64)
    if array.ndim == 1 and array.size in (width, 0):
        array = array.reshape(-1, width)
    if array.ndim != 2 or array.shape[1] != width or (n is not None and len(array) != n):
        rows = "n" if n is None else str(n)
        raise ValueError(f"{what}: expected shape ({rows}, {width}), got {array.shape}")
    return array


class Recorder:
    """Writes one run to an `.rrd` file with the default blueprint (see module docstring).

    Times `t` are simulated time [s] on the `sim_time` timeline; positions are [m] in the
    map frame (z up) unless stated; quaternions are (x, y, z, w) as PyBullet returns them.
    Use as a context manager, or call `close()` (idempotent) so the file gets its footer.
    """

    def __init__(
        self,
        path: Path,
        application: str = "avsim",
        recording_name: str = "",
        recording_id: str | None = None,
        flush_interval: float = FLUSH_INTERVAL,
    ) -> None:
        self.path = Path(path)
        self.recording_id = recording_id if recording_id is not None else str(uuid4())
        self._flush_interval = flush_interval  # [s] sim time
        self._next_flush = flush_interval  # [s] sim time of the next send of the buffers
        self._closed = False
        self._pose = _RowBuffer(7)  # x, y, z [m], qx, qy, qz, qw
        self._scalars: dict[str, _RowBuffer] = {}
        self._actors = _BoxBuffer()
        self._paths = _PathBuffer()
        self._tracks = _BoxBuffer()
        self._detections = _BoxBuffer()
        self._lanes = _StripBuffer()
        self._cameras: dict[str, _CameraSetup] = {}  # name -> static set-up last logged
        self._infractions: list[tuple[tuple[float, float, float], str]] = []  # marker, kind
        self.path.parent.mkdir(parents=True, exist_ok=True)
        # No wall-clock batching: batched log calls (static data, events) become chunks only
        # at the sim-time flushes, so identical runs give identically chunked files.
        self._rec = rr.RecordingStream(
            application,
            recording_id=self.recording_id,
            batcher_config=rr.ChunkBatcherConfig.NEVER(),
        )
        self._rec.set_log_time_enabled(False)
        self._rec.save(self.path, default_blueprint=default_blueprint())
        if recording_name:
            self._rec.send_recording_name(recording_name)
        self._log_scene_setup()

    # -- context manager ----------------------------------------------------------------------
    def __enter__(self) -> Self:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()

    @property
    def closed(self) -> bool:
        """Whether `close()` has been called."""
        return self._closed

    def close(self) -> None:
        """Send the buffered columns, then flush and close the file (writes the footer).

        Idempotent. Logging after close raises RuntimeError.
        """
        if self._closed:
            return
        self._closed = True
        try:
            self._flush_buffers()
        finally:
            self._rec.flush()
            self._rec.disconnect()

    # -- static ---------------------------------------------------------------------------------
    def _log_scene_setup(self) -> None:
        """World axes, the chase camera, the actor classes and box style (all static)."""
        rec = self._rec
        rec.log(bp.WORLD, rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
        half = 0.5 * CHASE_PITCH  # rotation about +y by CHASE_PITCH tips the x axis down
        rec.log(
            bp.CHASE_CAMERA,
            rr.Transform3D(
                translation=CHASE_OFFSET,
                quaternion=rr.Quaternion(xyzw=[0.0, math.sin(half), 0.0, math.cos(half)]),
            ),
            rr.Pinhole(
                fov_y=CHASE_FOV_Y,
                aspect_ratio=CHASE_ASPECT,
                camera_xyz=rr.ViewCoordinates.FLU,  # looks along the car's x axis
                image_plane_distance=0.05,
                color=[0, 0, 0, 0],  # invisible frustum: it is the eye, not a sensor
                line_width=0.0,
            ),
            static=True,
        )
        classes = [(cid, kind, rgb) for kind, (cid, rgb) in ACTOR_CLASSES.items()]
        rec.log(bp.ACTORS, rr.AnnotationContext(classes), static=True)
        rec.log(
            bp.ACTORS,
            rr.Boxes3D.from_fields(fill_mode=rr.components.FillMode.Solid, show_labels=True),
            static=True,
        )
        self._log_perception_styles()

    def _log_perception_styles(self) -> None:
        """Track classes and box style, detection colour and style, lane line width."""
        rec = self._rec
        track_classes = [(cid, kind, rgb) for kind, (cid, rgb) in TRACK_CLASSES.items()]
        rec.log(bp.TRACKS, rr.AnnotationContext(track_classes), static=True)
        rec.log(
            bp.TRACK_BOXES,
            rr.Boxes3D.from_fields(
                fill_mode=rr.components.FillMode.TransparentFillMajorWireframe,
                show_labels=True,
            ),
            static=True,
        )
        detection_classes = [(cid, kind, DETECTION_RGB) for kind, (cid, _) in ACTOR_CLASSES.items()]
        rec.log(bp.DETECTIONS, rr.AnnotationContext(detection_classes), static=True)
        rec.log(
            bp.DETECTIONS,
            rr.Boxes3D.from_fields(fill_mode=rr.components.FillMode.MajorWireframe),
            static=True,
        )
        rec.log(bp.LANE_LINES, rr.LineStrips3D.from_fields(radii=LANE_RADIUS), static=True)

    def log_road_meshes(self, meshes: Sequence[MeshLike]) -> None:
        """Each mesh as a textured Mesh3D at `/world/road/<mesh.name>` (static)."""
        self._check_open()
        for mesh in meshes:
            self._rec.log(
                f"{bp.ROAD}/{mesh.name}",
                rr.Mesh3D(
                    vertex_positions=np.asarray(mesh.vertices, dtype=np.float32),
                    triangle_indices=np.asarray(mesh.indices, dtype=np.uint32),
                    vertex_normals=np.asarray(mesh.normals, dtype=np.float32),
                    vertex_texcoords=np.asarray(mesh.uvs, dtype=np.float32),
                    albedo_texture=np.ascontiguousarray(mesh.texture, dtype=np.uint8),
                ),
                static=True,
            )

    def log_static_boxes(
        self,
        path: str,
        centers: npt.ArrayLike,
        half_sizes: npt.ArrayLike,
        quaternions_xyzw: npt.ArrayLike,
        colors: npt.ArrayLike,
        labels: Sequence[str] | None = None,
    ) -> None:
        """Solid boxes at `path` (e.g. `/world/buildings`), static.

        centers (N, 3) [m], half_sizes (N, 3) [m], quaternions_xyzw (N, 4), colors (N, 3) or
        (3,) uint8 RGB, optional labels (N,).
        """
        self._check_open()
        self._rec.log(
            path,
            rr.Boxes3D(
                centers=_rows(centers, 3, "centers"),
                half_sizes=_rows(half_sizes, 3, "half_sizes"),
                quaternions=_rows(quaternions_xyzw, 4, "quaternions_xyzw"),
                colors=np.asarray(colors, dtype=np.uint8),
                labels=labels,
                fill_mode=rr.components.FillMode.Solid,
            ),
            static=True,
        )

    def log_static_lines(
        self, path: str, strips: Sequence[npt.ArrayLike], color: Rgb, radius: float
    ) -> None:
        """Line strips at `path` (e.g. lane centre lines at `/world/map/lanes`), static.

        strips: each (N_i, 3) [m]; radius [m] line half-width.
        """
        self._check_open()
        rows = [_rows(s, 3, "strip") for s in strips]
        self._rec.log(path, rr.LineStrips3D(rows, colors=color, radii=radius), static=True)

    def log_ego_body(
        self,
        *,
        body_half_size: tuple[float, float, float],
        body_center: tuple[float, float, float],
        wheel_centers: npt.ArrayLike,
        wheel_radius: float,
        wheel_half_width: float,
    ) -> None:
        """The car's shape in its own frame (x forward, y left, z up; origin at wheel-centre
        height), static under the moving `/world/ego`.

        body_half_size [m] and body_center [m] of the body box -> `/world/ego/body`;
        wheel_centers (4, 3) [m], wheel_radius [m], wheel_half_width [m] (half the tyre
        width) -> four boxes at `/world/ego/wheels` labelled FL, FR, RL, RR in that order.
        """
        self._check_open()
        wheels = _rows(wheel_centers, 3, "wheel_centers")
        self._rec.log(
            bp.EGO_BODY,
            rr.Boxes3D(
                centers=[body_center],
                half_sizes=[body_half_size],
                colors=EGO_BODY_RGB,
                fill_mode=rr.components.FillMode.Solid,
            ),
            static=True,
        )
        wheel_half = (wheel_radius, wheel_half_width, wheel_radius)
        self._rec.log(
            bp.EGO_WHEELS,
            rr.Boxes3D(
                centers=wheels,
                half_sizes=[wheel_half] * len(wheels),
                colors=EGO_WHEEL_RGB,
                fill_mode=rr.components.FillMode.Solid,
                labels=["FL", "FR", "RL", "RR"][: len(wheels)],
                show_labels=False,
            ),
            static=True,
        )

    # -- buffered time series -------------------------------------------------------------------
    def log_ego_pose(
        self, t: float, position: npt.ArrayLike, quaternion_xyzw: npt.ArrayLike
    ) -> None:
        """Ego pose at sim time t [s]: position (3,) [m] and orientation (4,) xyzw of the car
        frame in the map frame. Buffered; sent as Transform3D columns at `/world/ego`."""
        self._check_open()
        row = np.empty(7)
        row[:3] = position
        row[3:] = quaternion_xyzw
        self._pose.append(t, row)
        self._maybe_flush(t)

    def log_scalars(self, t: float, values: Mapping[str, float]) -> None:
        """Named scalars at sim time t [s], e.g. {"speed": 12.3} [m/s]. Buffered; sent as
        Scalars columns at `/metrics/<name>`. A name's series style (label with unit and
        colour, `SERIES_STYLES`) is logged statically the first time the name appears."""
        self._check_open()
        for name, value in values.items():
            buffer = self._scalars.get(name)
            if buffer is None:
                buffer = self._scalars[name] = _RowBuffer(1)
                self._log_series_style(name)
            buffer.append(t, value)
        self._maybe_flush(t)

    def log_actors(
        self,
        t: float,
        ids: Sequence[str],
        centers: npt.ArrayLike,
        half_sizes: npt.ArrayLike,
        quaternions_xyzw: npt.ArrayLike,
        kinds: Sequence[str],
    ) -> None:
        """The actors' boxes at sim time t [s] (ground truth or tracks), replacing the previous
        set: centers (N, 3) [m], half_sizes (N, 3) [m], quaternions_xyzw (N, 4), ids and kinds
        (N,). Labels are the ids; a kind outside `ACTOR_CLASSES` is drawn as "other".
        Buffered; sent as Boxes3D columns at `/world/actors` (N may be 0: no actors)."""
        self._check_open()
        n = len(ids)
        if len(kinds) != n:
            raise ValueError(f"log_actors: {n} ids but {len(kinds)} kinds")
        boxes = (
            _rows(centers, 3, "centers", n),
            _rows(half_sizes, 3, "half_sizes", n),
            _rows(quaternions_xyzw, 4, "quaternions_xyzw", n),
        )
        self._actors.append(t, boxes, ids, _class_ids(ACTOR_CLASSES, kinds))
        self._maybe_flush(t)

    def log_path(self, t: float, xy: npt.ArrayLike, z: float = 0.05) -> None:
        """The planned path at sim time t [s]: xy (N, 2) [m] in the map frame, drawn at
        height z [m]. Buffered; sent as LineStrips3D columns at `/world/plan/path`."""
        self._check_open()
        points = _rows(xy, 2, "xy")
        strip = np.column_stack([points, np.full(len(points), z)])
        self._paths.times.append(t)
        self._paths.strips.append(strip)
        self._maybe_flush(t)

    def log_tracks(
        self,
        t: float,
        ids: Sequence[int],
        centers: npt.ArrayLike,
        half_sizes: npt.ArrayLike,
        yaws: npt.ArrayLike,
        velocities: npt.ArrayLike,
        kinds: Sequence[str],
    ) -> None:
        """The tracker's tracks at sim time t [s], replacing the previous set (N may be 0).

        ids (N,) -> labels "id <n>"; centers (N, 3) [m] and yaws (N,) [rad] in the map frame;
        half_sizes (N, 3) [m]; velocities (N, 2) or (N, 3) [m/s] over ground, map frame;
        kinds (N,) coloured by `TRACK_CLASSES` (class ids as `ACTOR_CLASSES`; unknown kinds
        are "other"). Buffered; sent as Boxes3D columns at `/world/tracks/boxes` and as
        Arrows3D from the centres, `VELOCITY_HORIZON` of motion long, at
        `/world/tracks/velocity`.
        """
        self._check_open()
        n = len(ids)
        if len(kinds) != n:
            raise ValueError(f"log_tracks: {n} ids but {len(kinds)} kinds")
        velocity = np.asarray(velocities, dtype=np.float64)
        width = 2 if velocity.ndim == 2 and velocity.shape[1] == 2 else 3
        vectors = np.zeros((n, 3))
        vectors[:, :width] = _rows(velocity, width, "velocities", n) * VELOCITY_HORIZON
        centers_rows = _rows(centers, 3, "centers", n)
        boxes = (centers_rows, _rows(half_sizes, 3, "half_sizes", n), _yaw_quaternions(yaws, n))
        labels = [f"id {track_id}" for track_id in ids]
        self._tracks.append(t, boxes, labels, _class_ids(TRACK_CLASSES, kinds))
        self._tracks.vectors.append(vectors)
        self._maybe_flush(t)

    def log_detections(
        self,
        t: float,
        centers: npt.ArrayLike,
        half_sizes: npt.ArrayLike,
        yaws: npt.ArrayLike,
        kinds: Sequence[str],
    ) -> None:
        """Raw object detections at sim time t [s], replacing the previous set (N may be 0):
        centers (N, 3) [m] and yaws (N,) [rad] in the map frame, half_sizes (N, 3) [m],
        kinds (N,) (class ids as `ACTOR_CLASSES`, all drawn in `DETECTION_RGB`). Buffered;
        sent as wireframe Boxes3D columns at `/world/perception/detections`."""
        self._check_open()
        n = len(kinds)
        boxes = (
            _rows(centers, 3, "centers", n),
            _rows(half_sizes, 3, "half_sizes", n),
            _yaw_quaternions(yaws, n),
        )
        self._detections.append(t, boxes, (), _class_ids(ACTOR_CLASSES, kinds))
        self._maybe_flush(t)

    def log_lane_lines(
        self, t: float, strips: Sequence[npt.ArrayLike], colors: npt.ArrayLike
    ) -> None:
        """Detected lane lines at sim time t [s] (boundaries and centre), replacing the
        previous set: strips, each (M_i, 3) [m] in the map frame (may be none); colors (K, 3)
        uint8 RGB, one per strip, or (3,) for all. Buffered; sent as LineStrips3D columns at
        `/world/perception/lanes` (line half-width `LANE_RADIUS`)."""
        self._check_open()
        rows = [_rows(strip, 3, "strip") for strip in strips]
        rgb = np.asarray(colors, dtype=np.uint8)
        if rgb.shape == (3,):
            rgb = np.tile(rgb, (len(rows), 1))
        if rgb.shape != (len(rows), 3):
            raise ValueError(f"colors: expected shape ({len(rows)}, 3) or (3,), got {rgb.shape}")
        buf = self._lanes
        buf.times.append(t)
        buf.counts.append(len(rows))
        buf.strips.extend(rows)
        buf.colors.append(rgb)
        self._maybe_flush(t)

    # -- direct -----------------------------------------------------------------------------------
    def log_camera_image(
        self,
        t: float,
        name: str,
        rgb: npt.ArrayLike,
        fx: float,
        fy: float,
        cx: float,
        cy: float,
        *,
        jpeg_quality: int = JPEG_QUALITY,
        mount_xyz: tuple[float, float, float] | None = None,
        mount_rpy: tuple[float, float, float] = (0.0, 0.0, 0.0),
        ride_height: float = RIDE_HEIGHT,
    ) -> None:
        """A camera image at sim time t [s], as a JPEG at `/world/ego/camera_<name>`.

        rgb (H, W, 3) uint8 (an alpha channel is dropped); fx, fy [px] focal lengths and
        cx, cy [px] principal point, for a camera looking along its mount's x axis (x along
        the optical axis, y left, z up: `camera_xyz` FLU, as `world.frames.CameraInfo`).
        The Pinhole (and the mount) is logged statically, again only if it changes.

        mount_xyz [m], mount_rpy [rad]: the camera's mount in the *vehicle* frame (x forward,
        y left, z up from the ground, rotation Rz(yaw) Ry(pitch) Rx(roll), pitch > 0 looking
        down: exactly `world.frames.SensorMount`). `/world/ego` is the base link, whose origin
        is `ride_height` [m] above the ground, so the logged static Transform3D is the mount
        lowered by ride_height. Without mount_xyz no transform is logged (the camera sits at
        the base link's origin in the 3D views; the 2D view does not care).
        """
        self._check_open()
        image = _rgb_image(rgb)
        height, width = image.shape[:2]
        entity = bp.camera_entity(name)
        roll, pitch, yaw = (float(a) for a in mount_rpy)
        xyz = None if mount_xyz is None else _rows(mount_xyz, 3, "mount_xyz", 1)[0]
        setup = _CameraSetup(
            float(fx), float(fy), float(cx), float(cy), width, height,
            None if xyz is None else (float(xyz[0]), float(xyz[1]), float(xyz[2])),
            (roll, pitch, yaw), float(ride_height),
        )  # fmt: skip
        if self._cameras.get(name) != setup:
            self._cameras[name] = setup
            self._log_camera_setup(entity, setup)
        encoded = rr.Image(image).compress(jpeg_quality=jpeg_quality)
        if not isinstance(encoded, rr.EncodedImage):  # rerun logs and returns the raw image
            raise RuntimeError(f"log_camera_image: JPEG compression of {name!r} failed")
        self._rec.set_time(bp.TIMELINE, duration=t)
        self._rec.log(entity, encoded)
        self._maybe_flush(t)

    def log_lidar(
        self,
        t: float,
        points_world: npt.ArrayLike,
        colors: npt.ArrayLike | None = None,
        radius: float = LIDAR_RADIUS,
    ) -> None:
        """A LiDAR scan at sim time t [s]: points_world (N, 3) [m] in the map frame, optional
        colors (N, 3) uint8 RGB, point radius [m]. Points3D at `/world/lidar`, logged
        directly (float32 positions: 12 bytes a point before compression)."""
        self._check_open()
        points = _rows(points_world, 3, "points_world").astype(np.float32)
        rgb = None
        if colors is not None:
            rgb = np.asarray(colors, dtype=np.uint8)
            if rgb.shape != points.shape:
                raise ValueError(f"colors: expected shape {points.shape}, got {rgb.shape}")
        self._rec.set_time(bp.TIMELINE, duration=t)
        self._rec.log(bp.LIDAR, rr.Points3D(points, colors=rgb, radii=radius))
        self._maybe_flush(t)

    def log_state_machine(
        self, machine: str, states: Sequence[str], colors: Sequence[Rgb] | None = None
    ) -> None:
        """Optional: the states of FSM `machine` and their colours (one per state) for its
        lane at `/fsm/<machine>` (static StateConfiguration). Without it, Rerun picks."""
        self._check_open()
        rgb = None if colors is None else np.asarray(colors, dtype=np.uint8).reshape(-1, 3)
        self._rec.log(
            self._fsm_entity(machine),
            rr.StateConfiguration(values=list(states), colors=rgb),
            static=True,
        )

    def log_state(self, t: float, machine: str, state: str, reason: str | None = None,
                  text: bool = True) -> None:
        """FSM `machine` entered `state` at sim time t [s]: a StateChange on the lane
        `/fsm/<machine>` (shown by the FSM state timeline view) and, with `text`, a TextLog
        line "<machine>: <state> (<reason>)" at `/events` (without the parentheses if no
        reason). `machine` must be one entity path part (no "/")."""
        self._check_open()
        self._rec.set_time(bp.TIMELINE, duration=t)
        self._rec.log(self._fsm_entity(machine), rr.StateChange(state=state))
        if text:
            self.log_event(t, f"{machine}: {state}" + (f" ({reason})" if reason else ""))
        self._maybe_flush(t)

    def log_event(self, t: float, text: str, level: str = "INFO") -> None:
        """A text event (criterion event, FSM state change) at sim time t [s] at `/events`.

        level: one of TRACE, DEBUG, INFO, WARN, ERROR, CRITICAL.
        """
        self._check_open()
        if level not in TEXT_LOG_LEVELS:
            raise ValueError(f"log_event: level {level!r} not in {sorted(TEXT_LOG_LEVELS)}")
        self._rec.set_time(bp.TIMELINE, duration=t)
        self._rec.log(bp.EVENTS, rr.TextLog(text, level=level))

    def log_infraction(self, t: float, kind: str, message: str,
                       where: Sequence[float] | None) -> None:
        """An infraction at sim time t [s]: an ERROR line `<kind>: <message>` at `/events`
        and, when it happened at a place (`where`: map frame (x, y) [m]), a marker there at
        `/world/infractions`, which from t on shows every infraction so far, labelled by
        kind (the criterion's name)."""
        self.log_event(t, f"{kind}: {message}", "ERROR")
        if where is None:
            return
        self._infractions.append(((float(where[0]), float(where[1]), INFRACTION_HEIGHT), kind))
        positions = [p for p, _ in self._infractions]
        labels = [k for _, k in self._infractions]
        self._rec.set_time(bp.TIMELINE, duration=t)
        self._rec.log(bp.INFRACTIONS, rr.Points3D(positions, radii=INFRACTION_RADIUS,
                                                  colors=INFRACTION_RGB, labels=labels))

    def flush(self) -> None:
        """Send the buffered columns now (normally done every FLUSH_INTERVAL and at close)."""
        self._check_open()
        self._flush_buffers()

    # -- internals --------------------------------------------------------------------------------
    def _check_open(self) -> None:
        """RuntimeError once closed."""
        if self._closed:
            raise RuntimeError(f"Recorder for {self.path} is closed")

    @staticmethod
    def _fsm_entity(machine: str) -> str:
        """`/fsm/<machine>`, or ValueError unless `machine` is one entity path part."""
        if not machine or "/" in machine:
            raise ValueError(f"FSM machine name {machine!r}: one non-empty entity path part")
        return f"{bp.FSM_ROOT}/{machine}"

    def _log_camera_setup(self, entity: str, setup: _CameraSetup) -> None:
        """Static Pinhole (and mount Transform3D) of a camera."""
        if setup.mount_xyz is not None:
            x, y, z = setup.mount_xyz
            self._rec.log(
                entity,
                rr.Transform3D(
                    translation=[x, y, z - setup.ride_height],
                    quaternion=rr.Quaternion(xyzw=_rpy_quaternion(*setup.mount_rpy)),
                ),
                static=True,
            )
        self._rec.log(
            entity,
            rr.Pinhole(
                focal_length=[setup.fx, setup.fy],
                principal_point=[setup.cx, setup.cy],
                resolution=[setup.width, setup.height],
                camera_xyz=rr.ViewCoordinates.FLU,
                image_plane_distance=IMAGE_PLANE_DISTANCE,
            ),
            static=True,
        )

    def _log_series_style(self, name: str) -> None:
        """A metric's static SeriesLines: its `SERIES_STYLES` label and colour, else its name
        in the next `SERIES_PALETTE` colour."""
        n_custom = sum(1 for known in self._scalars if known not in SERIES_STYLES)
        default = (name, SERIES_PALETTE[(n_custom - 1) % len(SERIES_PALETTE)])
        label, rgb = SERIES_STYLES.get(name, default)
        self._rec.log(f"{bp.METRICS}/{name}", rr.SeriesLines(names=label, colors=rgb), static=True)

    def _maybe_flush(self, t: float) -> None:
        """Send the buffers once t [s] reaches the next multiple of the flush interval."""
        if t >= self._next_flush:
            self._flush_buffers()
            self._next_flush = (math.floor(t / self._flush_interval) + 1) * self._flush_interval

    def _flush_buffers(self) -> None:
        """Send every buffer's columns, emptying it."""
        self._rec.flush()  # the batched log calls first, then the columns: a fixed order
        self._flush_pose()
        self._flush_scalars()
        self._flush_actors()
        self._flush_paths()
        self._flush_tracks()
        self._flush_detections()
        self._flush_lanes()

    def _flush_pose(self) -> None:
        if not len(self._pose):
            return
        times, rows = self._pose.take()
        self._rec.send_columns(
            bp.EGO,
            indexes=[_time_column(times)],
            columns=rr.Transform3D.columns(translation=rows[:, :3], quaternion=rows[:, 3:]),
        )

    def _flush_scalars(self) -> None:
        for name, buffer in self._scalars.items():
            if not len(buffer):
                continue
            times, rows = buffer.take()
            self._rec.send_columns(
                f"{bp.METRICS}/{name}",
                indexes=[_time_column(times)],
                columns=rr.Scalars.columns(scalars=rows[:, 0]),
            )

    def _flush_actors(self) -> None:
        buf = self._actors
        if not buf.times:
            return
        self._rec.send_columns(
            bp.ACTORS, indexes=[_time_column(np.asarray(buf.times))], columns=buf.box_columns()
        )
        self._actors = _BoxBuffer()

    def _flush_tracks(self) -> None:
        buf = self._tracks
        if not buf.times:
            return
        times = _time_column(np.asarray(buf.times))
        self._rec.send_columns(bp.TRACK_BOXES, indexes=[times], columns=buf.box_columns())
        self._rec.send_columns(bp.TRACK_VELOCITY, indexes=[times], columns=buf.arrow_columns())
        self._tracks = _BoxBuffer()

    def _flush_detections(self) -> None:
        buf = self._detections
        if not buf.times:
            return
        times = _time_column(np.asarray(buf.times))
        self._rec.send_columns(bp.DETECTIONS, indexes=[times], columns=buf.box_columns())
        self._detections = _BoxBuffer()

    def _flush_lanes(self) -> None:
        buf = self._lanes
        if not buf.times:
            return
        columns = rr.LineStrips3D.columns(strips=buf.strips, colors=np.concatenate(buf.colors))
        self._rec.send_columns(
            bp.LANE_LINES,
            indexes=[_time_column(np.asarray(buf.times))],
            columns=columns.partition(buf.counts),
        )
        self._lanes = _StripBuffer()

    def _flush_paths(self) -> None:
        buf = self._paths
        if not buf.times:
            return
        k = len(buf.times)
        columns = rr.LineStrips3D.columns(
            strips=buf.strips, colors=[PATH_RGB] * k, radii=[PATH_RADIUS] * k
        )
        self._rec.send_columns(
            bp.PLAN_PATH,
            indexes=[_time_column(np.asarray(buf.times))],
            columns=columns.partition([1] * len(buf.times)),
        )
        self._paths = _PathBuffer()

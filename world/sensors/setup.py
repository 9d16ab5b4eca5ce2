"""The car's sensor set-up: cameras and LiDAR built from a profile and the URDF's mounts.

Profiles (`--profile`):

| profile   | front camera       | side cameras        | LiDAR (16 channels, 10 Hz) |
|-----------|--------------------|---------------------|----------------------------|
| `fast`    | 640x480 @ 10 Hz    | none                | 900 columns (0.4 deg)      |
| `default` | 640x480 @ 10 Hz    | 320x240 @ 2 Hz      | 1800 columns (0.2 deg)     |
| `paper`   | 1280x960 @ 10 Hz   | 1280x960 @ 10 Hz    | 1800 columns (0.2 deg)     |

The rates (and when frames reach the stack, and which the recording keeps) are the rates
table's (`world.core.rates.PROFILE_SENSORS`); GNSS and odometry are on every car, with or
without a profile (`world.core.rates.CAR_SENSORS`). A run captures a sensor's frames only as
often as somebody reads them (`avsim.run.sensor_loop.frames_read`): the stack reads the
front camera and the LiDAR, so the side cameras render only the frames the recording keeps
(`paper`: every 4th, 2.5 Hz), and not at all without a recording.

With the EGL renderer, `paper`'s 1280x960 images are drawn at 1024x768, the plugin's fixed
surface, and scaled up nearest-neighbour by Bullet (TinyRenderer draws them at full size).

Cameras have an 80 deg horizontal field of view. The LiDAR is VLP-16-like: channels from
-15 to +15 deg every 2 deg, 360 deg, 100 m. Mounts come from the URDF's sensor links (the
vehicle frame's origin is on the ground, the base link's origin `CarGeometry.ride_height`
above it: the wheel radius less the tyres' static compression).
The scenario's `sensors.lidar` block sets range noise and dropout.

Without a profile (`--profile none`) the car has no camera and no LiDAR: the stack sees no
lane and no object, and its pose is the scenario's GNSS receiver (`sensors.gnss`, the
`consumer` preset by default: a wandering bias of 1.2 m 1-sigma per axis) + odometry, placed
on the HD map, never corrected across the lane. The car then keeps its lane only as well as
the receiver places it. The stack sees only its sensors, and a run that checks planning and
control with its own perception names an accurate receiver (`sensors.gnss: {preset: rtk}`,
5 cm). Privileged truth mode (`stack: {privileged: true}`) adds the `truth` sensor
(`world.sensors.truth`): the ground truth, pose and objects, handed to the stack at the
control rate; every result of such a run says so. `localisation` states the pose's source
and its expected error for the run's header and result file.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass, replace

from vehicle_urdf import MountPose, read_geometry, read_sensor_mounts
from world.core.rates import CAR_SENSORS, PROFILE_SENSORS, TRUTH, SensorTiming
from world.frames import CameraInfo, LidarInfo, SensorKind, SensorMount, SensorSpec
from world.spec import GNSS_PRESETS, GnssSpec, LidarNoiseSpec

CAMERA_FOV = math.radians(80.0)  # [rad] horizontal
LIDAR_ELEVATIONS = tuple(math.radians(e) for e in range(-15, 16, 2))  # [rad] 16 channels
LIDAR_RANGE = 100.0  # [m]
LIDAR = "lidar"  # the LiDAR's name (a camera's is its `CameraInfo.name`)
TRUTH_SENSOR = "truth"  # the truth sensor's name (privileged truth mode only)


class Profile(enum.Enum):
    FAST = "fast"
    DEFAULT = "default"
    PAPER = "paper"


@dataclass(frozen=True, slots=True)
class SensorSetup:
    """Every sensor of the car for one run."""

    profile: Profile
    cameras: tuple[CameraInfo, ...]  # front first
    lidar: LidarInfo
    timings: tuple[tuple[str, SensorTiming], ...]  # (name, timing) of each camera (in
    #   `cameras` order) and of the LiDAR: the profile's entries in the rates table

    def camera(self, name: str) -> CameraInfo:
        for c in self.cameras:
            if c.name == name:
                return c
        raise KeyError(f"no camera {name!r} in profile {self.profile.value}")

    def timing(self, name: str) -> SensorTiming:
        """The timing of the camera or LiDAR `name`."""
        for n, timing in self.timings:
            if n == name:
                return timing
        raise KeyError(f"no sensor {name!r} in profile {self.profile.value}")


@dataclass(frozen=True, slots=True)
class _CameraSpec:
    name: str
    width: int  # [px]
    height: int  # [px]


_PROFILES: dict[Profile, tuple[tuple[_CameraSpec, ...], int]] = {
    Profile.FAST: ((_CameraSpec("front", 640, 480),), 900),
    Profile.DEFAULT: ((_CameraSpec("front", 640, 480), _CameraSpec("left", 320, 240),
                       _CameraSpec("right", 320, 240)), 1800),
    Profile.PAPER: ((_CameraSpec("front", 1280, 960), _CameraSpec("left", 1280, 960),
                     _CameraSpec("right", 1280, 960)), 1800),
}


def _mount(pose: MountPose, ride_height: float) -> SensorMount:
    x, y, z = pose.xyz
    roll, pitch, yaw = pose.rpy
    return SensorMount(x, y, z + ride_height, roll, pitch, yaw)


def sensor_setup(profile: Profile, lidar_noise: LidarNoiseSpec | None = None) -> SensorSetup:
    """The profile's sensors on the URDF's mounts, with the scenario's LiDAR noise."""
    mounts = read_sensor_mounts()
    ride_height = read_geometry().ride_height  # [m] base link origin above the ground
    cams_spec, columns = _PROFILES[profile]
    cameras = tuple(
        CameraInfo(name=c.name, width=c.width, height=c.height, fov_x=CAMERA_FOV,
                   mount=_mount(mounts[f"camera_{c.name}_link"], ride_height))
        for c in cams_spec
    )
    lidar = LidarInfo(elevations=LIDAR_ELEVATIONS, azimuth_steps=columns, max_range=LIDAR_RANGE,
                      mount=_mount(mounts["lidar_link"], ride_height))
    if lidar_noise is not None:
        lidar = replace(lidar, range_sigma=lidar_noise.range_sigma, dropout=lidar_noise.dropout)
    table = PROFILE_SENSORS[profile.value]
    names = [*(c.name for c in cameras), LIDAR]
    if set(table) != set(names):
        raise ValueError(f"profile {profile.value}: the rates table has {sorted(table)}, "
                         f"the profile {sorted(names)}")
    return SensorSetup(profile, cameras, lidar, tuple((n, table[n]) for n in names))


def sensor_timings(setup: SensorSetup | None, privileged: bool = False) -> tuple[
        tuple[str, SensorTiming], ...]:
    """(name, timing) of every sensor of the car, in the order a capture lists them: the
    profile's cameras (front first) and LiDAR (none without a profile), then the sensors on
    every car (GNSS, odometry), then, in privileged truth mode only, the `truth` sensor."""
    truth = ((TRUTH_SENSOR, TRUTH),) if privileged else ()
    return (setup.timings if setup is not None else ()) + tuple(CAR_SENSORS.items()) + truth


def sensor_specs(setup: SensorSetup | None, privileged: bool = False) -> tuple[
        SensorSpec, ...]:
    """Every sensor of the car as the stack is told of it (`world.frames.SensorSpec`), in
    `sensor_timings`' order."""
    cameras = {c.name: c for c in setup.cameras} if setup is not None else {}
    kinds = {LIDAR: SensorKind.LIDAR, "gnss": SensorKind.GNSS, "odometry": SensorKind.ODOMETRY,
             TRUTH_SENSOR: SensorKind.TRUTH}
    out = []
    for name, timing in sensor_timings(setup, privileged):
        kind = SensorKind.CAMERA if name in cameras else kinds[name]
        info = cameras.get(name) or (setup.lidar if setup is not None and kind is SensorKind.LIDAR
                                     else None)
        out.append(SensorSpec(name, kind, timing.rate.hz, timing.latency, info))
    return tuple(out)


@dataclass(frozen=True, slots=True)
class Localisation:
    """Where the stack's pose comes from in a run (module doc), as the run's header and the
    result file state it."""

    source: str  # what the pose is made of
    receiver: str  # the GNSS receiver: its preset's name (`world.spec.GNSS_PRESETS`), or custom
    error: float  # [m] the receiver's expected position error per axis: its stated 1-sigma
    #   (white noise and wandering bias) plus the constant bias's size
    privileged: bool  # privileged truth mode: the stack is also given the ground truth
    note: str  # one line for the run's header

    def as_json(self) -> dict[str, object]:
        return {"source": self.source, "receiver": self.receiver,
                "error": round(self.error, 4), "privileged": self.privileged}


def receiver_name(gnss: GnssSpec) -> str:
    """The preset `gnss` is (`world.spec.GNSS_PRESETS`), or "custom" when knobs changed it."""
    return next((name for name, spec in GNSS_PRESETS.items() if spec == gnss), "custom")


def localisation(profile: Profile | None, gnss: GnssSpec,
                 privileged: bool = False, own: bool = False) -> Localisation:
    """The pose's source for a run with `profile` (None: `--profile none`), the scenario's
    receiver `gnss` and, with `privileged`, the ground truth (module doc); `own`: a user's
    perception localises the car (a whole stack of its own, or its perception stage), and
    only the car's sensors are known here."""
    found = _sensed(profile, gnss) if not own else _own(profile, gnss)
    if not privileged:
        return found
    return replace(found, privileged=True, note=f"{PRIVILEGED_NOTE}; sensors: {found.note}")


PRIVILEGED_NOTE = ("privileged: ground truth (the truth sensor gives the stack the true pose "
                   "and objects)")


def _own(profile: Profile | None, gnss: GnssSpec) -> Localisation:
    """A user's perception: its own pose from the car's sensors (`localisation`)."""
    receiver = receiver_name(gnss)
    error = gnss.stated_sigma + math.hypot(*gnss.bias)  # [m]
    sensors = "GNSS and odometry only" if profile is None else \
        f"profile {profile.value}'s cameras and LiDAR, GNSS and odometry"
    return Localisation(
        "own", receiver, error, False,
        f"{'profile none' if profile is None else f'profile {profile.value}'}: the stack "
        f"localises the car itself, from {sensors} (GNSS: {receiver} receiver, "
        f"{error:.2f} m 1-sigma per axis)")


def _sensed(profile: Profile | None, gnss: GnssSpec) -> Localisation:
    """The pose's source from the sensors alone (`localisation`)."""
    receiver = receiver_name(gnss)
    error = gnss.stated_sigma + math.hypot(*gnss.bias)  # [m]
    fix = f"GNSS ({receiver} receiver, {error:.2f} m 1-sigma per axis) + odometry"
    if profile is None:
        return Localisation(
            "gnss+odometry", receiver, error, False,
            f"profile none: no camera or LiDAR (no lane, no objects seen); the pose is {fix} "
            f"on the map: expect lane-keeping errors of the receiver's size ({error:.2f} m); "
            "sensors.gnss: {preset: rtk} for 5 cm")
    return Localisation(
        "gnss+odometry+camera_lane", receiver, error, False,
        f"profile {profile.value}: the pose is {fix}, corrected across the lane by the front "
        "camera's lane; objects from the LiDAR")

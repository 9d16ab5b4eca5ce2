"""Sensor data types: what the car's sensors hand to the stack.

This is a leaf module (dataclasses and numpy types only, no PyBullet) so that `perception/`
may import it without reaching into the simulator.

Frames:
- map: ENU-like, x east, y north, z up, yaw counter-clockwise from +x;
- vehicle: the car's footprint frame, origin on the ground below the car's centre (below the
  base link origin, which is at wheel-centre height), x forward, y left, z up; it moves with
  the body (pitch and roll included);
- sensor: a sensor's own frame, placed on the vehicle by its `SensorMount`; x along the
  sensor's axis (a camera's optical axis), y left, z up.

Conventions every stage shares (the stack may import this module): SI units inside, with
the one speed conversion named (`MPS_PER_KPH`, `kph`, `to_kph`); angles in radians,
headings and yaws wrapped to (-pi, pi] by `wrap_angle`.

It also holds the one Open3D importer (`import_open3d`, at the end): both the world (the
LiDAR's Embree ray caster) and perception (clustering the scans) use Open3D, and this is the
one module of ours both may import. Open3D 0.20 links against `libusb-1.0.so.0`, which a fresh
Debian machine lacks; the pinned `libusb-package` wheel carries a copy whose SONAME is
`libusb-1.0.so.0`, and loading it globally before Open3D satisfies the dynamic linker (a
system libusb, when present, is used instead). Nothing heavy is imported until it is called.
"""

from __future__ import annotations

import ctypes
import enum
import functools
import importlib
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import ModuleType
from typing import TypeAlias

import numpy as np
from numpy.typing import NDArray

__all__ = ["MPS_PER_KPH", "CameraFrame", "CameraInfo", "DriverControls", "Frame", "Frames",
           "GnssFix", "GroundTruth", "LidarInfo", "LidarScan", "Odometry", "SensorKind",
           "SensorMount", "SensorSpec", "TruthObject", "VehicleInfo", "Wheel", "import_open3d",
           "kph", "to_kph", "wrap_angle"]

MPS_PER_KPH = 1.0 / 3.6  # [m/s per km/h]


def kph(speed_kph: float) -> float:
    """[m/s] of a speed in km/h."""
    return speed_kph * MPS_PER_KPH


def to_kph(speed: float) -> float:
    """[km/h] of a speed in m/s."""
    return speed / MPS_PER_KPH


def wrap_angle(angle: float) -> float:
    """[rad] `angle` wrapped to (-pi, pi] (exact: IEEE remainder by 2 pi)."""
    wrapped = math.remainder(angle, math.tau)
    return math.pi if wrapped == -math.pi else wrapped


class Wheel(enum.Enum):
    """The wheels, named as the odometry orders them."""

    FRONT_LEFT = "front_left"
    FRONT_RIGHT = "front_right"
    REAR_LEFT = "rear_left"
    REAR_RIGHT = "rear_right"


@dataclass(frozen=True, slots=True)
class VehicleInfo:
    """The car's own dimensions, as the stack is configured with them (its calibration, like
    a camera's `CameraInfo`); the world makes it from the URDF's `CarGeometry`."""

    length: float  # [m] body, bumper to bumper
    width: float  # [m] body, mirrors excluded
    wheelbase: float  # [m] front to rear axle
    track: float  # [m] left to right wheel centre
    front_axle: float  # [m] the car's centre to the front axle
    rear_axle: float  # [m] the car's centre to the rear axle (a positive distance)
    mass: float  # [kg] total, wheels included
    wheel_radius: float  # [m] the tyres' rolling radius
    max_steer: float  # [rad] the largest road-wheel angle of the bicycle model

    @property
    def front_overhang(self) -> float:
        """[m] the car's centre to its front bumper."""
        return self.length / 2

    @property
    def rear_overhang(self) -> float:
        """[m] the car's centre to its rear bumper."""
        return self.length / 2


@dataclass(frozen=True, slots=True)
class GnssFix:
    """A GNSS position and heading fix, with the sensor's noise and bias already in it.

    In an outage the receiver still reports each epoch, flagged ``valid=False`` (NMEA's
    status V, "no fix"): its position and heading are then NaN and mean nothing."""

    t: float  # [s] sim time of the measurement
    x: float  # [m] map frame, at the car's centre (base link origin)
    y: float  # [m] map frame
    heading: float  # [rad] yaw of the car's body, counter-clockwise from +x, in (-pi, pi]
    sigma: float  # [m] the receiver's stated 1-sigma horizontal accuracy, per axis
    heading_sigma: float  # [rad] the receiver's stated 1-sigma heading accuracy
    valid: bool = True  # False: no fix this epoch (an outage)


class Indicator(enum.Enum):
    """The turn indicators' switch (lamps are truth, like the hazard lights)."""

    OFF = "off"
    LEFT = "left"
    RIGHT = "right"


@dataclass(frozen=True, slots=True)
class DriverControls:
    """The driver's controls that the stack reads as vehicle signals besides the accelerator
    pedal: the cruise set speed buttons, the turn-signal stalk and the brake pedal. The car
    is drive-by-wire: none of them moves the car by itself; the stack arbitrates them
    (`planner.planner`)."""

    set_speed: float | None = None  # [m/s] the set speed the driver last chose (None: none
    #   chosen, the configured one holds)
    lane_request: int | None = None  # [-] the lane the stalk asks for (ego-direction index,
    #   0 rightmost), held until released; None: the stalk at rest
    brake: float = 0.0  # [-] 0..1, the brake pedal position
    activations: int = 0  # [-] how often the driver has switched the function on (a press
    #   after a brake override turns it back on)


@dataclass(frozen=True, slots=True)
class Odometry:
    """The vehicle signals sampled together: wheel encoders, steering encoder, yaw-rate
    gyro, the accelerator pedal sensor (drive-by-wire: the driver's, or an external control
    device's, pedal is an input the stack arbitrates, not a torque on the wheels) and the
    switch of the automated driving function."""

    t: float  # [s] sim time of the measurement
    wheel_speeds: tuple[float, float, float, float]  # [rad/s] FL, FR, RL, RR spin rates
    wheel_radius: float  # [m] the car's nominal rolling radius
    yaw_rate: float  # [rad/s] gyro z, counter-clockwise positive
    steering_angle: float  # [rad] measured road-wheel angle (bicycle equivalent), left +
    accelerator_pedal: float = 0.0  # [-] 0..1, the driver's accelerator pedal position sensor
    engaged: bool = True  # the driver's switch of the automated driving function: on, the
    #   stack drives; off, the driver holds the speed (an OpenSCENARIO file's car under test
    #   before its ActivateControllerAction)
    driver: DriverControls = field(default_factory=DriverControls)  # the driver's other
    #   controls

    @property
    def speed(self) -> float:
        """[m/s] forward speed from the mean rear-wheel spin (the undriven-by-steer axle)."""
        return 0.5 * (self.wheel_speeds[2] + self.wheel_speeds[3]) * self.wheel_radius


@dataclass(frozen=True, slots=True)
class SensorMount:
    """Where a sensor sits on the car: its frame in the vehicle frame (calibration data)."""

    x: float  # [m] forward of the car's centre
    y: float  # [m] left of the car's centre
    z: float  # [m] above the ground
    roll: float = 0.0  # [rad] about the sensor's x
    pitch: float = 0.0  # [rad] about y, positive looks DOWN (right-handed about +y)
    yaw: float = 0.0  # [rad] about z, counter-clockwise from the car's forward axis

    def rotation(self) -> NDArray[np.float64]:
        """(3, 3) sensor-to-vehicle rotation R = Rz(yaw) Ry(pitch) Rx(roll)."""
        cr, sr = math.cos(self.roll), math.sin(self.roll)
        cp, sp = math.cos(self.pitch), math.sin(self.pitch)
        cy, sy = math.cos(self.yaw), math.sin(self.yaw)
        return np.array([
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ])

    def to_vehicle(self, points: NDArray[np.floating]) -> NDArray[np.float64]:
        """(N, 3) points in the sensor frame -> the vehicle frame."""
        out: NDArray[np.float64] = points @ self.rotation().T + np.array([self.x, self.y, self.z])
        return out


@dataclass(frozen=True, slots=True)
class CameraInfo:
    """A pinhole camera: resolution, field of view and mounting (static calibration).

    Pixel (u, v): u to the right, v down, continuous, pixel i covering [i, i + 1). A point
    (X, Y, Z) in the camera's sensor frame (X along the optical axis, Y left, Z up, X > 0)
    images at ``u = cx - fx Y / X``, ``v = cy - fy Z / X``.
    """

    name: str  # the camera's place on the car: "front", "left", "right"
    width: int  # [px]
    height: int  # [px]
    fov_x: float  # [rad] horizontal field of view
    mount: SensorMount  # its frame on the car
    near: float = 0.1  # [m] the renderer's near clipping distance
    far: float = 250.0  # [m] the renderer's far clipping distance

    @property
    def fx(self) -> float:
        """[px] focal length (square pixels: fy = fx)."""
        return 0.5 * self.width / math.tan(0.5 * self.fov_x)

    @property
    def fy(self) -> float:
        """[px] vertical focal length, = fx."""
        return self.fx

    @property
    def cx(self) -> float:
        """[px] principal point, the image centre."""
        return 0.5 * self.width

    @property
    def cy(self) -> float:
        """[px] principal point, the image centre."""
        return 0.5 * self.height

    @property
    def fov_y(self) -> float:
        """[rad] vertical field of view."""
        return 2.0 * math.atan(0.5 * self.height / self.fy)

    def matrix(self) -> NDArray[np.float64]:
        """(3, 3) the intrinsic matrix K for OpenCV-style (x right, y down, z forward) rays."""
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])


@dataclass(frozen=True, slots=True, eq=False)
class CameraFrame:
    """One camera image."""

    t: float  # [s] sim time of the exposure
    info: CameraInfo
    rgb: NDArray[np.uint8]  # (height, width, 3)


@dataclass(frozen=True, slots=True)
class LidarInfo:
    """A spinning multi-channel LiDAR (VLP-16-like): the beam layout and mounting."""

    elevations: tuple[float, ...]  # [rad] per channel (ring), ascending
    azimuth_steps: int  # [-] columns per revolution
    max_range: float  # [m] farthest return
    mount: SensorMount  # its frame on the car
    range_sigma: float = 0.02  # [m] range noise, 1-sigma
    dropout: float = 0.0  # [-] fraction of returns lost

    @property
    def channels(self) -> int:
        """[-] beams (rings) per column."""
        return len(self.elevations)

    @property
    def rays(self) -> int:
        """[-] rays per revolution, channels * azimuth_steps."""
        return self.channels * self.azimuth_steps


@dataclass(frozen=True, slots=True, eq=False)
class LidarScan:
    """One revolution's returns (rays without a return, or dropped, are absent).

    The revolution is taken at one instant ``t`` (no motion skew). Azimuth 0 is the sensor's
    forward axis, increasing counter-clockwise.
    """

    t: float  # [s] sim time of the revolution
    info: LidarInfo
    points: NDArray[np.float32]  # [m] (N, 3) in the sensor frame
    ring: NDArray[np.uint8]  # (N,) channel index into info.elevations
    column: NDArray[np.uint16]  # (N,) azimuth step, 0 .. info.azimuth_steps - 1


@dataclass(frozen=True, slots=True)
class TruthObject:
    """One road user or obstacle as the simulator knows it (privileged truth mode only):
    its box, exactly, in the map frame."""

    id: str  # the scenario's name of the object (stable over the run)
    kind: str  # "car", "truck", "pedestrian", "obstacle"
    x: float  # [m] map frame, the box's centre
    y: float  # [m] map frame, the box's centre
    yaw: float  # [rad] map frame, the box's heading, counter-clockwise from +x, in (-pi, pi]
    vx: float  # [m/s] map frame, velocity over ground (its centre's motion since the last
    #   capture; at its first, its speed along its heading)
    vy: float  # [m/s] map frame
    length: float  # [m] along its heading
    width: float  # [m]
    height: float  # [m]


@dataclass(frozen=True, slots=True)
class GroundTruth:
    """The ground truth at one instant, the frame of the `truth` sensor (privileged truth
    mode only, `SensorKind.TRUTH`): the car's own state and every object the sensors could
    see (an object hidden from the sensors is not in it), exactly, in the map frame."""

    t: float  # [s] sim time
    x: float  # [m] map frame, the car's centre (base link origin)
    y: float  # [m] map frame
    heading: float  # [rad] the car's yaw, counter-clockwise from +x, in (-pi, pi]
    speed: float  # [m/s] forward (body x) speed
    yaw_rate: float  # [rad/s] counter-clockwise +
    steering_angle: float  # [rad] road-wheel angle (bicycle equivalent), left +
    objects: tuple[TruthObject, ...] = ()  # every other road user and obstacle


# What a sensor hands to the stack: one capture of one sensor (`world.sensors.sensor.Sensor`).
Frame: TypeAlias = CameraFrame | LidarScan | GnssFix | Odometry | GroundTruth

# One delivery: the frames of the sensors captured together, by sensor name (`SensorSpec`),
# in the order the sensors are listed.
Frames: TypeAlias = Mapping[str, Frame]


class SensorKind(enum.Enum):
    """What a sensor's frames are."""

    CAMERA = "camera"  # `CameraFrame`
    LIDAR = "lidar"  # `LidarScan`
    GNSS = "gnss"  # `GnssFix`
    ODOMETRY = "odometry"  # `Odometry`
    TRUTH = "truth"  # `GroundTruth` (privileged truth mode only)


@dataclass(frozen=True, slots=True)
class SensorSpec:
    """A sensor on the car, as the stack is told of it: its name (the key of its frames in
    a delivery), kind, timing and calibration."""

    name: str  # unique on the car: "front", "left", "right", "lidar", "gnss", "odometry",
    #   "truth" (privileged truth mode only)
    kind: SensorKind
    rate: float  # [Hz] captures per second
    latency: float  # [s] from a capture to its delivery
    info: CameraInfo | LidarInfo | None = None  # a camera's or LiDAR's calibration


# ---- Open3D, shared by the world and perception ----------------------------------------------


def preload_libusb() -> None:
    """Load a libusb-1.0 into the process so that Open3D's dependency resolves."""
    try:
        ctypes.CDLL("libusb-1.0.so.0", mode=ctypes.RTLD_GLOBAL)
        return
    except OSError:
        pass
    import libusb_package

    path = libusb_package.get_library_path()
    if path is None:
        raise ImportError("no libusb-1.0 found (install libusb-1.0-0 or libusb-package)")
    ctypes.CDLL(str(path), mode=ctypes.RTLD_GLOBAL)


@functools.cache
def import_open3d() -> ModuleType:
    """The open3d module, imported once, with its log quiet below errors."""
    preload_libusb()
    o3d = importlib.import_module("open3d")
    o3d.utility.set_verbosity_level(o3d.utility.VerbosityLevel.Error)
    return o3d

"""What perception hands to the planner, and the perception stage's interface
(`PerceptionStage`). A leaf module: dataclasses and a protocol only."""

from __future__ import annotations

import enum
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Protocol

from world.frames import DriverControls, Frames
from world.hdmap import LightColour


@dataclass(frozen=True, slots=True)
class EgoState:
    """The stack's own estimate of the car's state (fused GNSS + odometry)."""

    t: float  # [s] sim time of the estimate
    x: float  # [m] map frame, car centre
    y: float  # [m] map frame, car centre
    heading: float  # [rad] yaw, counter-clockwise from +x, in (-pi, pi]
    speed: float  # [m/s] forward speed
    yaw_rate: float  # [rad/s]
    steering_angle: float  # [rad] measured road-wheel angle (bicycle), left +
    position_sigma: float  # [m] 1-sigma of the position estimate


# ---- lanes (camera) ------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class LaneBoundary:
    """One painted boundary line, fitted in the vehicle frame as y = c0 + c1 x + c2 x^2."""

    coefficients: tuple[float, float, float]  # (c0 [m], c1 [-], c2 [1/m])
    x_min: float  # [m] nearest forward distance the fit is supported by pixels
    x_max: float  # [m] farthest
    pixels: int  # [-] bird's-eye-view pixels behind the fit

    def y_at(self, x: float) -> float:
        """[m] lateral position (left +) of the line at forward distance x [m]."""
        c0, c1, c2 = self.coefficients
        return c0 + c1 * x + c2 * x * x


@dataclass(frozen=True, slots=True)
class LaneEstimate:
    """The ego lane as the front camera sees it, in the vehicle frame at time ``t``.

    The lane centre is y(x) = -offset - tan(heading_error) x + curvature x^2 / 2 (`centre_y`;
    vehicle frame: x forward from the car's centre, y left). ``offset`` is where the car's
    centre is relative to that centre line (left +: the car is left of the lane centre),
    ``heading_error`` the car's heading minus the lane's (left +), ``curvature`` the lane's
    (left turn +). With ``confidence`` below the consumer's threshold the numbers are the
    filter's prediction, not a measurement. ``lines`` counts the boundaries the frame's
    detection saw; ``age`` is 0 for a detection, and for the filter's output the time since
    the last detection it took, over which it dead-reckoned the lane on odometry
    (`perception.lanes.LaneFilter`).
    """

    t: float  # [s] sim time of the camera frame
    offset: float  # [m] car centre relative to the lane centre, left +
    heading_error: float  # [rad] car heading minus lane heading, left +
    curvature: float  # [1/m] lane curvature at the car, left turn +
    width: float  # [m] lane width
    confidence: float  # [0, 1] how much of the lane was seen (both lines, windows, length)
    left: LaneBoundary | None  # the left boundary fit, if found in this frame
    right: LaneBoundary | None  # the right boundary fit, if found in this frame
    lines: int = 2  # [-] boundaries (0, 1, 2) the frame's detection saw
    age: float = 0.0  # [s] since the lane was last measured (the filter's prediction since)

    def centre_y(self, x: float) -> float:
        """[m] lateral position (left +) of the lane centre at forward distance x [m], from
        the car's centre, in the vehicle frame (second-order: offset, heading, curvature)."""
        return -self.offset - math.tan(self.heading_error) * x + 0.5 * self.curvature * x * x


# ---- objects (LiDAR) -----------------------------------------------------------------------


class ObjectClass(enum.Enum):
    """A coarse class from the box size."""

    CAR = "car"
    TRUCK = "truck"
    MOTORCYCLE = "motorcycle"  # a powered two-wheeler and its rider
    PEDESTRIAN = "pedestrian"
    OTHER = "other"


@dataclass(frozen=True, slots=True)
class Detection:
    """One object found in one LiDAR scan: an oriented box in the vehicle frame."""

    x: float  # [m] box centre, vehicle frame (forward)
    y: float  # [m] box centre, vehicle frame (left)
    z: float  # [m] box centre height above the ground
    length: float  # [m] along the box's heading
    width: float  # [m]
    height: float  # [m]
    yaw: float  # [rad] box heading in the vehicle frame, in (-pi/2, pi/2] (no front/back)
    cls: ObjectClass  # coarse class from the box size
    points: int  # [-] LiDAR returns in the cluster
    # the box's end nearer the sensor along its length was seen on the lower body (or no end
    #   faces the sensor): that end is where the object ends. False: a car whose returns
    #   there all lie above its lower body (a bonnet, boot deck or cabin, set back from the
    #   bumper by an unknown distance; one ring crosses it, the ring below meets the ground
    #   first): the object's end may lie nearer the sensor than the box's
    end_seen: bool = True


@dataclass(frozen=True, slots=True)
class Track:
    """A tracked object: filtered position and velocity over ground, in the map frame, and
    the same relative to the ego (vehicle frame at the track's time)."""

    id: int  # [-] stable while the track lives, never reused
    t: float  # [s] time of the state
    x: float  # [m] map frame, box centre
    y: float  # [m]
    vx: float  # [m/s] map frame, over ground
    vy: float  # [m/s]
    rel_x: float  # [m] vehicle frame: ahead of the car's centre
    rel_y: float  # [m] vehicle frame: left of the car's centre
    rel_vx: float  # [m/s] vehicle frame: relative velocity (object minus ego), forward
    rel_vy: float  # [m/s] vehicle frame, left
    length: float  # [m]
    width: float  # [m]
    height: float  # [m]
    yaw: float  # [rad] map frame box heading
    cls: ObjectClass  # majority class of the track's detections
    hits: int  # [-] scans this track was updated in
    misses: int  # [-] consecutive scans without a detection (coasting)
    position_sigma: float  # [m] 1-sigma of the position (largest axis)

    @property
    def speed(self) -> float:
        """[m/s] speed over ground."""
        return math.hypot(self.vx, self.vy)


# ---- signs (camera) ------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class SignDetection:
    """A traffic sign found in one camera frame: its plate's centre in the vehicle frame at
    time ``t`` (x forward from the car's centre, y left, z up from the ground below it)."""

    t: float  # [s] sim time of the camera frame
    kind: str  # [-] "stop"
    x: float  # [m] vehicle frame, plate centre ahead of the car's centre
    y: float  # [m] vehicle frame, left of the car's centre
    z: float  # [m] plate centre above the ground
    range: float  # [m] horizontal distance from the car's centre, hypot(x, y)
    box: tuple[int, int, int, int]  # [px] (u0, v0, u1, v1) of the sign's pixels, u1/v1 exclusive
    confidence: float  # [0, 1] how sign-like the blob is (shape, colour, size)

    def match(self, ego: EgoState, map_signs: Sequence[tuple[float, float, float]],
              tolerance: float = 5.0, range_tolerance: float = 0.15) -> float | None:
        """The station [m] of the map sign this detection is, or None.

        ``map_signs``: (station [m], x [m], y [m]) of each map sign (plate or pole, map
        frame). The detection is placed in the map frame with the ego's pose; a map sign
        matches when its offset from there is within ``tolerance`` [m] across the line of
        sight and ``tolerance + range_tolerance * range`` along it (the range, from the
        plate's apparent size, is the uncertain part); of several, the nearest in those
        normalised units."""
        c, s = math.cos(ego.heading), math.sin(ego.heading)
        det_x = ego.x + c * self.x - s * self.y
        det_y = ego.y + s * self.x + c * self.y
        bearing = ego.heading + math.atan2(self.y, self.x)
        ux, uy = math.cos(bearing), math.sin(bearing)
        along_tol = tolerance + range_tolerance * self.range
        best: tuple[float, float] | None = None  # (normalised distance, station)
        for station, x, y in map_signs:
            dx, dy = x - det_x, y - det_y
            along, across = dx * ux + dy * uy, -dx * uy + dy * ux
            if abs(along) > along_tol or abs(across) > tolerance:
                continue
            distance = math.hypot(along / along_tol, across / tolerance)
            if best is None or distance < best[0]:
                best = (distance, station)
        return None if best is None else best[1]


# ---- traffic lights (camera) ---------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class LightDetection:
    """The lit lamp of one map traffic light, as seen in one camera frame."""

    t: float  # [s] sim time of the camera frame
    light: int  # [-] the caller's id of the light's head (`TrafficLightDetector.detect`: its
    #   index in `RoadMap.traffic_lights`)
    colour: LightColour  # the lit lamp's colour
    range: float  # [m] horizontal distance from the car's centre to the head (map and pose)
    confidence: float  # [0, 1] how clearly the lamp was seen (size, uniqueness, position)
    box: tuple[int, int, int, int]  # [px] (u0, v0, u1, v1) of the lamp's pixels, u1/v1 exclusive


# ---- the one message the planner receives each tick ---------------------------------------


@dataclass(frozen=True, slots=True, eq=False)
class LaneView:
    """The camera's latest lane estimate and the stack's pose estimate at its frame's time
    (the estimate is in that pose's vehicle frame)."""

    estimate: LaneEstimate  # vehicle frame at `pose`
    pose: EgoState  # map frame, at the camera frame's time


@dataclass(frozen=True, slots=True, eq=False)
class SignView:
    """The traffic signs found in one camera frame and the pose estimate at its time."""

    signs: tuple[SignDetection, ...]  # vehicle frame at `pose`
    pose: EgoState  # map frame, at the camera frame's time


@dataclass(frozen=True, slots=True)
class SensorHealth:
    """What the stack noticed wrong with its sensors, from their data alone
    (`perception.health`): per sensor None while it is fine, else how the fault was noticed
    (the reason its state changes give)."""

    camera: str | None = None  # the front camera's frames (blank, frozen, late, missing)
    lidar: str | None = None  # the LiDAR's scans (late, missing, empty)
    gnss: str | None = None  # the GNSS fixes (missing, inconsistent with the odometry)
    occlusion: str | None = None  # part of the front camera's view covered (its frames are
    #   still perceived: the lane on what is seen)

    @property
    def ok(self) -> bool:
        """Every sensor is fine."""
        return (self.camera is None and self.lidar is None and self.gnss is None
                and self.occlusion is None)


@dataclass(frozen=True, slots=True, eq=False)
class PlannerInput:
    """What perception hands the planner each control tick.

    `ego`, `lane` and `tracks` hold the latest estimates (the lane and tracks are as old as
    the last camera frame / LiDAR scan, one sensor period or more). `signs` and `lights`
    are what the frame delivered since the last tick showed, given once: None / empty on
    the ticks between frames."""

    ego: EgoState  # the pose and speed estimate now
    lane: LaneView | None = None  # None before the camera's first lane (or without one)
    tracks: tuple[Track, ...] = ()  # the confirmed tracks
    signs: SignView | None = None  # the signs of a frame delivered this tick
    lights: tuple[LightDetection, ...] = ()  # the lights of a frame delivered this tick
    pedal: float = 0.0  # [-] 0..1, the driver's accelerator pedal position
    engaged: bool = True  # the automated driving function is switched on (off: the driver
    #   holds the speed, `planner.planner`)
    driver: DriverControls = field(default_factory=DriverControls)  # the driver's set
    #   speed, turn-signal stalk and brake pedal (`planner.planner`)
    flat_tyre: bool = False  # a flat tyre is detected (from the wheel speeds)
    health: SensorHealth = SensorHealth()  # the sensor faults noticed now


# ---- the stage -------------------------------------------------------------------------


@dataclass(frozen=True, slots=True, eq=False)
class PerceptionReport:
    """What perception made of one delivery of camera / LiDAR data, for scoring against the
    truth and for the recording (any field None: not made from this delivery)."""

    t: float  # [s] capture time of the data
    pose: EgoState  # the stack's pose estimate at that time
    lane_raw: LaneEstimate | None = None  # the lane camera's detection in this frame
    lane: LaneEstimate | None = None  # ... filtered
    detections: tuple[Detection, ...] | None = None  # None: no scan in this delivery
    tracks: tuple[Track, ...] | None = None  # the tracks after this scan


class PerceptionStage(Protocol):
    """The perception stage: sensor frames in, `PlannerInput` out.

    The runner calls `on_frames` with each delivery, in time order, then `perceive` once
    per control tick (after that tick's deliveries)."""

    @property
    def reads(self) -> frozenset[str] | None:
        """The names of the sensors whose frames it uses (None: all); a camera no stage
        reads is not rendered unless the recording needs it."""

    def on_frames(self, t: float, frames: Frames) -> PerceptionReport | None:
        """One delivery: `frames` captured together at time `t` [s], by sensor name; a
        report for scoring and the recording, or None."""

    def perceive(self, t: float) -> PlannerInput:
        """The planner's input for the control tick at time `t` [s]."""

"""The driving stack, wired: perception -> planner -> control.

It is fed only sensor data (`GnssFix`, `Odometry`, camera frames, LiDAR scans: the frames
`on_frames` takes, each to its consumer) and the static HD map, and returns a
`VehicleCommand`. The sensor loop hands it the frames at their rates, the runner applies
its command to the ego's joints.

Camera and LiDAR data arrive one sensor period after their capture (`world.sensors.pipeline`); the
stack keeps its own pose estimates of the last seconds, so that each frame is interpreted in
the pose the car had when it was taken: the lane estimate and the tracks refer to it.
Without a sensor set-up (no profile) the stack is GNSS + odometry on the map only.
"""

from __future__ import annotations

import bisect
from collections.abc import Sequence
from dataclasses import dataclass, replace

from avsim.scenario.scenario import DriverSettings
from control.actuation import VehicleParams
from control.command import VehicleCommand
from control.stanley import MAX_STEER, StanleyParams
from control.vehicle_controller import VehicleController, VehicleControllerParams
from perception.flat_tyre import FlatTyreDetector
from perception.health import HealthMonitor
from perception.lanes import LaneDetector, LaneFilter
from perception.lights import TrafficLightDetector
from perception.localization import LaneMatch, Localizer, LocalizerParams, clear_ahead
from perception.messages import (
    Detection,
    EgoState,
    LaneEstimate,
    LaneView,
    LightDetection,
    PlannerInput,
    SignView,
    Track,
)
from perception.objects import ObjectDetector
from perception.signs import StopSignDetector
from perception.stop_lines import StopLineDetector
from perception.tracking import MultiObjectTracker
from planner.messages import Plan
from planner.motion_layer import MotionLayerParams
from planner.planner import Planner, PlannerParams
from vehicle_urdf import CarGeometry
from world.core.rates import CAR_SENSORS
from world.core.stopwatch import Stopwatch
from world.ego.body import vehicle_info
from world.frames import (
    CameraFrame,
    CameraInfo,
    DriverControls,
    Frame,
    GnssFix,
    LidarScan,
    Odometry,
    wrap_angle,
)
from world.hdmap import RoadMap
from world.sensors.setup import LIDAR
from world.spec import EgoSpec

POSE_HISTORY = 2.0  # [s] own pose estimates kept for interpreting late sensor data


@dataclass(frozen=True, slots=True, eq=False)
class StackOutput:
    plan: Plan
    command: VehicleCommand


@dataclass(frozen=True, slots=True, eq=False)
class PerceptionOutput:
    """What perception made of one delivery of sensor data (for scoring and recording)."""

    t: float  # [s] capture time of the data
    pose: EgoState  # the stack's pose estimate at that time
    lane_raw: LaneEstimate | None  # this frame's detection
    lane: LaneEstimate | None  # filtered
    detections: tuple[Detection, ...] | None  # None: no scan in this delivery
    tracks: tuple[Track, ...] | None


def _corrected(pose: EgoState, match: LaneMatch | None) -> EgoState:
    """The pose at a camera frame's time, moved by the map-matching correction that frame
    made (the frame's lane is placed in the map with it, as the car's pose now is)."""
    if match is None or not match.accepted:
        return pose
    dx, dy, dpsi = match.correction
    return replace(pose, x=pose.x + dx, y=pose.y + dy, heading=wrap_angle(pose.heading + dpsi))


class Stack:
    """Localizer, lane and object perception, lane-keeping planner, vehicle controller."""

    def __init__(self, road: RoadMap, ego: EgoSpec, driver: DriverSettings, car: CarGeometry,
                 front_camera: CameraInfo | None = None, watch: Stopwatch | None = None) -> None:
        """`ego`: the car's start and limits; `driver`: what the driver asks of the stack;
        `front_camera`: the camera the lane is found in; None for a map-only stack; `watch`:
        times each stage (localisation, each perception stage, planner, control)."""
        self.watch = watch if watch is not None else Stopwatch()
        self.reads = frozenset({*CAR_SENSORS, LIDAR}
                               | ({front_camera.name} if front_camera is not None else set()))
        #   the sensors whose frames it uses (it ignores the side cameras')
        self.localizer = Localizer(LocalizerParams(rear_axle=car.rear_axle),
                                   road=road if front_camera is not None else None,
                                   start_lane=ego.lane)
        #   the camera's lane corrects the pose across the lane (map matching)
        vehicle = vehicle_info(car)
        self.planner = Planner(
            road, PlannerParams(set_speed=driver.set_speed, max_speed=ego.max_speed,
                                vehicle=vehicle, lane=ego.lane,
                                camera=front_camera is not None,
                                motion=MotionLayerParams(overtake=driver.overtake))
        )
        lateral = StanleyParams(
            wheelbase=car.wheelbase, centre_to_front_axle=car.front_axle,
            max_steer=min(MAX_STEER, car.max_steer),
        )
        self.controller = VehicleController(VehicleControllerParams(
            lateral=lateral, vehicle=VehicleParams(mass=car.mass, wheel_radius=car.wheel_radius)))
        self.lane_detector = LaneDetector(front_camera) if front_camera is not None else None
        self.stop_line_detector = StopLineDetector(front_camera) \
            if front_camera is not None else None
        self.sign_detector = StopSignDetector(front_camera) if front_camera is not None \
            else None
        self.light_detector = TrafficLightDetector(front_camera, road, vehicle) \
            if front_camera is not None and road.traffic_lights else None
        self.lane_filter = LaneFilter()
        self.object_detector = ObjectDetector()
        self.flat_detector = FlatTyreDetector(vehicle)
        self.health = HealthMonitor()
        self.tracker = MultiObjectTracker()
        self._times: list[float] = []  # [s] of the poses below, increasing
        self._poses: list[EgoState] = []
        self._view: LaneView | None = None
        self._tracks: tuple[Track, ...] = ()
        self._signs: SignView | None = None  # the last frame's signs, for the next tick
        self._lights: tuple[LightDetection, ...] = ()  # the last frame's lights, likewise
        self._pedal = 0.0  # [-] the driver's accelerator pedal, from the odometry
        self._engaged = True  # the function's switch, from the odometry
        self._driver = DriverControls()  # the driver's other controls, from the odometry

    def on_frames(self, t: float, frames: Sequence[Frame]) -> PerceptionOutput | None:
        """One delivery: the frames captured together at time `t` [s], each to its
        consumer. GNSS fixes and odometry go to the localiser (in their order); camera frames
        and a LiDAR scan are perceived together (`on_sensors`; None if there are none)."""
        cameras: list[CameraFrame] = []
        scan: LidarScan | None = None
        for frame in frames:
            if isinstance(frame, GnssFix):
                self.on_gnss(frame)
            elif isinstance(frame, Odometry):
                self.on_odometry(frame)
            elif isinstance(frame, CameraFrame):
                cameras.append(frame)
            else:
                scan = frame
        if not cameras and scan is None:
            return None
        return self.on_sensors(t, tuple(cameras), scan)

    def on_gnss(self, fix: GnssFix) -> None:
        """A fix inconsistent with the odometry's prediction is not fused
        (`perception.health`)."""
        with self.watch("localisation"):
            predicted = self.localizer.predicted_fix(fix.t) if fix.valid else None
            if self.health.fix(fix, predicted).accepted:
                self.localizer.on_gnss(fix)

    def on_odometry(self, odo: Odometry) -> None:
        with self.watch("localisation"):
            self.localizer.on_odometry(odo)
        self._pedal = odo.accelerator_pedal
        self._engaged = odo.engaged
        self._driver = odo.driver
        with self.watch("perception flat tyre"):
            self.flat_detector.update(odo)

    def on_sensors(self, t: float, frames: tuple[CameraFrame, ...],
                   scan: LidarScan | None) -> PerceptionOutput | None:
        """Perceive the data captured at time `t` (late by the sensor latency); None when
        the stack has no pose for that time yet (before the first GNSS fix)."""
        pose = self._pose_at(t)
        if pose is None:
            return None
        front = next((f for f in frames if f.info.name == "front"), None)
        watch = self.watch
        now = self._times[-1] if self._times else t  # [s] the stack's clock: its last tick
        if scan is not None and self.health.scan(scan, now) is not None:
            scan = None  # late or empty: nothing to perceive in it
        if front is not None and self.lane_detector is not None:
            with watch("perception health"):
                fault = self.health.camera(front, pose.speed, now)
            if fault is not None:  # nothing to perceive in it: the lane is found anew after
                front, self._view = None, None
                self.lane_filter.reset()
        lane_raw = lane = None
        if front is not None and self.lane_detector is not None:
            prior = self._view.estimate if self._view is not None else None
            with watch("perception lanes"):
                lane_raw = self.lane_detector.detect(front, prior,
                                                     self.localizer.lane_width(pose))
            with watch("perception lane filter"):
                lane = self.lane_filter.update(lane_raw, pose.speed, pose.yaw_rate)
            with watch("localisation"):
                match = self.localizer.on_lane(lane, pose)
                self.localizer.on_line_end(lane, pose,
                                           clear_ahead(self._tracks, 0.5 * lane.width))
                self._gnss_across(lane.t, match)
            self._stop_line(front, lane, pose)
            self._view = LaneView(lane, _corrected(pose, match))
        if front is not None and self.sign_detector is not None:
            with watch("perception signs"):
                self._signs = SignView(tuple(self.sign_detector.detect(front)), pose)
        if front is not None and self.light_detector is not None:
            with watch("perception lights"):
                self._lights = self.light_detector.detect(front, pose)
        detections = tracks = None
        if scan is not None:
            with watch("perception objects"):
                detections = self.object_detector.detect(scan)
            with watch("perception tracking"):
                mount = scan.info.mount
                tracks = self.tracker.update(t, pose, detections, (mount.x, mount.y))
            self._tracks = tracks
        return PerceptionOutput(t, pose, lane_raw, lane, detections, tracks)

    def _gnss_across(self, t: float, match: LaneMatch | None) -> None:
        """Compare the fix with the camera's lane of time `t` [s] across the lane
        (`perception.health`); a receiver found inconsistent with it is no longer believed
        by the localiser."""
        if match is None:
            return
        self.health.across(t, match.fix_offset, match.fix_sigma,
                           self.localizer.params.lane_offset_sigma)
        self.localizer.gnss_consistent(self.health.gnss_inconsistent is None)

    def _stop_line(self, front: CameraFrame, lane: LaneEstimate, pose: EgoState) -> None:
        """Look for a stop line where the map has one ahead, and place the car along the
        route by it (`perception.stop_lines`, `Localizer.on_stop_line`). Ahead means within
        the reach a seen line is matched over (3 x ``stop_line_window``) of the camera's
        view: the estimate may be off along the route by metres where a car ahead hid the
        line, and the car then stands where it believes the line is, short of the view.
        Across the camera's lane; where that is no measurement (its lines end at the
        junction's mouth), across the map's lane on the pose (`Localizer.map_lane`)."""
        detector = self.stop_line_detector
        if detector is None:
            return
        p = detector.params
        reach = 3.0 * self.localizer.params.stop_line_window
        if not self.localizer.stop_lines_ahead(pose, p.min_x - reach, p.max_x + reach):
            return
        if lane.confidence < self.localizer.params.lane_confidence:
            on_map = self.localizer.map_lane(pose, lane.t)
            if on_map is None:
                return
            lane = on_map
        with self.watch("perception stop lines"):
            distance = detector.detect(front, lane)
        if distance is not None:
            with self.watch("localisation"):
                self.localizer.on_stop_line(distance, pose)

    def tick(self, t: float, dt: float) -> StackOutput:
        """Plan and control on the estimate now and the latest perception; a frame's signs
        and lights go to the planner once, at the tick after their delivery."""
        with self.watch("localisation"):
            ego = self.localizer.estimate(t)
        self._remember(ego)
        with self.watch("planner"):
            plan = self.planner.update(PlannerInput(
                ego=ego, lane=self._view, tracks=self._tracks, signs=self._signs,
                lights=self._lights, pedal=self._pedal, engaged=self._engaged,
                driver=self._driver,
                flat_tyre=self.flat_detector.state is not None, health=self.health.health(t)))
        self._signs, self._lights = None, ()
        with self.watch("control"):
            command = self.controller.update(plan, dt)
        return StackOutput(plan, command)

    def _remember(self, ego: EgoState) -> None:
        self._times.append(ego.t)
        self._poses.append(ego)
        drop = bisect.bisect_left(self._times, ego.t - POSE_HISTORY)
        if drop:
            del self._times[:drop], self._poses[:drop]

    def _pose_at(self, t: float) -> EgoState | None:
        """The pose estimate made at the control tick at (or just before) time `t`."""
        i = bisect.bisect_right(self._times, t + 1e-9) - 1
        return self._poses[i] if i >= 0 else None

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
from dataclasses import dataclass

from control.actuation import VehicleParams
from control.command import VehicleCommand
from control.stanley import StanleyParams
from control.vehicle_controller import VehicleController, VehicleControllerParams
from perception.flat_tyre import FlatTyreDetector, FlatTyreParams
from perception.lanes import LaneDetector, LaneFilter
from perception.lights import TrafficLightDetector
from perception.localization import Localizer
from perception.messages import Detection, EgoState, LaneEstimate, Track
from perception.objects import ObjectDetector
from perception.signs import StopSignDetector
from perception.tracking import MultiObjectTracker
from planner.events import EventParams
from planner.junctions import JunctionParams
from planner.messages import Plan
from planner.motion_layer import MotionLayerParams
from planner.planner import LaneKeepingParams, LaneKeepingPlanner, LaneView
from vehicle_urdf import CarGeometry
from world.frames import CameraFrame, CameraInfo, Frame, GnssFix, LidarScan, Odometry
from world.hdmap import RoadMap
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


class Stack:
    """Localizer, lane and object perception, lane-keeping planner, vehicle controller."""

    def __init__(self, road: RoadMap, ego: EgoSpec, car: CarGeometry,
                 front_camera: CameraInfo | None = None) -> None:
        """`front_camera`: the camera the lane is found in; None for a map-only stack."""
        self.localizer = Localizer()
        self.planner = LaneKeepingPlanner(
            road, LaneKeepingParams(set_speed=ego.set_speed, max_speed=ego.max_speed,
                                    lane=ego.lane, camera=front_camera is not None,
                                    motion=MotionLayerParams(overtake=ego.overtake),
                                    events=EventParams(front_overhang=car.front_overhang,
                                                       front_axle=car.front_axle,
                                                       rear_axle=car.rear_axle),
                                    junctions=JunctionParams(
                                        front_overhang=car.front_overhang))
        )
        lateral = StanleyParams(
            wheelbase=car.wheelbase, centre_to_front_axle=car.front_axle,
            max_steer=min(StanleyParams().max_steer, car.max_steer),
        )
        vehicle = VehicleParams(mass=car.mass, wheel_radius=car.wheel_radius)
        self.controller = VehicleController(
            VehicleControllerParams(lateral=lateral, vehicle=vehicle)
        )
        self.lane_detector = LaneDetector(front_camera) if front_camera is not None else None
        self.sign_detector = StopSignDetector(front_camera) if front_camera is not None \
            else None
        self.light_detector = TrafficLightDetector(front_camera) \
            if front_camera is not None and self.planner.junctions.lights else None
        self.lane_filter = LaneFilter()
        self.object_detector = ObjectDetector()
        self.flat_detector = FlatTyreDetector(FlatTyreParams(track=car.track,
                                                             wheelbase=car.wheelbase))
        self.tracker = MultiObjectTracker()
        self._times: list[float] = []  # [s] of the poses below, increasing
        self._poses: list[EgoState] = []
        self._view: LaneView | None = None
        self._tracks: tuple[Track, ...] = ()
        self._pedal = 0.0  # [-] the driver's accelerator pedal, from the odometry

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
        self.localizer.on_gnss(fix)

    def on_odometry(self, odo: Odometry) -> None:
        self.localizer.on_odometry(odo)
        self._pedal = odo.accelerator_pedal
        self.flat_detector.update(odo)

    def on_sensors(self, t: float, frames: tuple[CameraFrame, ...],
                   scan: LidarScan | None) -> PerceptionOutput | None:
        """Perceive the data captured at time `t` (late by the sensor latency); None when
        the stack has no pose for that time yet (before the first GNSS fix)."""
        pose = self._pose_at(t)
        if pose is None:
            return None
        front = next((f for f in frames if f.info.name == "front"), None)
        lane_raw = lane = None
        if front is not None and self.lane_detector is not None:
            prior = self._view.estimate if self._view is not None else None
            lane_raw = self.lane_detector.detect(front, prior)
            lane = self.lane_filter.update(lane_raw, pose.speed, pose.yaw_rate)
            self._view = LaneView(lane, pose)
        if front is not None and self.sign_detector is not None:
            signs = self.sign_detector.detect(front)
            self.planner.events.see_signs(signs, pose)
        if front is not None and self.light_detector is not None:
            station, _ = self.planner.localise(pose)
            heads = self.planner.junctions.heads_ahead(station)
            if heads:
                self.planner.junctions.see_lights(self.light_detector.detect(front, pose, heads))
        detections = tracks = None
        if scan is not None:
            detections = self.object_detector.detect(scan)
            tracks = self.tracker.update(t, pose, detections)
            self._tracks = tracks
        return PerceptionOutput(t, pose, lane_raw, lane, detections, tracks)

    def tick(self, t: float, dt: float) -> StackOutput:
        ego = self.localizer.estimate(t)
        self._remember(ego)
        plan = self.planner.update(ego, self._view, self._tracks, self._pedal,
                                   flat=self.flat_detector.state is not None)
        return StackOutput(plan, self.controller.update(plan, dt))

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

"""Perception's front door: the bundled perception stage (`perception.messages.PerceptionStage`).

It is told the car's sensors (`world.frames.SensorSpec`: name, kind, rate, calibration) and
takes each delivery by sensor name: GNSS fixes and odometry go to the localiser in their
order; the lane camera's frame (``lane_camera``, "front") and a LiDAR scan are perceived
together (`on_sensors`); the other cameras' frames are not read. A frame of a sensor it was
not told of, or of another kind than its sensor's, is refused (`ValueError`).

Camera and LiDAR data arrive one sensor period after their capture; the stage keeps its own
pose estimates of the last ``POSE_HISTORY`` seconds, so that each frame is interpreted in the
pose the car had when it was taken: the lane estimate and the tracks refer to it. Without a
camera it is GNSS + odometry on the map only (and the LiDAR's objects, if it has one).

At each control tick `perceive` gives the planner the estimate now and the latest lane and
tracks; a frame's signs and lights are given once, at the tick after their delivery.
"""

from __future__ import annotations

import bisect
from collections.abc import Callable, Sequence
from contextlib import AbstractContextManager, nullcontext
from dataclasses import replace

from perception.flat_tyre import FlatTyreDetector
from perception.health import HealthMonitor
from perception.lanes import LaneDetector, LaneFilter
from perception.lights import TrafficLightDetector
from perception.localization import LaneMatch, Localizer, LocalizerParams, clear_ahead
from perception.messages import (
    EgoState,
    LaneEstimate,
    LaneView,
    LightDetection,
    PerceptionReport,
    PlannerInput,
    SignView,
    Track,
)
from perception.objects import ObjectDetector
from perception.signs import StopSignDetector
from perception.stop_lines import StopLineDetector
from perception.tracking import MultiObjectTracker
from world.frames import (
    CameraFrame,
    CameraInfo,
    DriverControls,
    Frame,
    Frames,
    GnssFix,
    LidarScan,
    Odometry,
    SensorKind,
    SensorSpec,
    VehicleInfo,
    wrap_angle,
)
from world.hdmap import RoadMap

POSE_HISTORY = 2.0  # [s] own pose estimates kept for interpreting late sensor data
LANE_CAMERA = "front"  # the camera the lane, signs, lights and stop lines are found in

Timer = Callable[[str], AbstractContextManager[object]]  # a stage's name -> a span timing it

_KINDS: dict[SensorKind, type] = {SensorKind.CAMERA: CameraFrame, SensorKind.LIDAR: LidarScan,
                                   SensorKind.GNSS: GnssFix, SensorKind.ODOMETRY: Odometry}


def _untimed(stage: str) -> AbstractContextManager[object]:
    return nullcontext()


def _corrected(pose: EgoState, match: LaneMatch | None) -> EgoState:
    """The pose at a camera frame's time, moved by the map-matching correction that frame
    made (the frame's lane is placed in the map with it, as the car's pose now is)."""
    if match is None or not match.accepted:
        return pose
    dx, dy, dpsi = match.correction
    return replace(pose, x=pose.x + dx, y=pose.y + dy, heading=wrap_angle(pose.heading + dpsi))


def lane_camera(sensors: Sequence[SensorSpec], name: str = LANE_CAMERA) -> CameraInfo | None:
    """The calibration of the camera `name` among `sensors` (None: the car has none)."""
    for s in sensors:
        if s.name == name and s.kind is SensorKind.CAMERA and isinstance(s.info, CameraInfo):
            return s.info
    return None


class Perception:
    """Localiser, lane, sign, light and stop-line finding, LiDAR objects and tracking, the
    sensors' health and the flat-tyre detector (module doc)."""

    def __init__(self, road: RoadMap, vehicle: VehicleInfo, sensors: Sequence[SensorSpec],
                 start_lane: int, timer: Timer | None = None) -> None:
        """`sensors`: the car's (a delivery's frames are looked up by their names);
        `start_lane`: the lane the car starts in (ego-direction index); `timer`: times each
        stage ("localisation", "perception lanes", ...)."""
        self.timer = timer if timer is not None else _untimed
        self._kinds = {s.name: s.kind for s in sensors}
        front = lane_camera(sensors)
        self._front = front.name if front is not None else None
        self._reads = frozenset(s.name for s in sensors if s.kind is not SensorKind.CAMERA
                                or s.name == self._front)
        self.localizer = Localizer(LocalizerParams(rear_axle=vehicle.rear_axle),
                                   road=road if front is not None else None,
                                   start_lane=start_lane)
        #   the camera's lane corrects the pose across the lane (map matching)
        self.lane_detector = LaneDetector(front) if front is not None else None
        self.stop_line_detector = StopLineDetector(front) if front is not None else None
        self.sign_detector = StopSignDetector(front) if front is not None else None
        self.light_detector = TrafficLightDetector(front, road, vehicle) \
            if front is not None and road.traffic_lights else None
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

    @property
    def reads(self) -> frozenset[str]:
        """The GNSS, odometry and LiDAR, and the lane camera (not the other cameras)."""
        return self._reads

    def on_frames(self, t: float, frames: Frames) -> PerceptionReport | None:
        """One delivery (module doc); None if it holds no camera frame and no scan."""
        front: CameraFrame | None = None
        scan: LidarScan | None = None
        camera = False  # a camera's frame is in the delivery (read or not)
        for name, frame in frames.items():
            kind = self._kind(name, frame)
            if kind is SensorKind.GNSS:
                assert isinstance(frame, GnssFix)
                self.on_gnss(frame)
            elif kind is SensorKind.ODOMETRY:
                assert isinstance(frame, Odometry)
                self.on_odometry(frame)
            elif kind is SensorKind.LIDAR:
                assert isinstance(frame, LidarScan)
                scan = frame
            else:
                camera = True
                if name == self._front:
                    assert isinstance(frame, CameraFrame)
                    front = frame
        if not camera and scan is None:
            return None
        return self.on_sensors(t, front, scan)

    def _kind(self, name: str, frame: Frame) -> SensorKind:
        kind = self._kinds.get(name)
        if kind is None:
            raise ValueError(f"a frame of sensor {name!r}, which the car was not said to "
                             f"have (its sensors: {', '.join(self._kinds)})")
        if not isinstance(frame, _KINDS[kind]):
            raise ValueError(f"sensor {name!r} is a {kind.value} sensor, its frame a "
                             f"{type(frame).__name__}")
        return kind

    def on_gnss(self, fix: GnssFix) -> None:
        """A fix inconsistent with the odometry's prediction is not fused
        (`perception.health`)."""
        with self.timer("localisation"):
            predicted = self.localizer.predicted_fix(fix.t) if fix.valid else None
            if self.health.fix(fix, predicted).accepted:
                self.localizer.on_gnss(fix)

    def on_odometry(self, odo: Odometry) -> None:
        with self.timer("localisation"):
            self.localizer.on_odometry(odo)
        self._pedal = odo.accelerator_pedal
        self._engaged = odo.engaged
        self._driver = odo.driver
        with self.timer("perception flat tyre"):
            self.flat_detector.update(odo)

    def on_sensors(self, t: float, front: CameraFrame | None,
                   scan: LidarScan | None) -> PerceptionReport | None:
        """Perceive the lane camera's frame and the scan captured at time `t` (late by the
        sensor latency); None when the stage has no pose for that time yet (before the
        first GNSS fix)."""
        pose = self._pose_at(t)
        if pose is None:
            return None
        timer = self.timer
        now = self._times[-1] if self._times else t  # [s] the stage's clock: its last tick
        if scan is not None and self.health.scan(scan, now) is not None:
            scan = None  # late or empty: nothing to perceive in it
        if front is not None and self.lane_detector is not None:
            with timer("perception health"):
                fault = self.health.camera(front, pose.speed, now)
            if fault is not None:  # nothing to perceive in it: the lane is found anew after
                front, self._view = None, None
                self.lane_filter.reset()
        lane_raw = lane = None
        if front is not None and self.lane_detector is not None:
            prior = self._view.estimate if self._view is not None else None
            with timer("perception lanes"):
                lane_raw = self.lane_detector.detect(front, prior,
                                                     self.localizer.lane_width(pose))
            with timer("perception lane filter"):
                lane = self.lane_filter.update(lane_raw, pose.speed, pose.yaw_rate)
            with timer("localisation"):
                match = self.localizer.on_lane(lane, pose)
                self.localizer.on_line_end(lane, pose,
                                           clear_ahead(self._tracks, 0.5 * lane.width))
                self._gnss_across(lane.t, match)
            self._stop_line(front, lane, pose)
            self._view = LaneView(lane, _corrected(pose, match))
        if front is not None and self.sign_detector is not None:
            with timer("perception signs"):
                self._signs = SignView(tuple(self.sign_detector.detect(front)), pose)
        if front is not None and self.light_detector is not None:
            with timer("perception lights"):
                self._lights = self.light_detector.detect(front, pose)
        detections = tracks = None
        if scan is not None:
            with timer("perception objects"):
                detections = self.object_detector.detect(scan)
            with timer("perception tracking"):
                mount = scan.info.mount
                tracks = self.tracker.update(t, pose, detections, (mount.x, mount.y))
            self._tracks = tracks
        return PerceptionReport(t, pose, lane_raw, lane, detections, tracks)

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
        with self.timer("perception stop lines"):
            distance = detector.detect(front, lane)
        if distance is not None:
            with self.timer("localisation"):
                self.localizer.on_stop_line(distance, pose)

    def perceive(self, t: float) -> PlannerInput:
        """The estimate at time `t` [s] and the latest perception; a frame's signs and
        lights are handed on once."""
        with self.timer("localisation"):
            ego = self.localizer.estimate(t)
        self._remember(ego)
        out = PlannerInput(
            ego=ego, lane=self._view, tracks=self._tracks, signs=self._signs,
            lights=self._lights, pedal=self._pedal, engaged=self._engaged, driver=self._driver,
            flat_tyre=self.flat_detector.state is not None, health=self.health.health(t))
        self._signs, self._lights = None, ()
        return out

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

"""The sensor side of the closed loop: capture, delivery to the stack, scoring, recording.

At each control tick the loop collects from the sensing pipeline (`world.sensors.pipeline`)
the captures whose delivery step has come (camera frames and LiDAR scans taken one
`world.core.rates.FRAME_LATENCY` earlier: a real sensor's latency, and room for the
rendering worker to run while the main process steps physics and runs the stack), submits
the captures the schedule has due now (`world.sensors.schedule`, from the rates table: every
sensor of the car, GNSS and odometry included), then hands the stack, in this order, the
captures collected and those due at once (GNSS, odometry). The ground truth of each capture
instant whose data arrives late is kept until its delivery, to score perception
(`avsim.run.scoring`) on exactly the instant the data shows. The recording keeps every
`record_every`-th frame of each sensor (its entry in the rates table), by frame type: camera
images, LiDAR points.

The scenario's sensor faults (`world.sensors.faults`) are applied to every capture, in
either pipeline, before anything else sees it: the stack, the scoring and the recording get
the faulty data (the recording shows what the stack was given).

`frame_hook` lets a test (or a fault-injection study) alter the camera frames the stack
receives, e.g. a blinded camera; the scoring and the recording keep the true frames.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Collection, Iterable

import numpy as np

from avsim.record.recorder import Recorder
from avsim.run.scoring import CaptureTruth, PerceptionScore
from control.command import DrivingStack
from perception.messages import Detection, PerceptionReport
from world.core.rates import CONTROL_RATE, SensorTiming
from world.core.stopwatch import Stopwatch
from world.frames import CameraFrame, Frame, LidarScan, wrap_angle
from world.sensors.faults import FaultySensing, sensor_delays
from world.sensors.lidar import LidarTruth
from world.sensors.pipeline import (
    Capture,
    InlineSensing,
    ProcessSensing,
    Sensing,
    SensingWorker,
)
from world.sensors.schedule import Due, SensorSchedule
from world.sensors.setup import TRUTH_SENSOR, SensorSetup, sensor_timings
from world.world import World

FrameHook = Callable[[CameraFrame], CameraFrame]

RECORD_LIDAR_POINTS = 6000  # [-] at most this many points per recorded scan (even stride)
JUNCTION_UNSCORED = (10.0, 15.0)  # [m] before a town stop line, after the junction exit:
#   the lane is not scored there (the stack follows the map's path, `LaneSource.JUNCTION`)


def sensing_mode(requested: str) -> str:
    """'inline' or 'process' for a request of 'auto', 'inline' or 'process'."""
    if requested == "auto":
        return "process" if (os.cpu_count() or 1) >= 2 else "inline"
    if requested not in ("inline", "process"):
        raise ValueError(f"sensing mode {requested!r}: use auto, inline or process")
    return requested


def frames_read(timings: Iterable[tuple[str, SensorTiming]], reads: Collection[str] | None,
                recording: bool) -> dict[str, int]:
    """Per sensor, every how many of its frames somebody reads (`SensorSchedule`'s `keep`):
    all of those of the sensors the stack `reads` (None: every sensor), the recording's
    `record_every` of the others (a side camera renders only what the recording keeps), none
    without a recording."""
    return {name: 1 if reads is None or name in reads
            else timing.record_every if recording else 0 for name, timing in timings}


class SensorLoop:
    """Sensing pipeline + delivery to the stack + perception scoring + sensor recording for
    one run: every sensor of the car (`setup`'s cameras and LiDAR, if any; GNSS, odometry)."""

    def __init__(self, world: World, setup: SensorSetup | None, stack: DrivingStack, mode: str,
                 recorder: Recorder | None = None, frame_hook: FrameHook | None = None,
                 watch: Stopwatch | None = None, worker: SensingWorker | None = None) -> None:
        """`mode`: 'inline' or 'process' (`world.sensors.pipeline`; without cameras there is
        nothing to render elsewhere, and every sensor captures inline); `watch`: times the
        captures, the passing of frames, the scoring and the recording; `worker`: the
        sensing worker for 'process', started early (else it starts here)."""
        self.world, self.setup, self.stack = world, setup, stack
        timings = sensor_timings(setup, TRUTH_SENSOR in world.rig)
        self.schedule = SensorSchedule(timings, CONTROL_RATE,
                                       frames_read(timings, stack.reads, recorder is not None))
        self.watch = watch if watch is not None else Stopwatch()
        pipeline: Sensing = (ProcessSensing(world, setup, self.watch, worker)
                             if mode == "process" and setup is not None and setup.cameras
                             else InlineSensing(world, self.watch))
        self.sensing: Sensing = FaultySensing(
            pipeline, lambda: world.sensor_faults,
            sensor_delays(e.event for e in world.spec.events))
        self.mode = mode
        self.recorder = recorder
        self.frame_hook = frame_hook
        self.score = PerceptionScore()
        self._truth: dict[Due, CaptureTruth] = {}  # of the captures delivered late, till then
        self.last: PerceptionReport | None = None

    def tick(self) -> None:
        """At a control tick: the earlier captures due now reach the stack, then those
        captured now and due at once. The captures due now are submitted before the stack
        perceives anything, so that a worker renders while it does."""
        step = self.world.clock.step
        arrived = self.sensing.collect(step)
        dues = self.schedule.due(step)
        late = [due for due in dues if due.deliver > step]
        if late:
            with self.watch("scoring"):
                truth = self._capture_truth()
            self._truth.update((due, truth) for due in late)
        for due in dues:
            self.sensing.submit(due)
        self._deliver(arrived)
        self._deliver(self.sensing.collect(step))

    def close(self) -> None:
        self.sensing.close()

    def metrics(self) -> dict[str, float]:
        return self.score.metrics()

    # -- delivery --------------------------------------------------------------------------

    def _deliver(self, captures: tuple[Capture, ...]) -> None:
        for capture in captures:
            truth = self._truth.pop(capture.due, None)
            frames: dict[str, Frame] = {r.sensor: r.frame for r in capture.readings}
            if self.frame_hook is not None:
                hook = self.frame_hook
                frames = {name: hook(f) if isinstance(f, CameraFrame) else f
                          for name, f in frames.items()}
            out = self.stack.on_frames(capture.t, frames)
            if out is None:
                continue
            if not isinstance(out, PerceptionReport):  # a user's stack: the run's error
                raise TypeError(f"the stack's on_frames returned a {type(out).__name__}, "
                                "not a PerceptionReport or None")
            self.last = out
            with self.watch("scoring"):
                if truth is None:  # delivered at once: the truth is the present's
                    truth = self._capture_truth()
                self._score(capture, out, truth)
            if self.recorder is not None:
                with self.watch("recording"):
                    self._record(capture, out)
                    self._record_scores(out, truth)

    def _score(self, capture: Capture, out: PerceptionReport, truth: CaptureTruth) -> None:
        if out.lane_raw is not None:  # a frame of the stack's lane camera was perceived
            self.score.lane(out.lane_raw, out.lane, truth)
        scan_truth = next((r.truth for r in capture.readings
                           if isinstance(r.truth, LidarTruth)), None)
        if out.detections is not None and out.tracks is not None and scan_truth is not None:
            self.score.objects(out.detections, out.tracks, truth, scan_truth)

    def _record_scores(self, out: PerceptionReport, truth: CaptureTruth) -> None:
        """Perception against the truth at the capture instant, as time series."""
        assert self.recorder is not None
        values: dict[str, float] = {}
        if out.lane is not None:
            values["lane_confidence"] = out.lane.confidence
            if truth.lane_offset is not None:
                values["lane_offset_error"] = out.lane.offset - truth.lane_offset
                values["lane_heading_error"] = wrap_angle(
                    out.lane.heading_error - truth.lane_heading_error)
        if out.tracks is not None:
            values["tracks"] = float(len(out.tracks))
        if values:
            self.recorder.log_scalars(out.t, values)

    def _capture_truth(self) -> CaptureTruth:
        w = self.world
        truth = w.ego_truth
        xy = truth.position[:2]
        lane, s, r = w.road.lane_at(xy)
        if lane is not None and any(j.s_stop - JUNCTION_UNSCORED[0] <= s
                                    <= j.s_exit + JUNCTION_UNSCORED[1] for j in w.road.junctions):
            lane = None  # at a town junction: no painted lane (its lines end at the mouth)
        heading_error = 0.0
        if lane is not None:
            heading = float(w.road.lane(lane).heading_at(s))
            heading += math.pi if lane < 0 else 0.0
            heading_error = wrap_angle(truth.yaw - heading)
        return CaptureTruth(t=w.t, ego_xy=np.array(xy), ego_yaw=truth.yaw,
                            lane_offset=None if lane is None else r,
                            lane_heading_error=heading_error, actors=w.actors.poses)

    # -- recording -------------------------------------------------------------------------

    def _kept(self, sensor: str, step: int) -> bool:
        """Whether the recording keeps the frame `sensor` captured at `step`: every
        `record_every`-th of its frames, the first one included."""
        timing = self.schedule.timings[sensor]
        return timing.record_every > 0 and (step // timing.rate.every) % timing.record_every == 0

    def _record(self, capture: Capture, out: PerceptionReport) -> None:
        rec = self.recorder
        assert rec is not None
        t = capture.t
        for reading in capture.readings:
            frame = reading.frame
            if not self._kept(reading.sensor, capture.step):
                continue
            if isinstance(frame, CameraFrame):
                info = frame.info
                m = info.mount
                rec.log_camera_image(t, info.name, frame.rgb, info.fx, info.fy, info.cx, info.cy,
                                     mount_xyz=(m.x, m.y, m.z), mount_rpy=(m.roll, m.pitch, m.yaw))
            elif isinstance(frame, LidarScan):
                self._record_lidar(t, frame, out)
        if out.tracks is not None:
            self._record_tracks(t, out)
        if out.lane is not None:
            self._record_lane(t, out)

    def _record_lidar(self, t: float, scan: LidarScan, out: PerceptionReport) -> None:
        assert self.recorder is not None
        stride = max(1, math.ceil(len(scan.points) / RECORD_LIDAR_POINTS))
        local = scan.info.mount.to_vehicle(scan.points[::stride].astype(np.float64))
        colours = _cluster_colours(local, out.detections or ())
        self.recorder.log_lidar(t, _to_map(local, out), colours)

    def _record_tracks(self, t: float, out: PerceptionReport) -> None:
        assert self.recorder is not None and out.tracks is not None
        tracks = out.tracks
        centres = np.array([[tr.x, tr.y, 0.5 * tr.height] for tr in tracks]).reshape(-1, 3)
        half = np.array([[tr.length, tr.width, tr.height] for tr in tracks]).reshape(-1, 3) / 2
        self.recorder.log_tracks(t, [tr.id for tr in tracks], centres, half,
                                 np.array([tr.yaw for tr in tracks]),
                                 np.array([[tr.vx, tr.vy] for tr in tracks]).reshape(-1, 2),
                                 [tr.cls.value for tr in tracks])

    def _record_lane(self, t: float, out: PerceptionReport) -> None:
        assert self.recorder is not None and out.lane is not None
        lane = out.lane
        x = np.linspace(0.0, 30.0, 31)
        centre = np.array([lane.centre_y(v) for v in x])
        strips = [np.column_stack([x, centre + k * 0.5 * lane.width, np.full_like(x, 0.05)])
                  for k in (-1.0, 0.0, 1.0)]
        self.recorder.log_lane_lines(t, [_to_map(s, out) for s in strips],
                                     [(255, 140, 0), (255, 220, 0), (255, 140, 0)])


def _to_map(local: np.ndarray, out: PerceptionReport) -> np.ndarray:
    """Vehicle-frame points (N, 3) to the map frame with the stack's pose estimate."""
    pose = out.pose
    c, s = math.cos(pose.heading), math.sin(pose.heading)
    xy = local[:, :2] @ np.array([[c, s], [-s, c]]) + [pose.x, pose.y]
    return np.column_stack([xy, local[:, 2]])


_PALETTE = np.array([[230, 25, 75], [60, 180, 75], [255, 225, 25], [0, 130, 200],
                     [245, 130, 48], [145, 30, 180], [70, 240, 240], [240, 50, 230]],
                    dtype=np.uint8)


def _cluster_colours(local: np.ndarray, detections: tuple[Detection, ...]) -> np.ndarray:
    """Grey for points in no detection's box, a palette colour per detection otherwise."""
    colours = np.full((len(local), 3), 150, dtype=np.uint8)
    for k, det in enumerate(detections):
        c, s = math.cos(det.yaw), math.sin(det.yaw)
        d = local[:, :2] - [det.x, det.y]
        along, across = d @ [c, s], d @ [-s, c]
        inside = (np.abs(along) <= det.length / 2 + 0.2) & \
            (np.abs(across) <= det.width / 2 + 0.2) & (local[:, 2] > 0.2)
        colours[inside] = _PALETTE[k % len(_PALETTE)]
    return colours

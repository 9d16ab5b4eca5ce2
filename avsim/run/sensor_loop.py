"""The sensor side of the closed loop: capture, late delivery to the stack, scoring, recording.

At each sensor instant (a multiple of the control period) the loop first collects the
capture submitted one sensor period earlier and hands it to the stack's perception, then
submits the capture of this instant (`world.sensors.pipeline`): a real sensor's latency, and
room for the rendering worker to run while the main process steps physics and runs the stack. The
ground truth of each capture instant is kept until its data is delivered, to score
perception (`avsim.run.scoring`) on exactly the instant the data shows.

`frame_hook` lets a test (or a fault-injection study) alter what the stack receives, e.g.
a blinded camera; the scoring and the recording keep the true frames.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable

import numpy as np

from avsim.record.recorder import Recorder
from avsim.run.scoring import CaptureTruth, PerceptionScore
from avsim.run.stack import PerceptionOutput, Stack
from perception.messages import Detection
from world.frames import CameraFrame
from world.sensors.pipeline import InlineSensing, ProcessSensing, Sensing
from world.sensors.rig import SensorData, SensorSchedule
from world.sensors.setup import SensorSetup
from world.world import World

FrameHook = Callable[[CameraFrame], CameraFrame]

RECORD_FRONT_EVERY = 5  # record every 5th front frame (2 Hz at 10 Hz)
RECORD_SIDE_EVERY = 4  # every 4th side frame (0.5 Hz at 2 Hz)
RECORD_LIDAR_EVERY = 10  # every 10th scan (1 Hz at 10 Hz)
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


class SensorLoop:
    """Sensing pipeline + perception delivery + scoring + sensor recording for one run."""

    def __init__(self, world: World, setup: SensorSetup, stack: Stack, mode: str,
                 recorder: Recorder | None = None, frame_hook: FrameHook | None = None) -> None:
        self.world, self.setup, self.stack = world, setup, stack
        self.schedule = SensorSchedule(setup)
        self.sensing: Sensing = (InlineSensing(world) if mode == "inline"
                                 else ProcessSensing(world, setup))
        self.mode = mode
        self.recorder = recorder
        self.frame_hook = frame_hook
        self.score = PerceptionScore()
        self._truth: dict[float, CaptureTruth] = {}
        self._counts = {"front": 0, "left": 0, "right": 0, "lidar": 0}
        self.last: PerceptionOutput | None = None

    def tick(self) -> PerceptionOutput | None:
        """At a control tick: deliver and submit if a sensor instant is due now."""
        w = self.world
        due = self.schedule.due(w.clock.step)
        if not due:
            return None
        data = self.sensing.collect()
        self._truth[w.t] = self._capture_truth()
        self.sensing.submit(w.t, due)
        if data is None:
            return None
        return self._deliver(data)

    def close(self) -> None:
        self.sensing.close()

    def metrics(self) -> dict[str, float]:
        return self.score.metrics()

    # -- delivery --------------------------------------------------------------------------

    def _deliver(self, data: SensorData) -> PerceptionOutput | None:
        truth = self._truth.pop(data.t)
        frames = data.frames
        if self.frame_hook is not None:
            frames = tuple(self.frame_hook(f) for f in frames)
        out = self.stack.on_sensors(data.t, frames, data.scan)
        if out is None:
            return None
        self.last = out
        if data.frame("front") is not None:
            self.score.lane(out.lane_raw, out.lane, truth)
        if out.detections is not None and out.tracks is not None and data.scan_truth is not None:
            self.score.objects(out.detections, out.tracks, truth, data.scan_truth)
        if self.recorder is not None:
            self._record(data, out)
            self._record_scores(out, truth)
        return out

    def _record_scores(self, out: PerceptionOutput, truth: CaptureTruth) -> None:
        """Perception against the truth at the capture instant, as time series."""
        assert self.recorder is not None
        values: dict[str, float] = {}
        if out.lane is not None:
            values["lane_confidence"] = out.lane.confidence
            if truth.lane_offset is not None:
                values["lane_offset_error"] = out.lane.offset - truth.lane_offset
                values["lane_heading_error"] = math.remainder(
                    out.lane.heading_error - truth.lane_heading_error, 2.0 * math.pi)
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
            heading_error = math.remainder(truth.yaw - heading, 2.0 * math.pi)
        return CaptureTruth(t=w.t, ego_xy=np.array(xy), ego_yaw=truth.yaw,
                            lane_offset=None if lane is None else r,
                            lane_heading_error=heading_error, actors=w.actors.poses)

    # -- recording -------------------------------------------------------------------------

    def _record(self, data: SensorData, out: PerceptionOutput) -> None:
        rec = self.recorder
        assert rec is not None
        t = data.t
        for frame in data.frames:
            name = frame.info.name
            every = RECORD_FRONT_EVERY if name == "front" else RECORD_SIDE_EVERY
            if self._counts[name] % every == 0:
                info = frame.info
                m = info.mount
                rec.log_camera_image(t, name, frame.rgb, info.fx, info.fy, info.cx, info.cy,
                                     mount_xyz=(m.x, m.y, m.z), mount_rpy=(m.roll, m.pitch, m.yaw))
            self._counts[name] += 1
        if data.scan is not None:
            if self._counts["lidar"] % RECORD_LIDAR_EVERY == 0:
                self._record_lidar(data, out)
            self._counts["lidar"] += 1
        if out.tracks is not None:
            self._record_tracks(t, out)
        if out.lane is not None:
            self._record_lane(t, out)

    def _record_lidar(self, data: SensorData, out: PerceptionOutput) -> None:
        assert self.recorder is not None and data.scan is not None
        scan = data.scan
        stride = max(1, math.ceil(len(scan.points) / RECORD_LIDAR_POINTS))
        local = scan.info.mount.to_vehicle(scan.points[::stride].astype(np.float64))
        colours = _cluster_colours(local, out.detections or ())
        self.recorder.log_lidar(data.t, _to_map(local, out), colours)

    def _record_tracks(self, t: float, out: PerceptionOutput) -> None:
        assert self.recorder is not None and out.tracks is not None
        tracks = out.tracks
        centres = np.array([[tr.x, tr.y, 0.5 * tr.height] for tr in tracks]).reshape(-1, 3)
        half = np.array([[tr.length, tr.width, tr.height] for tr in tracks]).reshape(-1, 3) / 2
        self.recorder.log_tracks(t, [tr.id for tr in tracks], centres, half,
                                 np.array([tr.yaw for tr in tracks]),
                                 np.array([[tr.vx, tr.vy] for tr in tracks]).reshape(-1, 2),
                                 [tr.cls.value for tr in tracks])

    def _record_lane(self, t: float, out: PerceptionOutput) -> None:
        assert self.recorder is not None and out.lane is not None
        lane = out.lane
        x = np.linspace(0.0, 30.0, 31)
        centre = np.array([lane.centre_y(v) for v in x])
        strips = [np.column_stack([x, centre + k * 0.5 * lane.width, np.full_like(x, 0.05)])
                  for k in (-1.0, 0.0, 1.0)]
        self.recorder.log_lane_lines(t, [_to_map(s, out) for s in strips],
                                     [(255, 140, 0), (255, 220, 0), (255, 140, 0)])


def _to_map(local: np.ndarray, out: PerceptionOutput) -> np.ndarray:
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

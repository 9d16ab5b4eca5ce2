"""Sensor health: notice a failing sensor from its data alone.

Nothing tells the stack that a sensor has failed: a camera that goes dark or hangs, a LiDAR
that stops, a GNSS receiver that loses its fix or jumps all still look like sensors. This
monitor watches what they deliver and says, per sensor, how it noticed a fault
(`perception.messages.SensorHealth`, the planner's input). The laws:

- camera (the stack's lane camera): a frame whose grey levels spread less than
  ``blank_spread`` (standard deviation over a subsample of every ``stride``-th pixel)
  carries no information (a dead or covered sensor); a frame bitwise identical to the one
  before while the car moves at ``freeze_speed`` or more is frozen (a real scene changes as
  the car moves), and the camera stays frozen until a frame differs from the held one (a
  frozen camera at a standstill is not told apart from a still scene: it is noticed before
  the car stops, or not at all); a frame older at its delivery than ``max_age`` (the
  sensor's latency and one period, with a margin) is late; no frame for ``camera_timeout``
  is a missing camera. A faulty frame is not perceived (`avsim.run.stack`). A sound frame
  with ``occluded`` or more of its tiles (a ``tiles`` grid) dark (mean below
  ``dark_level``) and featureless (spread below ``blank_spread``) is partly occluded: it is
  perceived (the lane on what is seen), and the occlusion is reported on its own.
- LiDAR: a scan older at its delivery than ``max_age`` is late (and not perceived); no scan
  for ``lidar_timeout`` (captured that long ago, delivery latency included), or a scan with
  no return at all (a working LiDAR always sees the ground).
- GNSS: no valid fix for ``gnss_timeout`` (the receiver's short dropouts are bridged by the
  odometry; this is an outage); a fix farther from the position the odometry predicts
  (`perception.localization.Localizer.predicted_fix`: the estimate extrapolated to the fix,
  bias included) than its gate, max(``gnss_gate``, ``gnss_gate_sigmas`` x the 1-sigma of
  prediction and fix together), is inconsistent: it is rejected (not fused), and the GNSS is
  faulty until a fix passes the gate again. A fix that disagrees with the camera's lane
  across the lane (`perception.localization.LaneMatch.fix_offset`, each confident lane
  estimate against the fix of its time, both on the HD map) by more than its stated accuracy
  allows (the squared difference over its variance, fix and camera together, above
  ``across_gate``: a chi-square test) at every confident frame for ``across_time`` is
  inconsistent with the camera (`gnss_inconsistent`): a receiver may be off by more than it
  states (an RTK fix that is not), and the localiser stops believing its accuracy; it is
  faulty until they agree for ``across_time`` again. No confident frame for ``across_time``
  starts the count anew (the camera cannot tell).

A sensor is watched from its first delivery on (a stack without a LiDAR, or before its first
frame, has nothing to miss).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from perception.messages import SensorHealth
from world.frames import CameraFrame, GnssFix, LidarScan


@dataclass(frozen=True, slots=True)
class HealthParams:
    blank_spread: float = 2.0  # [grey levels] a frame spreading less carries no information
    #   (a rendered or real road scene spreads by tens of levels; sensor noise alone by ~2)
    stride: int = 4  # [px] every this many pixels in both directions are looked at
    tiles: tuple[int, int] = (6, 8)  # [-] rows, columns of the occlusion grid
    dark_level: float = 20.0  # [grey levels] a tile darker than this on average is dark
    occluded: float = 0.2  # [-] this fraction of dark, featureless tiles: partly occluded
    max_age: float = 0.25  # [s] a camera frame or LiDAR scan older at delivery is late
    #   (10 Hz with 0.1 s latency: 0.1 s old, 0.2 s with one period missed)
    freeze_speed: float = 1.0  # [m/s] moving this fast, the next frame must differ
    camera_timeout: float = 0.5  # [s] no camera frame for this long: missing (5 periods)
    lidar_timeout: float = 0.5  # [s] no LiDAR scan captured this recently: missing
    #   (10 Hz with 0.1 s latency: a scan is normally 0.1 - 0.2 s old)
    gnss_timeout: float = 3.0  # [s] no valid fix for this long: an outage (the consumer
    #   receiver's own dropouts average 2 s and are bridged)
    gnss_gate: float = 5.0  # [m] the least gate between a fix and its prediction
    gnss_gate_sigmas: float = 4.0  # [-] the gate in 1-sigmas of prediction and fix together
    across_gate: float = 10.8  # [-] squared difference across the lane over its variance
    #   (chi^2, 1 dof, 99.9 %): an RTK fix (5 cm) more than 0.52 m from the camera's lane
    across_time: float = 0.5  # [s] that long at every confident frame: inconsistent (a car
    #   driving on a fix 1.3 m wrong leaves its lane within 1.5 s); as long agreeing: sound


@dataclass(frozen=True, slots=True)
class FixCheck:
    """Whether a GNSS fix agrees with the odometry's prediction."""

    accepted: bool  # fuse it
    distance: float  # [m] from the prediction (NaN: nothing to compare)
    gate: float  # [m]


def grey(rgb: NDArray[np.uint8], stride: int) -> NDArray[np.float32]:
    """(H / stride, W / stride) the mean of the channels over every `stride`-th pixel of an
    (H, W, 3) image."""
    out: NDArray[np.float32] = rgb[::stride, ::stride, :3].astype(np.float32).mean(axis=2)
    return out


def grey_spread(rgb: NDArray[np.uint8], stride: int) -> float:
    """[grey levels] standard deviation of `grey(rgb, stride)`."""
    return float(grey(rgb, stride).std())


def dark_tiles(image: NDArray[np.float32], tiles: tuple[int, int], dark: float,
               spread: float) -> float:
    """[-] the fraction of the tiles of a (rows, columns) grid over the grey `image` that are
    dark (mean below `dark`) and featureless (standard deviation below `spread`)."""
    rows, cols = tiles
    h, w = image.shape[0] // rows * rows, image.shape[1] // cols * cols
    blocks = image[:h, :w].reshape(rows, h // rows, cols, w // cols)
    means, stds = blocks.mean(axis=(1, 3)), blocks.std(axis=(1, 3))
    return float(np.mean((means < dark) & (stds < spread)))


class HealthMonitor:
    """Watches the sensors' data (module doc); `health(t)` says what is wrong at time t."""

    def __init__(self, params: HealthParams | None = None) -> None:
        self.params = params if params is not None else HealthParams()
        self.reset()

    def reset(self) -> None:
        self._frame: NDArray[np.uint8] | None = None  # the last camera image
        self._frame_t: float | None = None  # [s] its capture time
        self._frozen = False
        self._camera: str | None = None  # the last frame's fault
        self._occlusion: str | None = None  # the last frame's partial occlusion
        self._scan_t: float | None = None  # [s] the last scan's capture time
        self._scan_fault: str | None = None  # the last scan's fault (empty, late)
        self._fix_t: float | None = None  # [s] the last valid, accepted fix's time
        self._gnss_seen = False
        self._rejected: str | None = None  # how the last valid fix failed its gate
        self._apart: float | None = None  # [s] the first frame of this run of disagreement
        self._agree: float | None = None  # [s] the first frame of this run of agreement
        self._across_t: float | None = None  # [s] the last confident frame compared
        self._inconsistent: str | None = None  # how the fixes disagree with the camera

    def camera(self, frame: CameraFrame, speed: float, now: float) -> str | None:
        """Check the lane camera's `frame` (the car moving at `speed` [m/s]), delivered at
        `now` [s]; how it is faulty, or None when it is fine."""
        p = self.params
        rgb = frame.rgb
        previous, self._frame, self._frame_t = self._frame, rgb, frame.t
        image = grey(rgb, p.stride)
        spread = float(image.std())
        same = previous is not None and np.array_equal(rgb, previous)
        self._occlusion = None
        if now - frame.t > p.max_age:
            self._frozen = False
            self._camera = (f"camera frame {now - frame.t:.2f} s old at delivery (at most "
                            f"{p.max_age:g} s)")
        elif spread < p.blank_spread:
            self._frozen = False
            self._camera = (f"camera frame carries no information (grey spread {spread:.1f} "
                            f"< {p.blank_spread:g})")
        elif same and (self._frozen or speed >= p.freeze_speed):
            self._frozen = True
            self._camera = f"camera frame identical to the last at {speed:.1f} m/s (frozen)"
        else:
            self._frozen = False
            self._camera = None
            covered = dark_tiles(image, p.tiles, p.dark_level, p.blank_spread)
            if covered >= p.occluded:
                self._occlusion = (f"{covered:.0%} of the camera frame dark and featureless "
                                   "(partly occluded)")
        return self._camera

    def scan(self, scan: LidarScan, now: float) -> str | None:
        """Check a LiDAR scan delivered at `now` [s]; how it is faulty, or None."""
        p = self.params
        self._scan_t = scan.t
        if now - scan.t > p.max_age:
            self._scan_fault = (f"LiDAR scan {now - scan.t:.2f} s old at delivery (at most "
                                f"{p.max_age:g} s)")
        elif len(scan.points) == 0:
            self._scan_fault = "LiDAR scan with no return"
        else:
            self._scan_fault = None
        return self._scan_fault

    def fix(self, fix: GnssFix, predicted: tuple[float, float, float] | None) -> FixCheck:
        """Check a GNSS `fix` against its prediction (x, y, 1-sigma) [m], if any; whether
        to fuse it."""
        p = self.params
        self._gnss_seen = True
        if not fix.valid:
            return FixCheck(False, math.nan, math.nan)
        if predicted is None:  # nothing to compare with yet: the first fix
            self._fix_t, self._rejected = fix.t, None
            return FixCheck(True, math.nan, math.nan)
        x, y, sigma = predicted
        distance = math.hypot(fix.x - x, fix.y - y)
        gate = max(p.gnss_gate, p.gnss_gate_sigmas * math.hypot(sigma, fix.sigma))
        if distance > gate:
            self._rejected = (f"GNSS fix {distance:.1f} m from the odometry's prediction "
                              f"(gate {gate:.1f} m)")
            return FixCheck(False, distance, gate)
        self._fix_t, self._rejected = fix.t, None
        return FixCheck(True, distance, gate)

    def across(self, t: float, offset: float, stated: float, camera: float) -> str | None:
        """Compare a confident camera lane of time `t` [s] with the fix of its time: the
        fix's `offset` [m] across the lane less the camera's (NaN: nothing to compare), the
        fix stating `stated` [m] 1-sigma, the camera's offset of 1-sigma `camera` [m]. How
        the fixes are inconsistent with the camera, or None."""
        p = self.params
        sigma = math.hypot(stated, camera)  # [m] of the difference
        if math.isnan(offset) or sigma <= 0.0:
            return self._inconsistent
        if self._across_t is not None and t - self._across_t > p.across_time:
            self._apart = self._agree = None  # the camera could not tell for a while
        self._across_t = t
        if offset * offset > p.across_gate * sigma * sigma:
            self._agree = None
            self._apart = t if self._apart is None else self._apart
            if t - self._apart >= p.across_time - 1e-9:
                self._inconsistent = (
                    f"GNSS fix {abs(offset):.1f} m across the lane from the camera's lane for "
                    f"{t - self._apart:.1f} s (it states {stated:.2f} m)")
        else:
            self._apart = None
            self._agree = t if self._agree is None else self._agree
            if t - self._agree >= p.across_time - 1e-9:
                self._inconsistent = None
        return self._inconsistent

    @property
    def gnss_inconsistent(self) -> str | None:
        """How the GNSS fixes disagree with the camera's lane (`across`); None: they agree
        (or there was nothing to compare)."""
        return self._inconsistent

    def health(self, t: float) -> SensorHealth:
        """What is wrong at time `t` [s] (module doc)."""
        p = self.params
        camera = self._camera
        if self._frame_t is not None and t - self._frame_t > p.camera_timeout:
            camera = f"no camera frame for {t - self._frame_t:.1f} s"
        lidar = None
        if self._scan_t is not None and t - self._scan_t > p.lidar_timeout:
            lidar = f"no LiDAR scan for {t - self._scan_t:.1f} s"
        elif self._scan_fault is not None:
            lidar = self._scan_fault
        gnss = self._rejected
        if gnss is None and self._fix_t is not None and t - self._fix_t > p.gnss_timeout:
            gnss = f"no valid GNSS fix for {t - self._fix_t:.1f} s"
        if gnss is None:
            gnss = self._inconsistent
        return SensorHealth(camera, lidar, gnss, self._occlusion)

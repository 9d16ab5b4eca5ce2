"""Multi-object tracking of LiDAR detections in the map frame.

Input, every scan: the time t [s], the localiser's `EgoState` at t and the scan's `Detection`
boxes (vehicle frame of the ego at t). Output: the confirmed `Track`s, by id.

Model (one linear Kalman filter per track, filterpy's `KalmanFilter`):

- state [x, y, vx, vy] [m, m, m/s, m/s] in the map frame (over ground: parked cars stand
  still whatever the ego does), constant velocity: x' = x + vx dt;
- process noise: continuous white acceleration of spectral density ``accel_psd`` [m^2/s^3]
  on each axis, Q = q [[dt^3/3, dt^2/2], [dt^2/2, dt]] per axis;
- measurement: the box centre, moved to the map frame with the ego pose, R =
  ``position_sigma``^2 I (the box completion's centre error; the ego pose error is smaller
  and is not added), placed by the box's near faces: the detector keeps a face where it was
  seen and grows the box away from the sensor to its class's size (`perception.objects`),
  so along each box axis whose near end the sensor sees, the centre measured is that face
  plus half the track's own extent, and when the track's smoothed size changes its centre
  moves with it, the near faces staying (`_away`). A box whose size changes from one scan to
  the next (a car revealed by a cut-out, its first few returns a pedestrian's box, then a
  car's) so moves its far end, not its centre: its velocity stays the object's (the box
  centre moved away at 0.7 m/s from a standing car before, and the ACC's need with it).
  A car whose near end was not seen (`Detection.end_seen` False: only a face above its
  lower body, a bonnet, boot deck or cabin set back from the bumper) measures no range along
  its length (noise ``setback_sigma`` along it) when the track is settled (confirmed, and
  its last detection's near face and length agreed with it within ``setback_margin``, or
  were set back) and the face lies between ``setback_margin`` and the track's length
  beyond the end the track predicts: the track's range coasts on its velocity there and
  the face places it across.
  A face nearer than that is measured (the car cannot end beyond the body seen: a braking
  car is followed), and so is every face of a tentative track (nothing else known);
- a new track starts at its detection with zero velocity, ``init_speed_sigma`` per axis.

Steps of `MultiObjectTracker.update`:

0. Follow the ego pose's corrections: the tracks are measured relative to the car, so when
   the localiser moves its pose estimate (a GNSS fix, the camera's lane matched on the map:
   metres at once when a GNSS bias is found) the tracks move with it. The pose at t is
   compared with the last scan's pose dead-reckoned to t on its own speed and yaw rate
   (`pose_jump`); the difference, a rotation about the car and a shift, is applied to every
   track's position, velocity and covariance. So the tracks live in the car's odometry frame
   (smooth, like a ROS `odom` frame) and are reported in the map frame; without this, a
   pose jump leaves a track where the car thought it was and starts a second one for the
   same object, the first coasting (a truck beside the car coasting into its lane).
1. Predict every track to t.
2. Associate: the cost is the squared Mahalanobis distance of the centre each detection
   measures for each track (its near faces and the track's extents, as in step 3's update)
   to the track's predicted centre (S = H P H^T + R); pairs beyond the chi-square gate
   ``gate`` are not allowed; `scipy.optimize.linear_sum_assignment` finds the least summed
   cost.
3. Update the matched tracks: the filter; the box size (exponential smoothing with weight
   ``size_alpha``); the box heading (the same smoothing on the doubled angle, so that a box's
   front/back ambiguity does not matter); the class (majority vote over the track's
   detections, ties to the most recent class, then to the enum's order).
4. Manage: a track is CONFIRMED once ``confirm_hits`` of its first ``confirm_window`` scans
   matched; a tentative track that can no longer reach that is deleted. A confirmed track
   coasts (predicted only) through misses and is deleted once unmatched for more than
   ``max_coast``. A track farther than ``max_distance`` from the ego is deleted. Then every
   unmatched detection within ``max_distance`` of the ego starts a TENTATIVE track. Ids are
   consecutive integers from 1, never reused.
5. Output: the confirmed tracks (coasting ones included, with ``misses`` > 0), by id. The
   yaw is the smoothed box heading (map frame); when the track moves faster than
   ``heading_min_speed`` it is the one of the two box directions closer to the velocity.
   ``rel_x, rel_y`` are the centre in the ego's vehicle frame; ``rel_vx, rel_vy`` the
   object's velocity minus the ego's (``ego.speed`` along ``ego.heading``), rotated into the
   vehicle frame (the frame's own rotation, yaw_rate x r, is not included);
   ``position_sigma`` is the square root of the position covariance's largest eigenvalue.

Deterministic: no random numbers; tracks are kept and processed by id, detections in the
order given.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from filterpy.kalman import KalmanFilter
from numpy.typing import NDArray
from scipy.optimize import linear_sum_assignment

from perception.messages import Detection, EgoState, ObjectClass, Track
from world.frames import wrap_angle

FloatArray = NDArray[np.float64]

DIM_X = 4  # [x, y, vx, vy]
_H = np.eye(2, DIM_X)  # (2, 4) the centre
_CLASS_ORDER = tuple(ObjectClass)
INFEASIBLE = 1e9  # [-] assignment cost of a pair outside the gate


@dataclass(frozen=True, slots=True)
class TrackerParams:
    """Noise, gating and track management of the tracker (see the module docstring)."""

    accel_psd: float = 1.0  # [m^2/s^3] white acceleration spectral density, per axis
    position_sigma: float = 0.15  # [m] measurement noise of a box centre, per axis
    init_speed_sigma: float = 10.0  # [m/s] velocity uncertainty of a new track, per axis
    gate: float = 9.21  # [-] chi-square (2 dof, 99 %) gate on the Mahalanobis distance^2
    confirm_hits: int = 3  # [-] M: matched scans needed for confirmation ...
    confirm_window: int = 5  # [-] N: ... within the track's first N scans
    max_coast: float = 0.5  # [s] a track unmatched for longer is deleted
    max_distance: float = 100.0  # [m] a track farther from the ego is deleted (the LiDAR's
    #   range: a car found far ahead is tracked from its first detection)
    size_alpha: float = 0.3  # [-] smoothing weight of a new box size / heading
    heading_min_speed: float = 1.0  # [m/s] faster tracks take the yaw closer to the velocity
    setback_margin: float = 0.45  # [m] an end face seen above the lower body farther than
    #   this beyond a settled track's predicted end is set back from it (three
    #   position_sigma)
    setback_sigma: float = 100.0  # [m] measurement noise of such a face's range: unmeasured


def process_noise(dt: float, q: float) -> FloatArray:
    """(4, 4) white-acceleration process noise of ``[x, y, vx, vy]`` over ``dt`` [s] for a
    spectral density ``q`` [m^2/s^3]."""
    block = q * np.array([[dt**3 / 3.0, dt**2 / 2.0], [dt**2 / 2.0, dt]])
    out = np.zeros((DIM_X, DIM_X))
    for axis in (0, 1):
        idx = np.ix_([axis, axis + 2], [axis, axis + 2])
        out[idx] = block
    return out


def transition(dt: float) -> FloatArray:
    """(4, 4) constant-velocity transition over ``dt`` [s]."""
    f = np.eye(DIM_X)
    f[0, 2] = f[1, 3] = dt
    return f


@dataclass(frozen=True, slots=True)
class MapDetection:
    """A detection moved to the map frame."""

    x: float  # [m] box centre, map frame
    y: float  # [m]
    yaw: float  # [rad] box heading, map frame (mod pi)
    length: float  # [m]
    width: float  # [m]
    height: float  # [m]
    cls: ObjectClass  # the detection's class
    end_seen: bool = True  # `Detection.end_seen`


def in_map(ego: EgoState, x: float, y: float) -> tuple[float, float]:
    """The point (x, y) [m] of ``ego``'s vehicle frame in the map frame."""
    c, s = math.cos(ego.heading), math.sin(ego.heading)
    return ego.x + c * x - s * y, ego.y + s * x + c * y


def to_map(det: Detection, ego: EgoState) -> MapDetection:
    """``det`` (vehicle frame of ``ego``) in the map frame."""
    x, y = in_map(ego, det.x, det.y)
    return MapDetection(x=x, y=y, yaw=det.yaw + ego.heading, length=det.length,
                        width=det.width, height=det.height, cls=det.cls,
                        end_seen=det.end_seen)


def pose_jump(prev: EgoState, now: EgoState) -> tuple[float, float, float]:
    """(dx [m], dy [m], dpsi [rad]), map frame: how far the pose estimate ``now`` lies from
    ``prev`` dead-reckoned to ``now.t`` on its speed and yaw rate (unicycle at the midpoint
    heading): the localiser's corrections in between."""
    dt = now.t - prev.t
    mid = prev.heading + 0.5 * prev.yaw_rate * dt
    x = prev.x + prev.speed * dt * math.cos(mid)
    y = prev.y + prev.speed * dt * math.sin(mid)
    return now.x - x, now.y - y, wrap_angle(now.heading - prev.heading - prev.yaw_rate * dt)


class _TrackState:
    """One track's filter and bookkeeping (mutable, private to the tracker)."""

    def __init__(self, track_id: int, t: float, det: MapDetection, p: TrackerParams) -> None:
        self.id = track_id
        self.kf = KalmanFilter(dim_x=DIM_X, dim_z=2)
        self.kf.x = np.array([[det.x], [det.y], [0.0], [0.0]])
        r = p.position_sigma**2
        self.kf.P = np.diag([r, r, p.init_speed_sigma**2, p.init_speed_sigma**2])
        self.kf.H = _H.copy()
        self.kf.R = np.eye(2) * r
        self.t = t  # [s] time of the filter state
        self.last_hit = t  # [s]
        self.scans = 1  # [-] scans since birth, this one included
        self.hits = 1  # [-] matched scans
        self.misses = 0  # [-] consecutive unmatched scans
        self.confirmed = False
        self.size = np.array([det.length, det.width, det.height])  # [m] smoothed
        self.axis = np.array([math.cos(2.0 * det.yaw), math.sin(2.0 * det.yaw)])  # doubled
        self.votes = dict.fromkeys(_CLASS_ORDER, 0)
        self.votes[det.cls] = 1
        self.last_cls = det.cls
        # its end is where its near faces were seen: confirmed, its last detection's near
        # face and length agreed with it (within setback_margin) or were set back
        self.settled = False

    @property
    def state(self) -> FloatArray:
        """(4,) ``[x, y, vx, vy]``."""
        return np.asarray(self.kf.x, dtype=np.float64).reshape(DIM_X)

    def predict(self, t: float, p: TrackerParams) -> None:
        dt = t - self.t
        if dt > 0.0:
            self.kf.predict(F=transition(dt), Q=process_noise(dt, p.accel_psd))
            self.t = t

    def move(self, pivot: tuple[float, float], jump: tuple[float, float, float]) -> None:
        """Rotate the track by jump[2] [rad] about ``pivot`` (x, y) [m], then shift it by
        (jump[0], jump[1]) [m] (step 0)."""
        dx, dy, dpsi = jump
        c, s = math.cos(dpsi), math.sin(dpsi)
        rot = np.array([[c, -s], [s, c]])
        x = self.state
        centre = np.asarray(pivot)
        pos = centre + rot @ (x[:2] - centre) + np.array([dx, dy])
        vel = rot @ x[2:]
        self.kf.x = np.concatenate([pos, vel]).reshape(DIM_X, 1)
        big = np.kron(np.eye(2), rot)  # on (x, y) and on (vx, vy)
        self.kf.P = big @ self.kf.P @ big.T
        self.axis = np.array([[math.cos(2 * dpsi), -math.sin(2 * dpsi)],
                              [math.sin(2 * dpsi), math.cos(2 * dpsi)]]) @ self.axis

    def mahalanobis2(self, z: FloatArray, r: FloatArray) -> float:
        """Squared Mahalanobis distance of a map-frame centre ``z`` (2,) [m] measured with
        noise ``r`` (2, 2) [m^2]."""
        y = z - self.state[:2]
        return float(y @ np.linalg.solve(self.kf.P[:2, :2] + r, y))

    def noise(self, det: MapDetection, z: FloatArray, away: FloatArray,
              p: TrackerParams) -> FloatArray:
        """(2, 2) [m^2] the noise of the centre ``z`` [m] that ``det`` measures (``away``:
        `_away`): the filter's R; but along the length, unmeasured (``setback_sigma``) when
        `set_back` (module doc, measurement)."""
        if not self.set_back(det, z, away, p):
            return np.asarray(self.kf.R, dtype=np.float64)
        u = away[0]
        return np.asarray(self.kf.R + p.setback_sigma**2 * np.outer(u, u), dtype=np.float64)

    def beyond(self, z: FloatArray, away: FloatArray) -> float:
        """[m] how far the centre ``z`` [m] measured lies beyond the track's, along the
        detection's length away from the sensor (0 when no end faces it)."""
        return float(away[0] @ (z - self.state[:2]))

    def set_back(self, det: MapDetection, z: FloatArray, away: FloatArray,
                 p: TrackerParams) -> bool:
        """Whether ``det``'s near end face is set back from the object's end: its end was
        not seen (`Detection.end_seen`), the track is `settled` and the face lies between
        ``setback_margin`` and the track's length beyond the end the track predicts."""
        if det.end_seen or not self.settled or not away[0].any():
            return False
        return p.setback_margin < self.beyond(z, away) <= float(self.size.max())

    def _axes_along(self, det: MapDetection) -> list[int]:
        """The indices of the track's size (length 0, width 1) along ``det``'s length and
        width axes: swapped when its box axis lies nearer ``det``'s width axis."""
        axis = 0.5 * math.atan2(float(self.axis[1]), float(self.axis[0]))
        turned = abs(wrap_angle(2.0 * (axis - det.yaw))) > 0.5 * math.pi  # beyond 45 deg
        return [1, 0] if turned else [0, 1]

    def measured_centre(self, det: MapDetection, away: FloatArray,
                        held: FloatArray | None = None) -> FloatArray:
        """(2,) [m] the centre ``det`` measures for this track: its near faces (``away``:
        `_away`) plus half the track's own extents (``held``: along ``det``'s axes, by
        default the track's size there)."""
        seen = np.array([det.length, det.width])  # [m] along the detection's axes
        if held is None:
            held = self.size[self._axes_along(det)]
        out: FloatArray = np.array([det.x, det.y]) + away.T @ (0.5 * (held - seen))
        return out

    def update(self, det: MapDetection, t: float, p: TrackerParams,
               sensor: tuple[float, float]) -> None:
        """Take ``det``, seen from ``sensor`` (x, y) [m, map frame]: its near faces are the
        measurement (module doc, step 3)."""
        away = _away(det, sensor)  # (2, 2) per box axis, the direction away from the sensor
        order = self._axes_along(det)
        held = self.size[order]
        z = self.measured_centre(det, away, held)
        set_back = self.set_back(det, z, away, p)
        self.settled = self.confirmed and (set_back or (
            abs(self.beyond(z, away)) <= p.setback_margin
            and abs(float(held[0]) - det.length) <= p.setback_margin))
        self.kf.update(z, R=self.noise(det, z, away, p))
        a = p.size_alpha
        self.size = (1.0 - a) * self.size + a * np.array([det.length, det.width, det.height])
        self.axis = (1.0 - a) * self.axis + a * np.array([math.cos(2.0 * det.yaw),
                                                          math.sin(2.0 * det.yaw)])
        grown = self.size[order] - held  # [m] the new size's change: the centre
        self.kf.x[:2, 0] += away.T @ (0.5 * grown)  # moves with it, the near faces stay
        self.votes[det.cls] += 1
        self.last_cls = det.cls
        self.hits += 1
        self.misses = 0
        self.last_hit = t

    def cls(self) -> ObjectClass:
        """The majority class; a tie goes to the most recent detection's class, then to
        the enum order."""
        best = max(self.votes.values())
        if self.votes[self.last_cls] == best:
            return self.last_cls
        return next(c for c in _CLASS_ORDER if self.votes[c] == best)

    def yaw(self, p: TrackerParams) -> float:
        """[rad] map-frame heading: the smoothed box axis, pointed along the velocity when
        moving."""
        axis = 0.5 * math.atan2(float(self.axis[1]), float(self.axis[0]))  # (-pi/2, pi/2]
        vx, vy = self.state[2:]
        if math.hypot(vx, vy) < p.heading_min_speed:
            return axis
        course = math.atan2(vy, vx)
        flipped = wrap_angle(axis + math.pi)
        return axis if abs(wrap_angle(axis - course)) <= abs(wrap_angle(flipped - course)) \
            else flipped


def _away(det: MapDetection, sensor: tuple[float, float]) -> FloatArray:
    """(2, 2) [-]: for ``det``'s length axis and its width axis (rows), the unit vector
    away from ``sensor`` (x, y) [m] along it where the sensor's projection on the axis lies
    beyond the box (a face seen: the detector keeps it where it was seen and grows the box
    away from it, `perception.objects`), else zero (both ends of the axis seen)."""
    c, s = math.cos(det.yaw), math.sin(det.yaw)
    out = np.array([[c, s], [-s, c]])
    half = (0.5 * det.length, 0.5 * det.width)
    rel = np.array([sensor[0] - det.x, sensor[1] - det.y])
    for k in (0, 1):
        along = float(out[k] @ rel)
        out[k] *= 0.0 if abs(along) <= half[k] else -math.copysign(1.0, along)
    return out


def relative(x: float, y: float, vx: float, vy: float,
             ego: EgoState) -> tuple[float, float, float, float]:
    """(rel_x, rel_y, rel_vx, rel_vy) [m, m, m/s, m/s] of a map-frame position and velocity
    in the ego's vehicle frame; the velocity is relative to the ego's (speed along heading)."""
    c, s = math.cos(ego.heading), math.sin(ego.heading)
    dx, dy = x - ego.x, y - ego.y
    dvx, dvy = vx - ego.speed * c, vy - ego.speed * s
    return c * dx + s * dy, -s * dx + c * dy, c * dvx + s * dvy, -s * dvx + c * dvy


def _cost(tr: _TrackState, det: MapDetection, away: FloatArray, p: TrackerParams) -> float:
    """The squared Mahalanobis distance of the centre ``det`` measures for ``tr``."""
    z = tr.measured_centre(det, away)
    return tr.mahalanobis2(z, tr.noise(det, z, away, p))


def associate(tracks: list[_TrackState], dets: list[MapDetection], p: TrackerParams,
              sensor: tuple[float, float] = (0.0, 0.0)) -> list[tuple[int, int]]:
    """(track index, detection index) pairs of the gated minimum-cost assignment; each
    pair's cost is the distance of the centre the detection measures for that track (its
    near faces seen from ``sensor`` [m, map frame], `_TrackState.measured_centre`)."""
    if not tracks or not dets:
        return []
    away = [_away(d, sensor) for d in dets]
    cost = np.array([[_cost(tr, d, a, p) for d, a in zip(dets, away, strict=True)]
                     for tr in tracks])  # (T, D)
    cost = np.where(cost <= p.gate, cost, INFEASIBLE)
    rows, cols = linear_sum_assignment(cost)
    return [(int(r), int(c)) for r, c in zip(rows, cols, strict=True)
            if cost[r, c] < INFEASIBLE]


class MultiObjectTracker:
    """Kalman-filter multi-object tracker in the map frame; see the module docstring."""

    def __init__(self, params: TrackerParams | None = None) -> None:
        self.params = params if params is not None else TrackerParams()
        self._tracks: list[_TrackState] = []
        self._next_id = 1
        self._last_ego: EgoState | None = None  # the pose of the last scan

    def update(self, t: float, ego: EgoState, detections: tuple[Detection, ...],
               sensor: tuple[float, float] = (0.0, 0.0)) -> tuple[Track, ...]:
        """Advance to time ``t`` [s] with the detections of the scan at ``t`` (vehicle frame
        of ``ego``), taken from the LiDAR at ``sensor`` (x, y) [m] in that frame, and return
        the confirmed tracks, by id."""
        p = self.params
        dets = [to_map(d, ego) for d in detections]
        seen_from = in_map(ego, *sensor)
        if self._last_ego is not None and ego.t >= self._last_ego.t:
            jump = pose_jump(self._last_ego, ego)
            for tr in self._tracks:
                tr.move((ego.x - jump[0], ego.y - jump[1]), jump)
        self._last_ego = ego
        for tr in self._tracks:
            tr.predict(t, p)
        pairs = associate(self._tracks, dets, p, seen_from)
        matched_tracks = {i for i, _ in pairs}
        matched_dets = {j for _, j in pairs}
        for i, j in pairs:
            self._tracks[i].update(dets[j], t, p, seen_from)
        for i, tr in enumerate(self._tracks):
            tr.scans += 1
            if i not in matched_tracks:
                tr.misses += 1
        self._manage(ego)
        for j, det in enumerate(dets):
            if j not in matched_dets and math.hypot(det.x - ego.x, det.y - ego.y) <= p.max_distance:
                self._tracks.append(_TrackState(self._next_id, t, det, p))
                self._next_id += 1
        return tuple(self._output(tr, ego) for tr in self._tracks if tr.confirmed)

    def _manage(self, ego: EgoState) -> None:
        """Confirm and delete tracks (module doc, step 4)."""
        p = self.params
        kept = []
        for tr in self._tracks:
            if not tr.confirmed and tr.hits >= p.confirm_hits:
                tr.confirmed = True
            misses_allowed = p.confirm_window - p.confirm_hits
            if not tr.confirmed and tr.scans - tr.hits > misses_allowed:
                continue
            if tr.confirmed and tr.t - tr.last_hit > p.max_coast + 1e-9:
                continue
            x, y = tr.state[:2]
            if math.hypot(x - ego.x, y - ego.y) > p.max_distance:
                continue
            kept.append(tr)
        self._tracks = kept

    def _output(self, tr: _TrackState, ego: EgoState) -> Track:
        x, y, vx, vy = (float(v) for v in tr.state)
        rel_x, rel_y, rel_vx, rel_vy = relative(x, y, vx, vy, ego)
        p_pos = tr.kf.P[:2, :2]
        length, width, height = (float(v) for v in tr.size)
        return Track(id=tr.id, t=tr.t, x=x, y=y, vx=vx, vy=vy, rel_x=rel_x, rel_y=rel_y,
                     rel_vx=rel_vx, rel_vy=rel_vy, length=length, width=width, height=height,
                     yaw=tr.yaw(self.params), cls=tr.cls(), hits=tr.hits, misses=tr.misses,
                     position_sigma=math.sqrt(max(float(np.linalg.eigvalsh(p_pos)[-1]), 0.0)))

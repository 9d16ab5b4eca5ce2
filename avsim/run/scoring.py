"""Perception scored against ground truth, every run (the stack never sees any of this).

Lane (per front-camera frame): the estimate's offset of the car's centre from the lane
centre and its heading error against the truth at the frame's time (the lane the car's centre
is in, `RoadMap.lane_at`); RMS and max over frames, for the filtered estimate (what the planner
uses) and the raw detection. Frames taken while the car is outside every lane are skipped.

Objects (per LiDAR scan): ground-truth vehicles (cars and trucks) within `detection_range`
(50 m) of the car's centre that the scan actually saw (at least `min_returns` returns on
them, from the scan's ray truth: occluded cars cannot be detected and are not counted) are
matched one-to-one (Hungarian, scipy) to the vehicle-class detections placed in the map
frame with the TRUE pose (detection quality alone), and to the confirmed vehicle tracks (in
the map frame, as the stack placed them: localisation error included), within
`match_distance` (2 m). Recall = matched / visible truth; precision = matched detections /
vehicle detections within range that match a true vehicle in range (seen or not); track
position error = track centre - true centre; track
speed error = track speed - true speed; an id switch is a car matched to a different track id
than at its previous match.

First tracked (every actor, any kind, at any range): the distance [m] from the car's centre
to the actor's when a confirmed track (any class) first lies within `match_distance` of it,
`first_tracked_distance_<actor id>` (NaN when never): how far ahead or aside the stack first
knew of it (the detection-range scenarios of UN R157's ALKS set).

Per class: the same recall, track recall, track errors and id switches for each true vehicle
class (its catalogue model's: car, truck, bus, motorbike; `world.actors.catalogue`), keyed
`<metric>_<class>` (`detection_recall_truck`), for the classes seen in the run; precision for
each vehicle class the detector gave (car, truck, motorcycle: `detection_precision_car` is
the share of the detections called cars that lie on a true vehicle of any class).
"""

from __future__ import annotations

import math
from array import array
from collections import defaultdict
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import linear_sum_assignment

from perception.messages import Detection, LaneEstimate, ObjectClass, Track
from world.actors.actor_set import ActorPoses
from world.frames import wrap_angle
from world.sensors.lidar import LidarTruth
from world.spec import ActorType

VEHICLES = (ActorType.CAR, ActorType.TRUCK)


def floats() -> array[float]:
    """Every error sample of a run, 8 bytes each (a list takes 40: a run of an hour scores
    ~10^5 camera frames and scans); the RMS and max are taken over them all at the end."""
    return array("d")
VEHICLE_CLASSES = (ObjectClass.CAR, ObjectClass.TRUCK, ObjectClass.MOTORCYCLE)


@dataclass(frozen=True, slots=True, eq=False)
class CaptureTruth:
    """Ground truth at a capture instant."""

    t: float  # [s]
    ego_xy: NDArray[np.float64]  # [m] (2,) car centre, map frame
    ego_yaw: float  # [rad]
    lane_offset: float | None  # [m] car centre from its lane's centre, left +; None: no lane
    lane_heading_error: float  # [rad] car heading minus the lane's, wrapped
    actors: ActorPoses


@dataclass(frozen=True, slots=True)
class ScoringParams:
    detection_range: float = 50.0  # [m]
    match_distance: float = 2.0  # [m]
    min_returns: int = 10  # [-] LiDAR returns on a car for it to count as seen


@dataclass
class ClassScore:
    """The object scores of one true vehicle class over a run."""

    visible: int = 0  # visible true vehicles of the class in range, summed over scans
    detected: int = 0  # of those, matched to a detection
    tracked: int = 0  # of those, matched to a confirmed track
    track_pos_err: array[float] = field(default_factory=floats)  # [m]
    track_speed_err: array[float] = field(default_factory=floats)  # [m/s]
    switches: int = 0  # id switches of the class's vehicles

    def metrics(self, suffix: str) -> dict[str, float]:
        """This class's entries of the result JSON, each key ending in `suffix`."""
        return {
            f"detection_recall{suffix}": self.detected / self.visible,
            f"track_recall{suffix}": self.tracked / self.visible,
            f"track_position_rmse{suffix}": _rms(self.track_pos_err),
            f"track_speed_rmse{suffix}": _rms(self.track_speed_err),
            f"id_switches{suffix}": float(self.switches),
        }


def _rms(x: array[float]) -> float:
    return math.sqrt(float(np.mean(np.square(x)))) if x else math.nan


def _max_abs(x: array[float]) -> float:
    return float(np.max(np.abs(x))) if x else math.nan


def _match(a: NDArray[np.float64], b: NDArray[np.float64],
           gate: float) -> list[tuple[int, int]]:
    """One-to-one pairs (i, j) of points a (N, 2) and b (M, 2) closer than `gate` [m]."""
    if len(a) == 0 or len(b) == 0:
        return []
    cost = np.linalg.norm(a[:, None, :] - b[None, :, :], axis=-1)
    rows, cols = linear_sum_assignment(np.where(cost <= gate, cost, 1e6))
    return [(int(i), int(j)) for i, j in zip(rows, cols, strict=True) if cost[i, j] <= gate]


@dataclass
class PerceptionScore:
    """Accumulates the scores of one run; `metrics()` gives the result JSON's entries."""

    params: ScoringParams = field(default_factory=ScoringParams)
    offset_err: array[float] = field(default_factory=floats)  # [m] filtered lane
    heading_err: array[float] = field(default_factory=floats)  # [rad]
    raw_offset_err: array[float] = field(default_factory=floats)  # [m] raw detection
    visible: int = 0  # visible true vehicles in range, summed over scans
    detected: int = 0  # of those, matched to a detection
    detections: int = 0  # vehicle detections in range
    true_detections: int = 0  # of those, matched to a true vehicle in range (seen or not)
    tracked: int = 0  # visible true vehicles matched to a confirmed track
    track_pos_err: array[float] = field(default_factory=floats)  # [m]
    track_speed_err: array[float] = field(default_factory=floats)  # [m/s]
    switches: dict[str, int] = field(default_factory=lambda: defaultdict(int))
    by_class: dict[str, ClassScore] = field(default_factory=dict)  # by true class
    detections_by_class: dict[str, int] = field(default_factory=dict)  # by detected class
    true_detections_by_class: dict[str, int] = field(default_factory=dict)
    _last_id: dict[str, int] = field(default_factory=dict)
    first_tracked: dict[str, float] = field(default_factory=dict)  # actor id -> [m] range
    _actor_ids: tuple[str, ...] = ()  # every actor seen in a capture's truth
    _first_t: float = math.inf
    _last_t: float = -math.inf

    def lane(self, raw: LaneEstimate | None, filtered: LaneEstimate | None,
             truth: CaptureTruth) -> None:
        if truth.lane_offset is None:
            return
        if filtered is not None:
            self.offset_err.append(filtered.offset - truth.lane_offset)
            self.heading_err.append(wrap_angle(filtered.heading_error - truth.lane_heading_error))
        if raw is not None and raw.confidence > 0.0:
            self.raw_offset_err.append(raw.offset - truth.lane_offset)

    def objects(self, detections: tuple[Detection, ...], tracks: tuple[Track, ...],
                truth: CaptureTruth, scan: LidarTruth) -> None:
        p = self.params
        self._first_t, self._last_t = min(self._first_t, truth.t), max(self._last_t, truth.t)
        idx = self._visible_vehicles(truth, scan)
        true_xy = truth.actors.centres[idx, :2]
        self.visible += len(idx)
        classes = [self._class_score(truth, int(i)) for i in idx]
        for score in classes:
            score.visible += 1
        det_xy, det_cls = self._detections_in_map(detections, truth)
        near = np.linalg.norm(det_xy - truth.ego_xy, axis=1) <= p.detection_range \
            if len(det_xy) else np.zeros(0, bool)
        near_cls = [c for c, n in zip(det_cls, near.tolist(), strict=True) if n]
        self.detections += int(near.sum())
        found = _match(true_xy, det_xy[near], p.match_distance)
        self.detected += len(found)
        for i, _ in found:
            classes[i].detected += 1
        all_xy = truth.actors.centres[self._vehicles_in_range(truth), :2]
        true_found = _match(all_xy, det_xy[near], p.match_distance)
        self.true_detections += len(true_found)
        for c in near_cls:
            self.detections_by_class[c] = self.detections_by_class.get(c, 0) + 1
        for _, j in true_found:
            c = near_cls[j]
            self.true_detections_by_class[c] = self.true_detections_by_class.get(c, 0) + 1
        self._first_tracked(tracks, truth)
        vehicle_tracks = [tr for tr in tracks if tr.cls in VEHICLE_CLASSES]
        trk_xy = np.array([[tr.x, tr.y] for tr in vehicle_tracks]).reshape(-1, 2)
        for i, j in _match(true_xy, trk_xy, p.match_distance):
            self._score_track(int(idx[i]), vehicle_tracks[j], truth)

    def _first_tracked(self, tracks: tuple[Track, ...], truth: CaptureTruth) -> None:
        """Each actor's range when a confirmed track first lies on it (module doc)."""
        a = truth.actors
        self._actor_ids = a.ids
        if not tracks or len(self.first_tracked) == len(a.ids):
            return
        trk_xy = np.array([[tr.x, tr.y] for tr in tracks])
        for i, name in enumerate(a.ids):
            if name in self.first_tracked:
                continue
            near = np.linalg.norm(trk_xy - a.centres[i, :2], axis=1)
            if near.min() <= self.params.match_distance:
                self.first_tracked[name] = float(np.linalg.norm(a.centres[i, :2]
                                                                - truth.ego_xy))

    def _in_range(self, truth: CaptureTruth) -> NDArray[np.bool_]:
        a = truth.actors
        vehicle = np.array([k in VEHICLES for k in a.kinds], dtype=bool)
        if not len(a.ids):
            return vehicle
        dist = np.linalg.norm(a.centres[:, :2] - truth.ego_xy, axis=1)
        out: NDArray[np.bool_] = vehicle & (dist <= self.params.detection_range)
        return out

    def _vehicles_in_range(self, truth: CaptureTruth) -> NDArray[np.intp]:
        return np.flatnonzero(self._in_range(truth))

    def _visible_vehicles(self, truth: CaptureTruth, scan: LidarTruth) -> NDArray[np.intp]:
        n = len(truth.actors.ids)
        hits = np.bincount(scan.actor[scan.actor >= 0], minlength=n)[:n]
        return np.flatnonzero(self._in_range(truth) & (hits >= self.params.min_returns))

    def _class_score(self, truth: CaptureTruth, actor: int) -> ClassScore:
        """The per-class score of a true vehicle's class (made when first seen)."""
        cls = truth.actors.truth_class(actor)
        assert cls is not None  # a vehicle
        return self.by_class.setdefault(cls.value, ClassScore())

    @staticmethod
    def _detections_in_map(detections: tuple[Detection, ...],
                           truth: CaptureTruth) -> tuple[NDArray[np.float64], list[str]]:
        """(N, 2) [m] map-frame centres of the vehicle-class detections, and their classes."""
        vehicle = [d for d in detections if d.cls in VEHICLE_CLASSES]
        if not vehicle:
            return np.zeros((0, 2)), []
        xy = np.array([[d.x, d.y] for d in vehicle])
        c, s = math.cos(truth.ego_yaw), math.sin(truth.ego_yaw)
        out: NDArray[np.float64] = truth.ego_xy + xy @ np.array([[c, s], [-s, c]])
        return out, [d.cls.value for d in vehicle]

    def _score_track(self, actor: int, track: Track, truth: CaptureTruth) -> None:
        a = truth.actors
        self.tracked += 1
        pos_err = math.hypot(track.x - a.centres[actor, 0], track.y - a.centres[actor, 1])
        speed_err = track.speed - abs(float(a.speeds[actor]))
        self.track_pos_err.append(pos_err)
        self.track_speed_err.append(speed_err)
        score = self._class_score(truth, actor)
        score.tracked += 1
        score.track_pos_err.append(pos_err)
        score.track_speed_err.append(speed_err)
        name = a.ids[actor]
        if name in self._last_id and self._last_id[name] != track.id:
            self.switches[name] += 1
            score.switches += 1
        self._last_id[name] = track.id

    def metrics(self) -> dict[str, float]:
        span = max(self._last_t - self._first_t, 1e-9)
        per_100s = max(self.switches.values(), default=0) * 100.0 / max(span, 100.0)
        out = {
            "lane_offset_rmse": _rms(self.offset_err),
            "lane_offset_max": _max_abs(self.offset_err),
            "lane_heading_rmse_deg": math.degrees(_rms(self.heading_err)),
            "lane_heading_max_deg": math.degrees(_max_abs(self.heading_err)),
            "lane_raw_offset_rmse": _rms(self.raw_offset_err),
            "lane_frames": float(len(self.offset_err)),
        }
        if self.visible or self.detections:
            out |= {
                "detection_recall": self.detected / self.visible if self.visible else math.nan,
                "detection_precision": (self.true_detections / self.detections
                                        if self.detections else math.nan),
                "track_recall": self.tracked / self.visible if self.visible else math.nan,
                "track_position_rmse": _rms(self.track_pos_err),
                "track_speed_rmse": _rms(self.track_speed_err),
                "id_switches": float(sum(self.switches.values())),
                "max_id_switches_per_car_per_100s": per_100s,
            }
        for name in sorted(self.by_class):
            out |= self.by_class[name].metrics(f"_{name}")
        for name in sorted(self.detections_by_class):
            out[f"detection_precision_{name}"] = (self.true_detections_by_class.get(name, 0)
                                                  / self.detections_by_class[name])
        for name in self._actor_ids:
            out[f"first_tracked_distance_{name}"] = self.first_tracked.get(name, math.nan)
        return out

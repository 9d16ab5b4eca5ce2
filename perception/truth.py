"""The perception stage of privileged truth mode: the ground truth as the planner's input.

For a user testing a planner without perception (the run is labelled privileged): it reads
the `truth` sensor (`world.frames.GroundTruth`) and the odometry's vehicle signals only, and
hands the planner

- the ego's state exactly (the truth's pose, speed, yaw rate and steering angle; position
  sigma 0);
- every object of the truth as a confirmed `Track` (its id numbered by first appearance,
  never reused), its position and relative velocity in the vehicle frame at the truth's
  time (`perception.tracking.relative`), position sigma 0; a car, truck or pedestrian is
  of that class, an obstacle `ObjectClass.OTHER`;
- no camera lane (`lane=None`) and no signs or lights: the planner keeps the HD map's lane;
- the driver's pedal, switch and controls, and the flat-tyre flag, from the odometry, as
  the bundled perception does.
"""

from __future__ import annotations

from perception.flat_tyre import FlatTyreDetector
from perception.messages import EgoState, ObjectClass, PerceptionReport, PlannerInput, Track
from perception.tracking import relative
from world.frames import (
    DriverControls,
    Frames,
    GroundTruth,
    Odometry,
    TruthObject,
    VehicleInfo,
)

TRUTH = "truth"  # the truth sensor's name
ODOMETRY = "odometry"  # the odometry's name
CLASSES = {"car": ObjectClass.CAR, "truck": ObjectClass.TRUCK,
           "pedestrian": ObjectClass.PEDESTRIAN}  # a truth object's kind -> its class (any
#   other kind: OTHER)


class TruthPerception:
    """`PerceptionStage` on the ground truth (module doc)."""

    reads = frozenset({TRUTH, ODOMETRY})

    def __init__(self, vehicle: VehicleInfo) -> None:
        self.flat_detector = FlatTyreDetector(vehicle)
        self._ids: dict[str, int] = {}  # a truth object's id -> its track's
        self._hits: dict[str, int] = {}  # [-] truth frames each object was in
        self._ego = EgoState(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
        self._tracks: tuple[Track, ...] = ()
        self._odometry: Odometry | None = None

    def on_frames(self, t: float, frames: Frames) -> PerceptionReport | None:
        odometry = frames.get(ODOMETRY)
        if isinstance(odometry, Odometry):
            self._odometry = odometry
            self.flat_detector.update(odometry)
        truth = frames.get(TRUTH)
        if not isinstance(truth, GroundTruth):
            return None
        self._ego = EgoState(t=truth.t, x=truth.x, y=truth.y, heading=truth.heading,
                             speed=truth.speed, yaw_rate=truth.yaw_rate,
                             steering_angle=truth.steering_angle, position_sigma=0.0)
        self._tracks = tuple(self._track(o) for o in truth.objects)
        return PerceptionReport(t=truth.t, pose=self._ego, tracks=self._tracks)

    def _track(self, o: TruthObject) -> Track:
        ident = self._ids.setdefault(o.id, len(self._ids))
        hits = self._hits[o.id] = self._hits.get(o.id, 0) + 1
        rel_x, rel_y, rel_vx, rel_vy = relative(o.x, o.y, o.vx, o.vy, self._ego)
        return Track(id=ident, t=self._ego.t, x=o.x, y=o.y, vx=o.vx, vy=o.vy, rel_x=rel_x,
                     rel_y=rel_y, rel_vx=rel_vx, rel_vy=rel_vy, length=o.length,
                     width=o.width, height=o.height, yaw=o.yaw,
                     cls=CLASSES.get(o.kind, ObjectClass.OTHER), hits=hits, misses=0,
                     position_sigma=0.0)

    def perceive(self, t: float) -> PlannerInput:
        """The truth's latest state (delivered at every control tick, no latency)."""
        odo = self._odometry
        return PlannerInput(
            ego=self._ego, tracks=self._tracks,
            pedal=odo.accelerator_pedal if odo is not None else 0.0,
            engaged=odo.engaged if odo is not None else True,
            driver=odo.driver if odo is not None else DriverControls(),
            flat_tyre=self.flat_detector.state is not None)

"""The default Rerun blueprint of a run, and the entity paths a recording uses.

Every `.rrd` written by `avsim.record.recorder.Recorder` carries this blueprint as its *default*
blueprint, so `rerun run.rrd` opens on this layout::

    +-------------------------------------+------------------------------+
    | [Chase | Overview]  3D views of     | speed, target speed, limit   |
    | /world: road, ego, actors, plan,    +------------------------------+
    | LiDAR, tracks, lane detections      | [Steering & CTE | Other]     |
    | (chase: eye = the chase camera)     +------------------------------+
    +------------------+------------------+ events (text log)            |
    | [Front | Left |  | FSM state        |                              |
    |  Right] camera   | timeline (/fsm)  |                              |
    +------------------+------------------+------------------------------+

The chase camera: Rerun 0.41's `EyeControls3D(tracking_entity=...)` follows an entity. For a
plain entity it only keeps the orbit centre on the entity's bounding box (the view direction
stays fixed in the world, and an entity without geometry of its own, such as the bare
transform at `/world/ego`, has no bounding box to follow). For a pinhole camera entity it
takes over the camera's pose. So the recorder logs an invisible pinhole `CHASE_CAMERA` rigidly
attached behind and above the car, and the 3D view tracks it: the eye moves and turns with
the car. The chase view leaves out the cameras' image planes (they would hang in front of
the car); the overview shows them in 3D, each in its frustum on its mount.

The camera views are 2D views rooted at the camera entities (`camera_entity(name)`), which
carry the image and its pinhole. Views whose data a run does not log (a profile without side
cameras, a run without FSM changes) simply stay empty.
"""

from __future__ import annotations

import rerun.blueprint as rrb

# -- entity paths (the recording's layout; the recorder and the blueprint share them) --------
WORLD = "/world"  # static ViewCoordinates RIGHT_HAND_Z_UP; map frame, z up, [m]
ROAD = "/world/road"  # /world/road/<mesh name>: static textured Mesh3D
EGO = "/world/ego"  # Transform3D over sim_time: car frame (x forward, y left, z up) in map frame
EGO_BODY = "/world/ego/body"  # static Boxes3D in the car frame
EGO_WHEELS = "/world/ego/wheels"  # static Boxes3D in the car frame
CHASE_CAMERA = "/world/ego/chase_camera"  # static Transform3D + invisible Pinhole (the eye)
ACTORS = "/world/actors"  # Boxes3D over sim_time, labels = actor ids, class = kind
PLAN_PATH = "/world/plan/path"  # LineStrips3D over sim_time: the planned path
LIDAR = "/world/lidar"  # Points3D over sim_time: the LiDAR scan in the map frame
TRACKS = "/world/tracks"  # static AnnotationContext: the tracks' class colours
TRACK_BOXES = "/world/tracks/boxes"  # Boxes3D over sim_time, labels "id <n>", class = kind
TRACK_VELOCITY = "/world/tracks/velocity"  # Arrows3D over sim_time: a horizon of motion
PERCEPTION = "/world/perception"  # perception outputs in the map frame
LANE_LINES = "/world/perception/lanes"  # LineStrips3D over sim_time: detected lane lines
DETECTIONS = "/world/perception/detections"  # Boxes3D over sim_time: raw detections
INFRACTIONS = "/world/infractions"  # Points3D over sim_time: every infraction so far, at
#   the place it happened
METRICS = "/metrics"  # /metrics/<name>: Scalars over sim_time, SeriesLines static
EVENTS = "/events"  # TextLog over sim_time
FSM_ROOT = "/fsm"  # /fsm/<machine>: StateChange over sim_time (StateConfiguration static)
TIMELINE = "sim_time"  # the one timeline: simulated time, a duration [s]

CAMERAS = ("front", "left", "right")  # the cameras the layout has a view for, front first


def camera_entity(name: str) -> str:
    """`/world/ego/camera_<name>`: the camera's mount (static Transform3D in the car frame),
    Pinhole (static) and image (EncodedImage over sim_time)."""
    return f"{EGO}/camera_{name}"


FRONT_CAMERA = camera_entity("front")

# -- metric names shown in the two fixed plots ---------------------------------------------
SPEED_METRICS = ("speed", "target_speed", "speed_limit")  # [m/s]
STEERING_METRICS = ("steering", "cross_track_error")  # [rad], [m]


def _metric_paths(names: tuple[str, ...]) -> list[str]:
    """`/metrics/<name>` of each name."""
    return [f"{METRICS}/{name}" for name in names]


def _world_views() -> rrb.Tabs:
    """The chase view (eye = the chase camera behind the car) and a free overview."""
    chase = rrb.Spatial3DView(
        origin=WORLD,
        contents=[f"+ {WORLD}/**", *(f"- {camera_entity(name)}" for name in CAMERAS)],
        name="Chase",
        eye_controls=rrb.EyeControls3D(tracking_entity=CHASE_CAMERA),
        line_grid=rrb.LineGrid3D(visible=False),
    )
    overview = rrb.Spatial3DView(
        origin=WORLD,
        name="Overview",
        line_grid=rrb.LineGrid3D(visible=False),
    )
    return rrb.Tabs(chase, overview, active_tab=0)


def _camera_views() -> rrb.Tabs:
    """One 2D view per camera (front first, active), each rooted at the camera entity."""
    views = [
        rrb.Spatial2DView(origin=camera_entity(name), name=f"{name.capitalize()} camera")
        for name in CAMERAS
    ]
    return rrb.Tabs(*views, active_tab=0)


def _sensor_views() -> rrb.Horizontal:
    """The camera images beside the FSM state lanes."""
    fsm = rrb.StateTimelineView(origin=FSM_ROOT, name="FSM")
    return rrb.Horizontal(_camera_views(), fsm, column_shares=[1.0, 1.0])


def _plots() -> rrb.Vertical:
    """Speed plot; steering and cross-track error; any other metric; the event log."""
    speed = rrb.TimeSeriesView(
        origin=METRICS,
        contents=_metric_paths(SPEED_METRICS),
        name="Speed [m/s]",
    )
    steering = rrb.TimeSeriesView(
        origin=METRICS,
        contents=_metric_paths(STEERING_METRICS),
        name="Steering [rad], cross-track error [m]",
    )
    excluded = [f"- {path}" for path in _metric_paths(SPEED_METRICS + STEERING_METRICS)]
    other = rrb.TimeSeriesView(
        origin=METRICS,
        contents=[f"+ {METRICS}/**", *excluded],
        name="Other metrics",
    )
    events = rrb.TextLogView(origin=EVENTS, name="Events")
    return rrb.Vertical(
        speed, rrb.Tabs(steering, other, active_tab=0), events, row_shares=[1.0, 1.0, 1.0]
    )


def default_blueprint() -> rrb.Blueprint:
    """The layout every run's recording opens with (see the module docstring)."""
    left = rrb.Vertical(_world_views(), _sensor_views(), row_shares=[3.0, 2.0])
    root = rrb.Horizontal(left, _plots(), column_shares=[3.0, 2.0])
    return rrb.Blueprint(root)

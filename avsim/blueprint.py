"""The default Rerun blueprint of a run, and the entity paths a recording uses.

Every `.rrd` written by `avsim.recorder.Recorder` carries this blueprint as its *default*
blueprint, so `rerun run.rrd` opens on this layout::

    +-------------------------------------+------------------------------+
    | [Chase | Overview]  3D views of     | speed, target speed, limit   |
    | /world (chase: eye tracks the       +------------------------------+
    | chase camera behind /world/ego)     | [Steering & CTE | Other]     |
    +-------------------------------------+------------------------------+
    | [Front camera | FSM]                | events (text log)            |
    +-------------------------------------+------------------------------+

The chase camera: Rerun 0.41's `EyeControls3D(tracking_entity=...)` follows an entity. For a
plain entity it only keeps the orbit centre on the entity's bounding box (the view direction
stays fixed in the world, and an entity without geometry of its own, such as the bare
transform at `/world/ego`, has no bounding box to follow). For a pinhole camera entity it
takes over the camera's pose. So the recorder logs an invisible pinhole `CHASE_CAMERA` rigidly
attached behind and above the car, and the 3D view tracks it: the eye moves and turns with
the car.

Room is reserved for later issues: the front camera's 2D view (`FRONT_CAMERA`) and the FSM
state timeline (`FSM_ROOT`) are in the layout already and stay empty until data arrives.
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
FRONT_CAMERA = "/world/ego/camera_front"  # reserved: front camera image (later issue)
ACTORS = "/world/actors"  # Boxes3D over sim_time, labels = actor ids, class = kind
PLAN_PATH = "/world/plan/path"  # LineStrips3D over sim_time: the planned path
METRICS = "/metrics"  # /metrics/<name>: Scalars over sim_time, SeriesLines static
EVENTS = "/events"  # TextLog over sim_time
FSM_ROOT = "/fsm"  # reserved: StateChange lanes of the motion / control FSMs (later issue)
TIMELINE = "sim_time"  # the one timeline: simulated time, a duration [s]

# -- metric names shown in the two fixed plots ---------------------------------------------
SPEED_METRICS = ("speed", "target_speed", "speed_limit")  # [m/s]
STEERING_METRICS = ("steering", "cross_track_error")  # [rad], [m]


def _metric_paths(names: tuple[str, ...]) -> list[str]:
    return [f"{METRICS}/{name}" for name in names]


def _world_views() -> rrb.Tabs:
    """The chase view (eye = the chase camera behind the car) and a free overview."""
    chase = rrb.Spatial3DView(
        origin=WORLD,
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


def _reserved_views() -> rrb.Tabs:
    """Views whose data later issues add: the front camera image and the FSM lanes."""
    front = rrb.Spatial2DView(origin=FRONT_CAMERA, name="Front camera")
    fsm = rrb.StateTimelineView(origin=FSM_ROOT, name="FSM")
    return rrb.Tabs(front, fsm, active_tab=0)


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
    left = rrb.Vertical(_world_views(), _reserved_views(), row_shares=[3.0, 2.0])
    root = rrb.Horizontal(left, _plots(), column_shares=[3.0, 2.0])
    return rrb.Blueprint(root)

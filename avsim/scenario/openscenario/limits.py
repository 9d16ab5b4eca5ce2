"""The bounds an OpenSCENARIO file's values must keep, beyond being finite: the YAML
format's times and speeds (`avsim.scenario.bounds`), entity sizes and name lengths. A value
outside is refused with the one-line error at its element; they are listed in
`docs/openscenario.md` ("Bounds")."""

from __future__ import annotations

from avsim.scenario.bounds import MAX_DURATION, MAX_SPEED_KPH

MAX_TIME = MAX_DURATION  # [s] a condition's time, delay or duration; a transition's time
MAX_SPEED = MAX_SPEED_KPH / 3.6  # [m/s] a target speed, a speed condition's value
MAX_BOX_LENGTH = 30.0  # [m] a bounding box's length (an articulated truck is about 25 m)
MAX_BOX_WIDTH = 5.0  # [m] a bounding box's width
MAX_BOX_HEIGHT = 5.0  # [m] a bounding box's height
MAX_NAME_CHARS = 100  # [characters] a name: of an entity, a parameter, a storyboard element,
#   a catalog entry
MAX_TRAJECTORY_POINTS = 10_000  # a trajectory's vertices, control points or spline segments
MAX_NURBS_ORDER = 16  # [-] a NURBS's order (its degree + 1)
MAX_TRAJECTORY_LENGTH = 20_000.0  # [m] a clothoid's or a spline's length (the YAML format's
#   longest route, `avsim.scenario.bounds.MAX_ROUTE_LENGTH`)
MAX_CURVATURE = 10.0  # [1/m] a clothoid's curvature (a 0.1 m radius)
MAX_CURVATURE_RATE = 100.0  # [1/m^2] a clothoid's curvature change per metre
MAX_PROFILE_ENTRIES = 1000  # a SpeedProfileAction's entries
MAX_DISTANCE = 1000.0  # [m] a lateral distance, a synchronize tolerance

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

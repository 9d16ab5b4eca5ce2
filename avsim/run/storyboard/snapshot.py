"""What the storyboard's conditions are judged on at one step: every entity's true state.

Truth, from the world (`world.truth`), never the stack's view. Positions are of each
entity's OpenSCENARIO reference point (a vehicle's rear axle centre, else its bounding box
centre projected to the ground), in the map frame; route coordinates are along the ego's
route (`world.hdmap.RoadMap`: station s along lane 0's centre, lateral offset left +).
An entity out of the world (deleted, or not yet added) is in `entities` (where it left, its
motion held) and named in `inactive`; conditions judge `active()`, without it.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class EntityState:
    """One entity's true state."""

    name: str
    x: float  # [m] map frame, the reference point
    y: float  # [m]
    heading: float  # [rad] of the body, map frame
    speed: float  # [m/s] over ground, signed along the heading
    s: float  # [m] route station of the reference point
    offset: float  # [m] lateral offset of the reference point from the route's reference
    #   line (lane 0's centre), left +
    lane: int | None  # the route lane its reference point is in (None: off every lane)
    route_heading: float  # [rad] the route's heading at s (for longitudinal / lateral axes)
    length: float  # [m] bounding box, along the heading
    width: float  # [m]
    centre_ahead: float  # [m] the box centre's distance ahead of the reference point along
    #   the heading (a vehicle's: half its length minus its rear overhang)
    odometer: float  # [m] distance travelled since the run started
    standing_for: float  # [s] how long it has been at rest (speed below 0.01 m/s), 0 moving
    off_road_for: float  # [s] how long its reference point has been off the paved road
    end_of_road_for: float  # [s] how long it has been beyond the route's ends
    acceleration: float = 0.0  # [m/s²] of its speed along its heading, between the last two
    #   snapshots (0 at the first)
    yaw_rate: float = 0.0  # [rad/s] of its heading, left +, between the last two snapshots


@dataclass(frozen=True, slots=True)
class Snapshot:
    """Every entity's true state at one step."""

    time: float  # [s] simulation time
    entities: Mapping[str, EntityState]  # by entity name
    categories: Mapping[str, str]  # entity name -> "vehicle" | "pedestrian" | "miscellaneous"
    inactive: frozenset[str] = frozenset()  # entities out of the world now

    def active(self) -> Snapshot:
        """This snapshot without the entities out of the world (itself when none is)."""
        if not self.inactive:
            return self
        entities = {n: e for n, e in self.entities.items() if n not in self.inactive}
        return Snapshot(self.time, entities, self.categories)

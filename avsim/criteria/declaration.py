"""How a criterion plugs in: its declaration, and what a run offers it to build from.

A declaration says which key under a scenario file's `criteria:` asks for the criterion
(or none, for the criteria that always apply), the setting's type as the file's validation
takes it (bounds and checks included) and its description (unit, bounds, default: the JSON
Schema's and the docs'), what the criterion needs from the run (`Need`: the map, the car's
geometry, the criteria rate, the route's signal plans, the driver's set speed, the names
of the bodies the ego may touch, the NPCs' true poses in each sample), and how to build it.

A new criterion is one module of `avsim.criteria` (its class and its declaration) and one
line in `avsim.criteria.registry.DECLARATIONS`. The scenario format's `criteria:` section,
its JSON Schema and its validation come from the declarations; `avsim.scenario` does not
change.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Generic, TypeVar

from avsim.criteria.base import MAX_LANE_CHANGE, Criterion, Need
from vehicle_urdf import CarGeometry
from world.hdmap import RoadMap
from world.spec import TownSpec, TrafficLightSpec

S = TypeVar("S")  # a declaration's setting, as validated


@dataclass(frozen=True, slots=True, eq=False)
class RunInputs:
    """What a run offers its criteria to build from. A declaration names in `needs` the
    fields its criteria use (`Need`'s value is the field's name); the registry's tests hold
    each declaration to that."""

    road: RoadMap  # the route's static map: lanes, limits, features
    car: CarGeometry  # the ego's dimensions
    rate: float  # [Hz] the criteria rate (samples of the truth)
    signals: tuple[TrafficLightSpec, ...]  # the route's signal plans (ground truth)
    set_speed: float  # [m/s] the driver's set speed
    bodies: Mapping[int, str]  # body id -> what it is, for each body the ego may touch
    lane_change_max: float = MAX_LANE_CHANGE  # [s] how long a lane change may take (the
    #   scenario's `lane_change.max_duration`)
    story: tuple[str, ...] = ()  # the actions and events that must fire
    #   (`avsim.criteria.story.story_label`)
    story_off: Mapping[str, str] = field(default_factory=dict)  # label -> why the file
    #   switches that action off by configuration (not in `story`)
    actor_bodies: Mapping[int, str] = field(default_factory=dict)  # NPC body id -> its
    #   actor's id
    town: TownSpec | None = None  # the town's layout and signal timing (None: a road)
    parameters: Mapping[str, int | float | bool | str] = field(default_factory=dict)  # an
    #   OpenSCENARIO file's global parameters, resolved (none for a YAML scenario)


@dataclass(frozen=True, slots=True)
class Declaration(Generic[S]):
    """How a scenario gets a criterion, or a family of them (`lane_change` gives two).

    `build(setting, run)` makes the criteria from the validated setting and the run's
    inputs. Without `always` they apply only when the file sets `key`, and `build` gets its
    value. With `always` they apply to every run, and `key` (if any) only tunes them:
    `build` gets None when the file leaves the key out (`reach_s` sets where `completes`
    is reached, by default the route's end less `route.END_MARGIN`)."""

    build: Callable[[S, RunInputs], Sequence[Criterion]]
    needs: frozenset[Need]  # what its criteria use: `RunInputs` fields, sample parts
    needs_if_set: frozenset[Need] = frozenset()  # what they use besides when the scenario
    #   sets the key (an always-on criterion that a setting makes look at more)
    key: str | None = None  # under the file's `criteria:`; None: nothing to set
    always: bool = False  # applies without its key
    setting: Any = None  # the setting's type as pydantic validates it (an annotated type or
    #   a model of the format's strict kind, `avsim.scenario.fields`); None without a key
    doc: str = ""  # the setting's description: unit, bounds, default
    example: object = None  # a valid setting as a file writes it (the JSON Schema's example)
    on_route: bool = False  # the setting is a station [m] that must lie on the ego's route
    switch: str | None = None  # a key whose `false` turns these always-on criteria off
    #   (`completes: false`); None: they cannot be turned off

    def __post_init__(self) -> None:
        if self.key is None and not (self.always and self.setting is None):
            raise ValueError("a declaration without a key always applies and has no setting")
        if self.switch is not None and not self.always:
            raise ValueError(f"criteria switch {self.switch!r}: only always-on criteria")
        if self.key is not None and (self.setting is None or not self.doc
                                     or self.example is None):
            raise ValueError(f"criteria key {self.key!r} needs a setting type, a doc and an "
                             f"example")

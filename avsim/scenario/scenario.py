"""A scenario as a run takes it: its name and duration, the world it happens in, what the
driver asks of the car, and the criteria it is judged by.

`avsim.scenario.load.load_scenario` returns one (SI units, radians, every default
resolved); the runner, the batch jobs, the CLI and the reports take it. The world's part
(`world.spec.WorldSpec`: roads or a town, the ego car's body, actors, events, sensors, the
seed) is what `world.World` is built from; the stack choice says which driving stack drives
the car (`avsim.run.stack`) and the driver's settings configure it; the criteria settings
choose and tune the criteria (`avsim.criteria.registry`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from avsim.criteria.registry import CriteriaSettings
from avsim.scenario.openscenario.program import StoryProgram
from avsim.stack.choice import StackChoice
from world.spec import WorldSpec


@dataclass(frozen=True, slots=True)
class DriverSettings:
    """What the driver asks of the car's driving stack (the file's `ego.set_speed_kph` and
    `ego.overtake`); the car's own limits and start are the world's (`world.spec.EgoSpec`)."""

    set_speed: float  # [m/s] the desired (cruise) speed
    overtake: bool = False  # may change lanes to pass a slower vehicle


@dataclass(frozen=True, slots=True)
class Scenario:
    """One scenario: what the run simulates, for how long, and how it is judged."""

    name: str  # [a-z0-9_]+
    description: str  # one line for humans
    situation: str  # which driving situation it exercises (the file's `situation`)
    duration: float  # [s] simulated time limit
    world: WorldSpec  # what the world is built from
    driver: DriverSettings  # what the driver asks of the stack
    criteria: CriteriaSettings = field(default_factory=CriteriaSettings)
    stack: StackChoice = field(default_factory=StackChoice)  # which stack drives the car
    #   (the file's `stack:`, `--stack` / `--perception` / `--planner` / `--controller`)
    story: StoryProgram | None = None  # an OpenSCENARIO file's storyboard (its director
    #   plays it: `avsim.run.storyboard`); None: the world spec's own scripted actions
    grid: tuple[tuple[str, tuple[object, ...]], ...] = ()  # the file's test grid: key paths
    #   and their values (`avsim suite` runs every point: `avsim.batch.suite.grid_entries`)
    sources: tuple[Path, ...] = field(default=(), compare=False)  # the files it was read
    #   from: the scenario file, an OpenSCENARIO file's road and sidecar (`avsim.outputs`
    #   never writes over one); not part of what the scenario is

    @property
    def seed(self) -> int:
        """The seed of the world's randomness (the file's `seed`)."""
        return self.world.seed

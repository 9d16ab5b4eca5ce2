"""What the runner plays of an OpenSCENARIO file besides the world it is built from: its
storyboard, with how the file's entities map onto the world's bodies."""

from __future__ import annotations

from dataclasses import dataclass

from avsim.scenario.openscenario.model import InitAction, OpenScenario
from world.map.opendrive import Chain


@dataclass(frozen=True, slots=True)
class StoryProgram:
    """An OpenSCENARIO file's storyboard, ready for the director (`avsim.run.storyboard`)."""

    scenario: OpenScenario  # the parsed file (its storyboard and parameters)
    chain: Chain  # the OpenDRIVE roads (linked end to end) the positions refer to
    ego: str  # the entity that is the car under test
    actors: tuple[tuple[str, int], ...]  # (entity name, index in `WorldSpec.actors`)
    centre_ahead: tuple[tuple[str, float], ...]  # (entity name, [m] its body's centre ahead
    #   of its OpenSCENARIO reference point): the rear axle's distance behind the centre for
    #   the car under test the stack drives, the file's bounding box centre for the others
    #   (and for a scripted car under test)
    lane_ids: tuple[int, ...]  # the OpenDRIVE id of each route lane (index 0 first)
    init_commands: tuple[InitAction, ...]  # Init actions that take time (a speed change
    #   with dynamics, a continuous distance to keep): started at t = 0 by the director
    held_out: tuple[str, ...] = ()  # entities out of the world until a story adds them
    #   (no Init action places them: `AddEntityAction`)
    ego_box: tuple[float, float] | None = None  # [m] the length and width conditions give
    #   the car under test: the file's bounding box when it is scripted (as esmini measures
    #   it; its reference point is then the file's too), None: avsim's car body

    def actor_index(self, entity: str) -> int | None:
        """The world actor index of `entity` (None: the car under test)."""
        return dict(self.actors).get(entity)

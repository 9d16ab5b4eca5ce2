"""The motion actions that cannot apply to the car under test: avsim's stack drives it, so
a synchronization, a speed profile, a lateral distance or a teleport in a story on it is
refused at load (one line, at the action), never mid-run."""

from __future__ import annotations

from avsim.scenario.errors import ScenarioError
from avsim.scenario.openscenario.model import (
    LateralDistanceAction,
    OpenScenario,
    SpeedProfileAction,
    SynchronizeAction,
    TeleportAction,
)

NOT_ON_EGO = (SynchronizeAction, SpeedProfileAction, LateralDistanceAction)
PROBLEM = "not supported on the car under test ({}: avsim's stack drives it)"


def refuse_on_ego(osc: OpenScenario, ego: str) -> None:
    """`ScenarioError` for the first action of `NOT_ON_EGO` (in Init or a story) or
    teleport in a story whose actors include `ego`."""
    for item in osc.storyboard.init:
        if item.entity == ego and isinstance(item.action, NOT_ON_EGO):
            raise ScenarioError(str(osc.path), f"Storyboard.Init.{ego}",
                                PROBLEM.format(type(item.action).__name__))
    for group, action in osc.storyboard.story_actions():
        inner = action.private_action
        if ego in group.actors.entities and isinstance(inner, (*NOT_ON_EGO, TeleportAction)):
            raise ScenarioError(str(osc.path), f"Storyboard.Action[{action.name}]",
                                PROBLEM.format(type(inner).__name__))

"""Which actions may apply to the car under test, refused at load (one line, at the
action), never mid-run.

- Never on it (scripted or not): a synchronization, a speed profile, a lateral distance,
  or a teleport in a story.
- On the car avsim's stack drives, only its driver's inputs (`driver_input`,
  `avsim.run.storyboard.driver`) besides its controller's actions and global actions: a
  SpeedAction (the set speed; not a continuous relative one: a driver sets a speed, he does
  not track another car's), a LaneChangeAction (the turn-signal stalk; to the target lane's
  centre: no targetLaneOffset), an OverrideControllerValueAction (its pedals).
- An OverrideControllerValueAction only on the car under test (the other entities have no
  driver avsim simulates).
- Never an EntityAction (add, delete) on it: the run is about it. Its VisibilityAction and
  LightStateAction are recorded (its own sensors never see it).
"""

from __future__ import annotations

from avsim.scenario.errors import ScenarioError
from avsim.scenario.openscenario.entity_actions import (
    AddEntityAction,
    DeleteEntityAction,
    LightStateAction,
    VisibilityAction,
)
from avsim.scenario.openscenario.global_actions import GlobalAction
from avsim.scenario.openscenario.model import (
    ActivateControllerAction,
    AssignControllerAction,
    LaneChangeAction,
    LateralDistanceAction,
    OpenScenario,
    OverrideControllerValueAction,
    RelativeTargetSpeed,
    SpeedAction,
    SpeedProfileAction,
    SynchronizeAction,
    TeleportAction,
)

NOT_ON_EGO = (SynchronizeAction, SpeedProfileAction, LateralDistanceAction)
PROBLEM = "not supported on the car under test ({}: avsim's stack drives it)"
PLAYED = (ActivateControllerAction, AssignControllerAction, OverrideControllerValueAction,
          GlobalAction, VisibilityAction, LightStateAction)  # on the stack's car: its
#   controller's, its pedals, global actions, its looks (recorded)


def refuse_on_ego(osc: OpenScenario, ego: str, scripted: bool = False) -> None:
    """`ScenarioError` for the first action of `NOT_ON_EGO` (in Init or a story) or
    teleport in a story whose actors include `ego`, and for an
    OverrideControllerValueAction on another entity (or on a `scripted` car under test)."""
    for item in osc.storyboard.init:
        if item.entity == ego and isinstance(item.action, NOT_ON_EGO):
            raise ScenarioError(str(osc.path), f"Storyboard.Init.{ego}",
                                PROBLEM.format(type(item.action).__name__))
        if isinstance(item.action, OverrideControllerValueAction) \
                and (item.entity != ego or scripted):
            raise ScenarioError(str(osc.path), f"Storyboard.Init.{item.entity}",
                                _no_driver(item.entity, ego, scripted))
    for group, action in osc.storyboard.story_actions():
        inner = action.private_action
        if isinstance(inner, AddEntityAction | DeleteEntityAction) and inner.entity == ego:
            raise ScenarioError(str(osc.path), f"Storyboard.Action[{action.name}]",
                                f"{type(inner).__name__} on the car under test: not "
                                "supported (the run is about it: it is always in the world)")
        if ego in group.actors.entities and isinstance(inner, (*NOT_ON_EGO, TeleportAction)):
            raise ScenarioError(str(osc.path), f"Storyboard.Action[{action.name}]",
                                PROBLEM.format(type(inner).__name__))
        others = [e for e in group.actors.entities if e != ego or scripted]
        if isinstance(inner, OverrideControllerValueAction) and others:
            raise ScenarioError(str(osc.path), f"Storyboard.Action[{action.name}]",
                                _no_driver(others[0], ego, scripted))


def _no_driver(entity: str, ego: str, scripted: bool) -> str:
    if entity == ego and scripted:
        return ("OverrideControllerValueAction on a scripted car under test: not supported "
                "(its controllers are not simulated)")
    return (f"OverrideControllerValueAction on {entity}: not supported (only the car under "
            "test has a driver in avsim)")


def driver_input(action: object) -> str | None:
    """None if `action` on the car the stack drives is played (module doc), else why not."""
    if isinstance(action, PLAYED):
        return None
    if isinstance(action, SpeedAction):
        target = action.target
        if isinstance(target, RelativeTargetSpeed) and target.continuous:
            return ("SpeedAction on the car under test: a continuous relative target is not "
                    "supported (its driver sets a speed once; avsim's stack drives it)")
        return None
    if isinstance(action, LaneChangeAction):
        if action.target_lane_offset:
            return ("LaneChangeAction on the car under test: targetLaneOffset is not "
                    "supported (its driver asks for a lane; avsim's stack keeps its centre)")
        return None
    return (f"{type(action).__name__} on the car under test: not supported (avsim's stack "
            "drives it: only a SpeedAction, a LaneChangeAction and controller actions are "
            "its driver's inputs; `--ego scripted` plays the file's actions on it)")

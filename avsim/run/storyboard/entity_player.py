"""Playing the entity actions on the world: an entity added (AddEntityAction) or deleted
(DeleteEntityAction), seen or not (VisibilityAction), its lights (LightStateAction).

Each completes at once and is recorded as a storyboard state change (`state.StateChange`,
kind "entity", "visibility" or "light": the result's `storyboard_state` and the recording's
event lines).

- Added: the actor's body enters the world at the action's position (its motion teleported
  there), at the speed it had when it left (0 if it never was in the world); an entity
  already in the world stays where it is (as esmini, which skips the action).
- Deleted: its body leaves the world (`ActorSet.withdraw`): no contacts, unseen; its
  motion is held. Deleting an entity not in the world changes nothing.
- Visibility: `sensors` false hides the actor from the LiDAR and the cameras, `graphics`
  false from the cameras (avsim draws nothing but what its cameras see); `traffic` is
  recorded (avsim's actors follow their scripts and do not react to the others). The body
  stays in the physics and the truth: a hidden car hit is a contact.
- Lights: recorded (the actors' bodies are boxes without lamps; the car under test's lamps
  show its stack's hazard lights only).
"""

from __future__ import annotations

from avsim.run.storyboard.commands import Commands
from avsim.run.storyboard.snapshot import Snapshot
from avsim.run.storyboard.state import StateChange, StoryState
from avsim.scenario.openscenario.actions import TeleportAction
from avsim.scenario.openscenario.entity_actions import (
    AddEntityAction,
    DeleteEntityAction,
    LightStateAction,
    VisibilityAction,
)
from avsim.scenario.openscenario.program import StoryProgram
from world.world import World

ENTITY_ACTIONS = (AddEntityAction, DeleteEntityAction, VisibilityAction, LightStateAction)
LookAction = AddEntityAction | DeleteEntityAction | VisibilityAction | LightStateAction


def _flag(value: bool) -> str:
    return "true" if value else "false"


def light_text(action: LightStateAction) -> str:
    """A light's new state as one value: its mode, then what the file says of it."""
    state = action.state
    parts: list[str] = [state.mode]
    if state.mode == "flashing" and state.flashing_on is not None:
        parts.append(f"on {state.flashing_on:g} s")
    if state.mode == "flashing" and state.flashing_off is not None:
        parts.append(f"off {state.flashing_off:g} s")
    if state.intensity is not None:
        parts.append(f"{state.intensity:g} cd")
    if state.colour is not None:
        parts.append(state.colour)
    if action.transition_time:
        parts.append(f"over {action.transition_time:g} s")
    return ", ".join(parts)


class EntityPlayer:
    """The entity actions of one storyboard on one world (module doc)."""

    def __init__(self, program: StoryProgram, world: World, commands: Commands,
                 state: StoryState) -> None:
        self.world = world
        self.commands = commands
        self.state = state
        self._index = dict(program.actors)
        for name in program.held_out:  # out of the world until a story adds it
            world.actors.withdraw(self._index[name])

    def play(self, tag: str, entity: str, action: LookAction, snap: Snapshot) -> None:
        """Play `action` on `entity` now (its tag: the command's, for a teleport)."""
        i = self._index.get(entity)  # None: the car under test (recorded only)
        if isinstance(action, AddEntityAction) and i is not None:
            self._add(tag, entity, i, action, snap)
        elif isinstance(action, DeleteEntityAction) and i is not None:
            self._record(snap.time, "entity", entity, self._delete(i))
        elif isinstance(action, VisibilityAction):
            if i is not None:
                self.world.set_actor_visibility(i, cameras=action.graphics and action.sensors,
                                                lidar=action.sensors)
            self._record(snap.time, "visibility", entity,
                         f"graphics={_flag(action.graphics)} traffic={_flag(action.traffic)} "
                         f"sensors={_flag(action.sensors)}")
        elif isinstance(action, LightStateAction):
            self._record(snap.time, "light", f"{entity}.{action.light}", light_text(action))

    def _add(self, tag: str, entity: str, i: int, action: AddEntityAction,
             snap: Snapshot) -> None:
        actors = self.world.actors
        if not actors.gone[i]:
            self._record(snap.time, "entity", entity, "added (already in the world)")
            return
        motion = actors.motions[i]
        motion.command(self.commands.teleport(tag, TeleportAction(action.position),
                                              snap.entities[entity], snap))
        motion.finished.remove(tag)  # done at once: the runtime completes it
        actors.restore(i)
        self._record(snap.time, "entity", entity, "added")

    def _delete(self, i: int) -> str:
        actors = self.world.actors
        if actors.gone[i]:
            return "deleted (not in the world)"
        actors.withdraw(i)
        return "deleted"

    def _record(self, t: float, kind: str, name: str, value: str) -> None:
        self.state.changes.append(StateChange(t, kind, name, value))

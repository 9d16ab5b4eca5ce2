"""The driving stack the runner drives: a whole stack (`control.command.DrivingStack`), or
three stages composed into one (`ComposedStack`): perception -> planner -> control.

It is fed only sensor frames (by sensor name) and was built with the static HD map
(`avsim.stack.StackContext`); it returns a `StackStep` (the command, and its plan if it
shows one). The sensor loop hands it the frames at their rates, the runner applies its
command to the ego's joints.
"""

from __future__ import annotations

from typing import cast

from avsim.stack import bundled as bundled_stages
from avsim.stack.choice import BUNDLED, STAGES, StackChoice, StackChoiceError, resolve
from avsim.stack.context import StackContext, Timer, untimed
from control.command import ControllerStage, DrivingStack, StackStep
from perception.messages import PerceptionReport, PerceptionStage
from planner.messages import PlannerStage
from world.frames import Frames


class ComposedStack:
    """Perception, planner and controller, each called by its front door, in that order at
    every control tick; `timer` times the planner ("planner") and control ("control"), and
    perception ("perception") unless it times its own parts (`perception_timed`)."""

    def __init__(self, perception: PerceptionStage, planner: PlannerStage,
                 controller: ControllerStage, timer: Timer | None = None,
                 perception_timed: bool = False) -> None:
        self.perception = perception
        self.planner = planner
        self.controller = controller
        self._timer = timer if timer is not None else untimed
        self._perceive_timer = untimed if perception_timed else self._timer

    @property
    def reads(self) -> frozenset[str] | None:
        return self.perception.reads

    def on_frames(self, t: float, frames: Frames) -> PerceptionReport | None:
        with self._perceive_timer("perception"):
            return self.perception.on_frames(t, frames)

    def tick(self, t: float, dt: float) -> StackStep:
        with self._perceive_timer("perception"):
            inp = self.perception.perceive(t)
        with self._timer("planner"):
            plan = self.planner.update(inp)
        with self._timer("control"):
            command = self.controller.update(plan, dt)
        return StackStep(command, plan)


_NEEDS = {"stack": ("on_frames", "tick"), "perception": ("on_frames", "perceive"),
          "planner": ("update",), "controller": ("update",)}  # what each kind must have


def _made(key: str, spec: str, made: object) -> object:
    """`made` by the factory `spec`, checked to have what a `key` needs (else a
    `StackChoiceError`)."""
    missing = [m for m in _NEEDS[key] if not callable(getattr(made, m, None))]
    if missing:
        raise StackChoiceError(key, f"{spec} made a {type(made).__name__}, which has no "
                               f"{', '.join(missing)} (a {key} needs "
                               f"{', '.join(_NEEDS[key])})")
    return made


def build_stack(choice: StackChoice, ctx: StackContext) -> DrivingStack:
    """The stack `choice` names, built for `ctx` (module doc): a user's whole stack, or the
    three stages, each the user's or the bundled one (`avsim.stack.bundled`)."""
    if choice.whole:
        spec = str(choice.stack)
        return cast(DrivingStack, _made("stack", spec, resolve("stack", spec)(ctx)))
    bundled = {"perception": bundled_stages.perception, "planner": bundled_stages.planner,
               "controller": bundled_stages.controller}
    stages: dict[str, object] = {}
    for key in STAGES:
        spec = getattr(choice, key)
        if spec in (None, BUNDLED):
            stages[key] = bundled[key](ctx)
        else:
            stages[key] = _made(key, spec, resolve(key, spec)(ctx))
    return ComposedStack(cast(PerceptionStage, stages["perception"]),
                         cast(PlannerStage, stages["planner"]),
                         cast(ControllerStage, stages["controller"]), ctx.timer,
                         perception_timed=choice.perception in (None, BUNDLED))


def close_stack(stack: object) -> None:
    """Call the stack's optional `close()` (what it holds open outside avsim: a child
    process, a socket) at the run's end; a stack without one has nothing to close."""
    close = getattr(stack, "close", None)
    if callable(close):
        close()

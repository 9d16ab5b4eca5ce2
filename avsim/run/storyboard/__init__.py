"""OpenSCENARIO's storyboard at run time: conditions judged on the truth, the storyboard
elements' states, and the director that starts the actions on the world's actors.

`snapshot` (what conditions read), `rules` and `geometry` (comparisons and distances),
`conditions` (one condition at one step), `triggers` (edges, delays, OR of ANDs),
`elements` (the element state machine, a table), `tree` (the elements of one run) and
`runtime` (`StoryRuntime`: the actions to start and stop at each step).

Where this differs from esmini (the reference):
- every condition of a trigger is evaluated at each update (esmini skips the delay-free
  conditions of a group after a false one, so their edges miss those steps), and a
  condition's edge history is kept after its trigger fired (esmini sets it back to idle
  then); it is cleared when its element is re-armed (maximumExecutionCount);
- a storyboard element state condition on a state reads the element's state now (esmini
  also matches a state passed through since the condition's previous evaluation);
  transitions are matched since the condition's previous evaluation, as esmini;
- an event overwritten by another is stopped (stopTransition, complete for good, as the
  1.2 spec says); a skipped event counts no execution and is skipped (skipTransition
  recorded) at each evaluation its trigger fires while another event of its maneuver runs;
- distances along the route for every coordinate system (entity, lane, road, trajectory);
  freespace along / across the route subtracts half the box's length / width, not its
  yaw's projection; equalTo / notEqualTo on floats within 1e-6;
- EndOfRoad / Offroad of duration 0 hold from the second step beyond the road (the
  snapshot's timers are 0 at the first);
- the world reports actions done (`StoryRuntime.action_done`); only controller
  assignment / activation and teleport are completed by the runtime itself, at once.
"""

from __future__ import annotations

from avsim.run.storyboard.conditions import ConditionContext, holds, judge
from avsim.run.storyboard.elements import ElementState, TransitionKind, TransitionRecord
from avsim.run.storyboard.runtime import StartedAction, StepResult, StoryRuntime
from avsim.run.storyboard.snapshot import EntityState, Snapshot
from avsim.run.storyboard.triggers import ConditionWatch, TriggerWatch

__all__ = [
    "ConditionContext",
    "ConditionWatch",
    "ElementState",
    "EntityState",
    "Snapshot",
    "StartedAction",
    "StepResult",
    "StoryRuntime",
    "TransitionKind",
    "TransitionRecord",
    "TriggerWatch",
    "holds",
    "judge",
]

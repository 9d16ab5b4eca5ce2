"""A condition's and a trigger's state across steps.

`ConditionWatch`: the condition's value now (`conditions.judge`), then its edge against the
value at the previous evaluation: "none" passes the value on (level), "rising" is true when
it was false then and is true now, "falling" the reverse, "risingOrFalling" on either
change. The first evaluation has no previous value: an edge condition is false there (as
esmini's `OSCCondition::CheckEdge`), so a condition already true at the first evaluation
does not rise. The edge's result is kept with its time; with `delay` the watch answers the
result of the latest evaluation at or before now - delay (false before the first one), as
esmini's condition history does. The history is kept back to `delay` only.

`TriggerWatch`: OR over the condition groups of AND of their conditions. Every condition is
evaluated at every update (so edges and delayed histories see every step; esmini skips
the delay-free conditions after a false one in a group). An empty trigger never fires; a
watch made for no trigger (None) fires at its first update ("starts at once").
"""

from __future__ import annotations

import dataclasses
from collections import deque
from collections.abc import Callable

from avsim.run.storyboard.conditions import ConditionContext, judge
from avsim.run.storyboard.snapshot import Snapshot
from avsim.scenario.openscenario.conditions import Condition, Edge, Trigger

TIME_EPS = 1e-9  # [s] slack when looking a delayed value up by time

_EDGES: dict[str, Callable[[bool, bool | None], bool]] = {
    "none": lambda now, before: now,
    "rising": lambda now, before: now and before is False,
    "falling": lambda now, before: (not now) and before is True,
    "risingOrFalling": lambda now, before: before is not None and now != before,
}


def edge_value(edge: Edge, now: bool, before: bool | None) -> bool:
    """The edge-processed value: `now` against the previous value `before` (None: there is
    none, the first evaluation)."""
    return bool(_EDGES[edge](now, before))


class ConditionWatch:
    """One condition's state across the steps it is evaluated at."""

    def __init__(self, condition: Condition) -> None:
        self.condition = condition
        self.previous: bool | None = None  # the raw value at the previous evaluation
        self.history: deque[tuple[float, bool]] = deque()  # (t, edge-processed value)
        self.mark = 0  # the context log's length at the previous evaluation
        self.triggering: tuple[str, ...] = ()  # the entities it held for, latest evaluation
        self.value = False  # the value passed on at the latest evaluation

    def reset(self) -> None:
        """Forget every previous evaluation (an element re-armed)."""
        self.previous = None
        self.history.clear()
        self.triggering = ()
        self.value = False

    def update(self, snap: Snapshot, ctx: ConditionContext) -> bool:
        """Evaluate at `snap.time`; the (edge-processed, delayed) value passed on now."""
        now, self.triggering = judge(self.condition, snap,
                                     dataclasses.replace(ctx, since=self.mark))
        self.mark = len(ctx.log)
        value = edge_value(self.condition.edge, now, self.previous)
        self.previous = now
        self.history.append((snap.time, value))
        self.value = self._at(snap.time - self.condition.delay)
        return self.value

    def _at(self, t: float) -> bool:
        """The value of the latest evaluation at or before `t`; drops the older ones."""
        while len(self.history) > 1 and self.history[1][0] <= t + TIME_EPS:
            self.history.popleft()
        first_t, first_value = self.history[0]
        return first_value if first_t <= t + TIME_EPS else False


class TriggerWatch:
    """A trigger's state across steps (module doc)."""

    def __init__(self, trigger: Trigger | None) -> None:
        self.trigger = trigger
        self.groups = () if trigger is None else tuple(
            tuple(ConditionWatch(c) for c in group.conditions) for group in trigger.groups)

    def reset(self) -> None:
        for group in self.groups:
            for watch in group:
                watch.reset()

    def update(self, snap: Snapshot, ctx: ConditionContext) -> bool:
        """Evaluate every condition at `snap.time`; whether the trigger fires now."""
        if self.trigger is None:
            return True
        fired = False
        for group in self.groups:
            values = [watch.update(snap, ctx) for watch in group]
            fired = fired or (bool(values) and all(values))
        return fired

    def triggering_entities(self) -> tuple[str, ...]:
        """The entities the conditions of the groups that fired at the latest update held for
        at the latest evaluation (with a delay: of the latest one, not the delayed one)."""
        names: dict[str, None] = {}
        for group in self.groups:
            if group and all(w.value for w in group):
                names.update(dict.fromkeys(n for w in group for n in w.triggering))
        return tuple(names)

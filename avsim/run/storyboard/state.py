"""The storyboard's run-time state besides its elements: the global parameters (changed by
ParameterActions), the variables (VariableActions) and the environment in effect
(EnvironmentActions), with every change recorded.

Conditions read this state live: a change made by an action is seen by every condition
evaluated after it, in the same trigger check for the elements the storyboard evaluates
later, else at the next. Attribute values written as `$name` were resolved when the file
was read and do not follow a parameter changed at run time (as esmini).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from avsim.scenario.openscenario.environment import Environment, EnvironmentAction, time_of_day_at
from avsim.scenario.openscenario.parameters import ParamValue
from avsim.scenario.openscenario.variables import VariableAction, VariableDeclaration, apply_change


@dataclass(frozen=True, slots=True)
class StateChange:
    """One change of the state: a variable or parameter set to `value`, or the environment
    (`kind` "environment", `name` the Environment's name, `value` None: see `environment`)."""

    t: float  # [s] simulation time
    kind: str  # "variable" | "parameter" | "environment"
    name: str
    value: ParamValue | None
    environment: Environment | None = None


class StoryState:
    """Parameters, variables and environment of one run (module doc)."""

    def __init__(self, parameters: Mapping[str, ParamValue] | None = None,
                 variables: tuple[VariableDeclaration, ...] = ()) -> None:
        self.parameters: dict[str, ParamValue] = dict(parameters or {})
        self.variables: dict[str, ParamValue] = {v.name: v.value for v in variables}
        self.environment: Environment | None = None
        self.environment_set_at = 0.0  # [s] when the environment in effect was set
        self.changes: list[StateChange] = []

    def apply(self, action: EnvironmentAction | VariableAction, t: float) -> None:
        """Play a global action at simulation time `t` [s]."""
        if isinstance(action, EnvironmentAction):
            self.environment, self.environment_set_at = action.environment, t
            self.changes.append(StateChange(t, "environment", action.environment.name, None,
                                            action.environment))
            return
        self._set(action, t)

    def _set(self, action: VariableAction, t: float) -> None:
        values = self.variables if action.target == "variable" else self.parameters
        values[action.name] = apply_change(values[action.name], action)
        self.changes.append(StateChange(t, action.target, action.name, values[action.name]))

    def time_of_day(self, t: float) -> float | None:
        """[s] since 1970-01-01T00:00:00 UTC: the environment's time of day at simulation
        time `t` [s] (advanced since it was set when animated); None when none is set."""
        env = self.environment
        if env is None or env.time_of_day is None:
            return None
        return time_of_day_at(env.time_of_day, self.environment_set_at, t)

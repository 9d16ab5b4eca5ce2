"""The GlobalAction choices avsim plays: EnvironmentAction, EntityAction, VariableAction
and the deprecated ParameterAction (others are refused when the file is read)."""

from __future__ import annotations

from avsim.scenario.openscenario.entity_actions import EntityAction
from avsim.scenario.openscenario.environment import EnvironmentAction
from avsim.scenario.openscenario.variables import VariableAction

GlobalAction = EnvironmentAction | VariableAction | EntityAction

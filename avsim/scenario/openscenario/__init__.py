"""ASAM OpenSCENARIO 1.0-1.3 (XML, .xosc) reading: `load_openscenario(path, overrides)`
parses a file, resolves its parameters (`$name`, `${...}`, constraint groups) and catalogs,
and gives the typed model in `model` (`OpenScenario`); `declared_parameters(path)` lists the
global parameters for sweeps. Every problem is one `ScenarioError` line."""

from __future__ import annotations

from avsim.scenario.openscenario.model import OpenScenario
from avsim.scenario.openscenario.parameters import ParameterInfo
from avsim.scenario.openscenario.parse import declared_parameters, load_openscenario

__all__ = ["OpenScenario", "ParameterInfo", "declared_parameters", "load_openscenario"]

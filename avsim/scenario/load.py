"""Load a scenario file: find it, read its YAML, apply overrides, validate it strictly, refuse
what is not simulated yet, check what spans several keys and convert it.

`load_scenario(path_or_name)` returns a `Scenario` (`avsim.scenario.scenario`: SI units,
radians, every default resolved) or raises `ScenarioError`, whose message is one line
`<file>: <key.path>: <problem>`, e.g.

    scenarios/x.yaml: actors.0.lane: lane 3 does not exist at s = 55 m (the road has 2 lanes there)

The steps, one module each: find the file (a path, or the name of a bundled scenario in
`<repo>/scenarios/`) and parse the YAML, duplicate keys being errors (`files`); apply
`overrides` (dotted paths with list indices, as `avsim sweep --set PATH=V` gives them;
`overrides`); validate against the pydantic models of `avsim.scenario.model`, their errors
translated into the one-line form (`validation`); refuse what the simulator does not
simulate yet (`UNSUPPORTED`, here); check what spans several keys (lanes at a station,
stations on the route, `after` indices, arc radii, actor ids; `checks`) and convert
(`convert`).
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping, Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

from avsim.scenario.convert import convert
from avsim.scenario.errors import FILE_KEY, KeyPath, LocatedError, ScenarioError, dotted
from avsim.scenario.files import (
    bundled_scenarios,
    looks_like_path,
    read_raw,
    scenario_path,
    shown_name,
)
from avsim.scenario.overrides import apply_overrides
from avsim.scenario.scenario import Scenario
from avsim.scenario.validation import validate
from avsim.stack.choice import BUNDLED, STAGES, StackChoiceError, resolve

__all__ = ["UNSUPPORTED", "ScenarioError", "bundled_scenarios", "load_scenario", "scenario_path"]

# What the format allows but the simulator does not simulate yet. A key is a dotted path
# into the file: `*` matches every list index, `key=value` a mapping whose `key` is `value`
# (the reported key path ends at `key`). Loading a file that uses one of these raises
# `<file>: <key.path>: not supported yet (<what>)`. Delete a line once it is simulated.
UNSUPPORTED: dict[str, str] = {
    "road.segments.*.exit=left": "exits on the left",
}


def load_scenario(
    path_or_name: str | Path, overrides: Mapping[str, object] | None = None,
    criteria_file: Path | None = None, search_paths: Sequence[Path] = (),
    scripted_ego: bool = False,
) -> Scenario:
    """Load, validate and convert a scenario file.

    `path_or_name` is a file path or the name of a bundled scenario (`scenarios/<name>.yaml`
    in the repository). `overrides` maps dotted key paths with list indices
    (`actors.0.speed_kph`) to values set into the file's data before validation; values are
    used as given (parse command-line text with `avsim.scenario.files.parse_value` first).

    An OpenSCENARIO file (`.xosc`) loads with its sidecar (`criteria_file`, else
    `NAME.criteria.yaml` beside it): `avsim.scenario.openscenario.convert.load_xosc`. Its
    references (road, catalogs, sidecar) must resolve inside its own folder tree or one of
    `search_paths` (`avsim run --search-path DIR`); a YAML file references none.

    `scripted_ego` (`avsim run --ego scripted`): the OpenSCENARIO file's own actions move
    the car under test, as esmini's default controller does (`EgoSpec.scripted`); a YAML
    scenario has no story for its ego and is refused.

    Raises `ScenarioError` with a one-line message `<file>: <key.path>: <problem>`.
    """
    path = scenario_path(path_or_name)
    if path.suffix == ".xosc":
        from avsim.scenario.openscenario.convert import load_xosc

        return _with_stack(load_xosc(path, overrides, criteria_file, search_paths,
                                     scripted_ego), str(path_or_name))
    if scripted_ego:
        raise ScenarioError(str(path_or_name), "ego", "--ego scripted is for OpenSCENARIO "
                            "files (a YAML scenario scripts no actions for its ego)")
    if criteria_file is not None:
        raise ScenarioError(str(path_or_name), FILE_KEY, "--criteria is for OpenSCENARIO "
                            "files (a YAML scenario has its own criteria: section)")
    shown = shown_name(path_or_name, path)
    if not looks_like_path(path_or_name) and not path.exists():
        raise ScenarioError(
            str(path_or_name), FILE_KEY, "no such file or bundled scenario (see `avsim list`)"
        )
    try:
        raw = apply_overrides(read_raw(path), overrides or {})
        model = validate(raw, overrides or {})
        _check_supported(raw)
        scenario = replace(convert(model), sources=(path,))
    except LocatedError as problem:
        raise ScenarioError(shown, problem.key, problem.problem) from None
    return _with_stack(scenario, shown)


def _with_stack(scenario: Scenario, shown: str) -> Scenario:
    """`scenario`, once every factory its stack choice names is found (imported: a stack
    that cannot be is bad input, refused before anything runs)."""
    choice = scenario.stack
    for key in ("stack", *STAGES):
        spec = getattr(choice, key)
        if spec not in (None, BUNDLED):
            try:
                resolve(key, spec)
            except StackChoiceError as exc:
                raise ScenarioError(shown, f"stack.{key}", exc.problem) from None
    return scenario


def _check_supported(raw: dict[str, Any]) -> None:
    """Raise `<key>: not supported yet (<what>)` for the first `UNSUPPORTED` entry used."""
    for pattern, what in UNSUPPORTED.items():
        for found in _matches(raw, pattern.split("."), ()):
            raise LocatedError(dotted(found), f"not supported yet ({what})")


def _matches(node: object, parts: list[str], prefix: KeyPath) -> Iterator[KeyPath]:
    """Key paths in `node` matching an `UNSUPPORTED` pattern (null values do not count)."""
    if not parts:
        yield prefix
        return
    head, rest = parts[0], parts[1:]
    if head == "*":
        items = node if isinstance(node, list) else []
        for index, item in enumerate(items):
            yield from _matches(item, rest, (*prefix, index))
        return
    key, _, value = head.partition("=")
    if not isinstance(node, dict) or node.get(key) is None:
        return
    if not value or node[key] == value:
        yield from _matches(node[key], rest, (*prefix, key))


"""Load a scenario file: read the YAML, validate it strictly, convert it into the world's spec.

`load_scenario(path_or_name)` returns a `world.spec.ScenarioSpec` (SI units, radians, every
default resolved) or raises `ScenarioError`, whose message is one line
`<file>: <key.path>: <problem>`, e.g.

    scenarios/x.yaml: actors.0.lane: lane 3 does not exist at s = 55 m (the road has 2 lanes there)

The steps: find the file (a path, or the name of a bundled scenario in `<repo>/scenarios/`),
parse the YAML (duplicate keys are errors), apply `overrides` (dotted paths with list
indices, as `avsim sweep --set PATH=V` gives them), validate against the pydantic models of
`avsim.scenario.model` (their errors are translated into the one-line form), refuse what the
simulator does not simulate yet (`UNSUPPORTED`), check what spans several keys (lanes at a
station, stations on the route, `after` indices, arc radii, actor ids) and convert.
"""

from __future__ import annotations

import copy
import difflib
import math
import os
import re
from collections.abc import Hashable, Iterator, Mapping, Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any, TypeVar, get_args

import yaml
from pydantic import BaseModel, ValidationError
from pydantic_core import ErrorDetails

from avsim.scenario.model import (
    ActionModel,
    ActorModel,
    CrosswalkFeature,
    EventModel,
    FeatureModel,
    RoadModel,
    ScenarioModel,
    SegmentModel,
    SpeedBumpFeature,
    SpeedLimitFeature,
    StopSignFeature,
    TrafficLightFeature,
    TriggerModel,
)
from world import frames, hdmap, spec
from world.map.town import TownError, TownLayout, compile_route

REPO_ROOT = Path(__file__).resolve().parents[2]
SCENARIO_DIR = REPO_ROOT / "scenarios"

MPS_PER_KPH = 1000.0 / 3600.0  # [m/s] per [km/h]
DEFAULT_SPEED_UP = 2.0  # [m/s^2] a speed action's accel when it speeds up
DEFAULT_SLOW_DOWN = -3.0  # [m/s^2] a speed action's accel when it slows down
FILE_KEY = "(file)"

# What the format allows but the simulator does not simulate yet. A key is a dotted path
# into the file: `*` matches every list index, `key=value` a mapping whose `key` is `value`
# (the reported key path ends at `key`). Loading a file that uses one of these raises
# `<file>: <key.path>: not supported yet (<what>)`. Delete a line once it is simulated.
UNSUPPORTED: dict[str, str] = {
    "road.segments.*.exit=left": "exits on the left",
}

KeyPath = tuple[str | int, ...]
_T = TypeVar("_T")


class ScenarioError(Exception):
    """A scenario file cannot be loaded. `str()` is one line: `<file>: <key.path>: <problem>`.

    `key` is a dotted path into the file (`actors.0.lane`), `line N` for YAML syntax errors,
    or `(file)` for the file as a whole.
    """

    def __init__(self, file: str, key: str, problem: str) -> None:
        super().__init__(file, key, problem)
        self.file = file
        self.key = key
        self.problem = problem

    def __str__(self) -> str:
        return f"{self.file}: {self.key}: {self.problem}"


class _LocatedError(Exception):
    """Internal: a problem at a key, before the file name is attached."""

    def __init__(self, key: str, problem: str) -> None:
        super().__init__(key, problem)
        self.key = key
        self.problem = problem


# ---------------------------------------------------------------------------------------
# Finding and reading files
# ---------------------------------------------------------------------------------------


def bundled_scenarios() -> list[Path]:
    """The bundled scenario files, `<repo>/scenarios/*.yaml`, sorted by name."""
    return sorted(SCENARIO_DIR.glob("*.yaml"))


def scenario_path(path_or_name: str | Path) -> Path:
    """The file a scenario argument names: a path (anything with a `/`, a `.yaml` / `.yml`
    suffix, or an existing file), else the bundled `<repo>/scenarios/<name>.yaml`."""
    candidate = Path(path_or_name)
    if _looks_like_path(path_or_name) or candidate.exists():
        return candidate
    return SCENARIO_DIR / f"{candidate.name}.yaml"


def _looks_like_path(path_or_name: str | Path) -> bool:
    text = str(path_or_name)
    is_file_name = Path(text).suffix in {".yaml", ".yml"}
    return isinstance(path_or_name, Path) or is_file_name or "/" in text or os.sep in text


def _shown_name(path_or_name: str | Path, path: Path) -> str:
    """How the file is named in messages: as the user wrote it, or for a bundled name its
    path relative to the working directory when it lies below it."""
    if _looks_like_path(path_or_name) or not path.is_relative_to(SCENARIO_DIR):
        return str(path_or_name)
    try:
        return str(path.relative_to(Path.cwd()))
    except ValueError:
        return str(path)


_MERGE_TAG = "tag:yaml.org,2002:merge"


class _StrictLoader(yaml.SafeLoader):
    """A safe YAML loader that refuses duplicate keys instead of keeping the last one."""

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict[Hashable, Any]:
        seen: dict[Hashable, yaml.Node] = {}
        for key_node, _ in node.value:
            if key_node.tag == _MERGE_TAG:  # `<<: *anchor`; its keys may be overridden
                continue
            key = self.construct_object(key_node, deep=deep)
            if isinstance(key, Hashable) and key in seen:
                first = seen[key].start_mark.line + 1
                line = key_node.start_mark.line + 1
                raise _LocatedError(
                    f"line {line}", f"duplicate key {key!r} (first at line {first})"
                )
            if isinstance(key, Hashable):
                seen[key] = key_node
        return super().construct_mapping(node, deep=deep)


def _read_raw(path: Path) -> dict[str, Any]:
    """The file's YAML as a mapping, or a `_LocatedError` keyed `(file)` or `line N`."""
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise _LocatedError(FILE_KEY, "no such file") from None
    except IsADirectoryError:
        raise _LocatedError(FILE_KEY, "is a directory, not a file") from None
    except UnicodeDecodeError:
        raise _LocatedError(FILE_KEY, "not UTF-8 text") from None
    except OSError as exc:
        raise _LocatedError(FILE_KEY, f"cannot read it ({exc.strerror})") from None
    try:
        data = yaml.load(text, Loader=_StrictLoader)
    except yaml.MarkedYAMLError as exc:
        raise _yaml_problem(exc) from None
    except yaml.YAMLError as exc:
        raise _LocatedError(FILE_KEY, f"YAML error: {exc}") from None
    if data is None:
        raise _LocatedError(FILE_KEY, "empty file")
    if not isinstance(data, dict):
        raise _LocatedError(
            FILE_KEY, f"must be a mapping of keys (format, name, ...), got {_show(data)}"
        )
    return data


def _yaml_problem(exc: yaml.MarkedYAMLError) -> _LocatedError:
    """`line N: YAML syntax error: <what> (<context> at line M)` from PyYAML's error."""
    mark = exc.problem_mark or exc.context_mark
    key = f"line {mark.line + 1}" if mark is not None else FILE_KEY
    what = exc.problem or exc.context or "malformed YAML"
    if exc.problem and exc.context and exc.context_mark is not None:
        what += f" ({exc.context} at line {exc.context_mark.line + 1})"
    return _LocatedError(key, f"YAML syntax error: {what}")


# ---------------------------------------------------------------------------------------
# Overrides
# ---------------------------------------------------------------------------------------


def _apply_overrides(raw: dict[str, Any], overrides: Mapping[str, object]) -> dict[str, Any]:
    """A copy of `raw` with each dotted `path` set to its value (before validation).

    Every mapping and list on the way must exist and list indices be in range; the last key
    may be new (validation then rejects it if the format has no such key)."""
    data = copy.deepcopy(raw)
    for path, value in overrides.items():
        _set_path(data, path, copy.deepcopy(value))
    return data


def _set_path(data: dict[str, Any], path: str, value: object) -> None:
    parts = path.split(".")
    if not all(parts):
        raise _LocatedError(path or "(override)", "override path is empty or has an empty part")
    node: object = data
    for depth, part in enumerate(parts[:-1]):
        node = _child(node, part, ".".join(parts[: depth + 1]), path)
    last = parts[-1]
    if isinstance(node, list):
        node[_index(node, last, path)] = value
    elif isinstance(node, dict):
        node[last] = value
    else:
        raise _LocatedError(
            path, f"cannot set: {'.'.join(parts[:-1])} is {_show(node)}, not a mapping or list"
        )


def _child(node: object, part: str, where: str, path: str) -> object:
    """The item `part` of the mapping or list `node` on the way along an override path."""
    if isinstance(node, list):
        return node[_index(node, part, path)]
    if isinstance(node, dict):
        if part not in node:
            raise _LocatedError(path, f"cannot set: the file has no key {where}")
        return node[part]
    raise _LocatedError(
        path, f"cannot set: {where.rpartition('.')[0]} is {_show(node)}, not a mapping or list"
    )


def _index(node: list[Any], part: str, path: str) -> int:
    if not part.isdigit() or int(part) >= len(node):
        raise _LocatedError(path, f"cannot set: {part!r} is not an index of a list of {len(node)}")
    return int(part)


# ---------------------------------------------------------------------------------------
# Validation errors in one line
# ---------------------------------------------------------------------------------------

_EXPECTED = {
    "float_type": "a number",
    "float_parsing": "a number",
    "int_type": "an integer",
    "int_from_float": "an integer",
    "int_parsing": "an integer",
    "string_type": "a string",
    "bool_type": "true or false",
    "model_type": "a mapping (key: value)",
    "model_attributes_type": "a mapping (key: value)",
    "dict_type": "a mapping (key: value)",
    "list_type": "a list",
    "tuple_type": "a list",
    "finite_number": "a finite number",
}
_BOUNDS = {
    "greater_than": ">",
    "greater_than_equal": ">=",
    "less_than": "<",
    "less_than_equal": "<=",
}
_BOUND_KEYS = {
    "greater_than": "gt",
    "greater_than_equal": "ge",
    "less_than": "lt",
    "less_than_equal": "le",
}


def _validate(raw: dict[str, Any], overrides: Mapping[str, object]) -> ScenarioModel:
    """The validated model, or a `_LocatedError` from the first validation error."""
    try:
        return ScenarioModel.model_validate(raw)
    except ValidationError as exc:
        error = _first_error(exc.errors(include_url=False))
        key, message = _translate(error, raw)
        if any(key == path or key.startswith(path + ".") for path in overrides):
            message += " (set by an override)"
        raise _LocatedError(key, message) from None


def _first_error(errors: list[ErrorDetails]) -> ErrorDetails:
    """The error to report: the first one, except that an unknown key beside a missing one
    (likely its misspelling) is reported instead of the missing key."""
    first = errors[0]
    if first["type"] == "missing":
        for error in errors:
            if error["type"] == "extra_forbidden" and error["loc"][:-1] == first["loc"][:-1]:
                return error
    return first


def _translate(error: ErrorDetails, raw: dict[str, Any]) -> tuple[str, str]:
    """A pydantic error as (dotted key path, friendly message)."""
    loc = _file_path(error["loc"], raw)
    context = error.get("ctx") or {}
    kind = error["type"]
    if kind == "avsim":
        if "key" in context:
            loc = (*loc, context["key"])
        return _dotted(loc), str(context["problem"])
    if kind in {"union_tag_invalid", "union_tag_not_found"}:
        noun = str(loc[-2]).removesuffix("s") + " " if len(loc) >= 2 else ""
        tags = ", ".join(re.findall(r"'([^']*)'", str(context.get("expected_tags", ""))))
        if kind == "union_tag_not_found":
            return _dotted((*loc, "type")), f"required key missing (the {noun}type)"
        got = context.get("tag")
        return _dotted((*loc, "type")), f"unknown {noun}type {got!r} (expected one of {tags})"
    return _dotted(loc), _message(error, loc)


def _message(error: ErrorDetails, loc: KeyPath) -> str:
    kind = error["type"]
    context = error.get("ctx") or {}
    got = _show(error.get("input"))
    if kind == "missing":
        too_few = bool(loc) and isinstance(loc[-1], int)
        return "item missing (too few items)" if too_few else "required key missing"
    if kind == "extra_forbidden":
        known = sorted(_keys_at(loc[:-1]))
        close = difflib.get_close_matches(str(loc[-1]), known, n=1, cutoff=0.75)
        return f"unknown key (did you mean {close[0]}?)" if close else "unknown key"
    if kind in _EXPECTED:
        return f"must be {_EXPECTED[kind]}, got {got}"
    if kind in _BOUNDS:
        return f"must be {_BOUNDS[kind]} {_fmt(context[_BOUND_KEYS[kind]])}, got {got}"
    if kind == "literal_error":
        choices = re.findall(r"'([^']*)'", str(context.get("expected", "")))
        expected = choices[0] if len(choices) == 1 else "one of " + ", ".join(choices)
        return f"must be {expected}, got {got}"
    if kind == "string_pattern_mismatch":
        pattern = str(context.get("pattern", "")).strip("^$")
        return f"must match {pattern} (lower-case letters, digits, _), got {got}"
    if kind in {"too_short", "too_long"}:
        bound = "at least" if kind == "too_short" else "at most"
        count = context.get("min_length" if kind == "too_short" else "max_length")
        return f"must have {bound} {count} item(s), got {context.get('actual_length')}"
    text = str(error["msg"])
    return text[:1].lower() + text[1:]


def _keys_at(parent: KeyPath) -> set[str]:
    """The keys the format allows in the mapping at `parent` (for "did you mean" hints);
    for a feature, those of every feature type."""
    models: list[type[BaseModel]] = [ScenarioModel]
    for part in parent:
        if isinstance(part, int):  # a list item: `_models_in` already unwrapped the list
            continue
        fields = [m.model_fields[part] for m in models if part in m.model_fields]
        models = [m for field in fields for m in _models_in(field.annotation)]
    return {name for model in models for name in model.model_fields}


def _models_in(annotation: object) -> list[type[BaseModel]]:
    """The pydantic models inside a field's type (`X | None`, `list[X]`, unions)."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    return [model for arg in get_args(annotation) for model in _models_in(arg)]


def _file_path(loc: Sequence[str | int], raw: object) -> KeyPath:
    """The error location as a path of the file's keys: pydantic adds union member names
    (a feature's `type`, ...) that are not keys of the file; they are dropped."""
    kept: list[str | int] = []
    node = raw
    for depth, part in enumerate(loc):
        child = _item(node, part)
        if child is not _ABSENT:
            node = child
        elif not (depth == len(loc) - 1 and isinstance(node, dict | list)):
            continue
        kept.append(part)
    return tuple(kept)


_ABSENT = object()


def _item(node: object, part: str | int) -> object:
    """`node[part]` for a mapping key or list index present in the file, else `_ABSENT`."""
    if isinstance(node, dict) and part in node:
        return node[part]
    if isinstance(node, list) and isinstance(part, int) and 0 <= part < len(node):
        return node[part]
    return _ABSENT


def _dotted(loc: KeyPath) -> str:
    return ".".join(str(part) for part in loc) or FILE_KEY


def _show(value: object) -> str:
    """A short rendering of a value from the file, for messages."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if value is None:
        return "null (nothing)"
    if isinstance(value, dict):
        return "a mapping"
    if isinstance(value, list | tuple):
        return "a list"
    if isinstance(value, int | float):
        return _fmt(value)
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def _fmt(value: object) -> str:
    """A number without a trailing `.0`."""
    if isinstance(value, float) and math.isfinite(value) and value.is_integer():
        return str(int(value))
    if isinstance(value, float):
        return f"{value:.6g}"
    return str(value)


# ---------------------------------------------------------------------------------------
# Not supported yet
# ---------------------------------------------------------------------------------------


def _check_supported(raw: dict[str, Any]) -> None:
    """Raise `<key>: not supported yet (<what>)` for the first `UNSUPPORTED` entry used."""
    for pattern, what in UNSUPPORTED.items():
        for found in _matches(raw, pattern.split("."), ()):
            raise _LocatedError(_dotted(found), f"not supported yet ({what})")


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


# ---------------------------------------------------------------------------------------
# Checks across keys
# ---------------------------------------------------------------------------------------


def _route_length(segments: Sequence[spec.SegmentSpec]) -> float:
    return sum(segment.length for segment in segments)


def _segment_at(segments: Sequence[spec.SegmentSpec], s: float) -> spec.SegmentSpec:
    """The segment at station s (a joint belongs to the later segment; the end to the last)."""
    start = 0.0
    for segment in segments:
        if s < start + segment.length:
            return segment
        start += segment.length
    return segments[-1]


def _check_station(key: str, s: float, length: float) -> None:
    if s > length:
        raise _LocatedError(
            key, f"station {_fmt(s)} m is beyond the end of the route ({_fmt(length)} m)"
        )


def _check_lane(
    key: str, lane: int, s: float, segments: Sequence[spec.SegmentSpec], oncoming: bool
) -> None:
    """Lane `lane` exists at station s (oncoming lanes -1, -2, ... only if `oncoming`)."""
    segment = _segment_at(segments, s)
    lowest = -segment.oncoming_lanes if oncoming else 0
    if lowest <= lane < segment.lanes:
        return
    there = f"the road has {segment.lanes} lane{'s' if segment.lanes != 1 else ''} there"
    if oncoming and segment.oncoming_lanes:
        there += f" and {segment.oncoming_lanes} oncoming (-1 to -{segment.oncoming_lanes})"
    raise _LocatedError(key, f"lane {lane} does not exist at s = {_fmt(s)} m ({there})")


def _check_arcs(road: RoadModel) -> None:
    """Every arc's radius exceeds the road's whole paved width (conservative: the inner
    paved edge stays clear of the arc's centre whichever way it turns)."""
    for index, segment in enumerate(road.segments):
        if segment.arc is None:
            continue
        lanes = _or(segment.lanes, road.lanes) + _or(segment.oncoming_lanes, road.oncoming_lanes)
        width = lanes * road.lane_width + _or(segment.shoulder, road.shoulder)
        if not segment.arc.radius > width:
            raise _LocatedError(
                f"road.segments.{index}.arc.radius",
                f"must be larger than the road's paved width there, {_fmt(width)} m "
                f"((lanes + oncoming_lanes) x lane_width + shoulder), "
                f"got {_fmt(segment.arc.radius)}",
            )


def _check_exits(road: RoadModel) -> None:
    """An exit leaves the road of the segment before it: not on the first segment."""
    if road.segments and road.segments[0].exit is not None:
        raise _LocatedError("road.segments.0.exit",
                            "the first segment has no road before it to leave")


def _check_ego(model: ScenarioModel, segments: Sequence[spec.SegmentSpec]) -> None:
    ego = model.ego
    for town_key in ("start", "route"):
        if getattr(ego, town_key) is not None:
            raise _LocatedError(f"ego.{town_key}", "only for a town map (on a road use lane and s)")
    if ego.s is None:
        raise _LocatedError("ego.s", "required key missing (the ego's station on the road)")
    _check_station("ego.s", ego.s, _route_length(segments))
    _check_lane("ego.lane", _or(ego.lane, 0), ego.s, segments, oncoming=False)
    for key in ("speed_kph", "set_speed_kph"):
        value = getattr(ego, key)
        if value > ego.max_speed_kph:
            raise _LocatedError(
                f"ego.{key}",
                f"must be <= max_speed_kph ({_fmt(ego.max_speed_kph)}), got {_fmt(value)}",
            )


def _check_actors(model: ScenarioModel, segments: Sequence[spec.SegmentSpec]) -> None:
    first_seen: dict[str, int] = {}
    for index, actor in enumerate(model.actors):
        key = f"actors.{index}"
        if actor.id in first_seen:
            raise _LocatedError(
                f"{key}.id", f"duplicate id {actor.id!r} (also actors.{first_seen[actor.id]})"
            )
        first_seen[actor.id] = index
        _check_actor(key, actor, segments)


def _check_actor(key: str, actor: ActorModel, segments: Sequence[spec.SegmentSpec]) -> None:
    for town_key in ("start", "route"):
        if getattr(actor, town_key) is not None:
            raise _LocatedError(
                f"{key}.{town_key}", "only for a town map (on a road use lane and s)"
            )
    if actor.s is None:
        raise _LocatedError(f"{key}.s", "required key missing (the actor's station on the road)")
    length = _route_length(segments)
    _check_station(f"{key}.s", actor.s, length)
    _check_lane(f"{key}.lane", _or(actor.lane, 0), actor.s, segments, oncoming=True)
    if actor.type == "obstacle" and actor.speed_kph != 0:
        raise _LocatedError(
            f"{key}.speed_kph", f"an obstacle does not move: must be 0, got {_fmt(actor.speed_kph)}"
        )
    if actor.type == "obstacle" and actor.actions:
        raise _LocatedError(f"{key}.actions", "an obstacle does not move: it takes no actions")
    for number, action in enumerate(actor.actions):
        action_key = f"{key}.actions.{number}"
        _check_trigger(f"{action_key}.trigger", action.trigger, number, length, "action")
        if action.lane_change is not None:
            _check_lane(
                f"{action_key}.lane_change.to_lane",
                action.lane_change.to_lane,
                actor.s,
                segments,
                oncoming=True,
            )
    _speed_accels(key, actor)


def _check_trigger(key: str, trigger: TriggerModel, index: int, length: float, what: str) -> None:
    """`after` names an earlier item of the same list; `ego_s` lies on the route."""
    if trigger.after is not None and trigger.after >= index:
        earlier = f"0..{index - 1}" if index > 0 else f"none: this is the first {what}"
        raise _LocatedError(
            f"{key}.after", f"must refer to an earlier {what} ({earlier}), got {trigger.after}"
        )
    if trigger.ego_s is not None:
        _check_station(f"{key}.ego_s", trigger.ego_s, length)


def _check_rest(
    model: ScenarioModel, road: RoadModel, segments: Sequence[spec.SegmentSpec]
) -> None:
    """Features, events and criteria that refer to stations or list indices."""
    length = _route_length(segments)
    for index, feature in enumerate(road.features):
        _check_station(f"road.features.{index}.s", feature.s, length)
    for index, event in enumerate(model.events):
        _check_trigger(f"events.{index}.trigger", event.trigger, index, length, "event")
        if event.trigger.gap is not None:
            raise _LocatedError(
                f"events.{index}.trigger.gap", "only for actors (the gap to the ego)"
            )
    if model.criteria.reach_s is not None:
        _check_station("criteria.reach_s", model.criteria.reach_s, length)


def _speed_accels(key: str, actor: ActorModel) -> dict[int, float]:
    """[m/s^2] the signed acceleration of each speed action, by action index.

    The speed before an action is taken as the target of the speed / stop action before it
    in the list (the actor's initial speed for the first): it picks the default (+2 when
    speeding up, -3 when slowing) and a given accel must have the matching sign."""
    accels: dict[int, float] = {}
    speed_kph = actor.speed_kph
    for index, action in enumerate(actor.actions):
        if action.speed is not None:
            target = action.speed.kph
            accel = action.speed.accel
            if accel is None:
                accel = DEFAULT_SPEED_UP if target >= speed_kph else DEFAULT_SLOW_DOWN
            elif (target - speed_kph) * accel < 0:
                sign = "> 0" if target > speed_kph else "< 0"
                raise _LocatedError(
                    f"{key}.actions.{index}.speed.accel",
                    f"must be {sign} to go from {_fmt(speed_kph)} to {_fmt(target)} km/h "
                    f"(signed acceleration), got {_fmt(accel)}",
                )
            accels[index] = accel
            speed_kph = target
        elif action.stop is not None:
            speed_kph = 0.0
    return accels


def _or(value: _T | None, default: _T) -> _T:
    """`value`, or `default` when it is None."""
    return default if value is None else value


# ---------------------------------------------------------------------------------------
# Conversion into world.spec (SI units, radians, defaults resolved)
# ---------------------------------------------------------------------------------------


def _kph(value: float) -> float:
    return value * MPS_PER_KPH


def _segment_spec(segment: SegmentModel, road: RoadModel) -> spec.SegmentSpec:
    if segment.arc is not None:
        angle = math.radians(segment.arc.angle_deg)
        length = segment.arc.radius * abs(angle)
        curvature = math.copysign(1.0 / segment.arc.radius, angle)
    else:
        length, curvature = float(_or(segment.straight, 0.0)), 0.0
    limit = segment.speed_limit_kph
    return spec.SegmentSpec(
        length=length,
        curvature=curvature,
        lanes=_or(segment.lanes, road.lanes),
        oncoming_lanes=_or(segment.oncoming_lanes, road.oncoming_lanes),
        lane_width=road.lane_width,
        shoulder=_or(segment.shoulder, road.shoulder),
        speed_limit=None if limit is None else _kph(limit),
        zone=None if segment.zone is None else hdmap.Zone(segment.zone),
        exit=None if segment.exit is None else hdmap.Side(segment.exit),
    )


def _feature_spec(feature: FeatureModel) -> spec.FeatureSpec:
    if isinstance(feature, SpeedLimitFeature):
        return hdmap.SpeedLimitSign(s=feature.s, limit=_kph(feature.kph))
    if isinstance(feature, StopSignFeature):
        return hdmap.StopSign(s=feature.s)
    if isinstance(feature, CrosswalkFeature):
        return hdmap.Crosswalk(s=feature.s, width=feature.width)
    if isinstance(feature, SpeedBumpFeature):
        return hdmap.SpeedBump(
            s=feature.s,
            height=feature.height,
            length=feature.length,
            pass_speed=_kph(feature.pass_kph),
        )
    assert isinstance(feature, TrafficLightFeature)
    return spec.TrafficLightSpec(
        s=feature.s,
        green=feature.green,
        yellow=feature.yellow,
        red=feature.red,
        phase=feature.phase,
    )


def _road_spec(road: RoadModel) -> spec.RoadSpec:
    buildings = road.buildings
    return spec.RoadSpec(
        segments=tuple(_segment_spec(segment, road) for segment in road.segments),
        speed_limit=_kph(road.speed_limit_kph),
        features=tuple(_feature_spec(feature) for feature in road.features),
        buildings=None
        if buildings is None
        else spec.BuildingsSpec(density=buildings.density, setback=buildings.setback),
    )


def _trigger_spec(trigger: TriggerModel) -> spec.Trigger:
    kind = trigger.kind
    if kind == "time":
        return spec.TimeTrigger(time=float(_or(trigger.time, 0.0)))
    if kind == "ego_s":
        return spec.EgoStationTrigger(s=float(_or(trigger.ego_s, 0.0)))
    if kind == "gap":
        return spec.GapTrigger(gap=float(_or(trigger.gap, 0.0)))
    return spec.AfterTrigger(index=_or(trigger.after, 0), delay=float(_or(trigger.delay, 0.0)))


def _action_spec(action: ActionModel, accel: float | None) -> spec.Action:
    if action.speed is not None:
        magnitude = abs(_or(accel, DEFAULT_SPEED_UP))
        return spec.SpeedAction(speed=_kph(action.speed.kph), accel=magnitude)
    if action.lane_change is not None:
        return spec.LaneChangeAction(
            to_lane=action.lane_change.to_lane, lateral_speed=action.lane_change.lateral_speed
        )
    if action.walk is not None:
        return spec.WalkAction(to_offset=action.walk.to_offset, speed=_kph(action.walk.speed_kph))
    assert action.stop is not None
    return spec.StopAction(decel=action.stop.decel)


def _actor_spec(index: int, actor: ActorModel) -> spec.ActorSpec:
    accels = _speed_accels(f"actors.{index}", actor)
    actions = tuple(
        spec.ActionSpec(
            trigger=_trigger_spec(action.trigger), action=_action_spec(action, accels.get(number))
        )
        for number, action in enumerate(actor.actions)
    )
    return spec.ActorSpec(
        id=actor.id,
        type=spec.ActorType(actor.type),
        lane=_or(actor.lane, 0),
        s=float(_or(actor.s, 0.0)),
        offset=actor.offset,
        speed=_kph(actor.speed_kph),
        actions=actions,
    )


def _event_spec(event: EventModel) -> spec.EventSpec:
    trigger = _trigger_spec(event.trigger)
    if event.accelerator_override is not None:
        override = event.accelerator_override
        return spec.EventSpec(
            trigger, spec.AcceleratorOverride(pedal=override.pedal, duration=override.duration)
        )
    assert event.flat_tire is not None
    return spec.EventSpec(trigger, spec.FlatTire(wheel=frames.Wheel(event.flat_tire.wheel)))


def _sensors_spec(model: ScenarioModel) -> spec.SensorsSpec:
    gnss, lidar = model.sensors.gnss, model.sensors.lidar
    return spec.SensorsSpec(
        gnss=spec.GnssSpec()
        if gnss is None
        else spec.GnssSpec(
            sigma=gnss.sigma,
            heading_sigma=math.radians(gnss.heading_sigma_deg),
            bias=(float(gnss.bias[0]), float(gnss.bias[1])),
        ),
        lidar=spec.LidarNoiseSpec()
        if lidar is None
        else spec.LidarNoiseSpec(range_sigma=lidar.range_sigma, dropout=lidar.dropout),
    )


def _build(model: ScenarioModel) -> spec.ScenarioSpec:
    """Check what spans several keys and convert the validated model into the world spec."""
    if model.road is None:
        return _build_town(model)
    road_spec = _road_spec(model.road)
    _check_arcs(model.road)
    _check_exits(model.road)
    _check_ego(model, road_spec.segments)
    _check_actors(model, road_spec.segments)
    _check_rest(model, model.road, road_spec.segments)
    return _scenario_spec(model, road_spec,
                          tuple(_actor_spec(i, actor) for i, actor in enumerate(model.actors)))


def _scenario_spec(model: ScenarioModel, road_spec: spec.RoadSpec,
                   actors: tuple[spec.ActorSpec, ...],
                   town: spec.TownSpec | None = None) -> spec.ScenarioSpec:
    ego = model.ego
    criteria = model.criteria
    return spec.ScenarioSpec(
        name=model.name,
        description=model.description,
        situation=model.situation,
        duration=float(model.duration),
        seed=model.seed,
        road=road_spec,
        ego=spec.EgoSpec(
            lane=_or(ego.lane, 0),
            s=float(_or(ego.s, 0.0)),
            speed=_kph(ego.speed_kph),
            set_speed=_kph(ego.set_speed_kph),
            max_speed=_kph(ego.max_speed_kph),
            overtake=ego.overtake,
        ),
        actors=actors,
        sensors=_sensors_spec(model),
        events=tuple(_event_spec(event) for event in model.events),
        criteria=spec.CriteriaSpec(
            min_gap=criteria.min_gap, max_decel=criteria.max_decel, reach_s=criteria.reach_s,
            lane_change=None if criteria.lane_change is None else (
                criteria.lane_change.max_duration, criteria.lane_change.max_lateral_accel),
            standstill_gap=criteria.standstill_gap, resume_within=criteria.resume_within,
        ),
        town=town,
    )


# ---------------------------------------------------------------------------------------
# Towns
# ---------------------------------------------------------------------------------------

TOWN_START_S = 5.0  # [m] default station of a car on its town route (past the start mouth)


def _build_town(model: ScenarioModel) -> spec.ScenarioSpec:
    """A town: each car's `start` and `route` compile into its own route road
    (`world.map.town`); the ego's is the scenario's `road`."""
    assert model.town is not None  # the model has exactly one map
    t = model.town
    town = spec.TownSpec(t.blocks_x, t.blocks_y, float(t.block), t.lanes, float(t.lane_width),
                         _kph(t.speed_limit_kph), t.junctions)
    layout = TownLayout(town)
    try:
        layout.check("town")
        ego_road = _town_route(layout, "ego", model.ego.start, model.ego.route)
        roads = [_town_route(layout, f"actors.{i}", a.start, a.route)
                 for i, a in enumerate(model.actors)]
    except TownError as error:
        raise _LocatedError(error.key, error.problem) from None
    _check_town_car("ego", model.ego.lane, model.ego.s, ego_road)
    actors = []
    for index, (actor, road) in enumerate(zip(model.actors, roads, strict=True)):
        _check_town_car(f"actors.{index}", actor.lane, actor.s, road)
        actors.append(replace(_actor_spec(index, actor), s=_or(actor.s, TOWN_START_S), road=road))
    _check_town_ids(model)
    length = _route_length(ego_road.segments)
    for index, event in enumerate(model.events):
        _check_trigger(f"events.{index}.trigger", event.trigger, index, length, "event")
    if model.criteria.reach_s is not None:
        _check_station("criteria.reach_s", model.criteria.reach_s, length)
    for key in ("speed_kph", "set_speed_kph"):
        if getattr(model.ego, key) > model.ego.max_speed_kph:
            raise _LocatedError(f"ego.{key}", f"must be <= max_speed_kph "
                                f"({_fmt(model.ego.max_speed_kph)}), got "
                                f"{_fmt(getattr(model.ego, key))}")
    scenario = _scenario_spec(model, ego_road, tuple(actors), town)
    return replace(scenario, ego=replace(scenario.ego, s=_or(model.ego.s, TOWN_START_S)))


def _town_route(layout: TownLayout, key: str, start: tuple[int, int, str] | None,
                route: Sequence[str] | None) -> spec.RoadSpec:
    if start is None:
        raise _LocatedError(f"{key}.start", "required key missing in a town ([ix, iy, heading])")
    turns = tuple(hdmap.Manoeuvre(turn) for turn in (route or ()))
    return compile_route(layout, (start[0], start[1], start[2]), turns, key)


def _check_town_car(key: str, lane: int | None, s: float | None, road: spec.RoadSpec) -> None:
    """In a town a car starts in lane 0 of its route, `s` metres past its start junction."""
    if lane not in (None, 0):
        raise _LocatedError(f"{key}.lane", "in a town a car starts in lane 0 of its route")
    if s is not None:
        _check_station(f"{key}.s", s, _route_length(road.segments))


def _check_town_ids(model: ScenarioModel) -> None:
    first_seen: dict[str, int] = {}
    for index, actor in enumerate(model.actors):
        if actor.id in first_seen:
            raise _LocatedError(f"actors.{index}.id", f"duplicate id {actor.id!r} "
                                f"(also actors.{first_seen[actor.id]})")
        first_seen[actor.id] = index


# ---------------------------------------------------------------------------------------
# The entry point
# ---------------------------------------------------------------------------------------


def load_scenario(
    path_or_name: str | Path, overrides: Mapping[str, object] | None = None
) -> spec.ScenarioSpec:
    """Load, validate and convert a scenario file.

    `path_or_name` is a file path or the name of a bundled scenario (`scenarios/<name>.yaml`
    in the repository). `overrides` maps dotted key paths with list indices
    (`actors.0.speed_kph`) to values set into the file's data before validation; values are
    used as given (parse command-line text with `yaml.safe_load` first).

    Raises `ScenarioError` with a one-line message `<file>: <key.path>: <problem>`.
    """
    path = scenario_path(path_or_name)
    shown = _shown_name(path_or_name, path)
    if not _looks_like_path(path_or_name) and not path.exists():
        raise ScenarioError(
            str(path_or_name), FILE_KEY, "no such file or bundled scenario (see `avsim list`)"
        )
    try:
        raw = _apply_overrides(_read_raw(path), overrides or {})
        model = _validate(raw, overrides or {})
        _check_supported(raw)
        return _build(model)
    except _LocatedError as problem:
        raise ScenarioError(shown, problem.key, problem.problem) from None

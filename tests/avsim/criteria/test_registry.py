"""The criteria registry (`avsim.criteria.registry`), table by table over its declarations:
every key a scenario can set loads from a file and builds its criteria; unknown keys and bad
settings are one-line errors naming the key; the JSON Schema and the docs list every key;
each declaration builds and runs on what it declares it needs and nothing else; the samples
carry the NPCs' poses only when a criterion of the set needs them."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from pydantic import BaseModel

from avsim.criteria.base import Criterion, Need, TruthSample
from avsim.criteria.declaration import Declaration, RunInputs
from avsim.criteria.registry import (
    DECLARATIONS,
    CriteriaSettings,
    build_criteria,
    keyed,
    setting_keys,
)
from avsim.scenario.load import ScenarioError, load_scenario
from avsim.scenario.model import CriteriaModel
from avsim.scenario.schema import scenario_json_schema
from tests.roads import KPH, make_map, seg
from vehicle_urdf import read_geometry
from world.actors.actor_set import ActorPoses
from world.hdmap import Crosswalk, SpeedBump, StopSign
from world.spec import ActorType, TrafficLightSpec

DOC = Path(__file__).parents[3] / "docs" / "scenario-format.md"
LIGHT = TrafficLightSpec(600.0, 20.0, 3.0, 15.0, 0.0)
FEATURES = (StopSign(300.0), Crosswalk(400.0, 4.0), SpeedBump(500.0, 0.1, 0.9, 5 * KPH), LIGHT)
ROAD = make_map(seg(1000.0), features=FEATURES)
PLAIN_ROAD = make_map(seg(1000.0))  # no features: nothing for the feature criteria to watch
CAR = read_geometry()
RATE = 40  # [Hz]
BODY = 7  # the body id the ego touches in `samples`


def run_inputs(road: Any = ROAD) -> RunInputs:
    return RunInputs(road=road, car=CAR, rate=RATE, signals=(LIGHT,), set_speed=10.0,
                     bodies={BODY: "actor lead"})


ALWAYS = ["no_collision", "tyres_in_lane", "speed_limit", "stop_signs", "red_lights",
          "crosswalks", "speed_bumps", "completes", "minimum_risk_stop", "story"]


def scenario_file(tmp_path: Path, criteria: object) -> Path:
    path = tmp_path / "registry.yaml"
    path.write_text(scenario_file_text(criteria), encoding="utf-8")
    return path


def names(settings: CriteriaSettings, road: Any = ROAD) -> list[str]:
    return [c.name for c in build_criteria(settings, run_inputs(road)).items]


def setting(key: str, value: object) -> object:
    """`value` as the file's validation gives it for criteria key `key`."""
    return getattr(CriteriaModel.model_validate({key: value}), key)


# -- every key builds, in registry order -----------------------------------------------------


@pytest.mark.parametrize("declaration", keyed(), ids=lambda d: d.key)
def test_every_key_loads_from_a_file_and_builds_its_criteria(
        declaration: Declaration[Any], tmp_path: Path) -> None:
    key = str(declaration.key)
    settings = load_scenario(scenario_file(tmp_path, {key: declaration.example})).criteria
    assert settings.keys() == (key,)
    own = [c.name for c in declaration.build(settings.get(key), run_inputs())]
    assert own, key
    built = names(settings)
    if declaration.always:  # the key tunes criteria that are there anyway
        assert built == ALWAYS and set(own) <= set(ALWAYS)
    else:  # the key adds them, after the default criteria
        assert built == [*ALWAYS, *own]
        assert names(CriteriaSettings()) == ALWAYS


def test_the_full_set_in_the_order_of_a_runs_results() -> None:
    settings = CriteriaSettings.of({"min_gap": "r157", "max_decel": 3.5, "resume_within": 15.0,
                                    "standstill_gap": (2.0, 6.0), "reach_s": 600.0,
                                    "lane_change": setting("lane_change", {})})
    assert names(settings) == [
        *ALWAYS, "max_decel", "min_gap", "lane_change_duration", "lane_change_lateral_accel",
        "standstill_gap", "time_to_resume"]


def test_reach_s_sets_where_completes_is_reached_else_the_end_less_30_m() -> None:
    def threshold(settings: CriteriaSettings) -> float:
        (completes,) = (c for c in build_criteria(settings, run_inputs()).items
                        if c.name == "completes")
        return completes.result().threshold

    assert threshold(CriteriaSettings()) == ROAD.length - 30.0
    assert threshold(CriteriaSettings.of({"reach_s": 300.0})) == 300.0


def test_keys_and_names_are_unique() -> None:
    keys = [d.key for d in keyed()]
    assert len(keys) == len(set(keys))
    full = CriteriaSettings.of({str(d.key): setting(str(d.key), d.example) for d in keyed()})
    built = names(full)
    assert len(built) == len(set(built))


def test_settings_with_a_key_no_declaration_has_are_refused() -> None:
    with pytest.raises(ValueError, match="nope"):
        build_criteria(CriteriaSettings.of({"nope": 1.0}), run_inputs())


def test_a_declaration_is_complete_or_refused() -> None:
    def build(_: object, run: RunInputs) -> list[Criterion]:
        return []

    with pytest.raises(ValueError, match="always applies"):
        Declaration(build=build, needs=frozenset())  # no key: must always apply
    with pytest.raises(ValueError, match="setting type, a doc and an example"):
        Declaration(build=build, needs=frozenset(), key="x", setting=float, doc="[m] x")


# -- bad input: one line naming the key ------------------------------------------------------


@pytest.mark.parametrize(("criteria", "key", "problem"), [
    ({"min_gapp": 3.0}, "criteria.min_gapp", "unknown key (did you mean min_gap?)"),
    ({"no_collision": True}, "criteria.no_collision", "unknown key"),  # always on: no key
    ({"colour": "red"}, "criteria.colour", "unknown key"),
    ({"lane_change": {"max_duraton": 3}}, "criteria.lane_change.max_duraton",
     "unknown key (did you mean max_duration?)"),
])
def test_an_unknown_key_is_a_one_line_error_naming_it(
        criteria: dict[str, object], key: str, problem: str, tmp_path: Path) -> None:
    path = scenario_file(tmp_path, criteria)
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    assert str(info.value) == f"{path}: {key}: {problem}"


@pytest.mark.parametrize("bad", ["fast", -1, True, [1.0, 2.0, 3.0]])
@pytest.mark.parametrize("declaration", keyed(), ids=lambda d: d.key)
def test_every_key_refuses_a_bad_setting_in_one_line(
        declaration: Declaration[Any], bad: object, tmp_path: Path) -> None:
    path = scenario_file(tmp_path, {declaration.key: bad})
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(f"{path}: criteria.{declaration.key}"), message
    assert info.value.key.startswith(f"criteria.{declaration.key}")


def test_a_station_setting_must_lie_on_the_route(tmp_path: Path) -> None:
    path = scenario_file(tmp_path, {"reach_s": 1500})
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    assert str(info.value) == (f"{path}: criteria.reach_s: station 1500 m is beyond the end "
                               f"of the route (1000 m)")


# -- the schema and the docs list every key --------------------------------------------------


def test_the_schema_lists_every_key_with_its_doc_and_example() -> None:
    import jsonschema  # type: ignore[import-untyped]

    schema = scenario_json_schema()
    section = schema["$defs"]["CriteriaModel"]
    assert list(section["properties"]) == list(setting_keys())
    assert setting_keys()[-1] == "completes"  # the one switch: `completes: false`
    assert section["properties"]["completes"]["anyOf"][0] == {"type": "boolean"}
    assert section["additionalProperties"] is False
    for d in keyed():
        field = section["properties"][d.key]
        assert field["description"] == d.doc
        assert field["examples"] == [d.example]
    top = schema["properties"]["criteria"]["description"]
    assert all(key in top for key in setting_keys())
    validator = jsonschema.Draft202012Validator(schema)
    file = yaml.safe_load(scenario_file_text({d.key: d.example for d in keyed()}))
    validator.validate(file)
    assert not validator.is_valid({**file, "criteria": {"min_gapp": 3}})


def scenario_file_text(criteria: object) -> str:
    return yaml.safe_dump({"format": "avsim/1", "name": "registry", "duration": 10,
                           "road": {"speed_limit_kph": 50, "segments": [{"straight": 1000}]},
                           "ego": {"s": 10, "set_speed_kph": 40}, "criteria": criteria})


def test_the_docs_name_every_key_and_every_field_of_a_setting() -> None:
    doc = DOC.read_text(encoding="utf-8")
    assert "| `completes` |" in doc
    for d in keyed():
        assert f"| `{d.key}` |" in doc, f"no row for criteria key {d.key} in {DOC.name}"
        if isinstance(d.setting, type) and issubclass(d.setting, BaseModel):
            for name, field in d.setting.model_fields.items():
                assert field.description, f"{d.key}.{name}"
                assert f"`{name}`" in doc, f"{d.key}.{name} is not in {DOC.name}"


# -- needs: a declaration builds and runs on what it declares, and the samples carry the ------
# -- actors only when one needs them --------------------------------------------------------


class Withheld:
    """Stands in for what a declaration did not declare: any use of it fails."""

    def __init__(self, need: Need) -> None:
        self.need = need

    def __getattr__(self, name: str) -> object:
        raise AssertionError(f"used {self.need.value}.{name} without declaring {self.need}")


def poses(station: float) -> ActorPoses:
    """A car 25 m ahead in the ego's lane and a pedestrian on the crosswalk."""
    return ActorPoses(ids=("lead", "walker"), kinds=(ActorType.CAR, ActorType.PEDESTRIAN),
                      centres=np.zeros((2, 3)), yaws=np.zeros(2),
                      half_sizes=np.array([[2.3, 0.9, 0.75], [0.25, 0.3, 0.875]]),
                      stations=np.array([station + 25.0, 402.0]),
                      offsets=np.zeros(2), speeds=np.array([5.0, 0.0]), accels=np.zeros(2))


def samples(with_actors: bool) -> list[TruthSample]:
    """40 s at 40 Hz along the featured road, through its stop line, crosswalk, bump and
    light: 10 m/s, slowing to a stand and on again, touching a body for a moment, a lane
    change to lane 1 in between; the NPCs' poses in each, or (without) a stand-in that
    fails when used."""
    out = []
    station = 250.0
    for k in range(1600):
        t = k / RATE
        speed = 10.0 if k < 400 or k > 600 else max(0.0, 10.0 - 0.1 * (k - 400))
        station += speed / RATE
        changing = 800 <= k < 900
        d = 3.5 * min(1.0, max(0.0, (k - 800) / 100))  # lane 0's centre to lane 1's
        out.append(TruthSample(
            t=t, speed=speed, station=station, front_station=station + 2.4,
            tyres=np.zeros((4, 2)), tyre_stations=station + np.array([1.35, 1.35, -1.35, -1.35]),
            tyre_offsets=d + np.array([0.8, -0.8, 0.8, -0.8]), offset=d,
            touching=frozenset({BODY}) if 100 <= k < 110 else frozenset(),
            actors=poses(station) if with_actors else Withheld(Need.ACTORS),  # type: ignore[arg-type]
            lateral_accel=0.1 * changing,
            xy=(station, 0.0)))
    return out


def validated(declaration: Declaration[Any]) -> list[object]:
    """The settings to build a declaration with: its example as validated (and None, the
    default, for one that always applies)."""
    if declaration.key is None:
        return [None]
    value = setting(declaration.key, declaration.example)
    return [value, None] if declaration.always else [value]


@pytest.mark.parametrize("declaration", DECLARATIONS,
                         ids=lambda d: d.key or d.build(None, run_inputs())[0].name)
def test_a_declaration_builds_and_runs_on_what_it_declares_it_needs(
        declaration: Declaration[Any]) -> None:
    for value in validated(declaration):
        declared = declaration.needs | (declaration.needs_if_set if value is not None
                                        else frozenset())
        withheld = {n.value: Withheld(n) for n in Need if n not in declared}
        inputs = dataclasses.replace(run_inputs(), **{k: v for k, v in withheld.items()
                                                      if k != Need.ACTORS.value})
        criteria = declaration.build(value, inputs)
        for sample in samples(Need.ACTORS in declared):
            for c in criteria:
                c.update(sample)
        assert all(c.result().name == c.name for c in criteria)


@pytest.mark.parametrize(("road", "settings", "actors"), [
    (PLAIN_ROAD, {}, False),  # the default criteria on a map without crosswalks
    (ROAD, {}, True),  # a crosswalk: pedestrians to watch
    (PLAIN_ROAD, {"min_gap": 20.0}, True),
    (PLAIN_ROAD, {"standstill_gap": (2.0, 6.0)}, True),
    (PLAIN_ROAD, {"resume_within": 15.0}, True),
    (PLAIN_ROAD, {"max_decel": 3.0, "reach_s": 300.0}, False),
    (PLAIN_ROAD, {"unavoidable": "r157"}, True),  # cut-ins judged from the NPCs' poses
])
def test_the_samples_carry_the_actors_only_when_a_criterion_needs_them(
        road: Any, settings: dict[str, object], actors: bool) -> None:
    needs = build_criteria(CriteriaSettings.of(settings), run_inputs(road)).needs
    assert (Need.ACTORS in needs) is actors


def test_completes_false_turns_route_completion_off(tmp_path: Path) -> None:
    settings = load_scenario(scenario_file(tmp_path, {"completes": False})).criteria
    assert "completes" not in names(settings)
    assert names(CriteriaSettings.of({"completes": True})) == ALWAYS
    with pytest.raises(ScenarioError, match="completes"):
        load_scenario(scenario_file(tmp_path, {"completes": "no"}))

"""Tests of strict scenario loading (`avsim.scenario.load`), its models and JSON Schema."""

from __future__ import annotations

import math
import pickle
import re
from pathlib import Path
from typing import Any, get_args

import jsonschema  # type: ignore[import-untyped]
import pytest
import yaml
from pydantic import BaseModel

from avsim.criteria.registry import CriteriaSettings
from avsim.scenario import convert as conversion
from avsim.scenario import files as scenario_files
from avsim.scenario import load as scenario_module
from avsim.scenario import model as scenario_model
from avsim.scenario.files import SCENARIO_DIR, parse_value
from avsim.scenario.load import (
    UNSUPPORTED,
    ScenarioError,
    bundled_scenarios,
    load_scenario,
    scenario_path,
)
from avsim.scenario.scenario import DriverSettings
from avsim.scenario.schema import scenario_json_schema
from tests.avsim.texts import MINIMAL
from world import spec
from world.actors.catalogue import CATALOGUE, DEFAULT_MODEL

HERE = Path(__file__).parents[1]
BAD_DIR = HERE / "bad_scenarios"
DOC = HERE.parents[1] / "docs" / "scenario-format.md"
KPH = conversion.MPS_PER_KPH  # [m/s] per [km/h], checked against 1 / 3.6 below


# SCENARIO_FORMAT.md's complete example, verbatim but for the comments.
FULL_EXAMPLE = """\
format: avsim/1
name: cut_in_then_out
description: A slower car cuts in from the left, then leaves again.
situation: cut_in_out
duration: 45
seed: 3
road:
  lanes: 2
  oncoming_lanes: 0
  lane_width: 3.5
  shoulder: 2.5
  speed_limit_kph: 50
  segments:
    - straight: 300
    - arc: {radius: 250, angle_deg: 30}
    - straight: 200
    - {arc: {radius: 80, angle_deg: -40}, lanes: 1, speed_limit_kph: 25, zone: ramp, exit: right}
    - {straight: 120, lanes: 1, oncoming_lanes: 1, speed_limit_kph: 40, zone: city}
  features:
    - {type: speed_limit, s: 150, kph: 40}
    - {type: stop_sign, s: 400}
    - {type: crosswalk, s: 470, width: 4}
    - {type: speed_bump, s: 520, height: 0.1, length: 0.9, pass_kph: 5}
    - {type: traffic_light, s: 600, green: 20, yellow: 3, red: 15, phase: 0}
  buildings: {density: 0.6, setback: 6}
ego:
  lane: 0
  s: 20
  speed_kph: 50
  set_speed_kph: 50
  max_speed_kph: 54
actors:
  - id: cutter
    type: car
    lane: 1
    s: 55
    speed_kph: 30
    actions:
      - trigger: {time: 4}
        lane_change: {to_lane: 0, lateral_speed: 2.0}
      - trigger: {after: 0, delay: 15}
        lane_change: {to_lane: 1, lateral_speed: 2.0}
  - id: parked
    type: obstacle
    lane: 1
    s: 560
  - id: walker
    type: pedestrian
    s: 472
    offset: -6.0
    actions:
      - trigger: {ego_s: 430}
        walk: {to_offset: 9.0, speed_kph: 5}
sensors:
  gnss: {sigma: 0.05, heading_sigma_deg: 0.2, bias: [0.0, 0.0]}
  lidar: {range_sigma: 0.02, dropout: 0.0}
events:
  - trigger: {time: 20}
    accelerator_override: {pedal: 1.0, duration: 5}
  - trigger: {time: 38}
    flat_tire: {wheel: rear_left}
criteria:
  min_gap: r157
  max_decel: 5.0
  reach_s: 560
"""

TOWN_EXAMPLE = """\
format: avsim/1
name: town_loop
duration: 60
town: {blocks_x: 3, blocks_y: 3, block: 90, lanes: 1, lane_width: 3.5,
       speed_limit_kph: 40, junctions: stop_signs}
ego: {start: [0, 0, east], route: [straight, right, left, u_turn, straight], speed_kph: 0,
      set_speed_kph: 40}
"""


def _stripped_example() -> dict[str, Any]:
    """The full example without what is not supported yet."""
    data: dict[str, Any] = yaml.safe_load(FULL_EXAMPLE)
    del data["road"]["segments"][3]["exit"]
    data["road"]["features"] = data["road"]["features"][:1]
    data["actors"] = data["actors"][:2]
    return data


def _write(tmp_path: Path, data: str | dict[str, Any], name: str = "s.yaml") -> Path:
    path = tmp_path / name
    path.write_text(data if isinstance(data, str) else yaml.safe_dump(data), encoding="utf-8")
    return path


def _error(path_or_name: str | Path, overrides: dict[str, object] | None = None) -> ScenarioError:
    with pytest.raises(ScenarioError) as info:
        load_scenario(path_or_name, overrides)
    return info.value


# ---------------------------------------------------------------------------------------
# Malformed files: one line naming the file, the key and the problem
# ---------------------------------------------------------------------------------------

BAD: dict[str, tuple[str, str]] = {
    "unknown_top_key": ("colour", "unknown key"),
    "unknown_nested_key": ("actors.0.speed_kp", "unknown key (did you mean speed_kph?)"),
    "wrong_type": ("duration", "must be a number, got 'abc'"),
    "text_for_int": ("road.lanes", "must be an integer, got '2'"),
    "float_for_int": ("seed", "must be an integer, got 2.5"),
    "negative_length": ("road.segments.1.straight", "must be > 0, got -5"),
    "zero_arc_radius": ("road.segments.0.arc.radius", "must be > 0, got 0"),
    "zero_arc_angle": ("road.segments.1.arc.angle_deg", "must not be 0"),
    "arc_too_tight": ("road.segments.1.arc.radius", "must be larger than the road's paved width"),
    "ego_lane_out_of_range": (
        "ego.lane",
        "lane 2 does not exist at s = 20 m (the road has 2 lanes there)",
    ),
    "actor_lane_out_of_range": (
        "actors.0.lane",
        "lane 1 does not exist at s = 150 m (the road has 1 lane there)",
    ),
    "lane_change_missing_lane": ("actors.0.actions.0.lane_change.to_lane", "lane 2 does not"),
    "standstill_gap_reversed": ("criteria.standstill_gap", "low must be below high"),
    "lane_change_bad_bound": ("criteria.lane_change.max_lateral_accel", "must be > 0"),
    "station_beyond_route": ("actors.0.s", "beyond the end of the route (100 m)"),
    "unknown_feature_type": ("road.features.0.type", "unknown feature type 'zebra'"),
    "unknown_action": (
        "actors.0.actions.0",
        "unknown action 'teleport' (expected one of speed, lane_change, walk, stop)",
    ),
    "two_actions": ("actors.0.actions.0", "has 2 actions (speed, stop)"),
    "unknown_trigger": ("actors.0.actions.0.trigger", "unknown trigger 'distance'"),
    "after_forward": ("actors.0.actions.0.trigger.after", "must refer to an earlier action"),
    "wrong_accel_sign": ("actors.0.actions.0.speed.accel", "must be < 0"),
    "duplicate_actor_id": ("actors.1.id", "duplicate id 'lead'"),
    "moving_obstacle": ("actors.0.speed_kph", "an obstacle does not move"),
    "bad_yaml_syntax": ("line 9", "YAML syntax error"),
    "duplicate_key": ("line 12", "duplicate key 's' (first at line 10)"),
    "empty": ("(file)", "empty file"),
    "not_a_mapping": ("(file)", "must be a mapping"),
    "missing_required": ("duration", "required key missing"),
    "no_map": ("road", "a map is required"),
    "bad_name": ("name", "must match [a-z0-9_]+"),
    "wrong_format": ("format", "must be avsim/1, got 'avsim/2'"),
    "unsupported_left_exit": ("road.segments.1.exit", "not supported yet (exits on the left)"),
    "town_route_leaves_town": (
        "ego.route.1",
        "right at junction (2, 0) (heading east): no street leaves it heading south",
    ),
    "town_narrow_u_turn": ("ego.route.0", "u_turn at junction (1, 1): the street is too narrow"),
    "town_block_too_short": ("town.block", "must be at least 29 m with 1 lane(s) of 3.5 m"),
    "town_actor_without_start": ("actors.0.start", "required key missing in a town"),
    "bad_lidar_dropout": ("sensors.lidar.dropout", "must be <= 1, got 1.5"),
    "bad_gnss_preset": ("sensors.gnss.preset",
                        "must be one of rtk, consumer, degraded, got 'consumr'"),
    "bad_gnss_bias": ("sensors.gnss.bias.1", "must be <= 50, got 51"),
    "bad_gnss_sigma": ("sensors.gnss.sigma", "must be >= 0, got -0.1"),
    "unknown_vehicle_model": (
        "actors.0.model",
        "must be one of small_car, sedan, suv, van, bus, rigid_truck, semi_trailer, "
        "motorbike, got 'tank'",
    ),
    "model_on_pedestrian": ("actors.0.model", "only a car or truck takes a model"),
    "model_type_mismatch": ("actors.0.model", "a semi_trailer needs type: truck, not car"),
    "actor_overlaps_ego": ("actors.1", "overlaps the ego at s = 22 m"),
    "actors_overlap": ("actors.1", "overlaps actors.0 (lead) at s = 63 m"),
    "town_actors_overlap": ("actors.1", "overlaps actors.0 (a) at s = 7 m of its route"),
    "town_actor_overlaps_ego": ("actors.0", "overlaps the ego at s = 8 m of its route"),
    "too_many_lanes": ("road.lanes", "must be <= 6, got 500"),
    "route_too_long": ("road.segments", "the route is 22854 m long: at most 20000 m"),
    "duration_too_long": ("duration", "must be <= 7200"),
    "anchor_bomb": ("line 10", "more than 100000 values (anchors expanded)"),
    "grid_too_big": ("grid", "1089 points: at most 1000"),
    "grid_varies_grid": ("grid", "'grid.x': a grid cannot vary this key"),
    "grid_empty_values": ("grid.ego.speed_kph", "must have at least 1 item(s), got 0"),
    "fault_unknown_camera": ("events.0.camera_blackout.camera",
                             "must be one of front, left, right, got 'rear'"),
    "fault_zero_duration": ("events.0.lidar_outage.duration", "must be > 0, got 0"),
    "fault_jump_too_far": ("events.0.gnss_jump.offset.0", "must be <= 1000, got 5000"),
    "fault_delay_too_long": ("events.0.sensor_delay.delay", "must be <= 1, got 5"),
    "fault_occlusion_fraction": ("events.0.camera_occlusion.fraction", "must be <= 1, got 1.5"),
}


def test_every_bad_fixture_has_an_expectation() -> None:
    assert {path.stem for path in BAD_DIR.glob("*.yaml")} == set(BAD)


@pytest.mark.parametrize("name", sorted(BAD))
def test_bad_file_gives_one_line_with_file_and_key(name: str) -> None:
    key, problem = BAD[name]
    path = BAD_DIR / f"{name}.yaml"
    error = _error(path)
    message = str(error)
    assert "\n" not in message
    assert message.startswith(f"{path}: {key}: "), message
    assert problem in message
    assert (error.file, error.key) == (str(path), key)


def test_missing_file(tmp_path: Path) -> None:
    path = tmp_path / "nowhere.yaml"
    assert str(_error(path)) == f"{path}: (file): no such file"


def test_unknown_bundled_name() -> None:
    message = str(_error("no_such_scenario_here"))
    assert message.startswith("no_such_scenario_here: (file): no such file or bundled scenario")


def test_misspelt_required_key_is_named_not_the_missing_one(tmp_path: Path) -> None:
    path = _write(tmp_path, MINIMAL.replace("duration:", "duraton:"))
    assert str(_error(path)) == f"{path}: duraton: unknown key (did you mean duration?)"


def test_nan_is_refused(tmp_path: Path) -> None:
    path = _write(tmp_path, MINIMAL.replace("duration: 10", "duration: .nan"))
    assert str(_error(path)).endswith("duration: must be a finite number, got nan")


def test_error_pickles() -> None:
    error = ScenarioError("x.yaml", "duration", "must be > 0, got -1")
    again = pickle.loads(pickle.dumps(error))
    assert str(again) == str(error) == "x.yaml: duration: must be > 0, got -1"


# ---------------------------------------------------------------------------------------
# Good files and conversion
# ---------------------------------------------------------------------------------------


def test_minimal_file_and_defaults(tmp_path: Path) -> None:
    assert pytest.approx(1 / 3.6) == KPH
    loaded = load_scenario(_write(tmp_path, MINIMAL))
    assert (loaded.name, loaded.situation, loaded.description, loaded.seed) == (
        "minimal",
        "other",
        "",
        0,
    )
    assert loaded.duration == 10.0
    (segment,) = loaded.world.road.segments
    assert (segment.length, segment.curvature, segment.lanes, segment.oncoming_lanes) == (
        100.0,
        0.0,
        1,
        0,
    )
    assert (segment.lane_width, segment.shoulder, segment.speed_limit) == (3.5, 2.5, None)
    assert loaded.world.road.speed_limit == 50 * KPH
    assert loaded.world.ego == spec.EgoSpec(lane=0, s=10.0, speed=0.0, max_speed=15.0)
    assert loaded.driver == DriverSettings(set_speed=40 * KPH, overtake=False)
    assert loaded.world.seed == 0
    assert loaded.world.sensors == spec.SensorsSpec()
    assert loaded.criteria == CriteriaSettings()
    assert loaded.world.actors == ()
    assert loaded.world.events == ()


def test_vehicle_models_and_their_defaults(tmp_path: Path) -> None:
    text = MINIMAL + """\
actors:
  - {id: semi, type: truck, s: 50, model: semi_trailer}
  - {id: bike, type: car, s: 60, model: motorbike}
  - {id: car, type: car, s: 70}
  - {id: lorry, type: truck, s: 80}
  - {id: walker, type: pedestrian, s: 90}
"""
    actors = load_scenario(_write(tmp_path, text)).world.actors
    assert [a.model for a in actors] == [CATALOGUE["semi_trailer"], CATALOGUE["motorbike"],
                                         CATALOGUE[DEFAULT_MODEL["car"]],
                                         CATALOGUE[DEFAULT_MODEL["truck"]], None]
    assert (DEFAULT_MODEL["car"], DEFAULT_MODEL["truck"]) == ("sedan", "rigid_truck")


def test_format_names_every_catalogue_model() -> None:
    assert get_args(scenario_model.VehicleModelName) == tuple(CATALOGUE)


def test_example_converts(tmp_path: Path) -> None:
    loaded = load_scenario(_write(tmp_path, _stripped_example()))
    road = loaded.world.road
    straight, left, straight2, ramp, city = road.segments
    assert (straight.length, straight.curvature, straight.lanes) == (300.0, 0.0, 2)
    assert left.curvature == pytest.approx(1 / 250)
    assert left.length == pytest.approx(250 * math.pi / 6)
    assert ramp.curvature == pytest.approx(-1 / 80)
    assert ramp.length == pytest.approx(80 * math.radians(40))
    assert (ramp.lanes, ramp.oncoming_lanes, ramp.zone) == (1, 0, spec.Zone.RAMP)
    assert ramp.speed_limit == 25 * KPH
    assert (city.lanes, city.oncoming_lanes, city.zone) == (1, 1, spec.Zone.CITY)
    assert (straight2.lanes, straight2.speed_limit, straight2.zone) == (2, None, None)
    assert road.features == (spec.SpeedLimitSign(s=150.0, limit=40 * KPH),)
    assert road.buildings == spec.BuildingsSpec(density=0.6, setback=6.0)
    assert loaded.world.ego.speed == pytest.approx(50 / 3.6)
    assert loaded.world.ego.max_speed == pytest.approx(15.0)
    assert loaded.driver == DriverSettings(set_speed=50 * KPH)
    assert (loaded.seed, loaded.world.seed) == (3, 3)
    cutter, parked = loaded.world.actors
    assert (cutter.id, cutter.type, cutter.lane, cutter.s) == ("cutter", spec.ActorType.CAR, 1, 55)
    assert cutter.speed == 30 * KPH
    assert cutter.actions == (
        spec.ActionSpec(spec.TimeTrigger(4.0), spec.LaneChangeAction(to_lane=0, lateral_speed=2.0)),
        spec.ActionSpec(spec.AfterTrigger(index=0, delay=15.0), spec.LaneChangeAction(1, 2.0)),
    )
    assert (parked.type, parked.speed, parked.offset, parked.actions) == (
        spec.ActorType.OBSTACLE,
        0.0,
        0.0,
        (),
    )
    assert loaded.world.sensors.gnss.heading_sigma == pytest.approx(math.radians(0.2))
    assert loaded.world.events == (
        spec.EventSpec(spec.TimeTrigger(20.0), spec.AcceleratorOverride(pedal=1.0, duration=5.0)),
        spec.EventSpec(spec.TimeTrigger(38.0), spec.FlatTire(spec.Wheel.REAR_LEFT)),
    )
    assert loaded.criteria == CriteriaSettings.of({"min_gap": "r157", "max_decel": 5.0,
                                                   "reach_s": 560.0})


def test_full_example_converts_once_everything_is_supported(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Shrinking `UNSUPPORTED` is all it takes for the loader to convert those keys."""
    monkeypatch.setattr(scenario_module, "UNSUPPORTED", {"town": "the town map kind"})
    loaded = load_scenario(_write(tmp_path, FULL_EXAMPLE))
    assert loaded.world.road.segments[3].exit == spec.Side.RIGHT
    assert loaded.world.road.features[4] == spec.TrafficLightSpec(600.0, 20.0, 3.0, 15.0, 0.0)
    assert loaded.world.road.features[3].pass_speed == 5 * KPH  # type: ignore[union-attr]
    walker = loaded.world.actors[2]
    assert (walker.type, walker.lane, walker.offset) == (spec.ActorType.PEDESTRIAN, 0, -6.0)
    assert walker.actions[0].trigger == spec.EgoStationTrigger(s=430.0)
    assert walker.actions[0].action == spec.WalkAction(to_offset=9.0, speed=5 * KPH)
    assert loaded.world.events[1] == spec.EventSpec(
        spec.TimeTrigger(38.0), spec.FlatTire(spec.Wheel.REAR_LEFT)
    )
    assert loaded.world.sensors.lidar == spec.LidarNoiseSpec(range_sigma=0.02, dropout=0.0)
    assert loaded.criteria.get("min_gap") == "r157"


@pytest.mark.parametrize("pattern", sorted(UNSUPPORTED))
def test_each_unsupported_entry_is_refused(
    pattern: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(scenario_module, "UNSUPPORTED", {pattern: UNSUPPORTED[pattern]})
    text = TOWN_EXAMPLE if pattern == "town" else FULL_EXAMPLE
    if pattern == "road.segments.*.exit=left":  # the example's exit is on the right
        text = text.replace("exit: right", "exit: left")
    error = _error(_write(tmp_path, text))
    regex = re.escape(pattern.split("=", maxsplit=1)[0]).replace(r"\*", r"\d+")
    assert re.fullmatch(regex, error.key), error
    assert error.problem == f"not supported yet ({UNSUPPORTED[pattern]})"


def test_speed_and_stop_action_defaults(tmp_path: Path) -> None:
    data: dict[str, Any] = yaml.safe_load(MINIMAL)
    data["actors"] = [
        {
            "id": "lead",
            "type": "truck",
            "s": 50,
            "speed_kph": 30,
            "actions": [
                {"trigger": {"time": 1}, "speed": {"kph": 50}},
                {"trigger": {"gap": 10}, "speed": {"kph": 20}},
                {"trigger": {"after": 1}, "stop": None},  # `stop:` is `stop: {}`
                {"trigger": {"time": 30}, "speed": {"kph": 10, "accel": 1.5}},
            ],
        }
    ]
    actions = [a.action for a in load_scenario(_write(tmp_path, data)).world.actors[0].actions]
    assert actions == [
        spec.SpeedAction(speed=50 * KPH, accel=2.0),
        spec.SpeedAction(speed=20 * KPH, accel=3.0),
        spec.StopAction(decel=6.0),
        spec.SpeedAction(speed=10 * KPH, accel=1.5),
    ]
    triggers = [a.trigger for a in load_scenario(_write(tmp_path, data)).world.actors[0].actions]
    assert triggers[1:3] == [spec.GapTrigger(gap=10.0), spec.AfterTrigger(index=1, delay=0.0)]


def test_oncoming_lane_for_actors_only(tmp_path: Path) -> None:
    data: dict[str, Any] = yaml.safe_load(MINIMAL)
    data["road"]["oncoming_lanes"] = 1
    data["actors"] = [{"id": "oncoming", "type": "car", "lane": -1, "s": 90, "speed_kph": 40}]
    assert load_scenario(_write(tmp_path, data)).world.actors[0].lane == -1
    data["actors"][0]["lane"] = -2
    error = _error(_write(tmp_path, data))
    assert error.key == "actors.0.lane"
    assert "(the road has 1 lane there and 1 oncoming (-1 to -1))" in error.problem


def test_bundled_names_resolve(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    assert scenario_path("cut_in_then_out") == SCENARIO_DIR / "cut_in_then_out.yaml"
    assert scenario_path("my/file.yaml") == Path("my/file.yaml")
    assert all(p.parent == SCENARIO_DIR and p.suffix == ".yaml" for p in bundled_scenarios())
    monkeypatch.setattr(scenario_files, "SCENARIO_DIR", tmp_path)
    _write(tmp_path, MINIMAL, "minimal.yaml")
    assert load_scenario("minimal").name == "minimal"
    assert scenario_module.bundled_scenarios() == [tmp_path / "minimal.yaml"]


# ---------------------------------------------------------------------------------------
# Overrides
# ---------------------------------------------------------------------------------------


def test_overrides_set_paths(tmp_path: Path) -> None:
    path = _write(tmp_path, _stripped_example())
    loaded = load_scenario(
        path,
        {
            "actors.0.speed_kph": 40,
            "road.segments.1.arc.radius": 500,
            "actors.1.offset": 0.5,  # not in the file, a known key
            "duration": 20,
        },
    )
    assert loaded.world.actors[0].speed == 40 * KPH
    assert loaded.world.road.segments[1].curvature == pytest.approx(1 / 500)
    assert loaded.world.actors[1].offset == 0.5
    assert loaded.duration == 20.0
    assert load_scenario(path).world.actors[0].speed == 30 * KPH  # file untouched


@pytest.mark.parametrize(
    ("path", "problem"),
    [
        ("actors.5.speed_kph", "cannot set: '5' is not an index of a list of 2"),
        ("road.nope.x", "cannot set: the file has no key road.nope"),
        ("duration.x", "cannot set: duration is 45, not a mapping or list"),
        ("actors.x", "cannot set: 'x' is not an index of a list of 2"),
        ("actors..s", "override path is empty or has an empty part"),
        ("actors.0.speed_kp", "unknown key (did you mean speed_kph?) (set by an override)"),
        ("actors.0.speed_kph", "must be a number, got 'fast' (set by an override)"),
    ],
)
def test_bad_override_paths(path: str, problem: str, tmp_path: Path) -> None:
    file = _write(tmp_path, _stripped_example())
    error = _error(file, {path: "fast"})
    assert str(error) == f"{file}: {path}: {problem}"


# ---------------------------------------------------------------------------------------
# JSON Schema, descriptions and the docs
# ---------------------------------------------------------------------------------------


def _models() -> list[type[BaseModel]]:
    models = [
        value
        for value in vars(scenario_model).values()
        if isinstance(value, type)
        and issubclass(value, BaseModel)
        and value.__module__ == scenario_model.__name__
    ]
    return [m for m in models if m.model_fields]


def test_schema_validates_good_files_and_rejects_bad() -> None:
    schema = scenario_json_schema()
    jsonschema.Draft202012Validator.check_schema(schema)
    validator = jsonschema.Draft202012Validator(schema)
    for text in (MINIMAL, FULL_EXAMPLE, TOWN_EXAMPLE):
        validator.validate(yaml.safe_load(text))
    validator.validate(_stripped_example())
    assert schema["$id"] and schema["title"] and schema["description"]
    for name in (
        "unknown_top_key",
        "unknown_nested_key",
        "wrong_type",
        "negative_length",
        "unknown_feature_type",
        "unknown_action",
        "bad_name",
        "missing_required",
    ):
        data = yaml.safe_load((BAD_DIR / f"{name}.yaml").read_text(encoding="utf-8"))
        assert not validator.is_valid(data), name


def test_every_field_has_a_description() -> None:
    for model in _models():
        for name, field in model.model_fields.items():
            assert field.description, f"{model.__name__}.{name}"


def test_doc_names_every_key_and_unsupported_entry() -> None:
    doc = DOC.read_text(encoding="utf-8")
    for model in _models():
        for name in model.model_fields:
            assert f"`{name}`" in doc, f"{model.__name__}.{name} is not in {DOC.name}"
    for pattern in UNSUPPORTED:
        assert f"`{pattern}`" in doc, pattern


def test_plain_numbers_read_by_yaml_1_2(tmp_path: Path) -> None:
    """The YAML 1.2 core schema (issue L): `1e9` and `.5` are numbers, `yes` is text."""
    path = tmp_path / "numbers.yaml"
    path.write_text(MINIMAL.replace("duration: 10", "duration: 1e2").replace(
        "set_speed_kph: 40", "set_speed_kph: .5e2"), encoding="utf-8")
    scenario = load_scenario(path)
    assert scenario.duration == 100.0
    assert scenario.driver.set_speed == pytest.approx(50 / 3.6)
    path.write_text(MINIMAL + "criteria: {completes: yes}\n", encoding="utf-8")
    with pytest.raises(ScenarioError, match=r"criteria\.completes: .*'yes'"):
        load_scenario(path)


@pytest.mark.parametrize(("text", "value"), [
    ("1e9", 1e9), (".5", 0.5), ("-2.5E-3", -2.5e-3), ("010", 10), ("0o17", 15), ("0x1f", 31),
    ("yes", "yes"), ("on", "on"), ("2024-01-01", "2024-01-01"), ("1_000", "1_000"),
    ("true", True), ("~", None), ("-.inf", -math.inf), ("[1e3, west]", [1000.0, "west"]),
])
def test_a_value_reads_by_the_core_schema(text: str, value: object) -> None:
    assert parse_value(text) == value


def test_doc_gives_every_bound() -> None:
    """Every size a file can ask for has its bound in the docs (issue L)."""
    from avsim.scenario import bounds

    doc = DOC.read_text(encoding="utf-8")
    for name in dir(bounds):
        if name.startswith("MAX_"):
            assert f"`{name}`" in doc, name


def test_a_file_over_its_size_bound_is_refused_unread(tmp_path: Path) -> None:
    path = _write(tmp_path, MINIMAL + "# " + "x" * 600_000 + "\n")
    with pytest.raises(ScenarioError, match=r"\(file\): over 524288 bytes: at most 524288$"):
        load_scenario(path)


def test_a_broken_centre_line_paints_the_road_for_a_pass() -> None:
    """`centre_line: broken` paints one broken yellow centre line (the planner's pass and
    tyres_in_lane read it); the default keeps the road's own double solid line (no paint)."""
    from world.hdmap import MarkKind, PaintColour

    segment = load_scenario("overtake_two_lane").world.road.segments[0]
    assert segment.paint is not None
    assert segment.paint.left_edge.kind is MarkKind.BROKEN
    assert segment.paint.left_edge.colour is PaintColour.YELLOW
    plain = load_scenario("overtake_two_lane", {"road.centre_line": "solid"})
    assert plain.world.road.segments[0].paint is None


def test_a_centre_line_of_another_kind_is_refused() -> None:
    error = _error("overtake_two_lane", {"road.centre_line": "dotted"})
    assert error.key == "road.centre_line" and "solid" in error.problem


@pytest.mark.parametrize(("path", "value", "check"), [
    ("sensors.gnss.preset", "rtk", lambda s: s.world.sensors.gnss.sigma < 0.1),
    ("stack.planner", "avsim", lambda s: s.stack.bundled),
])
def test_an_override_makes_the_optional_sections_on_its_way(
        tmp_path: Path, path: str, value: str, check: Any) -> None:
    """A file without `sensors:` or `stack:`: `--set sensors.gnss.preset=rtk` and
    `--planner` make the mappings on the way (validation still judges the keys)."""
    file = tmp_path / "bare.yaml"
    file.write_text(MINIMAL, encoding="utf-8")
    assert check(load_scenario(file, {path: value}))
    with pytest.raises(ScenarioError) as err:
        load_scenario(file, {"sensors.gnsss.preset": "rtk"})
    assert err.value.key.startswith("sensors.gnsss")

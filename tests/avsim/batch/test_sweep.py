"""The sweep grid: `--set PATH=V1,V2,...` read as YAML values, and their product."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from avsim.batch.sweep import Axis, SweepError, format_value, grid, parse_set, split_values


@pytest.mark.parametrize(
    ("text", "path", "values"),
    [
        ("actors.0.speed_kph=20,30,40", "actors.0.speed_kph", (20, 30, 40)),
        ("seed=1", "seed", (1,)),
        ("ego.set_speed_kph=2.5, 7", "ego.set_speed_kph", (2.5, 7)),
        ("actors.0.start=[2,1,west],[3, 1, west]", "actors.0.start",
         ([2, 1, "west"], [3, 1, "west"])),
        ("criteria.min_gap=r157,12", "criteria.min_gap", ("r157", 12)),
        ("road.buildings={density: 0.2, setback: 6},{density: 0.8, setback: 6}",
         "road.buildings", ({"density": 0.2, "setback": 6}, {"density": 0.8, "setback": 6})),
    ],
)
def test_a_set_is_a_key_path_and_yaml_values(text: str, path: str,
                                             values: tuple[object, ...]) -> None:
    axis = parse_set(text)
    assert axis == Axis(path, values)


@pytest.mark.parametrize(
    ("text", "problem"),
    [
        ("seed", "expected PATH=V1,V2,..."),
        ("=1,2", "expected PATH=V1,V2,..."),
        ("Actors.0.s=1", "not a dotted key path"),
        ("actors..s=1", "not a dotted key path"),
        ("seed=1,,2", "an empty value"),
        ("seed=", "an empty value"),
        ("seed=1,1", "a value is given twice"),
        ("seed=[1,2", "not a YAML value"),
    ],
)
def test_a_bad_set_names_itself_and_the_problem(text: str, problem: str) -> None:
    with pytest.raises(SweepError) as err:
        parse_set(text)
    assert f"--set {text}" in str(err.value)
    assert problem in str(err.value)


def test_commas_inside_brackets_do_not_split() -> None:
    assert split_values("[1,2],{a: 1, b: 2},3") == ["[1,2]", "{a: 1, b: 2}", "3"]


def test_the_grid_is_the_product_the_last_key_fastest() -> None:
    runs = grid([parse_set("a=1,2"), parse_set("b=x,y,z")])
    assert runs == [{"a": 1, "b": "x"}, {"a": 1, "b": "y"}, {"a": 1, "b": "z"},
                    {"a": 2, "b": "x"}, {"a": 2, "b": "y"}, {"a": 2, "b": "z"}]


def test_a_key_swept_twice_is_refused() -> None:
    with pytest.raises(SweepError, match="swept twice"):
        grid([parse_set("a=1,2"), parse_set("a=3")])


@pytest.mark.parametrize("value", [20, 2.5, "west", [2, 1, "west"], {"density": 0.5}])
def test_a_value_prints_as_it_is_written_and_reads_back(value: object) -> None:
    axis = parse_set(f"k={format_value(value)}")
    assert axis.values == (value,)


def test_results_compare_equal_with_non_finite_numbers() -> None:
    """A criterion's NaN threshold (no lead: no d_min) must not make two equal runs differ."""
    from avsim.batch.jobs import RunJob, RunOutcome, Status
    from avsim.batch.suite import comparable

    job = RunJob("a", "a.yaml", Path("out"))
    result = {"criteria": [{"name": "min_gap", "value": math.inf, "threshold": math.nan}],
              "metrics": {"min_gap": math.nan}, "sim_time": 5.0, "state_changes": []}
    one = RunOutcome(job, Status.PASSED, result)
    two = RunOutcome(job, Status.PASSED, json.loads(json.dumps(result)))
    assert comparable(one) == comparable(two)
    other = RunOutcome(job, Status.PASSED, {**result, "sim_time": 5.1})
    assert comparable(one) != comparable(other)


GRID_FILE = """\
format: avsim/1
name: grid_file
duration: 5
road: {lanes: 1, speed_limit_kph: 50, segments: [{straight: 300}]}
ego: {lane: 0, s: 20, speed_kph: 30, set_speed_kph: 30}
actors: [{id: lead, type: car, lane: 0, s: 80, speed_kph: 10}]
"""


def test_a_files_grid_gives_a_suite_one_run_per_point(tmp_path: Path) -> None:
    from avsim.batch.suite import suite_entries
    from avsim.scenario.load import load_scenario

    plain = tmp_path / "plain.yaml"
    plain.write_text(GRID_FILE, encoding="utf-8")
    gridded = tmp_path / "gridded.yaml"
    gridded.write_text(GRID_FILE + "grid:\n  ego.speed_kph: [20, 30]\n"
                       "  actors.0.offset: [-0.8, 0, 0.8]\n", encoding="utf-8")
    assert load_scenario(gridded).world.ego.speed == pytest.approx(30 / 3.6)  # its own values
    entries = suite_entries([str(plain), str(gridded)])
    assert entries[0] == (None, str(plain), {})
    assert [e[0] for e in entries[1:]] == [f"grid_file_{k:03d}" for k in range(6)]
    assert [e[2] for e in entries[1:]] == [
        {"ego.speed_kph": v, "actors.0.offset": o} for v in (20, 30) for o in (-0.8, 0, 0.8)]
    for _, path, overrides in entries[1:]:  # every point is a valid scenario
        point = load_scenario(path, overrides)
        assert point.world.actors[0].offset == overrides["actors.0.offset"]


def test_comma_joined_grid_keys_take_their_values_together(tmp_path: Path) -> None:
    from avsim.batch.suite import suite_entries
    from avsim.scenario.load import ScenarioError, load_scenario

    path = tmp_path / "tied.yaml"
    path.write_text(GRID_FILE + "grid:\n  ego.speed_kph, ego.set_speed_kph: [[20, 25], [40, 45]]\n"
                    "  seed: [1, 2]\n", encoding="utf-8")
    entries = suite_entries([str(path)])
    assert [e[2] for e in entries] == [
        {"ego.speed_kph": 20, "ego.set_speed_kph": 25, "seed": 1},
        {"ego.speed_kph": 20, "ego.set_speed_kph": 25, "seed": 2},
        {"ego.speed_kph": 40, "ego.set_speed_kph": 45, "seed": 1},
        {"ego.speed_kph": 40, "ego.set_speed_kph": 45, "seed": 2}]
    path.write_text(GRID_FILE + "grid:\n  ego.speed_kph, ego.set_speed_kph: [[20, 25], 40]\n",
                    encoding="utf-8")
    with pytest.raises(ScenarioError, match=r"grid\.ego\.speed_kph, ego\.set_speed_kph: each "
                       r"value must be a list of 2 \(one per key\)"):
        load_scenario(path)

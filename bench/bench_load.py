"""The worst a scenario file can cost to load: seconds from a path to a scenario or its
one-line error, for files built up to the loader's bounds.

The fuzzer (`tests/avsim/scenario/test_fuzz.py`) checks what every mutated file gets; this
times the largest of them, which the machines' load makes too noisy to assert in a test:
- an ALKS OpenSCENARIO file (4.6.2) with one element repeated until the file is refused
  by its element bound or is as large as its byte bound lets it be;
- its OpenDRIVE road, the same way;
- a bundled YAML scenario as long as its file bound allows (a road of many segments);
- a YAML file full of values nested as deep as allowed (`MAX_DEPTH`), up to its value bound:
  parsed, composed and validated to its one-line error;
- a YAML merge-key bomb as large as the file bound allows, refused by the value count
  while it is parsed (`avsim.scenario.yaml_events`);
- a town at its bounds (`MAX_TOWN_BLOCKS` x `MAX_TOWN_BLOCKS` blocks of `MAX_BLOCK`,
  `MAX_TOWN_LANES` lanes of `MAX_LANE_WIDTH`): the file loaded and the run built as
  `avsim run` builds it (the world with its buildings, lights, meshes and the LiDAR's
  Embree scene, the default sensors, the stack).

Target: each under 5 s on the reference machine (2 cores), the town's start under 15 s.
Best of `--repeat` loads (the town: of at most 2).
`make bench` runs it; `--json FILE` also writes the figures.
"""

from __future__ import annotations

import argparse
import copy
import json
import shutil
import tempfile
import time
import xml.etree.ElementTree as ET
from pathlib import Path

import yaml

from avsim.scenario.bounds import (
    MAX_BLOCK,
    MAX_DEPTH,
    MAX_LANE_WIDTH,
    MAX_TOWN_BLOCKS,
    MAX_TOWN_LANES,
    MAX_VALUES,
)
from avsim.scenario.bounds import MAX_FILE_BYTES as MAX_YAML_BYTES
from avsim.scenario.files import SCENARIO_DIR, read_raw
from avsim.scenario.load import ScenarioError, load_scenario
from avsim.scenario.openscenario.xmlread import MAX_ELEMENTS as MAX_XOSC_ELEMENTS
from avsim.scenario.openscenario.xmlread import MAX_FILE_BYTES as MAX_XOSC_BYTES
from world.map.opendrive.parse import MAX_FILE_BYTES as MAX_XODR_BYTES
from world.map.opendrive.xmltree import MAX_ELEMENTS as MAX_XODR_ELEMENTS

ALKS = (Path(__file__).parents[1] / "tests" / "data" / "alks" / "logical_scenarios"
        / "concrete_scenarios")
XOSC = "alks_scenario_4_6_2_lateral_detection_range_template.xosc"
ROAD = Path("road_networks") / "alks_road_straight.xodr"
MINIMAL_YAML = """\
format: avsim/1
name: bench
duration: 10
road: {lanes: 2, speed_limit_kph: 50, segments: [{straight: 200}]}
ego: {s: 20, set_speed_kph: 40}
"""
TARGET = 5.0  # [s]
TOWN_TARGET = 15.0  # [s] a town at its bounds, loaded and built


def best_load(path: Path, repeat: int) -> tuple[float, str]:
    """[s] the fastest of `repeat` loads of `path`, and what it gave."""
    best, outcome = float("inf"), ""
    for _ in range(repeat):
        start = time.perf_counter()
        try:
            load_scenario(path)
            outcome = "loaded"
        except ScenarioError as exc:
            outcome = str(exc).rsplit(": ", 1)[-1]
        best = min(best, time.perf_counter() - start)
    return best, outcome


def flood(source: Path, target: Path, max_elements: int, max_bytes: int) -> None:
    """`source` written to `target` with its shortest leaf element repeated until the file
    holds more than `max_elements` or is about to outgrow `max_bytes`."""
    tree = ET.parse(source)
    root = tree.getroot()
    parents = {child: parent for parent in root.iter() for child in parent}
    leaf = min((e for e in root.iter() if e is not root and len(e) == 0),
               key=lambda e: len(ET.tostring(e)))
    room = max_bytes - source.stat().st_size - 1024
    for _ in range(min(max_elements, room // len(ET.tostring(leaf)))):
        parents[leaf].append(copy.deepcopy(leaf))
    tree.write(target, encoding="unicode")


def huge_yaml(folder: Path) -> Path:
    """normal_driving with as many road segments as the file bound allows."""
    file = SCENARIO_DIR / "normal_driving.yaml"
    doc = read_raw(file)
    road = doc["road"]
    one = len(yaml.safe_dump(road["segments"][:1], width=1_000_000))
    road["segments"] = [copy.deepcopy(road["segments"][0])] * (MAX_YAML_BYTES // one - 100)
    path = folder / file.name
    path.write_text(yaml.safe_dump(doc, sort_keys=False, width=1_000_000), encoding="utf-8")
    return path


def expression_flood(alks: Path) -> Path:
    """An ALKS file whose parameters are as many expressions of `MAX_LENGTH` characters as
    one load may evaluate (`MAX_EXPRESSION_CHARS`), and one more: the worst expression work
    a file can ask for, refused at the budget."""
    from avsim.scenario.openscenario.expressions import MAX_LENGTH
    from avsim.scenario.openscenario.parameters import MAX_EXPRESSION_CHARS

    one = "${" + "+".join(["(-$A*2)"] * (MAX_LENGTH // 8)) + "}"
    decls = [f'<ParameterDeclaration name="P{k}" parameterType="double" value="{one}"/>'
             for k in range(MAX_EXPRESSION_CHARS // len(one) + 1)]
    text = (ALKS / XOSC).read_text(encoding="utf-8-sig").replace(
        "<ParameterDeclarations>", '<ParameterDeclarations><ParameterDeclaration name="A" '
        'parameterType="double" value="1.5"/>' + "".join(decls), 1)
    path = alks / "expressions.xosc"
    path.write_text(text, encoding="utf-8")
    return path


def worst_xodr(folder: Path) -> tuple[float, str]:
    """[s] the OpenDRIVE reader and route builder on the worst road within the reader's
    bounds: `MAX_GEOMETRIES` spiral records swinging between curvatures +-1 /m (the
    tightest allowed) over the longest route, refused by the arc spline's piece bound."""
    from tests.world.map.opendrive.roads import geometry_xml, road_xml, winding
    from world.map.opendrive import OpenDriveError, load_opendrive
    from world.map.opendrive.parse import MAX_GEOMETRIES, MAX_ROUTE_LENGTH
    from world.map.opendrive.route import build_route

    length = MAX_ROUTE_LENGTH / MAX_GEOMETRIES  # [m] each record
    geoms = winding(MAX_GEOMETRIES, length, 1.0)
    path = folder / "worst_spirals.xodr"
    path.write_text(road_xml("".join(geometry_xml(g) for g in geoms), MAX_ROUTE_LENGTH),
                    encoding="utf-8")
    start = time.perf_counter()
    try:
        build_route(load_opendrive(path))
        outcome = "loaded"
    except OpenDriveError as exc:
        outcome = exc.problem
    return time.perf_counter() - start, outcome


def deepest_yaml(folder: Path) -> Path:
    """A minimal scenario with an extra key holding values nested `MAX_DEPTH` deep, as many
    as `MAX_VALUES` lets it hold: read, composed and validated in full (then refused as an
    unknown key)."""
    inner = MAX_DEPTH - 2  # the file's mapping and the list of copies are two levels
    one = "[" * inner + "1" + "]" * inner
    copies = (MAX_VALUES - 100) // (inner + 1)
    path = folder / "deepest.yaml"
    path.write_text(MINIMAL_YAML + f"extra: [{', '.join([one] * copies)}]\n", encoding="utf-8")
    return path


def merge_bomb_yaml(folder: Path) -> Path:
    """A minimal scenario followed by merge keys of one 10-key anchor up to the file bound:
    refused by the value count partway through its parse."""
    head = MINIMAL_YAML + "a: &a {" + ", ".join(f"k{k}: {k}" for k in range(10)) + "}\n"
    line = "m{:06d}: {{<<: *a}}\n"
    count = (MAX_YAML_BYTES - len(head) - 100) // len(line.format(0))
    path = folder / "merge_bomb.yaml"
    path.write_text(head + "".join(line.format(k) for k in range(count)), encoding="utf-8")
    return path


def best_town_start(repeat: int) -> tuple[float, str]:
    """[s] the fastest of `repeat` starts of a town at its bounds (module doc), and its size."""
    from avsim.run.runner import Runner
    from world.core.quiet import quiet_c_output
    from world.sensors.setup import Profile

    overrides: dict[str, object] = {
        "town.blocks_x": MAX_TOWN_BLOCKS, "town.blocks_y": MAX_TOWN_BLOCKS,
        "town.block": MAX_BLOCK, "town.lanes": MAX_TOWN_LANES,
        "town.lane_width": MAX_LANE_WIDTH}
    best, outcome = float("inf"), ""
    for _ in range(repeat):
        start = time.perf_counter()
        scenario = load_scenario("town_route", overrides)
        with quiet_c_output():
            runner = Runner(scenario, None, Profile.DEFAULT, "inline")
        best = min(best, time.perf_counter() - start)
        outcome = f"{runner.world.client.getNumBodies()} bodies"
        with quiet_c_output():
            runner.world.close()
    return best, outcome


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args()
    figures: dict[str, float] = {}
    print(f"worst-case loads (best of {args.repeat}; target under {TARGET:.0f} s each)")
    with tempfile.TemporaryDirectory() as tmp:
        alks = Path(tmp) / "concrete_scenarios"
        shutil.copytree(ALKS, alks)
        flood(ALKS / XOSC, alks / XOSC, MAX_XOSC_ELEMENTS, MAX_XOSC_BYTES)
        figures["xosc_past_element_bound_s"], xosc = best_load(alks / XOSC, args.repeat)
        shutil.copyfile(ALKS / XOSC, alks / XOSC)
        flood(ALKS / ROAD, alks / ROAD, MAX_XODR_ELEMENTS, MAX_XODR_BYTES)
        figures["xodr_past_element_bound_s"], xodr = best_load(alks / XOSC, args.repeat)
        shutil.copyfile(ALKS / ROAD, alks / ROAD)
        figures["yaml_huge_entries_s"], yml = best_load(huge_yaml(Path(tmp)), args.repeat)
        figures["xosc_expression_budget_s"], expr = best_load(expression_flood(alks),
                                                             args.repeat)
        figures["xodr_worst_spirals_s"], spirals = worst_xodr(Path(tmp))
        figures["yaml_deepest_nesting_s"], deep = best_load(deepest_yaml(Path(tmp)),
                                                            args.repeat)
        figures["yaml_merge_bomb_refused_s"], bomb = best_load(merge_bomb_yaml(Path(tmp)),
                                                               args.repeat)
    figures["town_at_bounds_start_s"], town = best_town_start(min(args.repeat, 2))
    outcomes = (xosc, xodr, yml, expr, spirals, deep, bomb, town)
    for (key, value), outcome in zip(figures.items(), outcomes, strict=True):
        print(f"  {key:<28} {value:6.2f} s  {outcome[:60]}")
    if args.json:
        args.json.write_text(json.dumps(figures, indent=2) + "\n")


if __name__ == "__main__":
    main()

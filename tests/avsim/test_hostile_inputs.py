"""Hostile OpenSCENARIO / OpenDRIVE inputs as a user gives them to `avsim run`: each is the
one-line refusal (`avsim: error: <file>: <key>: <problem>`), exit 2, no traceback, nothing
written. The loaders' own tests check the bounds and messages in detail
(tests/avsim/scenario/openscenario/test_hostile_*.py, tests/world/map/opendrive/
test_hostile.py); these check that the command line keeps the promise for each.

Refusals run in-process (click's runner): they stop before the simulator starts. Files that
could block a reader (FIFOs) run in a subprocess with a deadline, so that a regression fails
instead of hanging the test session.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner, Result

from avsim.cli import EXIT_BAD_INPUT, main
from tests.world.map.opendrive.roads import geometry_xml, winding
from world.map.opendrive import arcspline

HERE = Path(__file__).parent
REPO = HERE.parents[1]
ALKS = HERE.parent / "data" / "alks" / "logical_scenarios" / "concrete_scenarios"
CUT_IN = "alks_scenario_4_4_1_cut_in_no_collision_template.xosc"
ROAD = Path("road_networks") / "alks_road_straight.xodr"
VEHICLES = Path("catalogs") / "vehicles" / "vehicle_catalog.xosc"
DEADLINE = 60.0  # [s] a subprocess that blocks on a FIFO is killed after it (and fails)

SPEED = 'name="Ego_InitSpeed_Ve0_kph" parameterType="double" value="60.0"'
LANE = 'name="CutInVehicle_InitPosition_RelativeLaneId" parameterType="integer" value="-1"'
STOP = '<Condition name="End" delay="10.0"'
EGO_LANE = '<LanePosition roadId="0" laneId="-4" offset="0.0" s="5.0">'
BOX = 'width="2.0" length="5.0" height="1.8"'
CUT_IN_AT = 'dLane="$CutInVehicle_InitPosition_RelativeLaneId" ds="${$Cut'
LOGIC_FILE = 'filepath="./road_networks/alks_road_straight.xodr"'
ROAD_ELEMENT = '<road name="Road" length="10000"'
PLAN_VIEW = ('<geometry s="0" x="0" y="0" hdg="0" length="10000">\n        <line />\n'
             '      </geometry>')


@pytest.fixture
def tree(tmp_path: Path) -> Path:
    """A copy of the ALKS folder (scenarios, catalogs, roads) to spoil."""
    copy = tmp_path / "alks"
    shutil.copytree(ALKS, copy, ignore=shutil.ignore_patterns("openPASS_Resources"))
    return copy


def _edit(tree: Path, file: Path | str, old: str, new: str) -> None:
    path = tree / file
    text = path.read_text(encoding="utf-8-sig")
    assert old in text, f"{old!r} not in {file}"
    path.write_text(text.replace(old, new), encoding="utf-8")


def _run(tree: Path, *extra: str) -> Result:
    out = tree.parent / "out"
    return CliRunner().invoke(main, ["run", str(tree / CUT_IN), "--out", str(out / "x.rrd"),
                                     "--profile", "none", "--no-progress", *extra])


def _refused(result: Result, tree: Path) -> str:
    """The one line of a bad-input refusal that wrote nothing."""
    assert result.exit_code == EXIT_BAD_INPUT, (result.exit_code, result.output,
                                                result.exception)
    assert result.exception is None or isinstance(result.exception, SystemExit)
    assert "Traceback" not in result.stderr and result.stdout == ""
    lines = result.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("avsim: error: "), result.stderr
    assert not (tree.parent / "out").exists()
    return lines[0]


# ---- crashes, silently accepted values: the scenario file --------------------------------

SCENARIO_EDITS = {
    "floor_overflow": (SPEED, SPEED.replace("60.0", "${floor(1e308*10)}"),
                       "*: result out of range"),
    "round_infinity": (SPEED, SPEED.replace("60.0", "${round(1e999)}"), "result out of range"),
    "sin_infinity": (SPEED, SPEED.replace("60.0", "${sin(1e999)}"), "result out of range"),
    "int_5000_digits": (LANE, LANE.replace("-1", "-" + "1" * 5000),
                        "an integer of 5000 digits: at most 20"),
    "million_terms": (SPEED, SPEED.replace("60.0", "${" + "+".join(["1"] * 1_000_000) + "}"),
                      "characters evaluated (at most"),
    "position_nan": (EGO_LANE, EGO_LANE.replace('s="5.0"', 's="NaN"'),
                     "s: expected a finite number"),
    "stop_trigger_1e999": (STOP, STOP.replace("10.0", "1e999"),
                           "delay: expected a finite number"),
    "inside_the_ego": (CUT_IN_AT, 'dLane="0" ds="1" x="${$Cut', "overlaps the ego (Ego)"),
    "name_300000": ('<ScenarioObject name="CutInVehicle">',
                    '<ScenarioObject name="' + "x" * 300_000 + '">',
                    "name: 300000 characters: at most"),
    "logic_file_etc_passwd": (LOGIC_FILE, 'filepath="/etc/passwd"',
                              "filepath: /etc/passwd is outside the scenario's folder"),
    "logic_file_up": (LOGIC_FILE, 'filepath="../../../../../../etc/passwd"',
                      "is outside the scenario's folder and the search paths"),
    "catalog_anywhere": ('path="./catalogs/vehicles"', 'path="../.."', "is outside"),
}


@pytest.mark.parametrize("case", sorted(SCENARIO_EDITS))
def test_a_hostile_value_in_the_scenario_is_refused_in_one_line(tree: Path, case: str) -> None:
    old, new, problem = SCENARIO_EDITS[case]
    _edit(tree, CUT_IN, old, new)
    line = _refused(_run(tree), tree)
    assert line.startswith(f"avsim: error: {tree / CUT_IN}: ")
    assert problem in line


@pytest.mark.parametrize(("size", "problem"), [
    ('width="2.0" length="0" height="1.8"', "length: must be > 0 and <= 30 m, got 0"),
    ('width="-1.8" length="5.0" height="1.8"', "width: must be > 0 and <= 5 m, got -1.8"),
    ('width="2.0" length="1e9" height="1.8"', "length: must be > 0 and <= 30 m, got 1000000000"),
])
def test_a_bounding_box_out_of_bounds_is_refused_in_one_line(tree: Path, size: str,
                                                             problem: str) -> None:
    _edit(tree, VEHICLES, BOX, size)
    assert problem in _refused(_run(tree), tree)


def test_a_5000_digit_integer_parameter_on_the_command_line_is_refused(tree: Path) -> None:
    line = _refused(_run(tree, "--param",
                         "CutInVehicle_InitPosition_RelativeLaneId=-" + "1" * 5000), tree)
    assert "5000 digits" in line


# ---- files: symlink loops, devices, the road ---------------------------------------------


def test_a_logic_file_that_is_a_symlink_loop_is_refused_in_one_line(tree: Path) -> None:
    (tree / "loop_a.xodr").symlink_to(tree / "loop_b.xodr")
    (tree / "loop_b.xodr").symlink_to(tree / "loop_a.xodr")
    _edit(tree, CUT_IN, LOGIC_FILE, 'filepath="loop_a.xodr"')
    assert "RoadNetwork/LogicFile: filepath: a symlink loop" in _refused(_run(tree), tree)


@pytest.mark.parametrize("search", [False, True])
def test_a_catalog_folder_holding_a_link_to_dev_zero_is_refused(tree: Path,
                                                                search: bool) -> None:
    """Outside the tree it is refused by where it leads; allowed by --search-path /dev, by
    what it is (a device is never read)."""
    (tree / "catalogs" / "vehicles" / "zero.xosc").symlink_to("/dev/zero")
    line = _refused(_run(tree, *(["--search-path", "/dev"] if search else [])), tree)
    assert "zero.xosc: (file): " in line
    assert ("not a regular file (a character device)" if search else "is outside") in line


@pytest.mark.parametrize(("old", "new", "problem"), [
    ('length="10000"', 'length="0"', "length must be > 0"),
    (PLAN_VIEW, PLAN_VIEW + '<geometry s="10000" x="10000.42" y="0" hdg="0" length="10">'
     '<line/></geometry>', "/planView/geometry[2]: starts 0.42 m from where geometry[1] ends"),
    (PLAN_VIEW, PLAN_VIEW + '<geometry s="10000" x="10000" y="0" hdg="0.002" length="10">'
     '<line/></geometry>', "starts heading 0.002 rad off where geometry[1] ends"),
    (PLAN_VIEW, PLAN_VIEW + '<geometry s="9000" x="10000" y="0" hdg="0" length="10">'
     '<line/></geometry>', "/planView/geometry[2]: starts at s = 9000 m"),
])
def test_a_degenerate_road_is_refused_in_one_line(tree: Path, old: str, new: str,
                                                  problem: str) -> None:
    _edit(tree, ROAD, old, new)
    if old == PLAN_VIEW:  # the road's length is its records' (so only the joint is wrong)
        _edit(tree, ROAD, ROAD_ELEMENT, ROAD_ELEMENT.replace("10000", "10010"))
    line = _refused(_run(tree), tree)
    assert str(ROAD.name) in line and problem in line


def test_a_thousand_spiral_records_are_refused_with_bounded_work(
        tree: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """1,000 spirals swinging between +-1 /m over 20 km: refused after at most about twice
    the arc spline's piece bound of piece evaluations (counted, not timed)."""
    records = "".join(geometry_xml(g) for g in winding(1000, 20.0, 1.0))
    _edit(tree, ROAD, PLAN_VIEW, records)
    _edit(tree, ROAD, ROAD_ELEMENT, ROAD_ELEMENT.replace("10000", "20000"))
    calls: list[int] = []
    real = arcspline.piece_deviation

    def counted(*args: object) -> float:
        calls.append(1)
        return real(*args)  # type: ignore[arg-type]

    monkeypatch.setattr(arcspline, "piece_deviation", counted)
    line = _refused(_run(tree), tree)
    assert str(ROAD.name) in line
    assert len(calls) <= 2 * (arcspline.MAX_PIECES + 1) + 1000


# ---- FIFOs: refused, never blocked on (a subprocess with a deadline) ---------------------


def _fifo_in(tree: Path, where: str) -> Path:
    """The scenario to run, with a FIFO (no writer) as its `where` file."""
    if where == "scenario":
        os.mkfifo(tree / "fifo.xosc")
        return tree / "fifo.xosc"
    if where == "catalog":
        os.mkfifo(tree / "catalogs" / "vehicles" / "pipe.xosc")
    if where == "road":
        (tree / ROAD).unlink()
        os.mkfifo(tree / ROAD)
    return tree / CUT_IN


@pytest.mark.parametrize("where", ["scenario", "catalog", "road"])
def test_a_fifo_is_refused_without_blocking(tree: Path, where: str) -> None:
    scenario = _fifo_in(tree, where)
    work = tree.parent / "work"
    work.mkdir()
    proc = subprocess.run(
        [sys.executable, "-m", "avsim.cli", "run", str(scenario), "--profile", "none",
         "--no-progress"], cwd=work, capture_output=True, text=True, timeout=DEADLINE,
        check=False, env={**os.environ, "PYTHONPATH": str(REPO)})
    assert proc.returncode == EXIT_BAD_INPUT, proc.stderr
    assert proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr
    assert proc.stderr.startswith("avsim: error: ")
    assert proc.stdout == "" and list(work.iterdir()) == []

"""Hostile files around an OpenSCENARIO scenario: catalogs and roads that are devices, FIFOs,
symlink loops, or lie outside the scenario's folder tree and the user's search paths; each
is refused with the one-line error, never read without bound nor blocked on."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from avsim.scenario.errors import ScenarioError
from avsim.scenario.load import load_scenario
from avsim.scenario.openscenario.catalogs import MAX_CATALOG_FILES
from avsim.scenario.openscenario.references import MAX_SEARCH_PATHS
from avsim.scenario.openscenario.to_yaml import convert_xosc

ALKS = Path(__file__).parents[3] / "data" / "alks" / "logical_scenarios" / "concrete_scenarios"
CUT_IN = "alks_scenario_4_4_1_cut_in_no_collision_template.xosc"
ROAD = 'filepath="./road_networks/alks_road_straight.xodr"'
VEHICLES = 'path="./catalogs/vehicles"'


@pytest.fixture
def tree(tmp_path: Path) -> Path:
    """A copy of the ALKS folder (scenarios, catalogs, roads) to spoil."""
    copy = tmp_path / "alks"
    shutil.copytree(ALKS, copy, ignore=shutil.ignore_patterns("openPASS_Resources"))
    return copy


def _refusal(path: Path, **kwargs: object) -> str:
    with pytest.raises(ScenarioError) as err:
        load_scenario(path, **kwargs)  # type: ignore[arg-type]
    message = str(err.value)
    assert "\n" not in message
    return message


def _edit(tree: Path, old: str, new: str) -> Path:
    path = tree / CUT_IN
    text = path.read_text(encoding="utf-8-sig")
    assert old in text
    path.write_text(text.replace(old, new), encoding="utf-8")
    return path


def test_every_vendored_alks_file_loads_with_its_tree_alone() -> None:
    files = sorted(ALKS.glob("alks_scenario_*.xosc"))
    assert len(files) == 15
    for file in files:
        assert load_scenario(file).story is not None


def test_a_catalog_file_linked_to_dev_zero_is_refused(tree: Path) -> None:
    (tree / "catalogs" / "vehicles" / "zero.xosc").symlink_to("/dev/zero")
    assert "zero.xosc: (file): /dev/zero is outside" in _refusal(tree / CUT_IN)
    message = _refusal(tree / CUT_IN, search_paths=(Path("/dev"),))  # allowed, yet not read
    assert message.endswith("zero.xosc: (file): not a regular file (a character device)")


def test_a_catalog_fifo_is_refused_without_blocking(tree: Path) -> None:
    os.mkfifo(tree / "catalogs" / "vehicles" / "pipe.xosc")
    assert "pipe.xosc: (file): not a regular file (a FIFO)" in _refusal(tree / CUT_IN)


def test_the_scenario_file_itself_linked_to_dev_zero_is_refused(tmp_path: Path) -> None:
    link = tmp_path / "zero.xosc"
    link.symlink_to("/dev/zero")
    assert _refusal(link) == f"{link}: (file): not a regular file (a character device)"


def test_too_many_catalog_files_are_refused(tree: Path) -> None:
    folder = tree / "catalogs" / "vehicles"
    for k in range(MAX_CATALOG_FILES + 1):
        (folder / f"c{k:04d}.xosc").write_text("<x/>", encoding="utf-8")
    message = _refusal(tree / CUT_IN)
    assert f"VehicleCatalog/Directory: over {MAX_CATALOG_FILES} catalog files" in message


def test_a_road_that_is_a_symlink_loop_is_the_one_line_error(tree: Path) -> None:
    (tree / "loop_a.xodr").symlink_to(tree / "loop_b.xodr")
    (tree / "loop_b.xodr").symlink_to(tree / "loop_a.xodr")
    path = _edit(tree, ROAD, 'filepath="loop_a.xodr"')
    message = _refusal(path)
    assert "RoadNetwork/LogicFile: filepath: a symlink loop" in message


@pytest.mark.parametrize("written", ["/etc/passwd", "../../../../../../etc/passwd",
                                     "./road_networks/../../outside.xodr"])
def test_a_road_outside_the_tree_is_refused(tree: Path, written: str) -> None:
    (tree.parent / "outside.xodr").write_text("<OpenDRIVE/>", encoding="utf-8")
    message = _refusal(_edit(tree, ROAD, f'filepath="{written}"'))
    assert "/OpenSCENARIO/RoadNetwork/LogicFile: filepath: " in message
    assert "is outside the scenario's folder and the search paths" in message


def test_a_symlink_that_leads_out_is_refused_unless_a_search_path_allows(
        tree: Path, tmp_path: Path) -> None:
    roads = tmp_path / "roads"
    shutil.move(tree / "road_networks", roads)
    (tree / "road_networks").symlink_to(roads)  # the same written path, now leading out
    message = _refusal(tree / CUT_IN)
    assert f"filepath: {roads / 'alks_road_straight.xodr'} is outside" in message
    assert load_scenario(tree / CUT_IN, search_paths=(roads,)).world.road is not None


def test_a_search_path_finds_what_the_tree_lacks(tree: Path) -> None:
    shutil.rmtree(tree / "catalogs")
    message = _refusal(tree / CUT_IN)
    assert "catalog directory not found" in message
    scenario = load_scenario(tree / CUT_IN, search_paths=(ALKS,))  # ./catalogs of ALKS
    assert len(scenario.world.actors) == 1


def test_a_catalog_directory_outside_is_refused(tree: Path) -> None:
    path = _edit(tree, VEHICLES, 'path="../.."')
    message = _refusal(path)
    assert "VehicleCatalog/Directory: path: " in message and "is outside" in message


def test_too_many_search_paths_are_refused(tree: Path) -> None:
    many = tuple(tree for _ in range(MAX_SEARCH_PATHS + 1))
    message = _refusal(tree / CUT_IN, search_paths=many)
    assert f": --search-path: {MAX_SEARCH_PATHS + 1} search paths: at most" in message


def test_a_sidecar_linked_out_is_refused_but_criteria_given_are_the_users(
        tree: Path, tmp_path: Path) -> None:
    elsewhere = tmp_path / "elsewhere.criteria.yaml"
    elsewhere.write_text("duration: 7\n", encoding="utf-8")
    beside = tree / CUT_IN.replace(".xosc", ".criteria.yaml")
    beside.symlink_to(elsewhere)
    assert "the sidecar: " in _refusal(tree / CUT_IN) and "is outside" in _refusal(tree / CUT_IN)
    assert load_scenario(tree / CUT_IN, criteria_file=elsewhere).duration == 7.0
    assert load_scenario(tree / CUT_IN, search_paths=(tmp_path,)).duration == 7.0


def test_convert_takes_search_paths(tree: Path) -> None:
    shutil.rmtree(tree / "road_networks")
    with pytest.raises(ScenarioError):
        convert_xosc(tree / CUT_IN)
    assert convert_xosc(tree / CUT_IN, None, (ALKS,)).document["format"] == "avsim/1"


@pytest.mark.parametrize("command", ["run", "convert"])
def test_the_cli_refuses_a_road_outside_in_one_line(tree: Path, tmp_path: Path,
                                                    command: str) -> None:
    path = _edit(tree, ROAD, 'filepath="/etc/passwd"')
    work = tmp_path / "work"
    work.mkdir()
    extra = ("--no-progress", "--profile", "none") if command == "run" else ()
    proc = subprocess.run(
        [sys.executable, "-m", "avsim.cli", command, str(path), *extra,
         "--search-path", str(ALKS)],
        cwd=work, capture_output=True, text=True, timeout=120, check=False,
        env={**os.environ, "PYTHONPATH": str(Path(__file__).parents[4])})
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr
    assert proc.stderr.startswith(f"avsim: error: {path}: line ")
    assert "RoadNetwork/LogicFile: filepath: /etc/passwd is outside" in proc.stderr
    assert proc.stdout == "" and list(work.iterdir()) == []


def test_a_road_name_too_long_for_the_file_system_is_one_line(tree: Path) -> None:
    message = _refusal(_edit(tree, ROAD, 'filepath="' + "x" * 999 + '"'))
    assert "RoadNetwork/LogicFile: road network file not found" in message

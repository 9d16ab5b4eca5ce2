"""OpenSCENARIO files in batches, as a user runs them (subprocesses): a sweep over one ALKS
scenario's declared parameter (its constraint groups checked before anything runs), and a
suite mixing a `.xosc` file with a YAML scenario."""

from __future__ import annotations

import csv
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from tests.avsim.invoke import invoke

pytestmark = pytest.mark.slow
HERE = Path(__file__).parents[1]
ALKS = HERE.parent / "data" / "alks" / "logical_scenarios" / "concrete_scenarios"
CUT_IN = ALKS / "alks_scenario_4_4_1_cut_in_no_collision_template.xosc"
TRIGGERS = (20, 40)  # [m] CutInVehicle_HeadwayDistanceTrigger_dx0_m, >= 0 by its constraint
TIMEOUT = 600.0  # [s]


def avsim(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    env = {k: v for k, v in os.environ.items() if k != "RAY_ADDRESS"}
    return subprocess.run([sys.executable, "-m", "avsim.cli", *args], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=TIMEOUT, check=False)


@pytest.fixture(scope="module")
def work(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("xosc_batch")


@pytest.fixture(scope="module")
def swept(work: Path) -> subprocess.CompletedProcess[str]:
    """The cut-in's trigger distance swept; 14 s each (the cut-in starts within 10 s),
    map and GNSS only (no perception is judged here)."""
    return avsim("sweep", str(CUT_IN), "--param",
                 "CutInVehicle_HeadwayDistanceTrigger_dx0_m=" + ",".join(map(str, TRIGGERS)),
                 "--set", "duration=14", "--profile", "none", "--jobs", "2",
                 "--no-snapshots", "--out", "sweep", cwd=work)


def test_a_sweep_over_a_declared_parameter_runs(swept: subprocess.CompletedProcess[str],
                                                work: Path) -> None:
    assert swept.returncode in (0, 1), swept.stderr
    out = work / "sweep"
    with (out / "sweep.csv").open(newline="") as f:
        rows = list(csv.DictReader(f))
    column = "parameters.CutInVehicle_HeadwayDistanceTrigger_dx0_m"
    assert sorted(int(r[column]) for r in rows) == list(TRIGGERS)
    collisions = {}
    for run in json.loads((out / "results.json").read_text()):
        story = {e["element"]: e["fired_at"] for e in run["result"]["story"]}
        assert story["CutInAction"] == pytest.approx(9.2, abs=0.1)  # 10 s after the start
        trigger = run["overrides"]["parameters.CutInVehicle_HeadwayDistanceTrigger_dx0_m"]
        collisions[trigger] = run["result"]["metrics"]["collisions"]
    # the car cuts in 20 m or 40 m ahead of a stack that cannot see it (map and GNSS only):
    # the parameter changed the situation
    assert collisions == {20: 1.0, 40: 0.0}


def test_a_value_outside_the_constraint_groups_is_refused_before_any_run(work: Path) -> None:
    out = invoke("sweep", str(CUT_IN), "--param",
                 "CutInVehicle_HeadwayDistanceTrigger_dx0_m=20,-5", "--profile", "none",
                 "--out", "refused", cwd=work)
    assert out.returncode == 2 and out.stdout == ""
    assert out.stderr.count("\n") == 1
    assert "CutInVehicle_HeadwayDistanceTrigger_dx0_m = -5: breaks greaterOrEqual 0" \
        in out.stderr
    assert not (work / "refused").exists()


def test_a_suite_mixes_openscenario_and_yaml_files(work: Path) -> None:
    folder = work / "mixed"
    folder.mkdir()
    text = CUT_IN.read_text(encoding="utf-8-sig")  # its road and catalogs: ./ of ALKS
    (folder / "cut_in.xosc").write_text(text, encoding="utf-8")
    (folder / "cut_in.criteria.yaml").write_text("duration: 5\n", encoding="utf-8")
    shutil.copy(HERE / "batch_scenarios" / "follow.yaml", folder / "follow.yaml")
    out = avsim("suite", str(folder), "--profile", "none", "--jobs", "2", "--no-snapshots",
                "--out", "suite", "--search-path", str(ALKS), cwd=work)  # to the workers
    assert out.returncode in (0, 1), out.stderr
    runs = json.loads((work / "suite" / "results.json").read_text())
    names = sorted(run["result"]["scenario"] for run in runs)
    assert names == ["cut_in", "follow"]  # the sidecar is not taken for a scenario
    xosc = next(run["result"] for run in runs if run["result"]["scenario"] == "cut_in")
    assert xosc["sim_time"] == pytest.approx(5.0)  # the sidecar's duration
    assert (work / "suite" / "junit.xml").exists() and (work / "suite" / "summary.md").exists()

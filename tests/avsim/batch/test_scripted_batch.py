"""`--ego scripted` through the batch engine: `suite`, `sweep`, `campaign` and a
distribution file's runs load and run each scenario with the file's own actions moving the
car under test (`RunJob.ego`), say so in every result and report, replay from `--dry-run`
and resume only a run of the same ego mode. A YAML scenario is refused before any run.

The runs are short (1 s or less simulated) and read no sensors (profile none). The commands
run in this process (`tests.avsim.invoke`): the batch's workers are still processes, forked
from one forkserver for the module instead of one per command."""

from __future__ import annotations

import json
import shutil
import xml.etree.ElementTree as ET
from dataclasses import replace
from pathlib import Path

import pytest

from avsim.batch.jobs import RunJob
from avsim.batch.resume import run_key
from avsim.batch.suite import plan, run_command, suite_entries
from avsim.scenario.errors import ScenarioError
from tests.avsim.invoke import invoke
from tests.avsim.run.test_scripted_ego import ACTIVATE, OFFSET

ROOT = Path(__file__).parents[3]
EXAMPLES = ROOT / "docs" / "examples"
MINIMAL = EXAMPLES / "minimal.xosc"
ALKS = ROOT / "tests" / "data" / "alks" / "logical_scenarios" / "concrete_scenarios"
CUT_IN = ALKS / "alks_scenario_4_4_1_cut_in_no_collision_template.xosc"
NCAP = ROOT / "tests" / "data" / "ncap"
CCFHOS = NCAP / "OpenSCENARIO" / "NCAP" / "AEB_C2C_2023" / "Variations" \
    / "NCAP_AEB_C2C_CCFhos_Variation_2023.xosc"  # two runs (two GVT speeds)
YAML = ROOT / "scenarios" / "cut_in.yaml"
CAMPAIGN = ROOT / "scenarios" / "campaigns" / "cut_in.yaml"


@pytest.fixture
def offset(tmp_path: Path) -> Path:
    """The ALKS cut-in whose Ego takes a lane offset at 3 s: the stack refuses a motion
    action on its car (it is not its driver's input), a scripted ego plays it; so this file
    loads only where the ego mode reached the loader."""
    text = CUT_IN.read_text(encoding="utf-8-sig")
    assert ACTIVATE in text
    path = tmp_path / "ego_offset.xosc"
    path.write_text(text.replace(ACTIVATE, OFFSET), encoding="utf-8")
    return path


# ---- the plan (no run) ----------------------------------------------------------------------


def test_a_scripted_plan_loads_each_file_for_its_ego_and_carries_it(
        offset: Path, tmp_path: Path) -> None:
    scenarios = [str(MINIMAL), str(offset)]
    with pytest.raises(ScenarioError, match="LaneOffsetAction on the car under test"):
        plan(suite_entries(scenarios, search_paths=[ALKS]), tmp_path, "fast",
             search_paths=[ALKS])
    entries = suite_entries(scenarios, search_paths=[ALKS], ego="scripted")
    jobs = plan(entries, tmp_path, "fast", search_paths=[ALKS], ego="scripted")
    assert [(job.ego, job.profile) for job in jobs] == [("scripted", "none")] * 2
    assert all(job.scripted for job in jobs)


def test_a_dry_run_line_replays_the_scripted_run(offset: Path, tmp_path: Path) -> None:
    job, = plan(suite_entries([str(offset)], search_paths=[ALKS], ego="scripted"), tmp_path,
                "default", search_paths=[ALKS], ego="scripted")
    line = run_command(job)
    assert "--ego scripted --profile none" in line
    stack, = plan(suite_entries([str(MINIMAL)]), tmp_path, "fast")
    assert "--ego" not in run_command(stack)  # the stack is `run`'s default


def test_the_resume_key_tells_a_scripted_run_from_a_stack_run(tmp_path: Path) -> None:
    job = RunJob("minimal", str(MINIMAL), tmp_path, {"duration": 1.0}, "none")
    scripted = replace(job, ego="scripted")
    assert run_key(job, "code") != run_key(scripted, "code")
    assert run_key(scripted, "code") == run_key(replace(job, ego="scripted"), "code")


# ---- refusals: one line, exit 2, nothing written ------------------------------------------


@pytest.mark.parametrize("args", [
    ("suite", str(YAML)),
    ("sweep", str(YAML), "--set", "duration=1,2"),
    ("campaign", str(CAMPAIGN), "--n", "2"),
])
def test_a_yaml_scenario_with_a_scripted_ego_is_refused_before_any_run(
        args: tuple[str, ...], tmp_path: Path) -> None:
    proc = invoke(*args, "--ego", "scripted", "--out", "out", cwd=tmp_path)
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.startswith("avsim: error: ") and proc.stderr.count("\n") == 1
    assert "ego: --ego scripted is for OpenSCENARIO files" in proc.stderr
    assert proc.stdout == ""
    assert list(tmp_path.iterdir()) == []


def test_suite_dry_run_prints_scripted_runs(offset: Path) -> None:
    proc = invoke("suite", str(MINIMAL), str(offset), "--ego", "scripted", "--search-path",
                  str(ALKS), "--dry-run", "--out", "out", cwd=offset.parent)
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert len(lines) == 2
    assert all("--ego scripted --profile none" in line for line in lines)
    assert not (offset.parent / "out").exists()


# ---- runs -----------------------------------------------------------------------------------


def _results(out: Path) -> list[dict[str, object]]:
    runs = json.loads((out / "results.json").read_text(encoding="utf-8"))
    assert isinstance(runs, list)
    return runs


def _assert_scripted(out: Path, runs: list[dict[str, object]]) -> None:
    """Every run finished scripted at profile none, and the reports say so."""
    for run in runs:
        result = run["result"]
        assert isinstance(result, dict), run
        assert (run["ego"], result["ego"], result["profile"]) == ("scripted", "scripted",
                                                                  "none")
    summary = (out / "summary.md").read_text(encoding="utf-8")
    assert summary.count(", profile none, ego scripted") == len(runs)
    root = ET.parse(out / "junit.xml").getroot()
    egos = [p.attrib["value"] for p in root.iter("property") if p.attrib["name"] == "ego"]
    assert egos == ["scripted"] * len(runs)


def test_a_suite_of_two_openscenario_files_runs_scripted(offset: Path) -> None:
    out = offset.parent / "suite"
    proc = invoke("suite", str(MINIMAL), str(offset), "--ego", "scripted", "--set",
                  "duration=1", "--search-path", str(ALKS), "--jobs", "1", "--no-snapshots",
                  "--out", str(out), cwd=offset.parent)
    assert proc.returncode in (0, 1), proc.stderr
    runs = _results(out)
    assert [r["name"] for r in runs] == ["minimal", "ego_offset"]
    _assert_scripted(out, runs)
    assert all(r["result"]["sim_time"] == pytest.approx(1.0) for r in runs)  # type: ignore[index]


def test_a_sweep_over_a_parameter_runs_scripted(tmp_path: Path) -> None:
    for name in ("minimal.xosc", "straight.xodr"):
        shutil.copy(EXAMPLES / name, tmp_path / name)
    out = tmp_path / "sweep"
    proc = invoke("sweep", str(tmp_path / "minimal.xosc"), "--param", "Speed_kph=40,50",
                  "--set", "duration=1", "--ego", "scripted", "--jobs", "1",
                  "--no-snapshots", "--out", str(out), cwd=tmp_path)
    assert proc.returncode in (0, 1), proc.stderr
    runs = _results(out)
    assert [r["overrides"]["parameters.Speed_kph"] for r in runs] == [40, 50]  # type: ignore[index]
    _assert_scripted(out, runs)
    # the swept Init speed is the scripted car's, held (no stack, no set speed to reach)
    speeds = [r["result"]["metrics"]["max_speed"] for r in runs]  # type: ignore[index]
    assert speeds == [pytest.approx(40 / 3.6), pytest.approx(50 / 3.6)]


def test_a_distribution_file_runs_every_permutation_scripted(tmp_path: Path) -> None:
    out = tmp_path / "dist"
    proc = invoke("run", str(CCFHOS), "--ego", "scripted", "--search-path", str(NCAP),
                  "--set", "duration=0.5", "--out", str(out), "--no-progress",
                  cwd=tmp_path)
    assert proc.returncode in (0, 1), proc.stderr
    runs = _results(out)
    assert [r["name"] for r in runs] == ["ncap_aeb_c2c_ccfhos_variation_2023_p0",
                                         "ncap_aeb_c2c_ccfhos_variation_2023_p1"]
    _assert_scripted(out, runs)

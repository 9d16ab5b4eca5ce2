"""An OpenSCENARIO ParameterValueDistribution file through the batch engine: its runs as
suite entries, and `avsim run DIST.xosc` end to end (every run into --out, or one with
--permutation), in this process (`tests.avsim.invoke`)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from avsim.batch.suite import BatchError, collect_scenarios, suite_entries
from tests.avsim.invoke import invoke

EXAMPLES = Path(__file__).parents[3] / "docs" / "examples"
DIST = """<?xml version="1.0" encoding="utf-8"?>
<OpenSCENARIO>
  <FileHeader revMajor="1" revMinor="2" date="2026-01-01T00:00:00" author="avsim"
              description="two speeds of minimal.xosc"/>
  <ParameterValueDistribution>
    <ScenarioFile filepath="minimal.xosc"/>
    <Deterministic>
      <DeterministicSingleParameterDistribution parameterName="Speed_kph">
        <DistributionRange stepWidth="10">
          <Range lowerLimit="40" upperLimit="50"/>
        </DistributionRange>
      </DeterministicSingleParameterDistribution>
      <DeterministicSingleParameterDistribution parameterName="Deceleration_mps2">
        <DistributionSet><Element value="3"/></DistributionSet>
      </DeterministicSingleParameterDistribution>
    </Deterministic>
  </ParameterValueDistribution>
</OpenSCENARIO>
"""


@pytest.fixture
def dist(tmp_path: Path) -> Path:
    for name in ("minimal.xosc", "straight.xodr"):
        shutil.copy(EXAMPLES / name, tmp_path / name)
    path = tmp_path / "Two-Speeds.xosc"
    path.write_text(DIST)
    return path


def test_a_distribution_is_one_suite_entry_per_run(dist: Path) -> None:
    entries = suite_entries(collect_scenarios([str(dist)]), {"duration": 2})
    scenario = str((dist.parent / "minimal.xosc").resolve())
    assert entries == [
        ("two_speeds_p0", scenario, {"duration": 2, "parameters.Speed_kph": "40",
                                     "parameters.Deceleration_mps2": "3"}),
        ("two_speeds_p1", scenario, {"duration": 2, "parameters.Speed_kph": "50",
                                     "parameters.Deceleration_mps2": "3"}),
    ]


def test_a_folder_with_a_distribution_runs_its_runs_and_its_scenarios(dist: Path) -> None:
    entries = suite_entries(collect_scenarios([str(dist.parent)]))
    assert [name for name, _, _ in entries] == ["two_speeds_p0", "two_speeds_p1", None]


def test_an_override_of_a_distributed_parameter_is_refused(dist: Path) -> None:
    with pytest.raises(BatchError, match=r"parameters\.Speed_kph: the distribution sets"):
        suite_entries([str(dist)], {"parameters.Speed_kph": 30})


def test_run_a_distribution_runs_every_run_into_out(dist: Path) -> None:
    out = dist.parent / "out"
    proc = invoke("run", str(dist), "--profile", "none", "--set", "duration=1",
                  "--out", str(out), "--no-progress", cwd=dist.parent)
    assert proc.returncode in (0, 1), proc.stderr
    results = json.loads((out / "results.json").read_text())
    assert [(r["name"], r["overrides"]["parameters.Speed_kph"]) for r in results] == [
        ("two_speeds_p0", "40"), ("two_speeds_p1", "50")]
    assert all(r["result"]["sim_time"] == pytest.approx(1.0) for r in results)
    summary = (out / "summary.md").read_text()
    assert "| `duration=1, Speed_kph=40, Deceleration_mps2=3` |" in summary


def test_run_one_permutation(dist: Path) -> None:
    out = dist.parent / "one.rrd"
    proc = invoke("run", str(dist), "--permutation", "1", "--profile", "none", "--set",
                  "duration=1", "--out", str(out), "--no-progress", cwd=dist.parent)
    assert proc.returncode in (0, 1), proc.stderr
    assert "run 1 of 2: Speed_kph=50, Deceleration_mps2=3" in proc.stderr
    assert json.loads(out.with_suffix(".json").read_text())["sim_time"] == pytest.approx(1.0)


@pytest.mark.parametrize(("args", "problem"), [
    (("--permutation", "2"), "--permutation: 2: the file describes 2 runs (0 to 1)"),
    (("--json", "x.json"), "--json / --plot: a distribution file makes several runs"),
    (("--param", "Speed_kph=30"), "parameters.Speed_kph: the distribution sets this"),
])
def test_run_a_distribution_refuses_in_one_line(dist: Path, args: tuple[str, ...],
                                                problem: str) -> None:
    proc = invoke("run", str(dist), "--profile", "none", *args, cwd=dist.parent)
    assert proc.returncode == 2
    assert proc.stderr.startswith("avsim: error: ") and problem in proc.stderr
    assert proc.stderr.count("\n") == 1
    assert not (dist.parent / "runs").exists()


def test_permutation_is_for_distribution_files(dist: Path) -> None:
    proc = invoke("run", str(dist.parent / "minimal.xosc"), "--permutation", "0",
                  cwd=dist.parent)
    assert proc.returncode == 2
    assert "--permutation: is for a ParameterValueDistribution file" in proc.stderr

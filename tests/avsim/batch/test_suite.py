"""`avsim suite` and `avsim sweep` end to end, as a user runs them (subprocesses), on two
short scenarios (`batch_scenarios/`: `follow` passes, `too_far` fails):

- the suite's exit status, files, JUnit XML (parsed), summary.md (every criterion of every
  run, the snapshot of the failed run at its first failing moment);
- results do not depend on the number of workers (1 vs 2) nor on the executor (local vs
  Ray): same verdicts, criteria, metrics and state changes;
- a 3 x 3 sweep: its CSV and Markdown tables and the heat map, locally; its middle row on
  Ray gives the same runs. The sweeps judge the tables and the executors, not what the
  stack sees: profile none (no camera or LiDAR to simulate), on both executors.
"""

from __future__ import annotations

import csv
import json
import os
import subprocess
import sys
from pathlib import Path

import cv2
import pytest
from junitparser import Error, Failure, JUnitXml

pytestmark = pytest.mark.slow
HERE = Path(__file__).parents[1]
SCENARIOS = HERE / "batch_scenarios"
TIMEOUT = 600.0  # [s]
GAPS = (35, 50, 70)  # [m] the lead's station: the ego starts at 20
LEAD_SPEEDS = (10, 25, 40)  # [km/h] the ego comes at 40


def avsim(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    env = {k: v for k, v in os.environ.items() if k != "RAY_ADDRESS"}
    return subprocess.run([sys.executable, "-m", "avsim.cli", *args], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=TIMEOUT, check=False)


def results(out: Path) -> list[dict[str, object]]:
    """The batch's results.json, without what differs between executors and folders (the
    wall time, the recording's path in the batch's folder)."""
    runs: list[dict[str, object]] = json.loads(  # NaN and Infinity as tokens: NaN != NaN
        (out / "results.json").read_text(), parse_constant=str)
    for run in runs:
        result = run["result"]
        assert isinstance(result, dict)
        assert Path(str(result.pop("recording"))).parent.name == out.name
        del result["wall_time"]
    return runs


@pytest.fixture(scope="module")
def work(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("batch")


@pytest.fixture(scope="module")
def suite_two(work: Path) -> subprocess.CompletedProcess[str]:
    return avsim("suite", str(SCENARIOS), "--jobs", "2", "--profile", "fast",
                 "--out", "suite2", cwd=work)


@pytest.fixture(scope="module")
def suite_one(work: Path) -> subprocess.CompletedProcess[str]:
    return avsim("suite", str(SCENARIOS / "follow.yaml"), str(SCENARIOS / "too_far.yaml"),
                 "--jobs", "1", "--profile", "fast", "--no-snapshots", "--out", "suite1",
                 cwd=work)


def sweep(work: Path, out: str, *extra: str,
          speeds: tuple[int, ...] = LEAD_SPEEDS) -> subprocess.CompletedProcess[str]:
    return avsim("sweep", str(SCENARIOS / "follow.yaml"),
                 "--set", f"actors.0.s={','.join(map(str, GAPS))}",
                 "--set", f"actors.0.speed_kph={','.join(map(str, speeds))}",
                 "--set", "duration=3", "--metric", "min_gap", "--profile", "none",
                 "--no-snapshots", "--out", out, *extra, cwd=work)


@pytest.fixture(scope="module")
def sweep_local(work: Path) -> subprocess.CompletedProcess[str]:
    return sweep(work, "sweep_local", "--jobs", "2")


@pytest.fixture(scope="module")
def sweep_ray(work: Path) -> subprocess.CompletedProcess[str]:
    """The local sweep's middle row on Ray (3 runs: Ray's start-up is the cost, not the
    runs)."""
    return sweep(work, "sweep_ray", "--executor", "ray", "--jobs", "2",
                 speeds=(LEAD_SPEEDS[1],))


# ---- the suite -------------------------------------------------------------------------------


def test_a_failed_run_fails_the_suite_and_every_run_writes_its_files(
    suite_two: subprocess.CompletedProcess[str], work: Path,
) -> None:
    assert suite_two.returncode == 1, suite_two.stderr
    out = work / "suite2"
    for name in ("follow", "too_far"):
        for ext in (".rrd", ".json", ".png"):
            assert (out / f"{name}{ext}").stat().st_size > 0, name + ext
    runs = {r["name"]: r for r in results(out)}
    assert runs["follow"]["status"] == "passed"
    assert runs["too_far"]["status"] == "failed"
    # the terminal summary names the failed criterion
    assert "completes" in suite_two.stdout


def test_the_junit_file_parses_with_a_case_per_criterion(
    suite_two: subprocess.CompletedProcess[str], work: Path,
) -> None:
    xml = JUnitXml.fromfile(str(work / "suite2" / "junit.xml"))
    suites = {s.name: s for s in xml}
    assert set(suites) == {"follow", "too_far"}
    for name, suite in suites.items():
        result = json.loads((work / "suite2" / f"{name}.json").read_text())
        cases = {c.name: c for c in suite}
        assert set(cases) == {c["name"] for c in result["criteria"]}
        failed = {n for n, c in cases.items() if any(isinstance(r, Failure) for r in c.result)}
        assert failed == {c["name"] for c in result["criteria"] if c["passed"] is False}
        assert suite.tests == len(cases) and suite.failures == len(failed)
        assert not any(isinstance(r, Error) for c in suite for r in c.result)
    assert suites["too_far"].failures == 1 and suites["follow"].failures == 0


def test_the_summary_lists_every_criterion_and_shows_the_failure(
    suite_two: subprocess.CompletedProcess[str], work: Path,
) -> None:
    out = work / "suite2"
    summary = (out / "summary.md").read_text()
    for name in ("follow", "too_far"):
        result = json.loads((out / f"{name}.json").read_text())
        section = summary.split(f"## {name}", 1)[1].split("\n## ", 1)[0]
        for criterion in result["criteria"]:
            assert f"`{criterion['name']}`" in section, (name, criterion["name"])
        assert f"]({name}.rrd)" in summary and f"]({name}.png)" in summary
    # the failed run's snapshot, at its end (`completes` is judged there), embedded
    snapshot = out / "snapshots" / "too_far.png"
    picture = cv2.imread(str(snapshot))
    assert picture is not None and picture.shape[:2] == (900, 1600)
    assert picture.std() > 10.0  # not a blank viewer
    assert "](snapshots/too_far.png)" in summary
    assert not (out / "snapshots" / "follow.png").exists()


def test_one_or_two_workers_give_the_same_results(
    suite_one: subprocess.CompletedProcess[str], suite_two: subprocess.CompletedProcess[str],
    work: Path,
) -> None:
    assert suite_one.returncode == suite_two.returncode == 1
    assert results(work / "suite1") == results(work / "suite2")


# ---- the sweep -------------------------------------------------------------------------------


def test_a_three_by_three_sweep_writes_its_table_and_heat_map(
    sweep_local: subprocess.CompletedProcess[str], work: Path,
) -> None:
    assert sweep_local.returncode in (0, 1), sweep_local.stderr
    out = work / "sweep_local"
    with (out / "sweep.csv").open(newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 9
    grid = {(int(r["actors.0.s"]), int(r["actors.0.speed_kph"])) for r in rows}
    assert grid == {(g, v) for g in GAPS for v in LEAD_SPEEDS}
    assert all(r["duration"] == "3" for r in rows)
    gaps = [float(r["min_gap"]) for r in rows]
    assert max(gaps) - min(gaps) > 5.0  # the swept keys did change the runs
    heat = cv2.imread(str(out / "heatmap.png"))
    assert heat is not None and heat.shape[0] > 300
    assert "heat map" in sweep_local.stdout
    assert len(list(out.glob("follow_*.rrd"))) == 9


def test_ray_gives_the_same_sweep_as_local_workers(
    sweep_local: subprocess.CompletedProcess[str], sweep_ray: subprocess.CompletedProcess[str],
    work: Path,
) -> None:
    """Each Ray run's results equal the local run's with the same values (the run's name
    is its place in its own sweep)."""
    assert sweep_ray.returncode == sweep_local.returncode, sweep_ray.stderr
    local = {json.dumps(r["overrides"], sort_keys=True): r for r in results(work / "sweep_local")}
    ray = results(work / "sweep_ray")
    assert len(ray) == len(GAPS)
    for run in ray:
        twin = local[json.dumps(run["overrides"], sort_keys=True)]
        assert {k: v for k, v in run.items() if k != "name"} == \
            {k: v for k, v in twin.items() if k != "name"}
    assert (work / "sweep_ray" / "sweep.csv").exists()  # one row of values: no heat map
    assert len(list((work / "sweep_ray").glob("follow_*.rrd"))) == len(GAPS)

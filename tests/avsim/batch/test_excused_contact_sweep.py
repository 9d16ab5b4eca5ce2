"""A contact that a rule excuses is counted everywhere a sweep reports, end to end.

UN R157's cut-in grid at 100 km/h (`scenarios/acceptance/r157_cut_in.yaml`): a car at 60 km/h
in the next lane cuts in 10 or 14 m ahead at 1.5 or 2 m/s across, so that the time to
collision at its lane intrusion is under the regulation's bound (5.2.5.2) and the contact is
excused (`unavoidable: r157`). The runs are at `--profile none` (no camera, so an RTK
receiver keeps the car in its lane; perception is not what is judged here). Checked: each run
struck the cutter (the boxes overlapped) and passed; `sweep.csv` and `sweep.md` count the
contact and the excuse (the crash's first contact is excused and ends the judging; the
bodies' shapes may part and touch again in the same crash: counted, not judged, so not
excused); the summary counts it; JUnit shows `no_collision` as a passed
testcase with the excuse, never `skipped`; the heat map is written.
"""

from __future__ import annotations

import csv
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from junitparser import JUnitXml

REPO = Path(__file__).resolve().parents[3]
TIMEOUT = 600  # [s] a bound on the subprocess, not a speed target
RUNS = 4  # 2 gaps x 2 lateral speeds

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def sweep(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("excused") / "sweep"
    env = {k: v for k, v in os.environ.items() if k != "RAY_ADDRESS"}
    env["PYTHONPATH"] = str(REPO)
    done = subprocess.run(
        [sys.executable, "-m", "avsim.cli", "sweep", "acceptance/r157_cut_in",
         "--set", "ego.speed_kph=100", "--set", "ego.set_speed_kph=100",
         "--set", "ego.max_speed_kph=120", "--set", "road.speed_limit_kph=120",
         "--set", "actors.0.speed_kph=60",
         "--set", "actors.0.actions.0.trigger.gap=10,14",
         "--set", "actors.0.actions.0.lane_change.lateral_speed=1.5,2.0",
         "--set", "duration=11", "--set", "sensors={gnss: {preset: rtk}}",
         "--profile", "none", "--jobs", "2", "--no-snapshots", "--metric", "min_lead_gap",
         "--out", str(out)],
        cwd=REPO, env=env, capture_output=True, text=True, timeout=TIMEOUT, check=False)
    assert done.returncode == 0, done.stderr[-2000:]
    return out


def test_every_run_struck_the_cutter_and_passed(sweep: Path) -> None:
    with (sweep / "sweep.csv").open(encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == RUNS
    for row in rows:
        assert float(row["min_lead_gap"]) < 0.0, row  # the boxes overlapped: it did strike
        assert row["status"] == "passed", row
        assert float(row["collisions"]) >= 1.0, row
        assert float(row["collisions_excused"]) == 1.0, row  # the first, which ended judging


def test_the_tables_count_the_contacts(sweep: Path) -> None:
    table = (sweep / "sweep.md").read_text(encoding="utf-8")
    assert "`collisions`" in table and "`collisions_excused`" in table
    summary = (sweep / "summary.md").read_text(encoding="utf-8")
    contacts = [int(n) for n in re.findall(r"Contacts: (\d+) \(1 excused\)", summary)]
    assert len(contacts) == RUNS  # each run's own line: its one excused contact
    assert f"{sum(contacts)} ({RUNS} excused)" in summary  # the scenario's contacts column
    assert (sweep / "heatmap.png").stat().st_size > 0


def test_junit_shows_the_excused_contact_as_a_pass_with_its_excuse(sweep: Path) -> None:
    cases = [case for suite in JUnitXml.fromfile(str(sweep / "junit.xml"))
             for case in suite if case.name == "no_collision"]
    assert len(cases) == RUNS
    for case in cases:
        assert case.is_passed and not case.is_skipped, case.result
        assert case.system_out is not None
        assert "unavoidable: r157" in case.system_out and "TTC at lane intrusion" in case.system_out

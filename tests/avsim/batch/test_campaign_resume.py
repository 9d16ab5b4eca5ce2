"""`avsim campaign --resume` (`avsim.batch.resume`): a run that finished on the same file,
values, profile and code is taken from its files; every other runs again."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from avsim.batch.jobs import RunJob, Status
from avsim.batch.resume import (
    code_fingerprint,
    finished,
    keyed,
    resumed,
    run_key,
)

REPO = Path(__file__).resolve().parents[3]
CUT_IN = REPO / "scenarios" / "campaigns" / "cut_in.yaml"
TIMEOUT = 900  # [s] a bound on each subprocess, not a speed target
RUNS = 4
UNCOMPARED = ("file", "recording", "wall_time")  # where and how fast, not what happened


def _job(tmp_path: Path, **changes: object) -> RunJob:
    fields: dict[str, object] = {"name": "cut_in_0001", "scenario": str(CUT_IN),
                                 "out_dir": tmp_path, "overrides": {"ego.speed_kph": 55.5},
                                 "profile": "none"}
    return RunJob(**(fields | changes))  # type: ignore[arg-type]


# ---- the key ---------------------------------------------------------------------------


def test_the_key_changes_with_each_input_of_the_run(tmp_path: Path) -> None:
    base = run_key(_job(tmp_path), "code")
    assert run_key(_job(tmp_path), "code") == base  # a function of the input only
    assert run_key(_job(tmp_path, out_dir=tmp_path / "elsewhere"), "code") == base
    changed = [run_key(_job(tmp_path, overrides={"ego.speed_kph": 55.50001}), "code"),
               run_key(_job(tmp_path, profile="fast"), "code"),
               run_key(_job(tmp_path, name="cut_in_0002"), "code"),
               run_key(_job(tmp_path), "other code")]
    copy = tmp_path / "cut_in.yaml"
    copy.write_bytes(CUT_IN.read_bytes() + b"\n# one more line\n")
    changed.append(run_key(_job(tmp_path, scenario=str(copy)), "code"))
    assert base not in changed and len(set(changed)) == len(changed)


def test_the_code_fingerprint_is_stable_within_a_process() -> None:
    assert code_fingerprint() == code_fingerprint()
    assert len(code_fingerprint()) == 64


# ---- what counts as finished -----------------------------------------------------------


def _finished_files(job: RunJob, key: str, verdict: str) -> None:
    job.result_file.write_text(json.dumps({"verdict": verdict, "wall_time": 1.5,
                                           "criteria": [], "metrics": {}}))
    job.key_file.write_text(key)


@pytest.mark.parametrize(("verdict", "status"), [("pass", Status.PASSED),
                                                 ("fail", Status.FAILED)])
def test_a_run_with_its_key_and_result_is_taken(tmp_path: Path, verdict: str,
                                                status: Status) -> None:
    job = _job(tmp_path, resume_key="k" * 64)
    _finished_files(job, "k" * 64, verdict)
    outcome = finished(job, "k" * 64)
    assert outcome is not None and outcome.status is status and outcome.wall_time == 1.5
    assert resumed([job]) == {job.name: outcome}


def test_an_error_is_taken_with_its_line(tmp_path: Path) -> None:
    job = _job(tmp_path)
    job.result_file.write_text(json.dumps({
        "verdict": "error", "criteria": [], "metrics": {},
        "error": {"type": "ValueError", "message": "bad", "traceback": "", "sim_time": 2.0}}))
    job.key_file.write_text("k")
    outcome = finished(job, "k")
    assert outcome is not None and outcome.status is Status.ERROR
    assert outcome.error == f"{job.name}: run ended in error at t = 2.000 s: ValueError: bad"


@pytest.mark.parametrize("case", ["no key", "other key", "interrupted", "no result",
                                  "torn result", "not a result", "key is a directory"])
def test_anything_else_runs_again(tmp_path: Path, case: str) -> None:
    job = _job(tmp_path)
    _finished_files(job, "k", "interrupted" if case == "interrupted" else "pass")
    if case == "no key":
        job.key_file.unlink()
    elif case == "other key":
        job.key_file.write_text("j")
    elif case == "no result":
        job.result_file.unlink()
    elif case == "torn result":
        job.result_file.write_text('{"verdict": "pa')
    elif case == "not a result":
        job.result_file.write_text("[1, 2]")
    elif case == "key is a directory":
        job.key_file.unlink()
        job.key_file.mkdir()
    assert finished(job, "k") is None


def test_keyed_jobs_carry_the_key_of_their_run(tmp_path: Path) -> None:
    job = _job(tmp_path)
    (done,) = keyed([job])
    assert done.resume_key == run_key(job, code_fingerprint())


# ---- end to end --------------------------------------------------------------------------


def avsim(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    env = {k: v for k, v in os.environ.items() if k != "RAY_ADDRESS"}
    env["PYTHONPATH"] = str(REPO)
    return subprocess.run([sys.executable, "-m", "avsim.cli", *args], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=TIMEOUT, check=False)


def _campaign(work: Path, *extra: str) -> subprocess.CompletedProcess[str]:
    return avsim("campaign", str(CUT_IN), "--n", str(RUNS), "--seed", "3", "--jobs", "2",
                 "--profile", "none", "--set", "duration=3", "--out", "c", *extra, cwd=work)


def _results(out: Path) -> dict[str, dict[str, object]]:
    return {p.stem: {k: v for k, v in json.loads(p.read_text()).items() if k not in UNCOMPARED}
            for p in sorted(out.glob("cut_in_*.json"))}


@pytest.mark.slow
def test_a_resumed_campaign_runs_only_what_had_not_finished(tmp_path: Path) -> None:
    first = _campaign(tmp_path)
    assert first.returncode in (0, 1), first.stderr[-2000:]
    out = tmp_path / "c"
    before = _results(out)
    assert len(before) == RUNS and len(list(out.glob("*.key"))) == RUNS
    report = (out / "campaign.json").read_text()
    stamps = {p.name: p.stat().st_mtime_ns for p in out.glob("cut_in_*.json")}

    again = _campaign(tmp_path, "--resume")
    assert again.returncode == first.returncode, again.stderr[-2000:]
    assert f"resumed: {RUNS} of {RUNS} runs had finished; 0 to run" in again.stderr
    assert {p.name: p.stat().st_mtime_ns for p in out.glob("cut_in_*.json")} == stamps
    assert json.loads((out / "campaign.json").read_text())["runs"] == json.loads(report)["runs"]

    (out / "cut_in_0002.key").unlink()  # as if the campaign had been cut off in that run
    third = _campaign(tmp_path, "--resume")
    assert f"resumed: {RUNS - 1} of {RUNS} runs had finished; 1 to run" in third.stderr
    assert _results(out) == before  # the run made again gives its result bit for bit
    assert (out / "cut_in_0002.key").is_file()

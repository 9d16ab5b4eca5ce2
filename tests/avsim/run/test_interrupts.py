"""Interrupted runs keep what they recorded (issue L 1): SIGINT / SIGTERM end `avsim run` at
its tick with a valid recording at the path asked for, a result that says it was
interrupted and holds what was judged so far, exit 130 / 143, and no temporary file left."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from avsim.criteria.base import CriterionResult, judged_so_far
from avsim.run.interrupts import Interrupts

REPO = Path(__file__).resolve().parents[3]
RERUN = Path(sys.executable).parent / "rerun"


def test_what_was_judged_stands_and_what_the_end_would_settle_is_not_applicable() -> None:
    results = [
        CriterionResult("no_collision", True, 0.0, 0.0, "contacts"),
        CriterionResult("speed_limit", False, 3.0, 1.0, "km/h", first_failure=4.5),
        CriterionResult("completes", False, 120.0, 500.0, "m"),
        CriterionResult("story", False, 1.0, 0.0, "actions", note="never fired: events.0"),
        CriterionResult.not_applicable("stop_signs", 1.0, "s", "no stop line on the route"),
    ]
    judged = judged_so_far(results, 12.345)
    assert judged[:2] == results[:2]
    assert judged[4] == results[4]
    assert [(r.passed, r.value, r.note) for r in judged[2:4]] == [
        (None, None, "not judged: the run was interrupted at 12.35 s"),
        (None, None, "not judged: the run was interrupted at 12.35 s (never fired: events.0)")]


def test_a_signal_is_recorded_and_calls_back_and_the_handlers_come_back() -> None:
    before = signal.getsignal(signal.SIGTERM)
    calls: list[str] = []
    with Interrupts() as stop:
        stop.on_signal(lambda: calls.append("first"))
        os.kill(os.getpid(), signal.SIGTERM)
        stop.on_signal(lambda: calls.append("late"))  # registered after: called at once
        assert stop.exit_status == 143
    assert calls == ["first", "late"]
    assert signal.getsignal(signal.SIGTERM) is before


def _interrupted_run(tmp_path: Path, profile: str, sig: signal.Signals,
                     group: bool) -> tuple[subprocess.CompletedProcess[str], Path]:
    """`avsim run normal_driving` into tmp_path, sent `sig` 3 s after its recording opened
    (to its process group when `group`, as Ctrl-C at a terminal is)."""
    out = tmp_path / "run" / "nd.rrd"
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    proc = subprocess.Popen(
        [sys.executable, "-m", "avsim.cli", "run", "normal_driving", "--out", str(out),
         "--profile", profile, "--plot", "--no-progress",
         # without a camera the lane is the receiver's: an RTK one keeps the car in it
         *(["--set", "sensors={gnss: {preset: rtk}}"] if profile == "none" else [])],
        cwd=tmp_path, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        start_new_session=True)
    def under_way() -> bool:  # the recording's temporary file is open
        return out.parent.is_dir() and any(out.parent.glob(f".{out.name}.*.partial"))

    deadline = time.monotonic() + 120
    while not under_way() and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.2)
    assert under_way(), "the run never started"
    time.sleep(3.0)
    if group:
        os.killpg(proc.pid, sig)
    else:
        proc.send_signal(sig)
    stdout, stderr = proc.communicate(timeout=120)
    return subprocess.CompletedProcess(proc.args, proc.returncode, stdout, stderr), out


@pytest.mark.slow
@pytest.mark.parametrize(("profile", "sig", "group", "status"), [
    ("fast", signal.SIGINT, True, 130),  # Ctrl-C: the sensing worker gets it too
    ("none", signal.SIGTERM, False, 143),
])
def test_an_interrupted_run_keeps_its_recording_and_result(
        tmp_path: Path, profile: str, sig: signal.Signals, group: bool, status: int) -> None:
    done, out = _interrupted_run(tmp_path, profile, sig, group)
    assert done.returncode == status, done.stderr
    assert "Traceback" not in done.stderr
    result = json.loads(out.with_suffix(".json").read_text(encoding="utf-8"))
    assert result["interrupted"] is True
    assert 0.0 < result["sim_time"] < 100.0  # normal_driving runs 110 s
    verdicts = {c["name"]: c for c in result["criteria"]}
    assert verdicts["no_collision"]["verdict"] == "pass"  # judged so far
    completes = verdicts["completes"]  # the goal was not reached: the end would settle it
    assert completes["verdict"] == "not_applicable"
    assert completes["note"].startswith("not judged: the run was interrupted at")
    assert "so far (interrupted at" in done.stdout
    assert out.with_suffix(".png").is_file()
    check = subprocess.run([str(RERUN), "rrd", "verify", str(out)], capture_output=True,
                           text=True, check=False)
    assert check.returncode == 0, check.stderr
    assert sorted(p.name for p in out.parent.iterdir()) == ["nd.json", "nd.png", "nd.rrd"]


@pytest.mark.slow
def test_an_interrupted_sweep_keeps_its_finished_runs_and_reports(tmp_path: Path) -> None:
    """Ctrl-C (SIGINT to the process group) once the second of three runs is under way: it
    ends at its tick with its files, the third never starts; the reports cover all
    three; exit 130; no temporary file is left."""
    out = tmp_path / "sweep"
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    proc = subprocess.Popen(
        [sys.executable, "-m", "avsim.cli", "sweep", "normal_driving", "--set",
         "seed=1,2,3", "--set", "duration=60", "--jobs", "1", "--profile", "none", "--out",
         str(out)],
        cwd=tmp_path, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        start_new_session=True)
    def second_under_way() -> bool:  # its recording's temporary file is open
        return any(out.glob(".normal_driving_001.rrd.*.partial"))

    deadline = time.monotonic() + 300
    while not second_under_way() and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.05)
    assert second_under_way(), "the second run never started"
    time.sleep(1.0)  # well inside its 60 s simulated (6 s or more of wall time)
    os.killpg(proc.pid, signal.SIGINT)
    _, stderr = proc.communicate(timeout=300)
    assert proc.returncode == 130, stderr
    assert "Traceback" not in stderr
    runs = json.loads((out / "results.json").read_text(encoding="utf-8"))
    assert [r["status"] for r in runs][1:] == ["interrupted", "interrupted"]
    assert runs[0]["status"] in ("passed", "failed") and not runs[0]["result"]["interrupted"]
    assert runs[1]["result"]["interrupted"] is True  # ended at its tick, files written
    assert runs[2]["result"] is None and runs[2]["error"].endswith("not run (the batch was "
                                                                   "interrupted)")
    assert (out / "junit.xml").is_file() and (out / "sweep.csv").is_file()
    assert "**interrupted**: 2 runs" in (out / "summary.md").read_text(encoding="utf-8")
    for name in ("normal_driving_000", "normal_driving_001"):
        check = subprocess.run([str(RERUN), "rrd", "verify", str(out / f"{name}.rrd")],
                               capture_output=True, text=True, check=False)
        assert check.returncode == 0, check.stderr
    assert not (out / "normal_driving_002.rrd").exists()
    assert not [p for p in out.rglob(".*")], "a temporary file was left behind"


def _processes() -> dict[int, tuple[int, str]]:
    """pid -> (parent pid, start time) of every live process (zombies aside), from /proc."""
    out = {}
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            fields = (entry / "stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if fields[0] != "Z":
            out[int(entry.name)] = (int(fields[1]), fields[19])  # ppid, starttime
    return out


def _descendants(pid: int) -> dict[int, str]:
    """pid -> start time of every live descendant of `pid` (children of children, ...)."""
    procs = _processes()
    found: dict[int, str] = {}
    grew = True
    while grew:
        more = {p: start for p, (parent, start) in procs.items()
                if (parent == pid or parent in found) and p not in found}
        found |= more
        grew = bool(more)
    return found


def _alive(processes: dict[int, str]) -> list[int]:
    """Those of `processes` (pid -> start time) still alive (the same process: its start
    time too)."""
    now = _processes()
    return [p for p, start in processes.items() if p in now and now[p][1] == start]


@pytest.mark.slow
def test_an_interrupted_sweep_on_ray_cancels_its_tasks_and_keeps_what_finished(
        tmp_path: Path) -> None:
    """The same on a local Ray instance, one task at a time: SIGINT once the first run's
    files are back. The task under way and the one not started are cancelled (a Ray
    task's files come back only when it finishes: both are not run); the finished run's
    files and the reports stay; exit 130; Ray and its workers are gone with the sweep."""
    out = tmp_path / "sweep"
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    env.pop("RAY_ADDRESS", None)
    proc = subprocess.Popen(
        [sys.executable, "-m", "avsim.cli", "sweep", "normal_driving", "--set",
         "seed=1,2,3", "--set", "duration=40", "--executor", "ray", "--jobs", "1",
         "--profile", "none", "--no-snapshots", "--out", str(out)],
        cwd=tmp_path, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        start_new_session=True)
    first = out / "normal_driving_000.json"
    deadline = time.monotonic() + 400
    while not first.exists() and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.05)
    assert first.exists(), proc.communicate(timeout=60)[1]
    time.sleep(1.0)  # the second task under way (40 s simulated: several s of wall time)
    ray = _descendants(proc.pid)  # Ray's processes and workers, started by the sweep
    assert len(ray) >= 3, ray
    os.killpg(proc.pid, signal.SIGINT)
    _, stderr = proc.communicate(timeout=300)
    assert proc.returncode == 130, stderr
    assert "Traceback" not in stderr
    runs = {r["name"]: r for r in json.loads((out / "results.json").read_text(encoding="utf-8"))}
    assert runs["normal_driving_000"]["status"] in ("passed", "failed")
    for name in ("normal_driving_001", "normal_driving_002"):
        assert runs[name]["status"] == "interrupted" and runs[name]["result"] is None
        assert runs[name]["error"].endswith("not run (the batch was interrupted)")
        assert not (out / f"{name}.json").exists()
    assert (out / "junit.xml").is_file() and (out / "sweep.csv").is_file()
    assert "**interrupted**: 2 runs" in (out / "summary.md").read_text(encoding="utf-8")
    check = subprocess.run([str(RERUN), "rrd", "verify", str(out / "normal_driving_000.rrd")],
                           capture_output=True, text=True, check=False)
    assert check.returncode == 0, check.stderr
    assert not [p for p in out.rglob(".*")], "a temporary file was left behind"
    deadline = time.monotonic() + 30  # Ray's processes may take a moment to exit
    while _alive(ray) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert _alive(ray) == [], "Ray processes outlived the sweep"

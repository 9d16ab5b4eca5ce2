"""`avsim run`'s exit statuses mean one thing each (0 pass, 1 fail, 2 bad input, 3 error,
130 / 143 interrupted by SIGINT / SIGTERM), and a signal at any moment of a run gives a
status and files that agree: during the heavy imports (exit at once, nothing written),
while the world is built (a valid recording and a result that says interrupted, never
passed), after the last tick (the run is whole: its own verdict and status). A world that
cannot be built ends the run in error at 0 s, with its result and recording.

The subprocesses run `tests.avsim.run.cli_hooks`, which says when the moment has come
(a file) and waits for the test's go-ahead: no fixed sleeps."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest

from avsim.cli import EXIT_BAD_INPUT, EXIT_ERROR, EXIT_FAILED, _exit_status
from avsim.run.interrupts import Interrupts
from avsim.run.verdict import RunVerdict

REPO = Path(__file__).resolve().parents[3]
RERUN = Path(sys.executable).parent / "rerun"
DEADLINE = 180.0  # [s] the longest a test waits for a subprocess's moment


def avsim(tmp_path: Path, hook: str, *args: str) -> tuple[subprocess.Popen[str], Path, Path]:
    """`avsim ARGS` under `hook` (`cli_hooks`), in tmp_path; (process, mark, go)."""
    mark, go = tmp_path / "mark", tmp_path / "go"
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    proc = subprocess.Popen(
        [sys.executable, "-m", "tests.avsim.run.cli_hooks", hook, str(mark), str(go), *args],
        cwd=tmp_path, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    return proc, mark, go


def run_args(out: Path) -> list[str]:
    """A short run without cameras or LiDAR into `out`."""
    return ["run", "normal_driving", "--profile", "none", "--set", "duration=3", "--out",
            str(out), "--no-progress"]


def signalled(tmp_path: Path, hook: str, sig: signal.Signals
              ) -> tuple[subprocess.CompletedProcess[str], Path]:
    """A short run sent `sig` at `hook`'s moment; (the finished process, its recording)."""
    out = tmp_path / "run" / "nd.rrd"
    proc, mark, go = avsim(tmp_path, hook, *run_args(out))
    deadline = time.monotonic() + DEADLINE
    while not mark.exists() and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.01)
    assert mark.exists(), "the moment never came"
    proc.send_signal(sig)
    go.touch()
    stdout, stderr = proc.communicate(timeout=DEADLINE)
    return subprocess.CompletedProcess(proc.args, proc.returncode, stdout, stderr), out


def verified(recording: Path) -> None:
    """`rerun rrd verify` accepts the recording."""
    check = subprocess.run([str(RERUN), "rrd", "verify", str(recording)],
                           capture_output=True, text=True, check=False)
    assert check.returncode == 0, check.stderr


def test_each_verdict_has_its_own_exit_status() -> None:
    stop = Interrupts()
    statuses = {v: _exit_status(SimpleNamespace(verdict=v), stop)  # type: ignore[arg-type]
                for v in RunVerdict if v is not RunVerdict.INTERRUPTED}
    assert statuses == {RunVerdict.PASS: 0, RunVerdict.FAIL: EXIT_FAILED,
                        RunVerdict.ERROR: EXIT_ERROR}
    assert len({0, EXIT_FAILED, EXIT_BAD_INPUT, EXIT_ERROR, 130, 143}) == 6
    for sig in (signal.SIGINT, signal.SIGTERM):
        stop.received = sig
        interrupted: Any = SimpleNamespace(verdict=RunVerdict.INTERRUPTED)
        assert _exit_status(interrupted, stop) == 128 + sig


def test_a_run_that_ends_in_error_exits_3_with_one_line_and_its_files(tmp_path: Path) -> None:
    out = tmp_path / "run" / "nd.rrd"
    proc, _, _ = avsim(tmp_path, "planner", *run_args(out))
    stdout, stderr = proc.communicate(timeout=DEADLINE)
    assert proc.returncode == EXIT_ERROR, stderr
    lines = [line for line in stderr.splitlines() if line.startswith("avsim:")]
    assert len(lines) == 1 and "Traceback" not in stderr
    assert lines[0].startswith("avsim: run ended in error at t = ")
    assert lines[0].endswith(" s: ValueError: heading error 2.856 rad: the car does not head "
                             "along the lane")
    result = json.loads(out.with_suffix(".json").read_text(encoding="utf-8"))
    assert (result["verdict"], result["passed"]) == ("error", False)
    assert result["error"]["type"] == "ValueError"
    assert "Traceback (most recent call last)" in result["error"]["traceback"]
    assert f"at t = {result['error']['sim_time']:.3f} s" in lines[0]
    assert "ERROR at" in stdout
    verified(out)
    assert sorted(p.name for p in out.parent.iterdir()) == ["nd.json", "nd.rrd"]


def test_a_world_that_cannot_be_built_ends_in_error_with_its_result_and_recording(
        tmp_path: Path) -> None:
    out = tmp_path / "run" / "nd.rrd"
    proc, _, _ = avsim(tmp_path, "world", *run_args(out), "--plot")
    stdout, stderr = proc.communicate(timeout=DEADLINE)
    assert proc.returncode == EXIT_ERROR, stderr
    assert "Traceback" not in stderr
    lines = [line for line in stderr.splitlines() if line.startswith("avsim:")]
    assert lines == ["avsim: run ended in error at t = 0.000 s: RuntimeError: the world "
                     "cannot be built"]
    result = json.loads(out.with_suffix(".json").read_text(encoding="utf-8"))
    assert (result["verdict"], result["passed"], result["interrupted"], result["sim_time"]) \
        == ("error", False, False, 0.0)
    assert (result["criteria"], result["infractions"], result["metrics"]) == ([], [], {})
    assert result["error"]["type"] == "RuntimeError"
    assert result["error"]["message"] == "the world cannot be built"
    assert result["error"]["sim_time"] == 0.0
    assert "Traceback (most recent call last)" in result["error"]["traceback"]
    assert "ERROR at 0.0 s" in stdout
    verified(out)
    assert sorted(p.name for p in out.parent.iterdir()) == ["nd.json", "nd.rrd"]  # no plot


@pytest.mark.parametrize(("sig", "status"), [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_a_signal_during_the_imports_exits_at_once_and_writes_nothing(
        tmp_path: Path, sig: signal.Signals, status: int) -> None:
    done, out = signalled(tmp_path, "import", sig)
    assert done.returncode == status, done.stderr
    assert "Traceback" not in done.stderr and "Aborted!" not in done.stderr
    assert not out.parent.exists() or not list(out.parent.iterdir())


@pytest.mark.parametrize(("sig", "status"), [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_a_signal_while_the_world_is_built_gives_an_interrupted_result(
        tmp_path: Path, sig: signal.Signals, status: int) -> None:
    done, out = signalled(tmp_path, "build", sig)
    assert done.returncode == status, done.stderr
    assert "Traceback" not in done.stderr and "Aborted!" not in done.stderr
    result = json.loads(out.with_suffix(".json").read_text(encoding="utf-8"))
    assert (result["verdict"], result["passed"], result["interrupted"], result["sim_time"]) \
        == ("interrupted", False, True, 0.0)
    verified(out)
    assert sorted(p.name for p in out.parent.iterdir()) == ["nd.json", "nd.rrd"]


def test_a_signal_after_the_last_tick_leaves_the_run_its_verdict(tmp_path: Path) -> None:
    done, out = signalled(tmp_path, "after", signal.SIGINT)
    result = json.loads(out.with_suffix(".json").read_text(encoding="utf-8"))
    assert (result["verdict"], result["interrupted"], result["sim_time"]) == ("fail", False, 3.0)
    assert done.returncode == EXIT_FAILED, done.stderr  # not completed in 3 s: its own status
    verified(out)

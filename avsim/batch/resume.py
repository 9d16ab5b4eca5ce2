"""Resuming a campaign: which of its runs already finished, on the same input and code.

A run is a pure function of its input (the scenario file, its drawn and `--set` values,
the sensor profile, what drives the car under test) and of the simulator's code: same
input and seed, same result, bit for bit. So a finished run need not run again while none
of those changed. Each campaign run carries its key (`run_key`): a SHA-256 over the
scenario file's bytes, the job's name, overrides, profile and car under test (`RunJob.ego`:
a stack run and a scripted run of one file are different runs), and the code's fingerprint
(`code_fingerprint`). When the run has written its result JSON, the worker writes the key
beside it (`<run>.key`, after the result: a run cut off between the two has no key and runs
again). `avsim campaign --resume` takes the result of each run whose key file holds its key
and whose result says it finished (not interrupted), and runs the others.

Not compared: files the scenario file itself names (a road or catalog beside it); a
campaign whose files name such a file and that has changed must not be resumed.
"""

from __future__ import annotations

import functools
import hashlib
import json
import platform
from collections.abc import Sequence
from dataclasses import replace
from importlib import metadata
from pathlib import Path

from avsim.batch.jobs import VERDICT_STATUS, RunJob, RunOutcome, Status, outcome_of
from avsim.scenario.load import scenario_path
from world.core.safe_read import UnreadableFileError, read_bounded

CODE_PACKAGES = ("avsim", "world", "perception", "planner", "control")  # the simulator
DEPENDENCIES = ("numpy", "scipy", "pybullet", "opencv-python-headless", "open3d", "filterpy",
                "PyYAML")  # whose versions enter the fingerprint (absent: "-")
MAX_KEY_BYTES = 256  # a key file holds 64 hex digits
MAX_RESULT_BYTES = 256 * 1024 * 1024  # [B] a result JSON (its log included) read back


def _version(name: str) -> str:
    try:
        return metadata.version(name)
    except metadata.PackageNotFoundError:
        return "-"


@functools.cache
def code_fingerprint() -> str:
    """SHA-256 over every file of the simulator's packages (`CODE_PACKAGES`: path relative to
    the repository and bytes, in sorted order, caches left out), Python's version and the
    versions of the numeric dependencies."""
    root = Path(__file__).resolve().parents[2]
    digest = hashlib.sha256()
    digest.update(f"python {platform.python_version()}\n".encode())
    for name in DEPENDENCIES:
        digest.update(f"{name} {_version(name)}\n".encode())
    for package in CODE_PACKAGES:
        for path in sorted((root / package).rglob("*")):
            if not path.is_file() or "__pycache__" in path.parts:
                continue
            digest.update(str(path.relative_to(root)).encode() + b"\0")
            digest.update(hashlib.sha256(path.read_bytes()).digest())
    return digest.hexdigest()


def run_key(job: RunJob, fingerprint: str) -> str:
    """The key of `job`'s run: SHA-256 over its scenario file's bytes, name, overrides,
    profile, car under test (`RunJob.ego`), sidecar and the code's `fingerprint` (and a user
    stack's code, `RunJob.stack_code`)."""
    scenario = hashlib.sha256(scenario_path(job.scenario).read_bytes()).hexdigest()
    sidecar = (hashlib.sha256(job.criteria.read_bytes()).hexdigest()
               if job.criteria is not None else None)
    text = json.dumps({"name": job.name, "scenario": scenario, "overrides": job.overrides,
                       "profile": job.profile, "ego": job.ego, "sidecar": sidecar,
                       "code": fingerprint, **({"stack": job.stack_code}
                                               if job.stack_code else {})},
                      sort_keys=True, default=repr)
    return hashlib.sha256(text.encode()).hexdigest()


def finished(job: RunJob, key: str) -> RunOutcome | None:
    """`job`'s outcome from its files when its key file holds `key` and its result JSON
    says it finished (passed, failed or error); else None (it must run)."""
    try:
        held = read_bounded(job.key_file, MAX_KEY_BYTES).decode("ascii").strip()
        if held != key:
            return None
        result = json.loads(read_bounded(job.result_file, MAX_RESULT_BYTES))
    except (OSError, UnreadableFileError, UnicodeDecodeError, ValueError):
        return None
    if not isinstance(result, dict):
        return None
    status = VERDICT_STATUS.get(str(result.get("verdict")))
    if status is None or status is Status.INTERRUPTED:
        return None
    wall = result.get("wall_time")
    return outcome_of(job, result, float(wall) if isinstance(wall, (int, float)) else 0.0)


def keyed(jobs: Sequence[RunJob]) -> list[RunJob]:
    """`jobs`, each carrying its run's key (its run writes it beside its result)."""
    fingerprint = code_fingerprint()
    return [replace(job, resume_key=run_key(job, fingerprint)) for job in jobs]


def resumed(jobs: Sequence[RunJob]) -> dict[str, RunOutcome]:
    """The outcomes of the keyed `jobs` that already finished (`finished`), by job name."""
    outcomes = {job.name: finished(job, job.resume_key) for job in jobs
                if job.resume_key is not None}
    return {name: outcome for name, outcome in outcomes.items() if outcome is not None}

"""Golden results: a closed-loop run's verdicts, metrics, state changes and trajectory, kept
in `tests/scenarios/golden/` and compared exactly (determinism makes that possible).

Each scenario test module checks the runs it already makes against their golden files, so a
change meant to keep behaviour shows that it does, to the last bit. A change meant to alter
behaviour rewrites them with `make golden` (which sets ``AVSIM_GOLDEN=write``), and its
commit says which behaviour changed and why.

What is compared: every criterion (all fields), every metric, the story, every state change
of the machines the golden file lists, the simulated time and a SHA-256 of the ego's
trajectory (`TRAJECTORY`, as float64 bytes). Wall time is not kept. Keys and state machines
a later change adds are not in the older golden files, and are set aside.

Every run checked here also has its result file (`avsim.run.result`) parsed by a strict
JSON parser: no NaN, no infinities.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import os
from pathlib import Path

import numpy as np

from avsim.run.result import dumps, result_json
from avsim.run.runner import RunResult
from tests.scenarios.modes import SENSORS
from world.sensors.setup import Profile

GOLDEN_DIR = Path(__file__).resolve().parent / "golden"
WRITE = os.environ.get("AVSIM_GOLDEN") == "write"
TRAJECTORY = ("t", "x", "y", "yaw", "speed", "station", "steering", "drive_torque",
              "brake_torque", "target_speed")  # the log's fields in the digest


def record(result: RunResult) -> dict[str, object]:
    """The golden record of a run (plain JSON types; floats kept whole)."""
    digest = hashlib.sha256()
    for name in TRAJECTORY:
        digest.update(name.encode())
        digest.update(np.ascontiguousarray(result.log.array(name)).tobytes())
    changes = [{"t": c.t, "machine": c.machine, "from": c.source, "to": c.target,
                "reason": c.reason} for c in result.state_changes]
    return {
        "scenario": result.scenario.name,
        "profile": result.profile,
        "passed": result.passed,
        "sim_time": result.sim_time,
        "criteria": [dataclasses.asdict(c) for c in result.criteria],
        "metrics": dict(result.metrics),
        "story": [dataclasses.asdict(e) for e in result.story],
        "machines": sorted({c["machine"] for c in changes}),
        "state_changes": changes,
        "trajectory_sha256": digest.hexdigest(),
    }


def check(result: RunResult, label: str) -> None:
    """Assert that `result` equals the golden file `label`.json (or write it, with
    ``AVSIM_GOLDEN=write``)."""
    path = GOLDEN_DIR / f"{label}.json"
    strict_json(dumps(result_json(result, f"{label}.yaml", Path(f"{label}.rrd"),
                                  result.profile or "none")))
    now = json.loads(json.dumps(record(result)))  # as written: a tuple reads back a list
    if WRITE:
        GOLDEN_DIR.mkdir(exist_ok=True)
        path.write_text(json.dumps(now, indent=1) + "\n", encoding="utf-8")
        return
    assert path.exists(), f"no golden file {path.name}: run `make golden` (and say why)"
    expected = json.loads(path.read_text(encoding="utf-8"))
    diffs = differences(expected, now)
    assert not diffs, f"{label} differs from its golden file:\n" + "\n".join(diffs[:20])


def differences(expected: dict[str, object], now: dict[str, object]) -> list[str]:
    """`key: golden -> now` for each difference; keys only `now` has are set aside, and so
    are the state changes of machines the golden file does not list."""
    machines = set(expected.get("machines", ()))  # type: ignore[call-overload]
    now = dict(now)
    now["state_changes"] = [c for c in now["state_changes"]  # type: ignore[attr-defined]
                            if c["machine"] in machines]
    out: list[str] = []
    _diff("", expected, now, out)
    return out


def _diff(where: str, a: object, b: object, out: list[str]) -> None:
    if isinstance(a, dict) and isinstance(b, dict):
        for key in a:
            if key not in b:
                out.append(f"{where}{key}: missing now")
            else:
                _diff(f"{where}{key}.", a[key], b[key], out)
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            out.append(f"{where.rstrip('.')}: {len(a)} items -> {len(b)}")
        for k, (x, y) in enumerate(zip(a, b, strict=False)):
            _diff(f"{where}{k}.", x, y, out)
    elif not _same(a, b):
        out.append(f"{where.rstrip('.')}: {a!r} -> {b!r}")


def _same(a: object, b: object) -> bool:
    if isinstance(a, float) and isinstance(b, float | int) and not isinstance(b, bool):
        return a == b or (math.isnan(a) and math.isnan(float(b)))
    return a == b


def strict_json(text: str) -> object:
    """`text` parsed as strict JSON: NaN and the infinities (Python's extension) refused."""
    def refuse(constant: str) -> object:
        raise AssertionError(f"the result file is not strict JSON: {constant}")
    return json.loads(text, parse_constant=refuse)


def profile_label(name: str, profile: Profile) -> str:
    """The golden file of a sensor run on `profile` (`tests.scenarios.modes.PROFILES`): the
    `default` run keeps the module's `name`, another profile's is `name.<profile>`."""
    return name if profile is Profile.DEFAULT else f"{name}.{profile.value}"


def label(name: str, mode: str) -> str:
    """The golden file of a run in stack mode `mode` (`tests.scenarios.modes`): the sensor
    run keeps the module's `name`, the privileged truth run is `name.truth`."""
    return name if mode == SENSORS else f"{name}.truth"

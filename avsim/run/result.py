"""The result file (`--json`) of a run, as SCENARIO_FORMAT.md specifies it: strict JSON,
every number finite or null (`dumps` refuses anything else). Beside the sensor profile,
`localisation` says where the stack's pose came from and the receiver's expected error
(`world.sensors.setup.localisation`).

``verdict`` says how the run ended (`avsim.run.verdict`: pass, fail, error, interrupted);
``passed`` is true only for pass; ``error`` is the exception that ended a run in error
(type, message, traceback, sim time [s]), else null."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import TYPE_CHECKING

from avsim.run.story_state import state_change_json
from avsim.stack.choice import identity
from avsim.stack.context import API_VERSION
from world.sensors.setup import Localisation, Profile, localisation

if TYPE_CHECKING:
    from avsim.run.runner import RunResult
    from avsim.run.story import StoryEntry


def _clean(x: float) -> float | None:
    return round(x, 4) if math.isfinite(x) else None


def result_json(result: RunResult, file: str | Path, recording: Path, profile: str) -> dict[
    str, object
]:
    scenario = result.scenario
    return {
        "scenario": scenario.name,
        "file": str(file),
        "seed": scenario.seed,
        "profile": profile,
        "ego": "scripted" if scenario.world.ego.scripted else "stack",  # what drove the car
        "stack": identity(scenario.stack, API_VERSION).as_json(),  # which stack that is
        "localisation": run_localisation(result, profile).as_json(),
        "renderer": result.renderer,
        "verdict": result.verdict.value,
        "passed": result.passed,
        "interrupted": result.interrupted,
        "error": None if result.error is None else result.error.as_json(),
        "sim_time": round(result.sim_time, 4),
        "wall_time": round(result.wall_time, 3),
        "criteria": [c.as_json() for c in result.criteria],
        "infractions": [i.as_json() for i in result.infractions],
        "story": [_story_entry(e) for e in result.story],
        "storyboard_state": [state_change_json(c) for c in result.storyboard_state],
        "metrics": {k: _clean(v) for k, v in result.metrics.items()},
        "state_changes": [
            {"t": round(c.t, 4), "machine": c.machine, "from": c.source, "to": c.target,
             "reason": c.reason}
            for c in result.state_changes
        ],
        "recording": str(recording),
    }


def headline(payload: dict[str, object]) -> str:
    """A result's verdict in a few words: ``PASS``, ``FAIL``, ``PASS so far (interrupted
    at T s)`` or ``ERROR at T s (FAIL so far)``, from the criteria judged so far [s]."""
    criteria = payload["criteria"]
    assert isinstance(criteria, list)
    so_far = "FAIL" if any(c["passed"] is False for c in criteria) else "PASS"
    t = payload["sim_time"]
    assert isinstance(t, (int, float))
    if payload.get("verdict") == "error":
        return f"ERROR at {t:.1f} s ({so_far} so far)"
    if payload.get("interrupted"):
        return f"{so_far} so far (interrupted at {t:.1f} s)"
    return so_far


def run_localisation(result: RunResult, profile: str) -> Localisation:
    """The pose's source of a run with sensor profile `profile` ("none": no profile)."""
    stack = result.scenario.stack
    return localisation(None if profile == "none" else Profile(profile),
                        result.scenario.world.sensors.gnss, stack.privileged,
                        stack.own_perception)


def dumps(payload: object) -> str:
    """`payload` as the result files write it: indented strict JSON (a NaN or an infinity
    is a bug here: ValueError), with a final newline."""
    return json.dumps(payload, indent=2, allow_nan=False) + "\n"


def _story_entry(e: StoryEntry) -> dict[str, object]:
    """A story entry in the result: an actor's action, an ego event, or an OpenSCENARIO
    storyboard element (by name)."""
    if e.element is not None:
        where: dict[str, object] = {"element": e.element}
    elif e.actor is not None:
        where = {"actor": e.actor, "action": e.index}
    else:
        where = {"event": e.index}
    off = {} if e.off is None else {"off": e.off}  # switched off by the file's configuration
    return where | {"kind": e.kind, "optional": e.optional,
                    "fired_at": None if e.fired_at is None else round(e.fired_at, 4)} | off

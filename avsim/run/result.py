"""The result file (`--json`) of a run, as SCENARIO_FORMAT.md specifies it."""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from avsim.run.runner import RunResult


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
        "renderer": result.renderer,
        "passed": result.passed,
        "sim_time": round(result.sim_time, 4),
        "wall_time": round(result.wall_time, 3),
        "criteria": [c.as_json() for c in result.criteria],
        "infractions": [i.as_json() for i in result.infractions],
        "metrics": {k: _clean(v) for k, v in result.metrics.items()},
        "state_changes": [
            {"t": round(c.t, 4), "machine": c.machine, "from": c.source, "to": c.target,
             "reason": c.reason}
            for c in result.state_changes
        ],
        "recording": str(recording),
    }

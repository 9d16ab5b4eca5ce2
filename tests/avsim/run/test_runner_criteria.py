"""The runner and its criteria, on short closed-loop runs without cameras or LiDAR: the
criteria come from the registry in the order of the results; an infraction reaches the
result, its JSON and the recording (an ERROR line at /events and a marker at
/world/infractions, at its sim time); the samples carry the NPCs' poses only when a
criterion of the set needs them."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rerun.chunk import RrdReader

from avsim.record import blueprint as bp
from avsim.run.result import result_json
from avsim.run.runner import Runner
from avsim.scenario.load import load_scenario

# The ego starts at 40 km/h on a road posted at 20 km/h: `speed_limit` fails at once.
SCENARIO = """\
format: avsim/1
name: too_fast
duration: 2
road:
  speed_limit_kph: 20
  segments:
    - straight: 300
ego: {s: 10, speed_kph: 40, set_speed_kph: 20}
actors:
  - {id: lead, type: car, s: 150, speed_kph: 20}
"""


@pytest.fixture(scope="module")
def scenario_path(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("runner") / "too_fast.yaml"
    path.write_text(SCENARIO, encoding="utf-8")
    return path


def column(path: Path, entity: str, component: str) -> tuple[list[int], list[Any]]:
    """([ns] sim times, values) of one component of one entity, in time order."""
    chunks = RrdReader(path).store().stream().filter(content=entity,
                                                     components=component).to_chunks()
    batches = [c.to_record_batch() for c in chunks]
    times = [int(t) for b in batches
             for t in b.column(bp.TIMELINE).to_numpy().astype(np.int64)]
    values = [v for b in batches for v in b.column(component).to_pylist()]
    order = sorted(range(len(times)), key=lambda i: times[i])  # stable: same-time rows keep
    return [times[i] for i in order], [values[i] for i in order]  # their logging order


def test_an_infraction_reaches_the_result_its_json_and_the_recording(
        scenario_path: Path, tmp_path: Path) -> None:
    recording = tmp_path / "run.rrd"
    result = Runner(load_scenario(scenario_path), recording, profile=None).run()
    first = result.infractions[0]
    assert (first.kind, first.t) == ("speed_limit", 0.025)  # the first criteria sample
    assert re.fullmatch(r"speed 4\d\.\d km/h over the limit 20 km/h by 2\d\.\d km/h",
                        first.message), first.message
    assert first.where is not None and first.where[0] == pytest.approx(10.0, abs=0.5)
    assert [i.t for i in result.infractions] == sorted(i.t for i in result.infractions)
    limit = next(c for c in result.criteria if c.name == "speed_limit")
    assert not limit.passed and limit.first_failure == first.t
    payload = result_json(result, scenario_path, recording, "none")
    assert payload["infractions"] == [i.as_json() for i in result.infractions]

    times, texts = column(recording, bp.EVENTS, "TextLog:text")
    _, levels = column(recording, bp.EVENTS, "TextLog:level")
    line = f"speed_limit: {first.message}"
    k = [row[0] for row in texts].index(line)
    assert times[k] == round(1e9 * first.t) and levels[k] == ["ERROR"]
    assert any(row[0].startswith("criterion speed_limit: FAIL") for row in texts)  # the end
    marker_times, markers = column(recording, bp.INFRACTIONS, "Points3D:positions")
    assert marker_times[0] == round(1e9 * first.t)
    np.testing.assert_allclose(markers[0][0][:2], first.where)
    assert len(markers[-1]) == len([i for i in result.infractions if i.where is not None])


@pytest.mark.parametrize(("criteria", "sampled"), [
    ({}, False),  # the default criteria, no crosswalk on the road: no NPC poses
    ({"min_gap": 20}, True),
    ({"max_decel": 3.0}, False),
])
def test_the_samples_carry_the_npc_poses_only_when_a_criterion_needs_them(
        scenario_path: Path, criteria: dict[str, object], sampled: bool) -> None:
    runner = Runner(load_scenario(scenario_path, {"criteria": criteria, "duration": 0.5}),
                    None, profile=None)
    seen: list[bool] = []
    update = runner.criteria.update

    def watch(sample: Any) -> Any:
        seen.append(sample.actors is not None)
        return update(sample)

    runner.criteria.update = watch  # type: ignore[method-assign]
    result = runner.run()
    assert len(seen) == 20  # 0.5 s at 40 Hz
    assert set(seen) == {sampled}
    assert [c.name for c in result.criteria][:10] == [
        "no_collision", "tyres_in_lane", "speed_limit", "stop_signs", "red_lights",
        "crosswalks", "speed_bumps", "completes", "minimum_risk_stop", "story"]
    assert [c.name for c in result.criteria][10:] == list(criteria)

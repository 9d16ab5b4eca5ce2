"""The story plays out: a run ends early only once `completes` is reached and every required
action and event has fired; the result lists when each fired, and `story` fails for one
that never did (unless it is `optional`)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import yaml

from avsim.run.result import dumps, result_json
from avsim.run.runner import Runner, RunResult
from avsim.scenario.load import load_scenario


def run(tmp_path: Path, trigger: dict[str, object], optional: bool = False) -> RunResult:
    """The ego reaches `reach_s` (40 m) at about 2 s; the lead slows at `trigger`."""
    action: dict[str, object] = {"trigger": trigger, "speed": {"kph": 30}}
    if optional:
        action["optional"] = True
    text = {"format": "avsim/1", "name": "story", "duration": 12,
            "road": {"lanes": 2, "speed_limit_kph": 60, "segments": [{"straight": 500}]},
            "ego": {"s": 10, "speed_kph": 50, "set_speed_kph": 50},
            "actors": [{"id": "lead", "type": "car", "lane": 1, "s": 80, "speed_kph": 50,
                        "actions": [action]}],
            "criteria": {"reach_s": 40}}
    path = tmp_path / "story.yaml"
    path.write_text(yaml.safe_dump(text), encoding="utf-8")
    return Runner(load_scenario(path), None, profile=None).run()


def story(result: RunResult) -> tuple[bool | None, float | None, str | None]:
    c = next(c for c in result.criteria if c.name == "story")
    return c.passed, c.value, c.note


def test_the_run_waits_for_a_late_action_then_ends(tmp_path: Path) -> None:
    result = run(tmp_path, {"time": 6.0})
    reached = next(c for c in result.criteria if c.name == "completes")
    assert reached.passed and reached.value is not None and reached.value > 40.0
    entry = result.story[0]
    assert (entry.actor, entry.index, entry.kind, entry.fired_at) == ("lead", 0, "speed", 6.0)
    assert result.sim_time == pytest.approx(6.0 + 1.0, abs=0.05)  # fired, then 1 s settle
    assert story(result) == (True, 0.0, None)


def test_an_action_that_never_fires_fails_story_at_the_duration(tmp_path: Path) -> None:
    result = run(tmp_path, {"time": 50.0})
    assert result.sim_time == pytest.approx(12.0)  # it waited to the end for it
    assert result.story[0].fired_at is None
    assert story(result) == (False, 1.0, "never fired: actors.lead.actions.0")
    assert not result.passed
    payload = json.loads(dumps(result_json(result, "story.yaml", Path("x.rrd"), "none")))
    assert payload["story"] == [{"actor": "lead", "action": 0, "kind": "speed",
                                 "optional": False, "fired_at": None}]


def test_an_optional_action_need_not_fire(tmp_path: Path) -> None:
    result = run(tmp_path, {"time": 50.0}, optional=True)
    assert result.sim_time < 4.0  # reached at about 2 s, plus the settle
    assert story(result) == (None, None, "the scenario scripts no required action")
    assert result.passed

"""`avsim convert` round trip: every visible `.xosc` file that loads (the ALKS, Euro NCAP and
ASAM example sets, a distribution file by its first permutation, the docs' example) converts
to YAML that loads back as a scenario with the same world (road, car under test, actors),
and every story action is either written as an actor's action or listed as a misfit, never
dropped without a word."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from avsim.scenario.errors import ScenarioError
from avsim.scenario.load import load_scenario
from avsim.scenario.openscenario.actions import ActivateControllerAction, AssignControllerAction
from avsim.scenario.openscenario.convert import load_xosc
from avsim.scenario.openscenario.distribution import is_distribution, load_distribution
from avsim.scenario.openscenario.to_yaml import Conversion, convert_scenario, convert_xosc
from avsim.scenario.scenario import Scenario

REPO = Path(__file__).resolve().parents[4]
SETS = [REPO / "tests" / "data" / name for name in ("alks", "ncap", "asam_examples")]
EXAMPLES = REPO / "docs" / "examples"
FILES = [(f, root) for root in [*SETS, EXAMPLES] for f in sorted(root.rglob("*.xosc"))
         if "atalog" not in f.as_posix()]
CONTROLLER = (ActivateControllerAction, AssignControllerAction)  # the stack drives the ego


def _load(path: Path, root: Path) -> tuple[Path, Scenario]:
    """The scenario of `path` (a distribution file: its first run), or a skip with the
    loader's reason."""
    target, overrides = path, None
    try:
        if is_distribution(path):
            distribution = load_distribution(path, [root])
            target, overrides = distribution.scenario, distribution.runs[0].overrides()
        return target, load_xosc(target, overrides, None, [root])
    except ScenarioError as exc:
        pytest.skip(f"does not load: {exc}")


def _actions(scenario: Scenario) -> list[tuple[str, str, object]]:
    """(event, action, private action) of every story action."""
    assert scenario.story is not None
    board = scenario.story.scenario.storyboard
    return [(event.name, action.name, action.private_action)
            for story in board.stories for act in story.acts for group in act.maneuver_groups
            for maneuver in group.maneuvers for event in maneuver.events
            for action in event.actions]


def _accounted(conversion: Conversion, scenario: Scenario) -> None:
    misfits = "\n".join(conversion.misfits)
    for event, name, private in _actions(scenario):
        if name in conversion.converted or isinstance(private, CONTROLLER):
            continue
        assert f"action {name}:" in misfits or f"event {event}:" in misfits, (
            f"action {name} (event {event}) is neither converted nor listed as a misfit")
    written = [a for actor in conversion.document.get("actors", [])
               for a in actor.get("actions", [])]
    assert len(written) == len(conversion.converted)


def _same_world(original: Scenario, back: Scenario) -> None:
    a, b = original.world, back.world
    assert (b.ego.lane, b.ego.s, b.ego.speed) == pytest.approx(
        (a.ego.lane, a.ego.s, a.ego.speed), abs=1e-5)
    assert [x.id for x in b.actors] == [x.id for x in a.actors]
    for x, y in zip(a.actors, b.actors, strict=True):
        assert (y.type, y.lane) == (x.type, x.lane)
        assert (y.s, y.offset, y.speed) == pytest.approx((x.s, x.offset, x.speed), abs=1e-5)
    ra, rb = a.road, b.road
    assert (rb.segments[0].lanes, rb.segments[0].oncoming_lanes) == (
        ra.segments[0].lanes, ra.segments[0].oncoming_lanes)
    assert sum(s.length for s in rb.segments) == pytest.approx(
        sum(s.length for s in ra.segments), rel=1e-6)
    # the time StopTrigger that ends the file's run, else its time limit
    assert back.duration <= original.duration + 1e-5


@pytest.mark.parametrize(("path", "root"), FILES,
                         ids=[f.relative_to(REPO).as_posix() for f, _ in FILES])
def test_a_converted_file_loads_back_with_the_same_world(
        tmp_path: Path, path: Path, root: Path) -> None:
    target, scenario = _load(path, root)
    conversion = convert_scenario(scenario, target)
    out = tmp_path / "converted.yaml"
    out.write_text(yaml.safe_dump(conversion.document, sort_keys=False), encoding="utf-8")
    back = load_scenario(out)
    _same_world(scenario, back)
    _accounted(conversion, scenario)


def test_a_deceleration_is_written_as_a_negative_acceleration(tmp_path: Path) -> None:
    """minimal.xosc's Lead brakes from 50 km/h to a stop at 4 m/s^2 (a rate, unsigned in
    OpenSCENARIO): the YAML format's accel is signed."""
    conversion = convert_xosc(EXAMPLES / "minimal.xosc")
    (lead,) = conversion.document["actors"]
    (brake,) = lead["actions"]
    assert brake["speed"] == {"kph": 0.0, "accel": -4.0}
    out = tmp_path / "minimal.yaml"
    out.write_text(yaml.safe_dump(conversion.document, sort_keys=False), encoding="utf-8")
    action = load_scenario(out).world.actors[0].actions[0].action
    assert action.accel == pytest.approx(4.0)  # type: ignore[union-attr]


def test_a_lane_wider_than_the_format_takes_is_a_misfit() -> None:
    """The Euro NCAP track's one 28 m lane: the YAML's lanes are at most 6 m."""
    root = REPO / "tests" / "data" / "ncap"
    path = root / "OpenSCENARIO" / "NCAP" / "AEB_C2C_2023" / "NCAP_AEB_C2C_CCR_2023.xosc"
    conversion = convert_xosc(path, None, [root])
    assert conversion.document["road"]["lane_width"] == 6.0
    assert any("lane width 28 m" in m for m in conversion.misfits)

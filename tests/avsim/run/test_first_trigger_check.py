"""The storyboard's first trigger check is at t = 0, before the first physics step, as
esmini's (its first storyboard step is at time 0): a condition false there and true at the
next check rises there, and an act whose trigger holds at t = 0 starts at t = 0."""

from __future__ import annotations

from pathlib import Path

from avsim.run.runner import Runner
from avsim.scenario.load import load_scenario

ALKS = Path(__file__).resolve().parents[2] / "data" / "alks" / "logical_scenarios" \
    / "concrete_scenarios"
CUT_IN = ALKS / "alks_scenario_4_4_1_cut_in_no_collision_template.xosc"
CONDITION = """name="ActivateALKSControllerActCondition" delay="0" conditionEdge="{edge}">
              <ByValueCondition>
                <SimulationTimeCondition value="0" rule="{rule}" />"""
ACT_TRIGGER = CONDITION.format(edge="none", rule="greaterOrEqual")
RISING = CONDITION.format(edge="rising", rule="greaterThan")


def _act_starts(path: Path) -> list[float]:
    scenario = load_scenario(path, {"duration": 0.2}, search_paths=[ALKS],
                             scripted_ego=True)
    runner = Runner(scenario, profile=None)
    assert runner.run().error is None
    assert runner.director is not None
    return [t for t, kind, name, transition in runner.director.runtime.history()
            if (kind, name, transition) == ("act", "ActivateALKSControllerAct",
                                            "startTransition")]


def test_an_act_whose_trigger_holds_at_t0_starts_at_t0() -> None:
    assert _act_starts(CUT_IN) == [0.0]


def test_a_rising_edge_on_simulation_time_above_0_starts_the_act_at_the_second_check(
        tmp_path: Path) -> None:
    """`SimulationTimeCondition > 0`, rising (ASAM's 1.2 examples' act trigger): false at
    the check at t = 0, true at the next (0.025 s): it rises there (esmini: 0.025 s)."""
    text = CUT_IN.read_text()
    assert ACT_TRIGGER in text
    path = tmp_path / "rising.xosc"
    path.write_text(text.replace(ACT_TRIGGER, RISING))
    assert _act_starts(path) == [0.025]

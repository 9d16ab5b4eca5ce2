"""esmini's own example scenarios (`tests/data/esmini_examples/`, vendored unchanged) played
with a scripted car under test, against the times esmini gives (its `SOURCE.md`)."""

from __future__ import annotations

from pathlib import Path

from avsim.run.runner import Runner
from avsim.scenario.load import load_scenario
from tests.conformance.reference import EVENT_TOLERANCE

EXAMPLES = Path(__file__).resolve().parents[1] / "data" / "esmini_examples"


def _event_starts(name: str, duration: float) -> dict[str, list[float]]:
    scenario = load_scenario(EXAMPLES / "xosc" / name, {"duration": duration},
                             search_paths=[EXAMPLES], scripted_ego=True)
    runner = Runner(scenario, profile=None)
    result = runner.run()
    assert result.error is None, result.error
    director = runner.director
    assert director is not None
    starts: dict[str, list[float]] = {}
    for t, kind, element, transition in director.runtime.history():
        if kind == "event" and transition == "startTransition":
            starts.setdefault(element, []).append(t)
    return starts


def test_ttc_freespace_road_longitudinal_fires_when_esmini_fires_it() -> None:
    """A TimeToCollisionCondition (freespace, road, longitudinal) on a car in the lane beside
    the Ego, placed in lane 1 turned half a turn from that lane's direction (so it drives
    along the road, as esmini reads a relative orientation), in an act whose StartTrigger
    is empty (it starts at once, as esmini's): esmini starts the cut-in at 2.175 s, measuring
    the Ego's box from the file."""
    starts = _event_starts("alks_cut-in.xosc", 3.0)
    assert len(starts.get("CutInEvent", [])) == 1, starts
    assert abs(starts["CutInEvent"][0] - 2.175) <= EVENT_TOLERANCE + 1e-9, starts

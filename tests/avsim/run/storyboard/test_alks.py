"""The parsed ALKS storyboards at run time: 4_4_1 (cut-in) against a scripted sequence of
snapshots, and every ALKS file's storyboard built and stepped."""

from __future__ import annotations

from pathlib import Path

import pytest

from avsim.run.storyboard.elements import ElementState
from avsim.run.storyboard.runtime import StepResult, StoryRuntime
from avsim.run.storyboard.snapshot import Snapshot
from avsim.scenario.openscenario import load_openscenario
from avsim.scenario.openscenario.actions import LaneChangeAction, SpeedAction
from tests.avsim.run.storyboard.helpers import entity, snapshot

ALKS = Path(__file__).parents[3] / "data" / "alks" / "logical_scenarios" / "concrete_scenarios"
FILES = sorted(ALKS.glob("alks_scenario_*.xosc"))
CUT_IN = ALKS / "alks_scenario_4_4_1_cut_in_no_collision_template.xosc"
DT = 0.05  # [s]
EGO_V, CUT_IN_V = 60.0 / 3.6, 40.0 / 3.6  # [m/s]
GAP0 = 30.0 + 10.0 * 20.0 / 3.6  # [m] between reference points at t = 0 (the file's ds)
LENGTH = 5.0  # [m] both cars' boxes
CUT_IN_ID = "CutInStory/CutInAct/CutInManeuverGroup/CutInManeuver/CutInEvent/CutInAction#1"
LANE_CHANGE_TIME = 3.0  # [s] the scripted lane change's duration


def scripted(t: float) -> Snapshot:
    """Ego in its lane at 60 km/h, the cut-in car in the lane to its right at 40 km/h,
    GAP0 ahead at t = 0 (their boxes LENGTH long, centres 1.4 m ahead of the reference)."""
    box = {"length": LENGTH, "width": 2.0, "centre_ahead": 1.4}
    ego = entity("Ego", x=EGO_V * t, speed=EGO_V, **box)
    car = entity("CutInVehicle", x=GAP0 + CUT_IN_V * t, y=-3.5, speed=CUT_IN_V, **box)
    return snapshot(ego, car, t=t)


def freespace_gap(t: float) -> float:
    return GAP0 + (CUT_IN_V - EGO_V) * t - LENGTH


def test_cut_in_starts_at_30_m_and_the_run_stops_10_s_after_the_lane_change() -> None:
    scenario = load_openscenario(CUT_IN)
    rt = StoryRuntime(scenario.storyboard, scenario.parameters)
    results: list[StepResult] = []
    done_at: float | None = None
    reported: list[float] = []
    for k in range(int(40.0 / DT)):
        t = k * DT
        if done_at is not None and t >= done_at - 1e-9 and not any(
                h[2] == "CutInAction" and h[3] == "endTransition" for h in rt.history()):
            rt.action_done(CUT_IN_ID, t)  # the world reports the lane change done
            reported.append(t)
        result = rt.step(scripted(t))
        results.append(result)
        if any(a.name == "CutInAction" for a in result.started):
            done_at = t + LANE_CHANGE_TIME
        if result.ended:
            break

    controller = [(r.time, a) for r in results for a in r.started
                  if a.name == "ActivateALKSControllerAction"]
    assert [(round(t, 6), a.entities) for t, a in controller] == [(3.0, ("Ego",))]

    cut_in = [(r.time, a) for r in results for a in r.started if a.name.startswith("CutIn")]
    t_start = cut_in[0][0]
    assert freespace_gap(t_start) < 30.0 <= freespace_gap(t_start - DT)
    assert [a.name for _, a in cut_in] == ["CutInAction", "CutInAccelerateAction"]
    assert all(t == t_start and a.entities == ("CutInVehicle",) for t, a in cut_in)
    assert isinstance(cut_in[0][1].action, LaneChangeAction)
    assert isinstance(cut_in[1][1].action, SpeedAction)
    assert cut_in[0][1].action_id == CUT_IN_ID

    assert done_at is not None
    end = results[-1]
    assert end.ended and end.time == pytest.approx(done_at + 10.0)
    assert not any(r.ended for r in results[:-1])
    accelerate = CUT_IN_ID.replace("CutInAction", "CutInAccelerateAction")
    assert end.stopped == (accelerate,)  # never reported done: stopped at the end
    assert rt.state("action", "CutInAction") is ElementState.COMPLETE
    assert rt.state("story", "ActivateALKSControllerStory") is ElementState.COMPLETE
    ends = [h[0] for h in rt.history() if h[2:] == ("CutInAction", "endTransition")]
    assert ends == reported


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.stem)
def test_every_alks_storyboard_runs(path: Path) -> None:
    """Built (its element references unique) and stepped for 5 s with no world behind it:
    the controller activation at 3 s starts and completes at once."""
    scenario = load_openscenario(path)
    rt = StoryRuntime(scenario.storyboard, scenario.parameters)
    started = []
    for k in range(int(5.0 / DT) + 1):
        t = k * DT
        snap = snapshot(*(entity(e.name, x=10.0 * i) for i, e in enumerate(scenario.entities)),
                        t=t)
        started += [a.name for a in rt.step(snap).started]
    assert "ActivateALKSControllerAction" in started
    assert rt.state("action", "ActivateALKSControllerAction") is ElementState.COMPLETE

"""No ACC mode chatter in the bundled scenarios (issue K, item 2): outside safety
transitions (`avsim.run.holds.SAFETY_MODES`), no ACC mode is held for less than 0.5 s.

Measured on the golden results (`golden/`): every one is the exact record of a bundled
scenario's run, which its own test module checks to the last bit, so this reads those runs
without running them again."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from avsim.run.holds import shortest_hold
from planner.fsm.machine import StateChange

GOLDEN = sorted((Path(__file__).parent / "golden").glob("*.json"))
MIN_HOLD = 0.5  # [s]
#   Fixed (issue K, item 2): town_left_turn's TRAIL for 0.1 s as the yield ended (TRAIL
#   outlives a lost lead by lead_hold, `planner.fsm.acc`); decs_route's SPEED_LIMIT for 0.35 s
#   before OFF_RAMP (the ramp's event starts where its limit applies, `planner.events`);
#   town_route's CRUISE for 0.1 s between two YIELDs (a gap is taken once clear for
#   gap_confirm, then committed to, `planner.junctions`). Their runs hold every mode >= 2.1 s
#   (decs_route), 3.6 s (town_route, town_left_turn) once their goldens are rewritten.


def test_every_bundled_scenario_has_a_golden_run() -> None:
    assert len(GOLDEN) >= 15


KNOWN = {  # run -> why it still chatters (issue K, item 2)
    "tracking": "TRAIL for 0.1 s at 12.8 s: a new track 48 m ahead, a car's first returns "
                "boxed as a pedestrian standing in the lane (time to collision 2.4 s: urgent, "
                "the lead at once), is a car in the next lane on the next scan",
}


@pytest.mark.parametrize("path", [
    pytest.param(p, marks=pytest.mark.xfail(strict=True, reason=KNOWN[p.stem]))
    if p.stem in KNOWN else p for p in GOLDEN], ids=[p.stem for p in GOLDEN])
def test_no_acc_mode_is_held_for_less_than_half_a_second(path: Path) -> None:
    record = json.loads(path.read_text())
    changes = [StateChange(c["t"], c["machine"], c["from"], c["to"], c["reason"])
               for c in record["state_changes"]]
    assert any(c.machine == "acc" for c in changes), "no ACC mode in this run"
    assert shortest_hold(changes, "acc") >= MIN_HOLD

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
KNOWN = {  # what still chatters (issue K, items 2 and 6), kept visible (town_left_turn's
    #   TRAIL for 0.1 s as the yield ended is gone: TRAIL outlives a lost lead by lead_hold,
    #   `planner.fsm.acc`; its run holds every mode >= 0.6 s, once its golden is rewritten)
    "decs_route": "SPEED_LIMIT for 0.35 s before OFF_RAMP at 105.2 s: the ramp's lower limit "
                  "applies at the front bumper before the off-ramp event starts",
    "town_route": "CRUISE for 0.2 s at 18.8 s between two YIELDs: the junction's gap "
                  "acceptance takes a gap and gives it up",
}


def test_every_bundled_scenario_has_a_golden_run() -> None:
    assert len(GOLDEN) >= 15


@pytest.mark.parametrize("path", [
    pytest.param(p, marks=pytest.mark.xfail(strict=True, reason=KNOWN[p.stem]))
    if p.stem in KNOWN else p for p in GOLDEN], ids=[p.stem for p in GOLDEN])
def test_no_acc_mode_is_held_for_less_than_half_a_second(path: Path) -> None:
    record = json.loads(path.read_text())
    changes = [StateChange(c["t"], c["machine"], c["from"], c["to"], c["reason"])
               for c in record["state_changes"]]
    assert any(c.machine == "acc" for c in changes), "no ACC mode in this run"
    assert shortest_hold(changes, "acc") >= MIN_HOLD

"""The Euro NCAP 2023 AEB files (vendored in `tests/data/ncap/`) in closed loop with the stack,
through `avsim suite --criteria ncap`: the VUT held at the test speed by its driver with the
automated function off, only the AEB braking (the `ncap` set's `function: off`), judged by
the `ncap` verdict and summed in the scorecard.

One cheap run in `make test` (CCRs at 20 km/h, the `fast` profile); the rear-end, head-on and
straight-road VRU base files that load, at their defaults with the `default` profile, in
`make acceptance`.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from click.testing import CliRunner

from avsim.cli import main
from planner.fsm.control import ControlParams

NCAP = Path(__file__).parents[1] / "data" / "ncap"
C2C = NCAP / "OpenSCENARIO" / "NCAP" / "AEB_C2C_2023"
VRU = NCAP / "OpenSCENARIO" / "NCAP" / "AEB_VRU_2023"
KPH = 1.0 / 3.6  # [m/s] per km/h


def suite(files: list[Path], out: Path, profile: str) -> dict[str, dict[str, Any]]:
    """Each run's result JSON by run name after `avsim suite FILES --criteria ncap`."""
    result = CliRunner().invoke(main, ["suite", *map(str, files), "--criteria", "ncap",
                                       "--search-path", str(NCAP), "--profile", profile,
                                       "--out", str(out)])
    assert result.exit_code in (0, 1), result.output  # 1: a run failed its verdict
    return {p.stem: json.loads(p.read_text(encoding="utf-8"))
            for p in out.glob("*.json") if p.stem != "results"}


def ncap(run: dict[str, Any]) -> dict[str, Any]:
    """The run's `ncap` criterion."""
    return next(c for c in run["criteria"] if c["name"] == "ncap")


def changes(run: dict[str, Any], machine: str) -> list[str]:
    """The states `machine` entered, in order."""
    return [c["to"] for c in run["state_changes"] if c["machine"] == machine]


@pytest.mark.slow
def test_ccrs_at_20_kph_is_avoided_by_the_aeb_through_the_suite(tmp_path: Path) -> None:
    runs = suite([C2C / "NCAP_AEB_C2C_CCR_2023.xosc"], tmp_path, "fast")
    run = runs["ncap_aeb_c2c_ccr_2023"]
    verdict = ncap(run)
    details = verdict["details"]
    assert (details["test"], details["test_speed_kph"], details["overlap"]) == ("CCRs", 20.0,
                                                                                100.0)
    assert run["metrics"]["max_speed"] == pytest.approx(20.0 * KPH, abs=0.3)  # held
    assert changes(run, "acc") == []  # the function stays off: no ACC braked for it
    assert "emergency_stop" in changes(run, "control")  # the AEB did
    assert verdict["passed"] and details["avoided"], verdict["note"]
    summary = (tmp_path / "summary.md").read_text(encoding="utf-8")
    assert "## Euro NCAP scorecard" in summary
    assert "| ncap_aeb_c2c_ccr_2023 | CCRs | 20 | 0 | 100 % | yes |" in summary


@pytest.mark.acceptance
@pytest.mark.parametrize(("file", "test", "speed", "target"), [
    (C2C / "NCAP_AEB_C2C_CCR_2023.xosc", "CCRs", 20.0, 0.0),
    (VRU / "NCAP_AEB_VRU_CBLA_2023.xosc", "CBLA", 25.0, 15.0),
], ids=lambda v: v.stem if isinstance(v, Path) else None)
def test_a_base_file_at_its_defaults(file: Path, test: str, speed: float, target: float,
                                     tmp_path: Path) -> None:
    run = next(iter(suite([file], tmp_path, "default").values()))
    verdict = ncap(run)
    details = verdict["details"]
    assert details["test"] == test  # CCFhos's base file names itself CCFhol (its Scenario_ID)
    assert details["test_speed_kph"] == speed and details["target_speed_kph"] == target
    assert run["metrics"]["max_speed"] == pytest.approx(speed * KPH, abs=0.3)
    assert changes(run, "acc") == []
    assert verdict["passed"] and details["avoided"], verdict["note"]


@pytest.mark.acceptance
@pytest.mark.parametrize("file", [C2C / "NCAP_AEB_C2C_CCFhos_2023.xosc",
                                  C2C / "NCAP_AEB_C2C_CCFhol_2023.xosc"], ids=lambda v: v.stem)
def test_a_head_on_base_file_brakes_at_the_true_time_to_collision(file: Path,
                                                                  tmp_path: Path) -> None:
    """A target at 70 km/h coming at the car in its lane cannot be avoided by braking: the
    protocol scores the speed reduction (SA-CA 10.4.1 3.3.5: 0.25 points from 20 km/h).
    The AEB takes the oncoming car's speed into its time to collision, so it brakes at
    least `ttc_emergency` before the impact (braking only delays the impact)."""
    run = next(iter(suite([file], tmp_path, "default").values()))
    details = ncap(run)["details"]
    assert (details["test_speed_kph"], details["target_speed_kph"]) == (70.0, 70.0)
    assert changes(run, "acc") == []
    braked = next(c["t"] for c in run["state_changes"]
                  if c["machine"] == "control" and c["to"] == "emergency_stop")
    assert details["impact_t"] - braked >= ControlParams().ttc_emergency
    assert details["speed_reduction_kph"] >= 20.0 and details["points"] == 0.25

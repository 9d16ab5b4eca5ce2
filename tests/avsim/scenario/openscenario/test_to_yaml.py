"""`avsim convert FILE.xosc`: the avsim/1 YAML where the file fits the format (it loads as a
scenario), and what does not fit, listed."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from avsim.scenario.load import load_scenario
from avsim.scenario.openscenario.to_yaml import convert_xosc

ALKS = Path(__file__).parents[3] / "data" / "alks" / "logical_scenarios" / "concrete_scenarios"
CUT_IN = ALKS / "alks_scenario_4_4_1_cut_in_no_collision_template.xosc"


def test_the_cut_in_converts_to_a_yaml_scenario_that_loads(tmp_path: Path) -> None:
    conversion = convert_xosc(CUT_IN)
    doc = conversion.document
    (car,) = doc["actors"]
    assert car["actions"][0] == {"trigger": {"gap": 30.0},
                                 "lane_change": {"to_lane": 1, "lateral_speed": 2.0}}
    assert doc["road"]["segments"] == [{"straight": 10000.0}]
    assert doc["ego"] == {"lane": 1, "s": 6.35, "speed_kph": 60.0, "set_speed_kph": 60.0,
                          "max_speed_kph": 180.0}
    path = tmp_path / "cut_in.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False), encoding="utf-8")
    scenario = load_scenario(path)
    assert scenario.world.actors[0].s == pytest.approx(5.0 + 30.0 + 200.0 / 3.6 + 1.4)
    misfits = "\n".join(conversion.misfits)
    assert "sinusoidal shape" in misfits and "StopTrigger" in misfits
    assert "box 5 x 2 x 1.8 m" in misfits  # the catalogue has no such car
    assert "far carriageway (3 lanes" in misfits  # drawn in the world, not in the YAML


def test_a_curved_road_becomes_arcs_and_says_so() -> None:
    conversion = convert_xosc(ALKS / "alks_scenario_4_1_1_free_driving_template.xosc")
    segments = conversion.document["road"]["segments"]
    assert any("arc" in seg for seg in segments)
    assert sum(seg.get("straight", 0.0) + (seg["arc"]["radius"] * abs(
        seg["arc"]["angle_deg"]) * 3.141592653589793 / 180.0 if "arc" in seg else 0.0)
        for seg in segments) == pytest.approx(5100.0, rel=1e-3)
    assert any("clothoid" in m for m in conversion.misfits)
    assert conversion.document["duration"] == pytest.approx(300.0)  # a time StopTrigger


def test_the_command_prints_yaml_and_refuses_a_yaml_file(tmp_path: Path) -> None:
    out = subprocess.run([sys.executable, "-m", "avsim.cli", "convert", str(CUT_IN)],
                         capture_output=True, text=True, check=False, cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert yaml.safe_load(out.stdout)["format"] == "avsim/1"
    assert out.stdout.startswith("# avsim/1, converted from")
    assert "do not fit" in out.stderr
    bad = subprocess.run([sys.executable, "-m", "avsim.cli", "convert", "x.yaml"],
                         capture_output=True, text=True, check=False, cwd=tmp_path)
    assert bad.returncode == 2 and bad.stderr.count("\n") == 1
    assert list(tmp_path.iterdir()) == []

"""`--profile none` says what it means: no camera or LiDAR, the pose from the scenario's GNSS
receiver + odometry, and the lane-keeping error to expect from it, in the run's header and in
the result file (`world.sensors.setup.localisation`)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from world.sensors.setup import Profile, localisation, receiver_name
from world.spec import GNSS_PRESETS, GnssSpec

STRAIGHT = """\
format: avsim/1
name: straight
duration: 1
road:
  speed_limit_kph: 50
  segments:
    - straight: 300
ego: {s: 10, speed_kph: 40, set_speed_kph: 40}
"""


def test_a_run_without_profile_states_its_pose_source_and_error(tmp_path: Path) -> None:
    """A straight road with the default (consumer) receiver: the header names the receiver
    and its 1.24 m error, and the result file's `localisation` says the same."""
    scenario = tmp_path / "straight.yaml"
    scenario.write_text(STRAIGHT, encoding="utf-8")
    proc = subprocess.run(
        [sys.executable, "-m", "avsim.cli", "run", str(scenario), "--profile", "none",
         "--out", str(tmp_path / "x.rrd"), "--no-progress"],
        cwd=tmp_path, capture_output=True, text=True, timeout=120, check=False)
    assert proc.returncode in (0, 1), proc.stderr
    header = proc.stdout.splitlines()[0]
    assert header.startswith("straight: profile none: no camera or LiDAR")
    assert "GNSS (consumer receiver, 1.24 m 1-sigma per axis) + odometry" in header
    assert "expect lane-keeping errors of the receiver's size (1.24 m)" in header
    result = json.loads((tmp_path / "x.json").read_text(encoding="utf-8"))
    assert result["profile"] == "none"
    assert result["localisation"] == {"source": "gnss+odometry", "receiver": "consumer",
                                      "error": 1.2369, "privileged": False}


@pytest.mark.parametrize(("gnss", "name", "error"), [
    (GNSS_PRESETS["rtk"], "rtk", 0.05),
    (GNSS_PRESETS["degraded"], "degraded", 3.1048),
    (GnssSpec(bias=(3.0, 4.0)), "custom", 6.2369),  # a constant bias adds its size
])
def test_the_receiver_is_named_with_its_error(gnss: GnssSpec, name: str, error: float) -> None:
    assert receiver_name(gnss) == name
    loc = localisation(None, gnss)
    assert loc.receiver == name and loc.error == pytest.approx(error, abs=1e-4)
    assert f"({loc.error:.2f} m)" in loc.note and not loc.privileged


def test_with_a_camera_the_lane_corrects_the_pose() -> None:
    loc = localisation(Profile.FAST, GnssSpec())
    assert loc.source == "gnss+odometry+camera_lane" and "corrected across the lane" in loc.note

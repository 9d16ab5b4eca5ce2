"""`sensors.gnss`: presets, knobs, and how they combine (docs/scenario-format.md)."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import pytest

from avsim.scenario.load import load_scenario
from tests.avsim.texts import MINIMAL
from world.spec import GNSS_PRESETS, GnssSpec


def gnss(tmp_path: Path, block: str | None) -> GnssSpec:
    text = MINIMAL + (f"sensors:\n  gnss: {block}\n" if block is not None else "")
    path = tmp_path / "s.yaml"
    path.write_text(text)
    return load_scenario(path).world.sensors.gnss


def test_no_block_is_the_consumer_receiver(tmp_path: Path) -> None:
    assert gnss(tmp_path, None) == GNSS_PRESETS["consumer"]


@pytest.mark.parametrize("name", ["rtk", "consumer", "degraded"])
def test_a_preset_by_name(tmp_path: Path, name: str) -> None:
    assert gnss(tmp_path, f"{{preset: {name}}}") == GNSS_PRESETS[name]


def test_knobs_without_a_preset_mean_what_they_meant(tmp_path: Path) -> None:
    """White noise and a constant bias, no wander, no outages: the model before presets."""
    got = gnss(tmp_path, "{sigma: 0.1, heading_sigma_deg: 0.5, bias: [1.0, -1.5]}")
    assert got == replace(GNSS_PRESETS["rtk"], sigma=0.1, heading_sigma=math.radians(0.5),
                          bias=(1.0, -1.5))
    assert (got.bias_sigma, got.dropout_rate, got.velocity_sigma) == (0.0, 0.0, 0.0)


def test_knobs_override_the_preset(tmp_path: Path) -> None:
    got = gnss(tmp_path, "{preset: consumer, bias: [0.0, 1.5], dropout_rate: 0}")
    assert got == replace(GNSS_PRESETS["consumer"], bias=(0.0, 1.5), dropout_rate=0.0)

"""A pedestrian's walker keeps its box's height as its stature; its gait's amplitude is what
adapts to the box's length (`world.actors.shapes.actors.walker_amplitude`): every posed phase
fits the box within `MATCH`, the Euro NCAP targets walk with the full gait, and a box shorter
than the standing walker gets a standing walker whose excess is stated (`walker_excess`)."""

from __future__ import annotations

import numpy as np
import pytest

from world.actors.shapes import targets
from world.actors.shapes.actors import MATCH, walker_amplitude, walker_excess
from world.actors.shapes.humans import swept_range
from world.actors.shapes.walker import link_frames, posed_points, walker_model, walker_pose

ALKS_ADULT = (0.3, 0.5, 1.8)  # [m] the ALKS catalogue's "Adult" box: length, width, height
GENERIC = (0.5, 0.6, 1.75)  # [m] a YAML pedestrian's default box
PHASES = [k / 100 for k in range(100)] + [0.013, 0.2499, 0.5001, 0.7777]


def _extent(box: tuple[float, float, float]) -> tuple[float, float, float, float]:
    """[m] the largest |x|, |y| and the least and largest z of the box's walker over PHASES,
    posed by its forward kinematics."""
    length, width, height = box
    model = walker_model(height, width, walker_amplitude(length, width, height))
    half, lo_z, hi_z = np.zeros(2), np.inf, -np.inf
    for phase in PHASES:
        pose = walker_pose(height, phase, width, model.amplitude)
        for pts in posed_points(model, pose).values():
            half = np.maximum(half, np.abs(pts[:, :2]).max(axis=0))
            lo_z, hi_z = min(lo_z, float(pts[:, 2].min())), max(hi_z, float(pts[:, 2].max()))
    return float(half[0]), float(half[1]), lo_z, hi_z


@pytest.mark.parametrize("box", [ALKS_ADULT, GENERIC])
def test_a_short_box_keeps_the_stature_and_every_phase_fits(
        box: tuple[float, float, float]) -> None:
    length, width, height = box
    amplitude = walker_amplitude(length, width, height)
    assert 0.0 < amplitude < 1.0  # a shorter stride, not a shorter person
    assert walker_model(height, width, amplitude).height == height
    half_x, half_y, lo_z, hi_z = _extent(box)
    assert half_x <= 0.5 * length + MATCH
    assert half_y <= 0.5 * width + MATCH
    assert lo_z == pytest.approx(0.0, abs=0.01)  # on the ground
    assert hi_z == pytest.approx(height, abs=0.01)  # the crown at the stature (mid stance)
    assert walker_excess(length, width, height) <= MATCH


@pytest.mark.parametrize("box", [ALKS_ADULT, GENERIC])
def test_the_amplitude_is_the_largest_that_fits(box: tuple[float, float, float]) -> None:
    """A little more gait than the chosen one sweeps more than the box allows."""
    length, width, height = box
    amplitude = walker_amplitude(length, width, height)
    lo, hi, _ = swept_range(height, width, amplitude + 0.01)
    assert 0.5 * (hi - lo) > 0.5 * length + MATCH


@pytest.mark.parametrize("box", [ALKS_ADULT, GENERIC])
def test_the_legs_of_a_short_box_still_move(box: tuple[float, float, float]) -> None:
    length, width, height = box
    model = walker_model(height, width, walker_amplitude(length, width, height))
    assert model.amplitude > 0.0
    a, b = (link_frames(model, walker_pose(height, phase, width, model.amplitude))
            for phase in (0.0, 0.5))
    assert abs(a["left_foot"][1][0] - b["left_foot"][1][0]) > 1e-3  # [m]


@pytest.mark.parametrize("target", [targets.EPTA, targets.EPTC])
def test_the_euro_ncap_targets_walk_with_the_full_gait(target: targets.Target) -> None:
    assert walker_amplitude(target.length, target.width, target.height) == 1.0


def test_a_box_shorter_than_the_standing_walker_gets_a_standing_walker() -> None:
    """No gait fits a 0.2 m box for a 1.8 m person: the walker stands (amplitude 0) at its
    full stature, and its excess over the box is what the standing walker sweeps beyond."""
    length, width, height = 0.2, 0.5, 1.8
    assert walker_amplitude(length, width, height) == 0.0
    lo, hi, _ = swept_range(height, width, 0.0)
    excess = walker_excess(length, width, height)
    assert excess == pytest.approx(0.5 * (hi - lo) - 0.5 * length)
    assert excess > MATCH
    half_x, _, _, hi_z = _extent((length, width, height))
    assert half_x == pytest.approx(0.5 * length + excess, abs=1e-9)
    assert hi_z == pytest.approx(height, abs=0.01)

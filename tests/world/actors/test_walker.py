"""The articulated walker (`world.actors.shapes.walker`): posed by its own forward
kinematics it is `pedestrian_parts`, its legs move and bend, and its gait phase advances
with the distance walked so that the feet do not slide over a step."""

from __future__ import annotations

import numpy as np
import pytest

from world.actors.shapes import targets
from world.actors.shapes.humans import pedestrian_parts, phase_after, segments, stride_length
from world.actors.shapes.parts import points
from world.actors.shapes.walker import (
    BASE,
    LINK_NAMES,
    link_frames,
    posed_points,
    walker_model,
    walker_pose,
)

STATURES = [(targets.EPTA.height, targets.EPTA.width, 1.0),
            (targets.EPTC.height, targets.EPTC.width, 1.0), (targets.EPTA.height, None, 1.0),
            (1.8, 0.5, 0.3), (1.75, 0.6, 0.0)]  # (stature [m], width [m], gait amplitude [-])
PHASES = [k / 40 for k in range(40)] + [0.013, 0.2499, 0.5001, 0.7777, 0.999]


@pytest.mark.parametrize(("height", "width", "amplitude"), STATURES)
def test_posed_model_is_pedestrian_parts_at_every_phase(height: float, width: float | None,
                                                        amplitude: float) -> None:
    model = walker_model(height, width, amplitude)
    assert model.amplitude == amplitude
    for phase in PHASES:
        posed = posed_points(model, walker_pose(height, phase, width, amplitude))
        ref = {p.name: points(p) for p in pedestrian_parts(height, phase, width, amplitude)}
        assert posed.keys() == ref.keys()
        for name, pts in ref.items():
            np.testing.assert_allclose(posed[name], pts, rtol=0.0, atol=1e-9,
                                       err_msg=f"{name} at phase {phase}")


def test_the_model_has_a_trunk_and_eight_joints() -> None:
    model = walker_model(targets.EPTA.height, targets.EPTA.width)
    assert [p.name for p in model.base_parts] == ["torso", "head"]
    assert [link.name for link in model.links] == list(LINK_NAMES) == [
        "left_thigh", "left_shank", "left_foot", "right_thigh", "right_shank", "right_foot",
        "left_arm", "right_arm"]
    for link in model.links:
        assert np.linalg.norm(link.axis) == pytest.approx(1.0)
        assert abs(link.axis[1]) == 1.0  # all joints turn about the body's y
    # the pose's angles come in the links' order (a Bullet body's joint order)
    assert list(walker_pose(targets.EPTA.height, 0.3).angles) == list(LINK_NAMES)


def _frames(phase: float) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    h = targets.EPTA.height
    return link_frames(walker_model(h, targets.EPTA.width),
                       walker_pose(h, phase, targets.EPTA.width))


def test_the_legs_move_and_the_swinging_knee_bends() -> None:
    a, b = _frames(0.0), _frames(0.5)
    step = 0.5 * stride_length(targets.EPTA.height)
    # double support: the left foot ahead at phase 0, behind at 0.5, a step apart each time
    assert a["left_foot"][1][0] - a["right_foot"][1][0] == pytest.approx(step, abs=1e-9)
    assert b["left_foot"][1][0] - b["right_foot"][1][0] == pytest.approx(-step, abs=1e-9)
    assert a["left_foot"][1][0] - b["left_foot"][1][0] == pytest.approx(step, abs=1e-9)

    def knee(frames: dict[str, tuple[np.ndarray, np.ndarray]], side: str) -> float:
        """[rad] between the thigh's and the shank's long axes (their frames' z)."""
        thigh, shank = frames[f"{side}_thigh"][0][:, 2], frames[f"{side}_shank"][0][:, 2]
        return float(np.arccos(np.clip(thigh @ shank, -1.0, 1.0)))

    swing_left, swing_right = _frames(0.75), _frames(0.25)  # mid swing of each leg
    assert knee(swing_left, "left") > np.radians(15.0)
    assert knee(swing_left, "right") < 1e-6
    assert knee(swing_right, "right") > np.radians(15.0)
    assert knee(swing_right, "left") < 1e-6


def test_the_feet_stay_level_and_the_trunk_upright() -> None:
    for phase in PHASES:
        frames = _frames(phase)
        for name in ("left_foot", "right_foot", BASE):
            np.testing.assert_allclose(frames[name][0], np.eye(3), atol=1e-12)


@pytest.mark.parametrize(("height", "amplitude"), [(targets.EPTA.height, 1.0),
                                                   (targets.EPTC.height, 1.0), (1.8, 0.3)])
def test_the_standing_foot_does_not_slide_over_a_step(height: float, amplitude: float) -> None:
    """The left leg stands from phase 0 to 0.5: walking half a stride along x, its foot's
    place on the ground is the same at both ends, and strays little in between (a smaller
    gait amplitude, a shorter stride: no more slide)."""
    stride = stride_length(height, amplitude)
    seg = segments(height, None)

    def left_foot_on_ground(phase: float) -> float:
        foot = next(p for p in pedestrian_parts(height, phase, None, amplitude)
                    if p.name == "left_foot")
        return float(points(foot)[:, 0].min()) + stride * phase  # the body has walked on

    start, end = left_foot_on_ground(0.0), left_foot_on_ground(0.5)
    assert end == pytest.approx(start, abs=1e-9)
    between = [left_foot_on_ground(k / 100) for k in range(51)]
    assert max(between) - min(between) < 0.06 * (seg.thigh + seg.shank)


def test_phase_after_advances_one_cycle_per_stride() -> None:
    h = targets.EPTA.height
    stride = stride_length(h)
    assert 0.4 < stride < 0.6  # [m] two steps of a slow, short-stepping walker
    assert phase_after(0.0, 0.5 * stride, h) == pytest.approx(0.5)
    assert phase_after(0.75, 0.5 * stride, h) == pytest.approx(0.25)
    assert phase_after(0.1, -0.2 * stride, h) == pytest.approx(0.9)
    assert phase_after(0.3, 7 * stride, h) == pytest.approx(0.3)
    assert stride_length(targets.EPTC.height) < stride  # a child's legs are shorter


def test_a_smaller_gait_has_a_shorter_stride_and_none_stands() -> None:
    h = targets.EPTA.height
    assert 0.0 < stride_length(h, 0.3) < 0.35 * stride_length(h)
    short = stride_length(h, 0.3)
    assert phase_after(0.1, 0.5 * short, h, 0.3) == pytest.approx(0.6)
    assert stride_length(h, 0.0) == 0.0
    assert phase_after(0.25, 3.0, h, 0.0) == 0.25  # no stride: the phase stays


@pytest.mark.parametrize("height", [1.15, 1.52, 1.8])
def test_the_silhouette_has_no_gap_from_the_hips_to_the_crown(height: float) -> None:
    """Torso, neck and head are one column: a LiDAR ring crossing a walker at any height
    between its hips and its crown hits it (a body has a neck between shoulders and head)."""
    parts = pedestrian_parts(height, 0.25)
    spans = sorted((float(points(p)[:, 2].min()), float(points(p)[:, 2].max())) for p in parts)
    reach = 0.5 * height  # [m] below the hip joints: the thighs
    for lo, hi in spans:
        if lo <= reach + 1e-9:
            reach = max(reach, hi)
    assert reach == max(hi for _, hi in spans)  # the crown

"""Stop lines from camera pixels (`perception.stop_lines`): the near edge's distance on
rendered frames of a road with a stop sign's line and a zebra crossing; nothing on the
zebra or on a plain road."""

from __future__ import annotations

from dataclasses import replace

import pytest

from perception.messages import LaneEstimate
from perception.stop_lines import StopLineDetector, _nearest_run
from tests.perception.render_scene import Scene, front_camera, normal_driving_road, render
from world.hdmap import Crosswalk, StopSign

STOP = 150.0  # [m] station of the stop line's near edge
ZEBRA = 200.0  # [m]
ROAD = replace(normal_driving_road(), features=(StopSign(STOP), Crosswalk(ZEBRA, 4.0)))


def seen(scene: Scene) -> LaneEstimate:
    """The lane as a perfect lane finder would give it for this frame."""
    t = scene.truth
    return LaneEstimate(t=scene.frame.t, offset=t.offset, heading_error=t.heading_error,
                        curvature=t.curvature, width=t.width, confidence=1.0, left=None,
                        right=None)


@pytest.fixture(scope="module")
def detector() -> StopLineDetector:
    return StopLineDetector(front_camera())


@pytest.mark.parametrize(("ahead", "offset"), [(6.5, 0.0), (8.0, 0.4), (12.0, -0.3),
                                               (15.0, 0.0)])
def test_the_near_edge_of_a_stop_line(detector: StopLineDetector, ahead: float,
                                      offset: float) -> None:
    scene = render(ROAD, STOP - ahead, offset)
    distance = detector.detect(scene.frame, seen(scene))
    assert distance == pytest.approx(ahead, abs=0.15)


@pytest.mark.parametrize("s", [ZEBRA - 16.0, ZEBRA - 12.0, ZEBRA - 8.0, 100.0])
def test_no_stop_line_on_a_zebra_or_a_plain_road(detector: StopLineDetector, s: float) -> None:
    scene = render(ROAD, s)
    assert detector.detect(scene.frame, seen(scene)) is None


def test_nearest_run_of_the_right_depth() -> None:
    rows = [10.0, 10.05, 10.1, 10.15, 10.2, 14.0, 14.05]  # 0.25 m deep, then 0.1 m
    assert _nearest_run(rows, 0.05, 0.15, 0.6) == pytest.approx(9.975)
    assert _nearest_run(rows[5:], 0.05, 0.15, 0.6) is None
    assert _nearest_run([], 0.05, 0.15, 0.6) is None

"""Sensor faults as scenario events (`scenarios/faults/`): each fault happens to the data the
stack receives, the stack notices it from that data alone (its state changes say how), and
answers it: it keeps the lane on what is left and slows down, or makes a minimum-risk stop in
lane with hazard lights at no more than 4 m/s^2, and drives on when the sensor is back.

The runs use the `fast` profile (perception is not judged here, only what the stack does
with what it was given), and are shared within the module.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from numpy.typing import NDArray

from avsim.criteria.route import MRM_DECEL
from avsim.run.runner import RunResult
from planner.fsm.machine import StateChange
from tests.scenarios.golden import check
from world.frames import CameraFrame
from world.sensors.setup import Profile

pytestmark = pytest.mark.slow
FAULTS = Path(__file__).resolve().parents[2] / "scenarios" / "faults"
FIRES = 6.0  # [s] every fault's trigger time


class FrontFrames:
    """A frame hook that keeps the front camera's images as the stack received them (it
    changes nothing): (capture time [s], the image)."""

    def __init__(self) -> None:
        self.frames: list[tuple[float, NDArray[np.uint8]]] = []

    def __call__(self, frame: CameraFrame) -> CameraFrame:
        if frame.info.name == "front":
            self.frames.append((frame.t, frame.rgb))
        return frame

    def during(self, start: float, end: float) -> list[NDArray[np.uint8]]:
        return [rgb for t, rgb in self.frames if start <= t < end]


def run(run_scenario: Callable[..., RunResult], name: str,
        hook: FrontFrames | None = None) -> RunResult:
    return run_scenario(str(FAULTS / f"{name}.yaml"), record=False, profile=Profile.FAST,
                        frame_hook=hook)


def changes(result: RunResult, machine: str) -> list[StateChange]:
    return [c for c in result.state_changes if c.machine == machine]


def verdict(result: RunResult, name: str) -> str:
    return next(c for c in result.criteria if c.name == name).verdict.value


def fired(result: RunResult, kind: str) -> float:
    """[s] when the run's one event of `kind` fired (the event's truth)."""
    entry = next(e for e in result.story if e.kind == kind)
    assert entry.fired_at is not None, f"{kind} never fired"
    return entry.fired_at


def speed_at(result: RunResult, t: float) -> float:
    return float(np.interp(t, result.log.array("t"), result.log.array("speed")))


def assert_minimum_risk_stop(result: RunResult, stop_from: float, until: float) -> None:
    """The car stood still in lane, hazard lights on, between `stop_from` and `until` [s],
    having braked no harder than `MRM_DECEL`; no contact; the judged verdicts say so."""
    t, v = result.log.array("t"), result.log.array("speed")
    hazard = np.asarray(result.log.hazard)
    standing = (t >= stop_from) & (t < until)
    assert np.max(v[standing]) < 0.1
    assert np.all(hazard[standing])
    mrs = next(c for c in result.criteria if c.name == "minimum_risk_stop")
    assert mrs.passed and mrs.value is not None and mrs.value <= MRM_DECEL, mrs
    assert mrs.note == "a minimum-risk stop in lane during the sensor fault"
    for name in ("no_collision", "tyres_in_lane", "completes"):
        assert verdict(result, name) == "pass", name


def assert_drove_on_slowly(result: RunResult, resumed: float) -> None:
    """The lane kept on the camera all along, no hazard lights, 30 km/h when the sensor was
    sound again (at `resumed` [s]) and faster 6 s later; no contact; the judged verdicts
    say so."""
    assert [c.target for c in changes(result, "lane_source")] == ["camera"]
    assert changes(result, "hazard") == []
    assert speed_at(result, resumed) == pytest.approx(30 / 3.6, abs=0.3)
    assert speed_at(result, resumed + 6.0) > 13.0
    mrs = next(c for c in result.criteria if c.name == "minimum_risk_stop")
    assert mrs.passed and mrs.note == "it drove on through the sensor fault", mrs
    for name in ("no_collision", "tyres_in_lane", "completes"):
        assert verdict(result, name) == "pass", name


def test_camera_blackout_holds_on_the_map_then_stops_in_lane_and_resumes(
        run_scenario: Callable[..., RunResult]) -> None:
    hook = FrontFrames()
    r = run(run_scenario, "camera_blackout", hook)
    start = fired(r, "camera_blackout")
    end = start + 14.0
    assert start == pytest.approx(FIRES)
    # the fault happened: the stack's front frames were black for its 14 s, not before
    black = hook.during(start + 0.05, end - 0.05)
    assert len(black) >= 130 and all(not rgb.any() for rgb in black)
    assert all(rgb.any() for rgb in hook.during(0.0, start - 0.05))
    # how the stack noticed: from the pixels, within a frame or two
    lane = changes(r, "lane_source")
    lost = next(c for c in lane if c.target == "map_hold")
    assert start < lost.t < start + 0.3
    assert lost.reason.startswith("camera frame carries no information")
    stop = next(c for c in lane if c.target == "stop_in_lane")
    back = next(c for c in lane if c.t > stop.t)
    assert back.target == "camera" and end < back.t < end + 0.5  # once frames are sound
    hazard = changes(r, "hazard")
    assert [(c.target, c.t) for c in hazard] == [("on", stop.t), ("off", back.t)]
    assert "lane is lost" in hazard[0].reason
    # slowed on the map, stopped in lane, then drove on
    assert speed_at(r, stop.t) < 7.0
    assert_minimum_risk_stop(r, stop.t + 6.0, end)
    assert speed_at(r, back.t + 8.0) > 12.0


def test_lidar_outage_makes_a_minimum_risk_stop_in_lane_and_resumes(
        run_scenario: Callable[..., RunResult]) -> None:
    r = run(run_scenario, "lidar_outage")
    start = fired(r, "lidar_outage")
    end = start + 14.0
    assert start == pytest.approx(FIRES)
    # how the stack noticed: no scan for its timeout (`perception.health`)
    sensing = changes(r, "sensing")
    assert [c.target for c in sensing] == ["minimum_risk", "nominal"]
    noticed, resumed = sensing
    assert start + 0.3 < noticed.t < start + 0.7
    assert noticed.reason.startswith("no LiDAR scan for")
    assert end < resumed.t < end + 0.3
    hazard = changes(r, "hazard")
    assert [(c.target, c.t) for c in hazard] == [("on", noticed.t), ("off", resumed.t)]
    # the lane was kept on the camera all along
    assert [c.target for c in changes(r, "lane_source")] == ["camera"]
    assert_minimum_risk_stop(r, noticed.t + 11.0, end)
    assert speed_at(r, resumed.t + 8.0) > 12.0


def test_gnss_outage_slows_down_on_camera_and_odometry_and_speeds_up_again(
        run_scenario: Callable[..., RunResult]) -> None:
    r = run(run_scenario, "gnss_outage")
    start = fired(r, "gnss_outage")
    end = start + 15.0
    assert start == pytest.approx(FIRES)
    sensing = changes(r, "sensing")
    assert [c.target for c in sensing] == ["degraded", "nominal"]
    noticed, resumed = sensing
    assert noticed.t == pytest.approx(start + 3.0, abs=0.15)  # the outage's timeout
    assert noticed.reason.startswith("no valid GNSS fix for 3.0 s")
    assert end <= resumed.t < end + 0.3  # the first fix back
    # kept the lane on the camera (never lost it), slowed to 30 km/h, no stop, no hazard
    assert speed_at(r, noticed.t) > 13.0
    assert_drove_on_slowly(r, resumed.t)


def test_camera_freeze_is_noticed_as_a_still_image_of_a_moving_car(
        run_scenario: Callable[..., RunResult]) -> None:
    hook = FrontFrames()
    r = run(run_scenario, "camera_freeze", hook)
    start = fired(r, "camera_freeze")
    end = start + 14.0
    assert start == pytest.approx(FIRES)
    # the fault happened: for 14 s the stack got the last image from before it, over and over
    held = hook.during(start - 0.15, start - 0.05)
    frozen = hook.during(start - 0.05, end - 0.05)
    assert len(held) == 1 and len(frozen) >= 130
    assert all(np.array_equal(rgb, held[0]) for rgb in frozen)
    assert not np.array_equal(hook.during(end + 0.05, end + 0.15)[0], held[0])
    # how the stack noticed: the image did not change while the car moved
    lane = changes(r, "lane_source")
    lost = next(c for c in lane if c.target == "map_hold")
    assert start < lost.t < start + 0.3
    assert lost.reason.startswith("camera frame identical to the last at 13.")
    assert "frozen" in lost.reason
    stop = next(c for c in lane if c.target == "stop_in_lane")
    back = next(c for c in lane if c.t > stop.t)
    assert back.target == "camera" and end < back.t < end + 0.5
    hazard = changes(r, "hazard")
    assert [(c.target, c.t) for c in hazard] == [("on", stop.t), ("off", back.t)]
    # it stood still with a frozen image (no longer told from a still scene), still frozen
    assert_minimum_risk_stop(r, stop.t + 6.0, end)
    assert speed_at(r, back.t + 8.0) > 12.0


def test_gnss_jump_is_refused_against_the_odometry_and_the_car_slows_down(
        run_scenario: Callable[..., RunResult]) -> None:
    r = run(run_scenario, "gnss_jump")
    start = fired(r, "gnss_jump")
    end = start + 15.0
    assert start == pytest.approx(FIRES)
    sensing = changes(r, "sensing")
    assert [c.target for c in sensing] == ["degraded", "nominal"]
    noticed, resumed = sensing
    assert start <= noticed.t < start + 0.15  # the first fix that jumped
    assert noticed.reason.startswith("GNSS fix 15.0 m from the odometry's prediction")
    assert end <= resumed.t < end + 0.15  # the first fix back in the gate
    # the jumped fixes were not fused: the pose estimate did not jump (15 m), the camera's
    # lane stayed the lane kept, the tyres in it
    t, error = r.log.array("t"), r.log.array("pose_error")
    assert np.max(error[(t > start) & (t < end + 1.0)]) < 5.0
    assert speed_at(r, noticed.t) > 13.0
    assert_drove_on_slowly(r, resumed.t)


def test_camera_occlusion_keeps_the_lane_on_what_is_seen_and_slows_down(
        run_scenario: Callable[..., RunResult]) -> None:
    hook = FrontFrames()
    r = run(run_scenario, "camera_occlusion", hook)
    start = fired(r, "camera_occlusion")
    end = start + 14.0
    assert start == pytest.approx(FIRES)
    # the fault happened: the left half of every front frame was black for its 14 s
    covered = hook.during(start + 0.05, end - 0.05)
    assert len(covered) >= 130
    assert all(not rgb[:, :320].any() and rgb[:, 320:].any() for rgb in covered)
    assert all(rgb[:, :320].any() for rgb in hook.during(0.0, start - 0.05))
    # how the stack noticed: a dark, featureless part of its frames
    sensing = changes(r, "sensing")
    assert [c.target for c in sensing] == ["degraded", "nominal"]
    noticed, resumed = sensing
    assert start < noticed.t < start + 0.3
    assert noticed.reason.endswith("of the camera frame dark and featureless (partly "
                                   "occluded): the lane on what the camera sees, slowing to "
                                   "8.3 m/s")
    assert end < resumed.t < end + 0.3
    # the lane was kept on the camera (the right line), the car slowed, no stop, no hazard
    assert_drove_on_slowly(r, resumed.t)


def test_lidar_delay_is_noticed_from_the_scans_stamps_and_makes_a_minimum_risk_stop(
        run_scenario: Callable[..., RunResult]) -> None:
    r = run(run_scenario, "lidar_delay")
    start = fired(r, "sensor_delay")
    end = start + 14.0
    assert start == pytest.approx(FIRES)
    # how the stack noticed: the first late scan's stamp, 0.3 s older than it should be
    sensing = changes(r, "sensing")
    assert [c.target for c in sensing] == ["minimum_risk", "nominal"]
    noticed, resumed = sensing
    assert start < noticed.t < start + 0.15
    assert noticed.reason.startswith("LiDAR scan 0.38 s old at delivery (at most 0.25 s)")
    assert end < resumed.t < end + 0.15
    hazard = changes(r, "hazard")
    assert [(c.target, c.t) for c in hazard] == [("on", noticed.t), ("off", resumed.t)]
    assert [c.target for c in changes(r, "lane_source")] == ["camera"]
    assert_minimum_risk_stop(r, noticed.t + 11.0, end)
    assert speed_at(r, resumed.t + 8.0) > 12.0


def test_gnss_false_rtk_is_found_inconsistent_with_the_camera_and_the_lane_is_kept(
        run_scenario: Callable[..., RunResult]) -> None:
    """A receiver stating 5 cm but 1.3 m off across the road: before, the stack took it at
    its word, never found the camera's lane and left its lane by 0.45 m."""
    r = run(run_scenario, "gnss_false_rtk")
    gnss = r.scenario.world.sensors.gnss
    assert gnss.stated_sigma == pytest.approx(0.05) and gnss.bias == (0.0, 1.3)
    # how the stack noticed: its fixes 1.3 m across the lane from the camera's lane
    sensing = changes(r, "sensing")
    assert [c.target for c in sensing] == ["degraded"]
    noticed = sensing[0]
    assert noticed.t < 1.0
    assert noticed.reason.startswith("GNSS fix 1.3 m across the lane from the camera's lane "
                                     "for 0.5 s (it states 0.05 m): the lane kept without GNSS")
    # the camera's lane was found at once and kept; the pose followed it, not the fixes
    lane = changes(r, "lane_source")
    assert [c.target for c in lane] == ["camera"] and lane[0].t < 1.5
    assert changes(r, "hazard") == []
    t, error = r.log.array("t"), r.log.array("pose_error")
    assert np.max(error[t > 3.0]) < 0.3
    assert speed_at(r, 10.0) == pytest.approx(30 / 3.6, abs=0.3)
    for name in ("no_collision", "tyres_in_lane", "completes"):
        assert verdict(r, name) == "pass", name
    check(r, "fault_gnss_false_rtk")

"""A receiver that states more accuracy than it has: `perception.health` notices a lasting
disagreement between its fixes and the camera's lane across the lane (a chi-square test held
for `HealthParams.across_time`), and the localiser then stops believing the fixes across the
car (`Localizer.gnss_consistent`), so that the camera's lane pins the position there."""

from __future__ import annotations

import math

import numpy as np
import pytest

from perception.health import HealthMonitor, HealthParams
from perception.localization import Localizer
from perception.messages import EgoState
from tests.perception.test_map_matching import (
    CAMERA_DELAY,
    GNSS_EVERY,
    ODO_RATE,
    ROAD,
    SPEED,
    WHEEL_RADIUS,
    estimate,
)
from world.frames import GnssFix, Odometry, wrap_angle

P = HealthParams()
RTK = 0.05  # [m] an RTK receiver's stated accuracy
CONSUMER = 1.24  # [m] a consumer receiver's
CAMERA = 0.15  # [m] the camera's lane offset noise (`LocalizerParams.lane_offset_sigma`)
PERIOD = 0.1  # [s] between camera frames


def feed(health: HealthMonitor, offsets: list[float], stated: float = RTK,
         start: float = 0.0) -> list[str | None]:
    """One frame every PERIOD from `start` with each fix-less-camera offset [m]; the flag
    after each."""
    return [health.across(start + PERIOD * k, d, stated, CAMERA) for k, d in enumerate(offsets)]


# (offsets per frame, stated sigma, the first frame flagged (None: never))
TABLE = [
    ([1.3] * 10, RTK, 5),  # 1.3 m against 5 cm: flagged after 0.5 s of frames
    ([-1.3] * 10, RTK, 5),  # either side
    ([0.4] * 30, RTK, None),  # within the gate (0.52 m for 5 cm and the camera's 15 cm)
    ([1.3] * 30, CONSUMER, None),  # within what a consumer receiver states
    ([5.0] * 10, CONSUMER, 5),  # beyond it
    ([1.3] * 4 + [0.0] + [1.3] * 10, RTK, 10),  # one agreeing frame starts the count anew
    ([1.3, math.nan] * 3 + [1.3] * 5, RTK, 6),  # no comparison: the count goes on
]


@pytest.mark.parametrize(("offsets", "stated", "first"), TABLE)
def test_the_flag_table(offsets: list[float], stated: float, first: int | None) -> None:
    flags = feed(HealthMonitor(), offsets, stated)
    flagged = [k for k, f in enumerate(flags) if f is not None]
    assert (flagged[0] if flagged else None) == first, flags
    if first is not None:
        assert flagged == list(range(first, len(offsets)))


def test_the_reason_says_how_far_how_long_and_what_it_states() -> None:
    health = HealthMonitor()
    feed(health, [1.3] * 6)
    reason = health.gnss_inconsistent
    assert reason == ("GNSS fix 1.3 m across the lane from the camera's lane for 0.5 s (it "
                      "states 0.05 m)")
    assert health.health(0.6).gnss == reason  # the GNSS is faulty: the planner slows down


def test_it_is_sound_again_after_agreeing_for_as_long() -> None:
    health = HealthMonitor()
    feed(health, [1.3] * 6)
    after = feed(health, [0.1] * 6, start=0.6)
    assert all(flag is not None for flag in after[:5])
    assert after[5] is None and health.health(1.2).gnss is None


def test_a_gap_without_a_confident_frame_starts_the_count_anew() -> None:
    health = HealthMonitor()
    feed(health, [1.3] * 4)
    assert feed(health, [1.3] * 4, start=1.0) == [None] * 4  # 0.6 s without a comparison


def test_a_jump_or_an_outage_is_said_first() -> None:
    health = HealthMonitor()
    feed(health, [1.3] * 6)
    health.fix(GnssFix(0.0, 0.0, 0.0, 0.0, RTK, 0.01), None)
    health.fix(GnssFix(0.6, 30.0, 0.0, 0.0, RTK, 0.01), (0.0, 0.0, 0.05))
    gnss = health.health(0.6).gnss
    assert gnss is not None and gnss.startswith("GNSS fix 30.0 m from the odometry's")


def drive(bias: tuple[float, float], duration: float = 40.0, watch: bool = True,
          stated: float = RTK) -> tuple[Localizer, HealthMonitor, np.ndarray, np.ndarray,
                                        np.ndarray]:
    """Drive lane 0 of ROAD (straight, then a left arc) at SPEED with RTK-like fixes off by
    `bias`, the camera seeing the lane with 4 cm / 0.5 deg noise, its frames compared with
    the fixes as the stack does (`watch`). Returns the localiser, the monitor, the times
    and the estimate's errors across and along the lane [m] at each fix."""
    rng = np.random.default_rng(3)
    loc, health = Localizer(road=ROAD), HealthMonitor()
    lane0 = ROAD.lane(0)
    poses: dict[int, EgoState] = {}
    times, across, along = [], [], []
    for k in range(round(duration * ODO_RATE) + 1):
        t = k / ODO_RATE
        s = 20.0 + SPEED * t
        xy, heading = lane0.position(s, 0.0), float(lane0.heading_at(s))
        spin = SPEED / WHEEL_RADIUS
        loc.on_odometry(Odometry(t, (spin,) * 4, WHEEL_RADIUS,
                                 SPEED * float(lane0.curvature_at(s)) + rng.normal(0.0, 0.005),
                                 0.0))
        if k % GNSS_EVERY:
            continue
        loc.on_gnss(GnssFix(t, float(xy[0]) + bias[0] + rng.normal(0.0, 0.05),
                            float(xy[1]) + bias[1] + rng.normal(0.0, 0.05),
                            wrap_angle(heading + rng.normal(0.0, 0.003)), stated, 0.003))
        late = k - round(CAMERA_DELAY * ODO_RATE)
        if late in poses:
            lane = estimate(t - CAMERA_DELAY, rng.normal(0.0, 0.04),
                            rng.normal(0.0, math.radians(0.5)))
            match = loc.on_lane(lane, poses[late])
            if watch and match is not None:
                health.across(lane.t, match.fix_offset, match.fix_sigma, CAMERA)
                loc.gnss_consistent(health.gnss_inconsistent is None)
        est = loc.estimate(t)
        poses[k] = est
        d = np.array([est.x, est.y]) - xy
        times.append(t)
        across.append(float(np.array([-math.sin(heading), math.cos(heading)]) @ d))
        along.append(float(np.array([math.cos(heading), math.sin(heading)]) @ d))
    return loc, health, np.array(times), np.array(across), np.array(along)


@pytest.mark.parametrize("bias", [(0.0, 1.3), (0.0, -1.3), (0.0, 1.6)])
def test_a_false_rtk_fix_is_noticed_and_the_camera_keeps_the_position_across(
        bias: tuple[float, float]) -> None:
    """Without the comparison the estimate follows such a fix (1.3 m across the straight,
    `test_map_matching`); with it, within 2 s the camera's lane holds the position across
    the lane through the curve, and along it the estimate stays where it was."""
    loc, health, t, across, along = drive(bias)
    assert not loc.gnss_trusted and health.gnss_inconsistent is not None
    settled = t >= 2.0
    assert float(np.sqrt(np.mean(across[settled] ** 2))) < 0.05
    assert float(np.max(np.abs(across[settled]))) < 0.15
    assert float(np.max(np.abs(along[settled]))) < abs(bias[0]) + 0.3


@pytest.mark.parametrize(("camera", "compared"), [(1.0, True), (-1.5, True), (2.0, False),
                                                  (-2.5, False)])
def test_a_fix_half_a_lane_or_more_from_the_camera_is_not_compared(camera: float,
                                                                  compared: bool) -> None:
    """The fix on the lane's centre, the camera `camera` [m] across: within half the lane's
    width (1.75 m) the two are compared; as far apart as the lane beside, the camera may be
    the one wrong (lane lines look alike) and nothing is compared (no evidence against the
    receiver)."""
    loc = Localizer(road=ROAD)
    lane0 = ROAD.lane(0)
    spin = SPEED / WHEEL_RADIUS
    pose = None
    for k in range(round(1.0 * ODO_RATE) + 1):
        t = k / ODO_RATE
        s = 20.0 + SPEED * t
        loc.on_odometry(Odometry(t, (spin,) * 4, WHEEL_RADIUS, 0.0, 0.0))
        if k % GNSS_EVERY == 0:
            xy = lane0.position(s, 0.0)
            loc.on_gnss(GnssFix(t, float(xy[0]), float(xy[1]), 0.0, RTK, 0.003))
        pose = loc.estimate(t)
    assert pose is not None
    match = loc.on_lane(estimate(pose.t, camera), pose)
    assert match is not None
    assert math.isnan(match.fix_offset) is not compared
    if compared:
        assert match.fix_offset == pytest.approx(-camera, abs=0.05)


def test_without_the_comparison_the_false_fix_is_followed() -> None:
    _, _, t, across, _ = drive((0.0, 1.3), duration=10.0, watch=False)
    assert float(np.mean(across[t >= 2.0])) == pytest.approx(1.3, abs=0.2)


def test_a_true_rtk_fix_is_never_doubted_and_nothing_changes() -> None:
    """A receiver as good as it says: never flagged, and the estimate is bitwise the one
    made without the comparison (the answer acts only on inconsistent data)."""
    watched, health, _, across, along = drive((0.0, 0.0))
    assert watched.gnss_trusted and health.gnss_inconsistent is None
    plain, _, _, across0, along0 = drive((0.0, 0.0), watch=False)
    assert np.array_equal(across, across0) and np.array_equal(along, along0)
    assert np.array_equal(watched.covariance, plain.covariance)

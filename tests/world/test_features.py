"""Road features in the physics world: the stop sign the camera sees, the painted marks, and
the speed bump the car rides over (its body pitches; taken fast, it is a jolt)."""

from __future__ import annotations

import math
from collections.abc import Iterator

import cv2
import numpy as np
import pytest
from numpy.typing import NDArray

from tests.perception.render_scene import pose_ego
from world.core.rates import PHYSICS_RATE
from world.frames import CameraFrame
from world.hdmap import Crosswalk, SpeedBump, StopSign
from world.scene.bump import bump_height_at
from world.scene.scenery import octagon_corners
from world.sensors.sensor import vehicle_pose
from world.sensors.setup import Profile, sensor_setup
from world.spec import EgoSpec, RoadSpec, SegmentSpec, WorldSpec
from world.world import SIGN_POLE_RADIUS, World

KPH = 1 / 3.6  # [m/s] per km/h
STOP_S, ZEBRA_S, BUMP_S = 80.0, 84.0, 95.0  # [m]
BUMP = SpeedBump(BUMP_S, 0.1, 0.9, 5 * KPH)
LANES, LANE_WIDTH, SHOULDER = 2, 3.5, 2.5


def spec(ego_s: float, speed: float = 0.0, lanes: int = LANES) -> WorldSpec:
    road = RoadSpec(
        segments=(SegmentSpec(length=200.0, curvature=0.0, lanes=lanes, oncoming_lanes=0,
                              lane_width=LANE_WIDTH, shoulder=SHOULDER),),
        speed_limit=50 * KPH,
        features=(StopSign(STOP_S), Crosswalk(ZEBRA_S, 4.0), BUMP),
    )
    return WorldSpec(road=road, ego=EgoSpec(lane=0, s=ego_s, speed=speed, max_speed=15.0),
                     seed=0)


@pytest.fixture(scope="module")
def world() -> Iterator[World]:
    w = World(spec(20.0))
    yield w
    w.close()


# -- the static scene ----------------------------------------------------------------------


def test_scene_holds_the_features(world: World) -> None:
    scene = world.scene
    names = [m.name for m in scene.road_meshes]
    assert {"stop_line_0", "crosswalk_0", "speed_bump_0"} <= set(names)
    assert names.index("stop_line_0") > names.index("road_surface_0_0")  # painted on top
    (sign,) = scene.stop_signs
    assert sign.s == STOP_S
    (bump,) = scene.bumps
    (bump_body,) = scene.bump_bodies
    assert bump_body not in scene.obstacle_bodies  # driving over it is no collision ...
    assert bump_body in scene.static_bodies  # ... but the LiDAR sees it
    # the stop sign's pole is an obstacle standing at the sign's place
    poles = [b for b in scene.obstacle_bodies
             if math.dist(world.client.getBasePositionAndOrientation(b)[0][:2],
                          sign.pole_xy) < 1e-6]
    assert len(poles) == 1
    lo, hi = world.client.getAABB(poles[0])
    assert hi[2] == pytest.approx(sign.plate_height + sign.corner_radius, abs=0.01)
    assert hi[0] - lo[0] == pytest.approx(2 * SIGN_POLE_RADIUS, abs=0.01)
    assert (bump.s, bump.height, bump.length) == (BUMP.s, BUMP.height, BUMP.length)


def test_bump_collision_surface_is_its_profile(world: World) -> None:
    """Rays straight down meet the bump's hull on the circular profile (chords and Bullet's
    margin within 3 mm), across the ego lanes and the shoulder, and the ground beyond."""
    (bump,) = world.scene.bumps
    (body,) = world.scene.bump_bodies
    along = np.linspace(-0.6, 0.6, 13)
    across = np.linspace(bump.band[0] + 0.05, bump.band[1] - 0.05, 5)
    s, d = np.meshgrid(bump.s + along, across)
    xy = world.road.position(s.ravel(), d.ravel())
    starts = np.column_stack([xy, np.full(len(xy), 1.0)])
    ends = np.column_stack([xy, np.full(len(xy), -1.0)])
    hits = world.client.rayTestBatch(starts.tolist(), ends.tolist())
    z = np.array([h[3][2] for h in hits])
    hit_bump = np.array([h[0] == body for h in hits])
    expected = np.tile(bump_height_at(bump, along), len(across))
    assert np.abs(z - expected).max() < 0.003
    assert hit_bump[expected > 0.003].all()
    # beyond the bump's band (the oncoming side of the centre line) only the ground
    xy = world.road.position(bump.s, bump.band[1] + 0.3)
    hit = world.client.rayTest([*xy, 1.0], [*xy, -1.0])[0]
    assert hit[0] == world.scene.ground


# -- the camera sees the stop sign ---------------------------------------------------------


def project(world: World, frame: CameraFrame, points: NDArray[np.float64]) -> NDArray[
        np.float64]:
    """(N, 2) pixels (u, v) of world points (N, 3): the pinhole model of `CameraInfo`."""
    info = frame.info
    origin, rotation = vehicle_pose(world.ego.truth(), world.ego.geometry.ride_height)
    m = info.mount
    eye = origin + rotation @ np.array([m.x, m.y, m.z])
    axes = rotation @ m.rotation()
    cam = (points - eye) @ axes  # x forward, y left, z up
    assert np.all(cam[:, 0] > 0)
    return np.column_stack([info.cx - info.fx * cam[:, 1] / cam[:, 0],
                            info.cy - info.fy * cam[:, 2] / cam[:, 0]])


def red(rgb: NDArray[np.uint8]) -> NDArray[np.bool_]:
    c = rgb.astype(int)
    return (c[..., 0] > 110) & (c[..., 0] > 2 * c[..., 1]) & (c[..., 0] > 2 * c[..., 2])


def test_front_camera_sees_a_red_octagon_where_the_sign_is() -> None:
    """With the front camera 20 m before the stop line, the red pixels near the sign are
    inside the octagon the pinhole model projects, and fill most of it."""
    w = World(spec(20.0), sensor_setup(Profile.DEFAULT), lidar=False)
    try:
        mount_x = sensor_setup(Profile.DEFAULT).camera("front").mount.x
        pose_ego(w, 0, STOP_S - 20.0 - mount_x, 0.0, 0.0)
        frame = w.rig.capture(["front"], w.t, w.ego.truth())[0].frame
        assert isinstance(frame, CameraFrame)
        (sign,) = w.scene.stop_signs
        normal = np.array([math.cos(sign.yaw), math.sin(sign.yaw), 0.0])
        across = np.array([-math.sin(sign.yaw), math.cos(sign.yaw), 0.0])  # a viewer's right
        centre = np.array([*sign.pole_xy, sign.plate_height]) + 2 * SIGN_POLE_RADIUS * normal
        corners = octagon_corners((0.0, 0.0), sign.corner_radius)  # (right, down) on the plate
        points = centre + corners[:, :1] * across - corners[:, 1:] * np.array([0.0, 0.0, 1.0])
        uv = project(w, frame, points)
    finally:
        w.close()
    h, wd = frame.rgb.shape[:2]
    inside = np.zeros((h, wd), np.uint8)
    cv2.fillPoly(inside, [np.rint(uv * 16).astype(np.int32)], 1, shift=4)
    near = cv2.dilate(inside, np.ones((3, 3), np.uint8), iterations=2).astype(bool)
    inside_b = inside.astype(bool)
    mask = red(frame.rgb)
    size = float(np.ptp(uv[:, 0]))
    assert 10.0 < size < 20.0  # ~0.75 m at 20 m with fx ~381 px
    box = (slice(int(uv[:, 1].min()) - 15, int(uv[:, 1].max()) + 15),
           slice(int(uv[:, 0].min()) - 15, int(uv[:, 0].max()) + 15))
    assert mask[box].sum() > 0.4 * inside_b.sum()  # most of the plate is red
    assert mask[inside_b].mean() > 0.4
    assert not (mask & ~near)[box].any()  # no red beyond a 2 px rim around the octagon
    ys, xs = np.nonzero(mask[box])
    centroid = np.array([xs.mean() + box[1].start, ys.mean() + box[0].start])
    assert np.linalg.norm(centroid - uv.mean(axis=0)) < 1.5  # centred where projected
    # the letters: light pixels in the plate's middle, well inside its rim (the red plate's
    # green channel is ~20-40; the blurred white letters' is > 80)
    middle = cv2.erode(inside, np.ones((3, 3), np.uint8), iterations=2).astype(bool)
    assert middle.sum() > 20
    assert (frame.rgb[middle][:, 1] > 80).sum() >= 3


# -- the bump under the wheels -------------------------------------------------------------


def drive_over(speed_kph: float, seconds: float) -> dict[str, float]:
    """Start 6 m before the bump at `speed_kph` in lane 0 with a fixed drive torque of
    150 N m (about what holds the speed on the flat: rolling resistance is ~58 N m), no
    steering; return what happened."""
    w = World(spec(BUMP_S - 6.0, speed_kph * KPH, lanes=1))
    g = w.ego.geometry
    pitch, vz, z, t = [], [], [], []
    touched: set[int] = set()
    try:
        for step in range(round(seconds * PHYSICS_RATE)):
            if step % 6 == 0:
                w.ego.apply(0.0, 150.0, 0.0)
            w.step()
            truth = w.ego_truth
            x_axis = truth.rotation[:, 0]
            pitch.append(math.atan2(x_axis[2], math.hypot(x_axis[0], x_axis[1])))  # nose up +
            vz.append(float(truth.velocity[2]))
            z.append(float(truth.position[2]))
            t.append(w.t)
            touched |= {int(c[2]) for c in w.client.getContactPoints(bodyA=w.ego.body)}
        s = float(w.ego_route.station)
        speed = w.ego_truth.speed
    finally:
        w.close()
    window = PHYSICS_RATE // 60  # [steps] vertical acceleration averaged over 1/60 s
    az = (np.array(vz[window:]) - np.array(vz[:-window])) * PHYSICS_RATE / window
    settled = PHYSICS_RATE // 4  # the car settles on its tyres at spawn
    p = np.degrees(np.array(pitch[settled:]))
    return {
        "rear_axle_s": s - g.rear_axle, "speed_kph": speed / KPH,
        "nose_up_deg": float(p.max()), "nose_down_deg": float(-p.min()),
        "peak_az": float(np.abs(az[settled:]).max()), "rise": float(max(z) - z[settled]),
        "obstacles": float(len(touched - {w.scene.ground} - w.scene.bump_bodies)),
    }


@pytest.fixture(scope="module")
def slow() -> dict[str, float]:
    return drive_over(5.0, 6.0)


@pytest.fixture(scope="module")
def fast() -> dict[str, float]:
    return drive_over(30.0, 2.5)


def test_car_rides_over_the_bump_at_walking_pace(slow: dict[str, float]) -> None:
    """At 5 km/h both axles get over it; the body pitches nose up (front wheels on the
    bump), then nose down (rear wheels), by about atan(height / wheelbase) = 2.1 deg."""
    assert slow["rear_axle_s"] > BUMP_S + BUMP.length / 2 + 0.5  # over, not stuck
    assert slow["speed_kph"] > 3.0
    expected = math.degrees(math.atan(BUMP.height / 2.7))
    assert slow["nose_up_deg"] == pytest.approx(expected, rel=0.3)
    assert slow["nose_down_deg"] == pytest.approx(expected, rel=0.3)
    assert slow["obstacles"] == 0


def test_bump_taken_at_30_kph_is_a_jolt(slow: dict[str, float], fast: dict[str, float]) -> None:
    """At 30 km/h the body is thrown: more pitch, far more vertical acceleration."""
    assert fast["rear_axle_s"] > BUMP_S + 5.0
    assert fast["nose_up_deg"] > 2.0 * slow["nose_up_deg"]
    assert fast["peak_az"] > 4.0 * slow["peak_az"]
    assert fast["peak_az"] > 9.81  # the body leaves the ground's support for a moment
    assert fast["rise"] > 2.0 * slow["rise"]
    assert fast["obstacles"] == 0

"""The cameras: frames rendered from the car's true pose show the road where the pinhole
model says it is, from where the URDF's camera links are, with either renderer.

One world (normal_driving without its NPCs, the `default` profile's cameras, no LiDAR) is
built for the module; the ego is let settle on its wheels for a second of physics, braked.
The image regions below were read off a rendered 640 x 480 front frame of that pose (the
ego in the middle of lane 0, looking down the straight): sky above the buildings in the top
rows, the ego lane's asphalt between the lane lines just above the car's blue hood.
"""

from __future__ import annotations

import importlib.util
import math
import subprocess
import sys
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from numpy.typing import NDArray

from avsim.scenario.load import load_scenario
from world.core.client import make_client
from world.core.rates import PHYSICS_RATE
from world.core.rendering import Renderer, attach_renderer, shadow_switch
from world.frames import CameraFrame, CameraInfo
from world.scene.road_mesh import EDGE_LINE_INSET, SURFACE_Z
from world.sensors.camera import Camera
from world.sensors.sensor import vehicle_pose
from world.sensors.setup import Profile, SensorSetup, sensor_setup
from world.spec import WorldSpec
from world.world import World

CAMERAS = ("front", "left", "right")
BRAKE = 3000.0  # [N m] holds the car still while it settles
AHEAD = (6.0, 8.0, 10.0, 12.0, 14.0)  # [m] ground points ahead of the car's centre

# front frame regions, as fractions of the image (rows, columns)
SKY = (slice(0, 1 / 12), slice(0, 1))
ASPHALT = (slice(0.625, 0.77), slice(0.41, 0.58))  # ego lane, between the lines
HOOD = (slice(0.92, 1), slice(0.4, 0.6))
ROAD = (slice(0.6, 0.78), slice(0, 1))  # the road band above the hood, full width

Region = tuple[slice, slice]


def crop(rgb: NDArray[np.uint8], region: Region) -> NDArray[np.float64]:
    """(N, 3) pixels of a region given as fractions of the image."""
    h, w = rgb.shape[:2]
    rows, cols = region
    out = rgb[round(rows.start * h):round(rows.stop * h),
              round(cols.start * w):round(cols.stop * w)]
    return out.reshape(-1, 3).astype(np.float64)


def spec_without_actors() -> WorldSpec:
    return replace(load_scenario("normal_driving").world, actors=(), events=())


@pytest.fixture(scope="module")
def setup() -> SensorSetup:
    return sensor_setup(Profile.DEFAULT)


@pytest.fixture(scope="module")
def world(setup: SensorSetup) -> Iterator[World]:
    w = World(spec_without_actors(), setup, lidar=False)
    for _ in range(PHYSICS_RATE):  # one second
        w.ego.apply(0.0, 0.0, BRAKE)
        w.step()
    yield w
    w.close()


@pytest.fixture(scope="module")
def frames(world: World) -> dict[str, CameraFrame]:
    readings = world.rig.capture(CAMERAS, world.t, world.ego_truth)
    assert all(isinstance(r.frame, CameraFrame) for r in readings)
    return {r.sensor: r.frame for r in readings}  # type: ignore[misc]


def camera_pose(world: World, info: CameraInfo) -> tuple[NDArray[np.float64],
                                                         NDArray[np.float64]]:
    """The camera's world position and axes (columns x, y, z) for the ego's pose now: the
    vehicle frame's pose composed with the mount."""
    origin, rotation = vehicle_pose(world.ego.truth(), world.ego.geometry.ride_height)
    m = info.mount
    return origin + rotation @ np.array([m.x, m.y, m.z]), rotation @ m.rotation()


def project(world: World, info: CameraInfo, point: NDArray[np.float64]) -> tuple[float, float]:
    """Pixel (u, v) of a world point: the pinhole model of `CameraInfo`'s docstring."""
    eye, axes = camera_pose(world, info)
    x, y, z = axes.T @ (point - eye)
    assert x > 0.0
    return info.cx - info.fx * y / x, info.cy - info.fy * z / x


def lane_point(world: World, d: float, r: float) -> NDArray[np.float64]:
    """The road surface point d [m] ahead of the car's centre along lane 0, r [m] left of the
    lane's centre."""
    lane = world.road.lane(0)
    s, _ = lane.local_coordinates(world.ego.truth().position[:2])
    xy = lane.position(float(s) + d, r)
    return np.array([xy[0], xy[1], SURFACE_Z])


def pixel(frame: CameraFrame, uv: tuple[float, float]) -> NDArray[np.uint8]:
    u, v = uv
    assert 0.0 <= u < frame.info.width and 0.0 <= v < frame.info.height
    out: NDArray[np.uint8] = frame.rgb[math.floor(v), math.floor(u)]
    return out


def rotation_angle(a: NDArray[np.float64], b: NDArray[np.float64]) -> float:
    """[deg] the angle of the rotation between two rotation matrices."""
    cos = (np.trace(a.T @ b) - 1.0) / 2.0
    return math.degrees(math.acos(min(1.0, max(-1.0, cos))))


def angle(a: NDArray[np.float64], b: NDArray[np.float64]) -> float:
    """[deg] between two vectors."""
    cos = float(a @ b) / float(np.linalg.norm(a) * np.linalg.norm(b))
    return math.degrees(math.acos(min(1.0, max(-1.0, cos))))


def link_pose(world: World, name: str) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """PyBullet's own world pose of a camera link: position and rotation matrix."""
    c = world.client
    state = c.getLinkState(world.ego.body, world.ego.links[f"camera_{name}_link"],
                           computeForwardKinematics=True)
    position, quat = state[4], state[5]  # the URDF link frame (not the inertial frame)
    return np.array(position), np.array(c.getMatrixFromQuaternion(quat)).reshape(3, 3)


# -- checks shared by both renderers ---------------------------------------------------------


def check_sky_and_asphalt(frame: CameraFrame) -> None:
    sky = crop(frame.rgb, SKY)
    assert np.mean(sky.min(axis=1) > 150.0) > 0.95  # light ...
    assert sky[:, 2].mean() >= sky[:, 0].mean()  # ... and not reddish or yellowish
    asphalt = crop(frame.rgb, ASPHALT)
    grey = asphalt.mean(axis=1)
    assert np.median(grey) < 90.0 and np.percentile(grey, 98) < 120.0  # dark, no line in it
    r, g, b = np.median(asphalt, axis=0)
    assert max(r, g, b) - min(r, g, b) < 15.0  # grey: not the (blue) hood, not grass
    hood = crop(frame.rgb, HOOD)
    assert np.median(hood[:, 2] - hood[:, 0]) > 60.0  # the car's own blue hood below


def check_right_edge_line(world: World, frame: CameraFrame) -> None:
    """Ground points on the solid right edge line project onto light pixels; points 0.6 m
    inside the lane (and on its centre) onto dark asphalt."""
    lane = world.road.lane(0)
    s, _ = lane.local_coordinates(world.ego.truth().position[:2])
    section = world.road.cross_section_at(float(s))
    assert section.shoulder >= EDGE_LINE_INSET  # so the line is on the lane's right boundary
    edge = -0.5 * float(lane.width_at(s))
    for d in AHEAD:
        on_line = pixel(frame, project(world, frame.info, lane_point(world, d, edge)))
        inside = pixel(frame, project(world, frame.info, lane_point(world, d, edge + 0.6)))
        centre = pixel(frame, project(world, frame.info, lane_point(world, d, 0.0)))
        assert on_line.min() > 150, (d, on_line)
        assert inside.max() < 100 and centre.max() < 100, (d, inside, centre)


# -- tests -----------------------------------------------------------------------------------


def test_renderer_and_frames(world: World, setup: SensorSetup,
                             frames: dict[str, CameraFrame]) -> None:
    assert world.renderer in (Renderer.EGL, Renderer.TINY)
    assert set(world.rig.names) == {*CAMERAS, "gnss", "odometry"}  # cameras, no LiDAR
    assert all(world.rig.sensor(name).camera.renderer is world.renderer  # type: ignore[attr-defined]
               for name in CAMERAS)
    assert world.ego.truth().speed == pytest.approx(0.0, abs=0.01)  # at rest
    assert set(frames) == set(CAMERAS)
    for name, frame in frames.items():
        info = setup.camera(name)
        assert frame.info == info and frame.t == world.t
        assert frame.rgb.shape == (info.height, info.width, 3)
        assert frame.rgb.dtype == np.uint8 and frame.rgb.flags.c_contiguous
        assert frame.rgb.std() > 10.0, name  # a picture, not a blank frame
    assert frames["front"].rgb.shape == (480, 640, 3)
    assert frames["left"].rgb.shape == frames["right"].rgb.shape == (240, 320, 3)


def test_front_frame_shows_sky_and_asphalt(frames: dict[str, CameraFrame]) -> None:
    check_sky_and_asphalt(frames["front"])


def test_right_edge_line_is_where_the_pinhole_model_puts_it(
        world: World, frames: dict[str, CameraFrame]) -> None:
    check_right_edge_line(world, frames["front"])


def test_side_cameras_look_sideways(world: World, frames: dict[str, CameraFrame]) -> None:
    """The left camera sees the yellow centre line beside the car, the right one the paved
    shoulder's edge against the grass; both see some sky above."""
    lane = world.road.lane(0)
    s, _ = lane.local_coordinates(world.ego.truth().position[:2])
    section = world.road.cross_section_at(float(s))
    assert section.oncoming_lanes > 0
    left, right = frames["left"], frames["right"]

    def yellow(r: float) -> bool:  # a yellow pixel within 3 px of the point's image
        u, v = project(world, left.info, lane_point(world, 0.6, r))
        rows = slice(max(0, math.floor(v) - 3), math.floor(v) + 4)
        near = left.rgb[rows, math.floor(u)].astype(int)
        return bool(np.any((near[:, 0] > 150) & (near[:, 1] > 110) & (near[:, 2] < 110)))

    assert yellow(section.centre_line)  # the double line, 4.5 m from the camera
    assert not yellow(section.centre_line - 0.5 * section.lane_width)  # lane 1's middle
    paved = pixel(right, project(world, right.info, lane_point(world, 0.6,
                                                                section.right_edge + 0.5)))
    grass = pixel(right, project(world, right.info, lane_point(world, 0.6,
                                                               section.right_edge - 0.5)))
    assert np.ptp(paved.astype(int)) < 15 and paved.max() < 120, paved  # grey shoulder
    assert grass[1] > grass[0] + 15 and grass[1] > grass[2] + 15, grass  # green
    for frame in (left, right):
        top = crop(frame.rgb, (slice(0, 0.05), slice(0, 1))).mean(axis=1)
        assert np.mean(top > 150.0) > 0.2  # some sky between the buildings


class _ViewSpy:
    """A client stand-in that records `computeViewMatrix` calls and passes everything on."""

    def __init__(self, client: Any) -> None:
        self._client = client
        self.views: list[tuple[NDArray[np.float64], ...]] = []

    def computeViewMatrix(self, eye: list[float], target: list[float],  # noqa: N802
                          up: list[float]) -> Any:
        self.views.append((np.array(eye), np.array(target), np.array(up)))
        return self._client.computeViewMatrix(eye, target, up)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._client, name)


def check_render_pose_is_link_pose(world: World, monkeypatch: pytest.MonkeyPatch) -> None:
    """For each camera: the pose `Camera.render` looks from (eye, view direction, up) and
    vehicle_pose + mount both equal the camera link's pose in PyBullet."""
    truth = world.ego.truth()
    for name in CAMERAS:
        camera: Camera = world.rig.sensor(name).camera  # type: ignore[attr-defined]
        spy = _ViewSpy(camera._c)
        monkeypatch.setattr(camera, "_c", spy)
        world.rig.capture([name], world.t, truth)
        monkeypatch.undo()
        (eye, target, up), = spy.views
        link_xyz, link_rot = link_pose(world, name)
        assert np.linalg.norm(eye - link_xyz) < 0.01, name
        assert angle(target - eye, link_rot[:, 0]) < 0.5, name
        assert angle(up, link_rot[:, 2]) < 0.5, name
        xyz, axes = camera_pose(world, camera.info)
        assert np.linalg.norm(xyz - link_xyz) < 0.01, name
        assert rotation_angle(axes, link_rot) < 0.5, name


def test_camera_pose_is_the_camera_link_pose(world: World,
                                             monkeypatch: pytest.MonkeyPatch) -> None:
    # the ego at rest after a second of physics (as the fixture left it)
    check_render_pose_is_link_pose(world, monkeypatch)
    # and posed turned and tilted (a mirror pose), where rotation mistakes would show
    snap = world.snapshot()
    com, _, joints = world.ego.base_state()
    quat = world.client.getQuaternionFromEuler([0.04, -0.03, 2.3])
    try:
        world.ego.set_base_state(com, quat, joints)
        assert world.ego.truth().yaw == pytest.approx(2.3, abs=1e-6)
        check_render_pose_is_link_pose(world, monkeypatch)
    finally:
        world.apply_snapshot(snap)


def test_tiny_renderer(world: World, setup: SensorSetup, frames: dict[str, CameraFrame],
                       monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("AVSIM_RENDERER", "Tiny")
    client = make_client()
    try:
        assert attach_renderer(client) is Renderer.TINY
    finally:
        client.disconnect()
    tiny_world = World(spec_without_actors(), setup, lidar=False)
    try:
        assert tiny_world.renderer is Renderer.TINY
        assert tiny_world.rig.sensor("front").camera.renderer is Renderer.TINY  # type: ignore[attr-defined]
        tiny_world.apply_snapshot(world.snapshot())  # the same pose, nothing simulated
        tiny = tiny_world.rig.capture(["front"], tiny_world.t, tiny_world.ego_truth)[0].frame
        assert isinstance(tiny, CameraFrame)
        assert tiny.rgb.shape == (480, 640, 3) and tiny.rgb.dtype == np.uint8
        check_sky_and_asphalt(tiny)
        check_right_edge_line(tiny_world, tiny)
    finally:
        tiny_world.close()
    if world.renderer is not Renderer.EGL:
        pytest.skip("EGL is not available here: nothing to compare TinyRenderer with")
    egl = frames["front"]
    diff = np.abs(crop(tiny.rgb, ROAD) - crop(egl.rgb, ROAD))
    assert diff.mean() < 12.0  # measured 7.5: noise, shading and anti-aliasing differ
    # the measure tells pictures apart: the tiny frame moved 80 px sideways differs more
    shifted = np.abs(crop(np.roll(tiny.rgb, 80, axis=1), ROAD) - crop(egl.rgb, ROAD))
    assert shifted.mean() > 1.5 * diff.mean()


def test_egl_draws_no_shadow_map(world: World) -> None:
    """The EGL plugin's shadow pass is off (it ignores ``shadow=0`` by itself)."""
    if world.renderer is not Renderer.EGL:
        pytest.skip("EGL is not available here")
    spec = importlib.util.find_spec("eglRenderer")
    assert spec is not None and spec.origin is not None
    switch = shadow_switch(Path(spec.origin))
    assert switch is not None and switch.value == 0


FALLBACK = """
from world.core import rendering
from world.core.client import make_client
rendering._symbols = lambda library, names: None  # a build without the symbol table
print(rendering.attach_renderer(make_client()).value)
"""


def test_without_the_shadow_switch_egl_is_not_used() -> None:
    """Where the switch cannot be found, TinyRenderer draws (shadows on one machine and not
    on another would change results); in a fresh process: one EGL plugin per process."""
    out = subprocess.run([sys.executable, "-c", FALLBACK], capture_output=True, text=True,
                         check=True, timeout=120)
    assert out.stdout.split()[-1] == "tiny"

"""Tests of the traffic light body (`world.scene.traffic_light`) and its timing
(`world.map.signals.light_colour`): lamp colours, recolouring only on a change, the housing
mesh, collision, and what each renderer draws of it (the lamps seen from the front at
10-60 m, nothing of them from behind)."""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pybullet
import pytest
from pybullet_utils.bullet_client import BulletClient

from world.core.client import add_ground, make_client
from world.core.rendering import Renderer, attach_renderer
from world.hdmap import LightColour, LightHead
from world.map.signals import light_colour
from world.scene.traffic_light import (
    HOUSING_DEPTH,
    HOUSING_HEIGHT,
    HOUSING_WIDTH,
    LAMP_DIAMETER,
    LAMP_HEIGHT,
    LAMP_SEGMENTS,
    LIT_RGBA,
    TrafficLightBody,
    add_traffic_light,
    dim_rgba,
    disc_mesh,
    housing_mesh,
)
from world.sensors.camera import Camera
from world.sensors.setup import Profile, sensor_setup
from world.spec import TrafficLightSpec

HEAD = LightHead(10.0, -5.0, 3.5, math.pi)  # facing -x


class CountingClient:
    """A client that counts `changeVisualShape` calls and passes everything on."""

    def __init__(self, client: BulletClient) -> None:
        self._client = client
        self.recolours = 0

    def changeVisualShape(self, *args: Any, **kwargs: Any) -> Any:  # noqa: N802 (PyBullet's)
        self.recolours += 1
        return self._client.changeVisualShape(*args, **kwargs)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._client, name)


@pytest.fixture
def client() -> Iterator[BulletClient]:
    c = make_client()
    yield c
    c.disconnect()


def lamp_rgba(client: BulletClient,
              light: TrafficLightBody) -> dict[LightColour, tuple[float, ...]]:
    return {colour: tuple(client.getVisualShapeData(body)[0][7])
            for colour, body in light.lamps.items()}


# ---- lamps ----------------------------------------------------------------------------------


def test_lamps_start_dark(client: BulletClient) -> None:
    light = add_traffic_light(client, HEAD)
    assert light.colour is None
    for colour, rgba in lamp_rgba(client, light).items():
        assert rgba == pytest.approx(dim_rgba(colour))


@pytest.mark.parametrize("colour", list(LightColour))
def test_set_colour_lights_one_lamp(client: BulletClient, colour: LightColour) -> None:
    light = add_traffic_light(client, HEAD)
    for before in LightColour:  # whatever was lit before
        light.set_colour(before)
        light.set_colour(colour)
        assert light.colour is colour
        for lamp, rgba in lamp_rgba(client, light).items():
            assert rgba == pytest.approx(LIT_RGBA[lamp] if lamp is colour else dim_rgba(lamp))


def test_a_head_too_low_for_its_pole_is_refused(client: BulletClient) -> None:
    with pytest.raises(ValueError, match="pole"):
        add_traffic_light(client, LightHead(0.0, 0.0, 0.4, 0.0))


def test_lights_share_the_mesh_files_of_one_folder(client: BulletClient,
                                                   tmp_path: Path) -> None:
    first = add_traffic_light(client, HEAD, tmp_path)
    second = add_traffic_light(client, LightHead(30.0, 5.0, 4.0, 0.0), tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["light_housing.obj",
                                                          "light_lamp.obj"]
    assert first.body != second.body
    assert set(first.lamps.values()).isdisjoint(second.lamps.values())


def test_lamps_are_recoloured_only_on_a_change(client: BulletClient) -> None:
    counting = CountingClient(client)
    light = add_traffic_light(counting, HEAD)  # duck-typed: BulletClient is untyped
    steps = [(LightColour.GREEN, 1), (LightColour.GREEN, 0), (LightColour.YELLOW, 2),
             (LightColour.YELLOW, 0), (LightColour.RED, 2), (LightColour.RED, 0),
             (LightColour.GREEN, 2)]
    for colour, calls in steps:
        before = counting.recolours
        light.set_colour(colour)
        assert counting.recolours - before == calls, colour


def test_lit_lamps_are_saturated_and_dim_ones_dark() -> None:
    for colour, rgba in LIT_RGBA.items():
        assert max(rgba[:3]) == 1.0
        assert min(rgba[:3]) / max(rgba[:3]) < 0.05  # HSV saturation > 0.95
        assert max(dim_rgba(colour)[:3]) < 0.25


# ---- timing ---------------------------------------------------------------------------------

CYCLE = TrafficLightSpec(s=50.0, green=10.0, yellow=3.0, red=12.0, phase=0.0)  # 25 s


@pytest.mark.parametrize(("phase", "t", "colour"), [
    (0.0, 0.0, LightColour.GREEN),
    (0.0, 9.99, LightColour.GREEN),
    (0.0, 10.0, LightColour.YELLOW),
    (0.0, 12.99, LightColour.YELLOW),
    (0.0, 13.0, LightColour.RED),
    (0.0, 24.99, LightColour.RED),
    (0.0, 25.0, LightColour.GREEN),  # the cycle wraps
    (0.0, 59.0, LightColour.GREEN),  # 9 s into the third cycle
    (0.0, 60.0, LightColour.YELLOW),  # 10 s into it
    (20.0, 0.0, LightColour.RED),  # starts 20 s into the cycle
    (20.0, 4.99, LightColour.RED),
    (20.0, 5.0, LightColour.GREEN),  # phase wrap: 25 s into the cycle is its start
    (20.0, 15.0, LightColour.YELLOW),
    (30.0, 0.0, LightColour.GREEN),  # a phase beyond the cycle wraps: 30 s is 5 s in
    (0.0, -1.0, LightColour.RED),  # before t = 0: the end of the previous cycle
])
def test_light_colour_timing(phase: float, t: float, colour: LightColour) -> None:
    light = TrafficLightSpec(CYCLE.s, CYCLE.green, CYCLE.yellow, CYCLE.red, phase)
    assert light_colour(light, t) is colour


# ---- geometry -------------------------------------------------------------------------------


def test_housing_mesh_is_closed_outward_with_three_lamp_holes() -> None:
    vertices, faces = housing_mesh()
    a, b, c = (vertices[faces[:, i]] for i in range(3))
    normals = np.cross(b - a, c - a)
    areas = 0.5 * np.linalg.norm(normals, axis=1)
    centroids = (a + b + c) / 3.0
    assert (areas > 0).all()
    assert (np.einsum("ij,ij->i", normals, centroids) > 0).all()  # outward
    front = np.isclose(centroids[:, 0], HOUSING_DEPTH / 2)
    disc_v, disc_f = disc_mesh(LAMP_DIAMETER / 2, LAMP_SEGMENTS)
    da, db, dc = (disc_v[disc_f[:, i]] for i in range(3))
    disc_area = 0.5 * np.linalg.norm(np.cross(db - da, dc - da), axis=1).sum()
    assert areas[front].sum() == pytest.approx(HOUSING_WIDTH * HOUSING_HEIGHT - 3 * disc_area)
    assert areas.sum() == pytest.approx(
        2 * (HOUSING_WIDTH * HOUSING_HEIGHT + HOUSING_DEPTH * (HOUSING_WIDTH + HOUSING_HEIGHT))
        - 3 * disc_area)
    # the holes are exactly the discs: every disc vertex is a vertex of the front face
    front_points = {tuple(np.round(p[1:], 9)) for p in vertices[np.unique(faces[front])]}
    for z in LAMP_HEIGHT.values():
        for p in disc_v[1:]:
            assert (round(p[1], 9), round(p[2] + z, 9)) in front_points


def test_disc_faces_plus_x() -> None:
    vertices, faces = disc_mesh(0.11, 24)
    a, b, c = (vertices[faces[:, i]] for i in range(3))
    normals = np.cross(b - a, c - a)
    assert (normals[:, 0] > 0).all()
    assert np.abs(normals[:, 1:]).max() < 1e-12


def test_pole_and_housing_collide_and_lamps_do_not(client: BulletClient) -> None:
    light = add_traffic_light(client, HEAD)
    probe_shape = client.createCollisionShape(pybullet.GEOM_SPHERE, radius=0.05)
    probe = client.createMultiBody(0.0, probe_shape, -1, [HEAD.x - 0.3, HEAD.y, HEAD.z])
    assert client.getClosestPoints(probe, light.body, 0.5)  # the housing is there ...
    for lamp in light.lamps.values():
        assert client.getClosestPoints(probe, lamp, 0.5) == ()  # ... the lamps are not
    client.removeBody(probe)
    # a ray into the lamps' faces hits the housing's box; one at knee height, the pole
    hit = client.rayTest([HEAD.x - 3.0, HEAD.y, HEAD.z + 0.3], [HEAD.x, HEAD.y, HEAD.z + 0.3])[0]
    assert hit[0] == light.body
    assert hit[3][0] == pytest.approx(HEAD.x + HOUSING_DEPTH / 2 * math.cos(HEAD.facing))
    hit = client.rayTest([HEAD.x - 3.0, HEAD.y, 0.5], [HEAD.x, HEAD.y, 0.5])[0]
    assert hit[0] == light.body
    assert hit[3][0] == pytest.approx(HEAD.x - 0.06, abs=0.01)  # the pole's radius


# ---- rendered -------------------------------------------------------------------------------


def lamp_pixels(client: BulletClient, renderer: Renderer, distance: float,
                behind: bool = False) -> dict[LightColour, int]:
    """Lit-lamp pixels (S >= 240, V >= 100) of each hue band in the default front camera's
    frame, the car ``distance`` [m] before the head on its facing (or behind it)."""
    camera = Camera(client, sensor_setup(Profile.DEFAULT).camera("front"), renderer)
    side = -1.0 if behind else 1.0
    x = HEAD.x + side * distance * math.cos(HEAD.facing)
    yaw = HEAD.facing + (0.0 if behind else math.pi)
    rotation = np.array([[math.cos(yaw), -math.sin(yaw), 0.0],
                         [math.sin(yaw), math.cos(yaw), 0.0], [0.0, 0.0, 1.0]])
    right = 4.25 * side  # the head stands 4.25 m right of the car's path
    frame = camera.render(0.0, np.array([x, HEAD.y + right, 0.0]), rotation)
    hsv = cv2.cvtColor(frame.rgb, cv2.COLOR_RGB2HSV)
    lit = (hsv[..., 1] >= 240) & (hsv[..., 2] >= 100)
    bands = {LightColour.RED: (0, 8), LightColour.YELLOW: (15, 30), LightColour.GREEN: (55, 95)}
    return {c: int((lit & (hsv[..., 0] >= lo) & (hsv[..., 0] <= hi)).sum())
            for c, (lo, hi) in bands.items()}


@pytest.fixture(params=[Renderer.EGL, Renderer.TINY], ids=["egl", "tiny"])
def rendering(request: pytest.FixtureRequest) -> Iterator[tuple[BulletClient, Renderer]]:
    c = make_client()
    renderer = attach_renderer(c) if request.param is Renderer.EGL else Renderer.TINY
    if renderer is not request.param:
        c.disconnect()
        pytest.skip("no EGL renderer here")
    add_ground(c)
    yield c, renderer
    c.disconnect()


def test_lamps_are_drawn_from_the_front_only(rendering: tuple[BulletClient, Renderer]) -> None:
    """EGL's coarse depth buffer lost lamps on a box housing from 20-45 m; the hollow mesh
    housing keeps them to 60 m, and nothing of them shows from behind."""
    client, renderer = rendering
    light = add_traffic_light(client, HEAD)
    for colour in LightColour:
        light.set_colour(colour)
        for distance in (10.0, 30.0, 45.0, 60.0):
            seen = lamp_pixels(client, renderer, distance)
            assert seen[colour] >= 1, (colour, distance)
            assert sum(seen.values()) == seen[colour]
        assert sum(lamp_pixels(client, renderer, 20.0, behind=True).values()) == 0
    assert client.getVisualShapeData(light.lamps[LightColour.RED])[0][2] == pybullet.GEOM_MESH

"""The walker as a Bullet multibody (`world.actors.walker_body`): posed, its links are where
the model's forward kinematics puts them, rays and contacts meet its posed legs, and a
physics step leaves the pose alone."""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pybullet
import pytest
from pybullet_utils.bullet_client import BulletClient

from world.actors.shapes import targets
from world.actors.shapes.walker import (
    LINK_NAMES,
    WalkerModel,
    WalkerPose,
    link_frames,
    posed_points,
    walker_model,
    walker_pose,
)
from world.actors.walker_body import build_walker, bullet_links, pose_walker
from world.core.client import make_client

H, W = targets.EPTA.height, targets.EPTA.width
PLACE = (12.0, -3.0, 0.7)  # [m], [m], [rad] where the body frame is put in the world


@pytest.fixture
def client() -> Iterator[BulletClient]:
    c = make_client()
    yield c
    c.disconnect()


@pytest.fixture
def walker(client: BulletClient, tmp_path: Path) -> tuple[int, WalkerModel]:
    model = walker_model(H, W)
    return build_walker(client, model, tmp_path), model


def _to_world(p: np.ndarray) -> np.ndarray:
    """Body frame -> world at `PLACE`."""
    x, y, yaw = PLACE
    rot = np.array([[math.cos(yaw), -math.sin(yaw), 0.0], [math.sin(yaw), math.cos(yaw), 0.0],
                    [0.0, 0.0, 1.0]])
    return np.asarray(p @ rot.T + np.array([x, y, 0.0]), dtype=np.float64)


def _posed(client: BulletClient, body: int, phase: float) -> WalkerPose:
    pose = walker_pose(H, phase, W)
    pose_walker(client, body, *PLACE, pose)
    return pose


def test_the_body_has_the_models_joints(client: BulletClient,
                                        walker: tuple[int, WalkerModel]) -> None:
    body, model = walker
    assert bullet_links(model) == (*LINK_NAMES, "head")
    assert client.getNumJoints(body) == 9
    kinds = [client.getJointInfo(body, i)[2] for i in range(9)]
    assert kinds == [pybullet.JOINT_REVOLUTE] * 8 + [pybullet.JOINT_FIXED]


@pytest.mark.parametrize("phase", [0.0, 0.13, 0.25, 0.5, 0.61, 0.75, 0.9])
def test_posed_links_are_where_the_kinematics_puts_them(
        client: BulletClient, walker: tuple[int, WalkerModel], phase: float) -> None:
    body, model = walker
    pose = _posed(client, body, phase)
    frames = link_frames(model, pose)
    yaw = PLACE[2]
    turn = np.array([[math.cos(yaw), -math.sin(yaw), 0.0],
                     [math.sin(yaw), math.cos(yaw), 0.0], [0.0, 0.0, 1.0]])
    for i, name in enumerate(bullet_links(model)):
        rot, origin = frames.get(name, frames["base"])  # the head rides on the base
        state = client.getLinkState(body, i, computeForwardKinematics=1)
        np.testing.assert_allclose(state[0], _to_world(origin), atol=1e-6, err_msg=name)
        got = np.array(client.getMatrixFromQuaternion(state[1])).reshape(3, 3)
        np.testing.assert_allclose(got, turn @ rot, atol=1e-6, err_msg=name)


def _left_foot_ray(model: WalkerModel) -> tuple[list[float], list[float]]:
    """A ray across the left foot's middle at phase 0, from outside the body (left) to its
    centre plane, in the world."""
    foot = posed_points(model, walker_pose(H, 0.0, W))["left_foot"]
    x, z = 0.5 * (foot[:, 0].min() + foot[:, 0].max()), 0.5 * (foot[:, 2].min() + foot[:, 2].max())
    ends = _to_world(np.array([[x, 1.0, z], [x, 0.0, z]]))
    return ends[0].tolist(), ends[1].tolist()


def test_a_ray_meets_the_left_foot_only_where_it_is(client: BulletClient,
                                                    walker: tuple[int, WalkerModel]) -> None:
    body, model = walker
    start, end = _left_foot_ray(model)
    _posed(client, body, 0.0)
    hit = client.rayTest(start, end)[0]
    assert hit[0] == body and hit[1] == LINK_NAMES.index("left_foot")
    _posed(client, body, 0.5)  # the left foot a step behind
    assert client.rayTest(start, end)[0][0] == -1


@pytest.mark.parametrize("mass", [1.0, 0.0], ids=["dynamic_box", "static_box"])
def test_contacts_with_a_box_follow_the_legs(client: BulletClient,
                                             walker: tuple[int, WalkerModel],
                                             mass: float) -> None:
    """A box by the left shin at phase 0 touches it; at phase 0.5 the leg has left it."""
    body, model = walker
    pose = walker_pose(H, 0.0, W)
    shin = posed_points(model, pose)["left_shank"]
    centre = _to_world(0.5 * (shin.min(axis=0) + shin.max(axis=0)))
    shape = client.createCollisionShape(pybullet.GEOM_BOX, halfExtents=[0.03, 0.03, 0.03])
    box = client.createMultiBody(mass, shape, -1, centre.tolist(),
                                 useMaximalCoordinates=mass == 0.0)
    pose_walker(client, body, *PLACE, pose)
    client.performCollisionDetection()
    links = {p[3] for p in client.getContactPoints(body, box)}
    assert links == {LINK_NAMES.index("left_shank")}
    _posed(client, body, 0.5)
    client.performCollisionDetection()
    assert client.getContactPoints(body, box) == ()


def test_a_physics_step_leaves_the_pose(client: BulletClient,
                                        walker: tuple[int, WalkerModel]) -> None:
    body, _ = walker
    pose = _posed(client, body, 0.37)
    before = [client.getLinkState(body, i, computeForwardKinematics=1)[:2] for i in range(9)]
    for _ in range(24):
        client.stepSimulation()
    assert [client.getJointState(body, i)[0] for i in range(8)] == list(pose.angles.values())
    after = [client.getLinkState(body, i, computeForwardKinematics=1)[:2] for i in range(9)]
    assert after == before


def test_a_camera_sees_the_walker(client: BulletClient,
                                  walker: tuple[int, WalkerModel]) -> None:
    body, _ = walker
    _posed(client, body, 0.2)
    x, y, yaw = PLACE
    eye = [x + 4.0 * math.cos(yaw), y + 4.0 * math.sin(yaw), 1.0]
    view = client.computeViewMatrix(eye, [x, y, 1.0], [0.0, 0.0, 1.0])
    projection = client.computeProjectionMatrixFOV(40.0, 1.0, 0.1, 20.0)
    _, _, _, _, seg = client.getCameraImage(64, 64, view, projection,
                                            renderer=pybullet.ER_TINY_RENDERER)
    ids = np.asarray(seg).reshape(64, 64) & ((1 << 24) - 1)
    assert (ids == body).sum() > 100  # its visual meshes loaded and drawn

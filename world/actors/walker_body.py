"""A walking pedestrian in Bullet: a multibody built once from its articulated model
(`world.actors.shapes.walker`), posed kinematically each step.

The body is a fixed-base multibody of mass 0: its base carries the torso; link `i` (0 to 7)
is the model's link `i` (`LINK_NAMES`) on its revolute joint, so the joint index is the
link's index; each further base part (the head) rides on a fixed joint after them
(`bullet_links` names every Bullet link in order). Every link's inertial frame is its link
frame, so `getLinkState`'s first position is the link frame's origin. Nothing drives the
joints: `pose_walker` sets the base and every joint angle (`resetBasePositionAndOrientation`,
one `resetJointStatesMultiDof`), and a physics step leaves them there (mass-0 links take no
forces).

Asleep: the body is put to sleep when built (Bullet's deactivation). A sleeping multibody
skips the articulated-body pass and its joint motors in every physics step (8 awake walkers
add ~205 us to a step, 8 asleep ones ~20 us: `python -m bench.bench_walker`), yet a pose
still moves its links' colliders (PyBullet's resets update them), so contacts, rays and
drawings follow each pose, and an awake body (the ego) still collides with it.

Collision: each link is one convex hull, its model part's own points (`GEOM_MESH` with
vertices: no file, no rounding). Visual: the same hull as a flat-shaded OBJ mesh coloured
by its material. The mesh goes through a file because the EGL renderer drops meshes given
as vertex arrays; the files go into a folder the caller keeps while the client draws.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pybullet
from pybullet_utils.bullet_client import BulletClient

from world.actors.shapes.materials import MATERIALS
from world.actors.shapes.mesh import part_mesh
from world.actors.shapes.parts import BodyPart
from world.actors.shapes.walker import BASE, LINK_NAMES, WalkerModel, WalkerPose
from world.scene.collision import CollisionShapes, Part
from world.scene.solids import ConvexHull
from world.scene.traffic_light import write_obj

Rgba = tuple[float, float, float, float]  # [-] linear RGB and alpha, each in [0, 1]
UPRIGHT = (0.0, 0.0, 0.0, 1.0)  # a link frame's orientation in its parent's at zero angle


def material_rgba() -> dict[str, Rgba]:
    """Each material's own flat colour, opaque."""
    return {name: (*m.rgb, 1.0) for name, m in MATERIALS.items()}


def bullet_links(model: WalkerModel) -> tuple[str, ...]:
    """The Bullet body's link names by link index: the model's links, then the base's parts
    after its first (on fixed joints)."""
    return (*(link.name for link in model.links), *(p.name for p in model.base_parts[1:]))


def _collision(client: BulletClient, shapes: CollisionShapes, part: BodyPart) -> int:
    if not isinstance(part.solid, ConvexHull):
        raise ValueError(f"walker part {part.name!r} is not a convex hull")
    return shapes.create(client, Part(part.solid, part.position, part.orientation))


def _visual(client: BulletClient, part: BodyPart, folder: Path, key: str,
            rgba: Mapping[str, Rgba]) -> int:
    path = folder / f"{key}-{part.name}.obj"
    if not path.exists():
        vertices, triangles = part_mesh(part)
        write_obj(path, vertices, triangles.astype(np.int32))
    return int(client.createVisualShape(pybullet.GEOM_MESH, fileName=str(path),
                                        rgbaColor=list(rgba[part.material])))


def build_walker(client: BulletClient, model: WalkerModel, folder: Path,
                 rgba: Mapping[str, Rgba] | None = None,
                 shapes: CollisionShapes | None = None) -> int:
    """A walker of `model` in `client`, at zero angles with its body origin at the world's,
    asleep; its id. Mesh files go into `folder`; `rgba` colours the parts by material (each
    material's own colour when None); `shapes` keeps its base's and links' collision parts
    (`CollisionShapes.parts`, `.links`; a book of its own when None)."""
    book = CollisionShapes() if shapes is None else shapes
    colours = material_rgba() if rgba is None else rgba
    key = f"walker-{model.height:.4f}-{'free' if model.width is None else f'{model.width:.4f}'}"
    parts = [(BASE, p) for p in model.base_parts[1:]]
    links = [(link.parent, link.parts[0]) for link in model.links] + parts
    if any(len(link.parts) != 1 for link in model.links):
        raise ValueError("a walker link carries exactly one convex part")
    index = {BASE: 0} | {name: i + 1 for i, name in enumerate(LINK_NAMES)}
    n = len(links)
    trunk = _collision(client, book, model.base_parts[0])
    link_shapes = tuple(_collision(client, book, p) for _, p in links)
    body = int(client.createMultiBody(
        0.0, trunk, _visual(client, model.base_parts[0], folder, key, colours),
        [0.0, 0.0, 0.0], list(UPRIGHT),
        linkMasses=[0.0] * n,
        linkCollisionShapeIndices=list(link_shapes),
        linkVisualShapeIndices=[_visual(client, p, folder, key, colours) for _, p in links],
        linkPositions=[list(link.origin) for link in model.links] + [[0.0, 0.0, 0.0]] * len(parts),
        linkOrientations=[list(UPRIGHT)] * n,
        linkInertialFramePositions=[[0.0, 0.0, 0.0]] * n,
        linkInertialFrameOrientations=[list(UPRIGHT)] * n,
        linkParentIndices=[index[parent] for parent, _ in links],
        linkJointTypes=[pybullet.JOINT_REVOLUTE] * len(model.links)
        + [pybullet.JOINT_FIXED] * len(parts),
        linkJointAxis=[list(link.axis) for link in model.links] + [[0.0, 0.0, 1.0]] * len(parts)))
    client.changeDynamics(body, -1, activationState=pybullet.ACTIVATION_STATE_ENABLE_SLEEPING)
    client.changeDynamics(body, -1, activationState=pybullet.ACTIVATION_STATE_SLEEP)
    book.placed(body, trunk)
    return book.placed_links(body, link_shapes)


def pose_walker(client: BulletClient, body: int, x: float, y: float, yaw: float,
                pose: WalkerPose, z: float = 0.0) -> None:
    """Put walker `body`'s body frame at (`x`, `y`, `z`) [m] in the world, heading `yaw`
    [rad] (its x axis, counter-clockwise from the world's x), in `pose`."""
    c, s = math.cos(yaw), math.sin(yaw)
    client.resetBasePositionAndOrientation(
        body, [x + c * pose.base_x, y + s * pose.base_x, z + pose.base_height],
        [0.0, 0.0, math.sin(0.5 * yaw), math.cos(0.5 * yaw)])
    angles = list(pose.angles.values())
    client.resetJointStatesMultiDof(body, list(range(len(angles))), [[a] for a in angles])

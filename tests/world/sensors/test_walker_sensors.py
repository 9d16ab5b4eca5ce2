"""Walking pedestrians as the sensors and the physics see them: the Embree caster casts each
link posed where Bullet has it, the Bullet caster agrees with it, a leg's contact is a
contact with the walker's body, and a walk played twice is the same bit for bit."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from pybullet_utils.bullet_client import BulletClient

from avsim.scenario.load import load_scenario
from tests.world.sensors.ray_fans import ray_fan
from world.actors.body_build import BodyBuilder
from world.actors.shapes import targets
from world.actors.shapes.walker import LINK_NAMES, walker_model, walker_pose
from world.actors.walker_body import pose_walker
from world.core.client import add_ground, make_client
from world.scene.collision import CollisionShapes
from world.sensors.bullet_caster import BulletCaster
from world.sensors.embree_caster import EmbreeCaster
from world.truth import touching
from world.world import World

REACH = 60.0  # [m] the casters' range
H, W = targets.EPTA.height, targets.EPTA.width  # [m] the Euro NCAP adult's stature, width
AT = (12.0, 0.0)  # [m] where the walker's body frame stands
LEGS = frozenset(range(6))  # Bullet link indices of the thighs, shanks and feet
# [m] Bullet's convex hulls keep a collision margin (~1 cm) around their points: its ranges
# may be that much short, more at glancing incidence on a hull's edge
BULLET_HULL_SLACK = 0.03


def _walker() -> tuple[BulletClient, CollisionShapes, int, int]:
    client = make_client()
    ground = add_ground(client)
    shapes = CollisionShapes()
    body = BodyBuilder(client, shapes).walker(walker_model(H, W))
    return client, shapes, ground, body


def _pose(client: BulletClient, body: int, phase: float) -> None:
    """The walker at `AT`, walking along -y (its side to a sensor at the origin)."""
    pose_walker(client, body, *AT, -0.5 * math.pi, walker_pose(H, phase, W))


def _knee_fan() -> NDArray[np.float64]:
    """(N, 3) level rays 0.45 m up from (0, 0, 0.45), a fan of 1 deg around +x."""
    angles = np.radians(np.linspace(-0.5, 0.5, 201))
    return np.column_stack([np.cos(angles), np.sin(angles), np.zeros_like(angles)])


def test_embree_sees_the_legs_move() -> None:
    """Knee-height rays at two gait phases: both meet the legs, at different places."""
    client, shapes, ground, body = _walker()
    caster = EmbreeCaster(client, shapes, REACH, [body], ground, [])
    origin, dirs = np.array([0.0, 0.0, 0.45]), _knee_fan()
    hits = []
    for phase in (0.0, 0.25):  # heel strike, the legs apart; mid-swing, side by side
        _pose(client, body, phase)
        hit, fraction = caster.cast(origin, dirs, 0.0)
        assert np.sum(hit == body) >= 20  # the knees are there
        hits.append(np.where(hit == body, fraction * REACH, np.inf))
    both = np.isfinite(hits[0]) & np.isfinite(hits[1])
    # where the legs are across the fan, and how far, moves with the phase
    assert np.sum(np.isfinite(hits[0]) != np.isfinite(hits[1])) >= 10
    assert np.any(np.abs(hits[0][both] - hits[1][both]) > 0.02)
    client.disconnect()


def test_embree_and_bullet_agree_on_a_walker() -> None:
    """A 24-ring revolution over a walker at mid-swing: the same rays meet it (all but 3 %:
    rays grazing an edge), at the same ranges within Bullet's hull margin
    (`BULLET_HULL_SLACK`) but for at most 1 % grazing a link's edge (Bullet's margin stops
    them there, Embree's exact hull lets them on to a link behind), median within 2 mm."""
    client, shapes, ground, body = _walker()
    _pose(client, body, 0.3)
    columns = 7200
    embree = EmbreeCaster(client, shapes, REACH, [body], ground, [])
    bullet = BulletCaster(client, REACH, columns, [body], ground, [])
    origin = np.array([0.0, 0.0, 1.0])
    dirs = ray_fan(-5.0, 4.0, 24, columns)
    b_e, f_e = embree.cast(origin, dirs, 0.0)
    b_b, f_b = bullet.cast(origin, dirs, 0.0)
    on_e, on_b = b_e == body, b_b == body
    z = origin[2] + dirs[:, 2] * f_e * REACH
    assert on_e.sum() > 300 and np.sum(on_e & (z < 0.8)) > 50  # the legs are among them
    assert np.sum(on_e != on_b) <= 0.03 * on_e.sum()  # rays grazing an edge
    error = np.abs(f_e - f_b)[on_e & on_b] * REACH
    print(f"\n{on_e.sum()} hits, {np.sum(on_e != on_b)} disagree; range error median "
          f"{np.median(error) * 1e3:.2f} mm, 99 % {np.quantile(error, 0.99) * 1e3:.2f} mm, "
          f"worst {error.max() * 1e3:.2f} mm, over slack {np.sum(error > BULLET_HULL_SLACK)}")
    assert np.median(error) <= 2e-3
    assert np.sum(error > BULLET_HULL_SLACK) <= 0.01 * len(error)
    client.disconnect()


def test_a_leg_touching_is_a_contact_with_the_walker() -> None:
    """A dynamic box at the left foot of a walker in mid-stride touches the walker's body
    (its id, what the collision criteria map to the actor), through a leg link."""
    client, _, ground, body = _walker()
    _pose(client, body, 0.0)  # the left foot forward (-y), the right one back
    foot = np.array(client.getLinkState(body, LINK_NAMES.index("left_foot"))[4])
    box = client.createMultiBody(
        1.0, client.createCollisionShape(3, halfExtents=[0.05, 0.05, 0.05]), -1,
        [foot[0], foot[1] - 0.1, 0.1])  # 3: GEOM_BOX; just ahead of the toes, overlapping
    client.stepSimulation()
    assert body in touching(client, box, ground)
    links = {int(c[4]) for c in client.getContactPoints(bodyA=box, bodyB=body)}
    assert links and links <= LEGS
    client.disconnect()


SCENARIO = """\
format: avsim/1
name: walk
duration: 10
road:
  lanes: 1
  oncoming_lanes: 1
  lane_width: 3.5
  speed_limit_kph: 50
  segments:
    - {straight: 100}
ego:
  lane: 0
  s: 5
  speed_kph: 0
  set_speed_kph: 0
actors:
  - id: walker
    type: pedestrian
    s: 30
    offset: -4.0
    actions:
      - trigger: {time: 0.2}
        walk: {to_offset: 5.0, speed_kph: 5}
  - id: waiting
    type: pedestrian
    s: 35
    offset: 4.0
"""


def _play(path: Path) -> tuple[list[float], list[tuple[float, ...]], bytes]:
    """3 s of the scenario: each second the walkers' phases and joint angles, and at the
    end the link frames of every actor and a knee-height Embree scan."""
    w = World(load_scenario(path).world)
    phases, joints = [], []
    try:
        caster = EmbreeCaster(w.client, w.shapes, REACH, w.actors.bodies, w.scene.ground, [])
        for k in range(3 * 240):
            w.ego.apply(0.0, 0.0, 2000.0)
            w.step()
            if (k + 1) % 240 == 0:
                phases.append(list(w.actors.phases))
                joints.append(w.actors.joints())
        frames = [w.client.getLinkStates(b, list(range(w.client.getNumJoints(b))))
                  for b in w.actors.bodies]
        hit, fraction = caster.cast(np.array([30.0, -1.0, 0.45]), _knee_fan(), 0.0)
        out = repr(frames).encode() + hit.tobytes() + fraction.tobytes()
    finally:
        w.close()
    return [p for row in phases for p in row], [j for row in joints for j in row], out


def test_walking_moves_the_legs_and_standing_keeps_them(tmp_path: Path) -> None:
    path = tmp_path / "walk.yaml"
    path.write_text(SCENARIO, encoding="utf-8")
    phases, joints, _ = _play(path)
    walker, waiting = phases[0::2], phases[1::2]
    assert waiting == [0.25] * 3  # standing: the standing pose, frozen
    assert len(set(walker)) == 3  # walking: its phase moves on
    assert joints[0] != joints[2]


def test_a_walk_is_the_same_bit_for_bit(tmp_path: Path) -> None:
    path = tmp_path / "walk.yaml"
    path.write_text(SCENARIO, encoding="utf-8")
    assert _play(path) == _play(path)

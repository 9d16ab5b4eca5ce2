"""What an articulated walker costs per step, in CPU microseconds (best of several batches).

A walker (`world.actors.walker_body`) is a mass-0 fixed-base multibody of 9 links posed
kinematically. Measured in one process on a DIRECT client with the ground plane and the
ego's URDF car resting on it:
- a physics step of that scene alone, then with 1 and with 8 walkers standing on the
  ground, asleep as `build_walker` leaves them, then the 8 woken (every awake walker goes
  through the articulated-body pass and its feet touch the ground plane);
- posing a walker (`pose_walker`: the base and one `resetJointStatesMultiDof`);
- reading all 9 links' world poses (`getLinkStates` with and without
  `computeForwardKinematics`), as a LiDAR placing each link's hull needs every scan;
- the same poses from the model's own forward kinematics in numpy (`link_frames`).

Reported, not asserted (the machines are shared). Run it as `python -m bench.bench_walker`;
`--json FILE` also writes the figures.
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import pybullet
from pybullet_utils.bullet_client import BulletClient

from world.actors.shapes import targets
from world.actors.shapes.walker import link_frames, walker_model, walker_pose
from world.actors.walker_body import build_walker, pose_walker
from world.core.client import add_ground, make_client

URDF = Path(__file__).resolve().parents[1] / "vehicle_urdf" / "car.urdf"
BATCHES = 5  # [-] the best of these is reported
CALLS = 400  # [-] calls per batch


def _per_call(fn: Callable[[int], object]) -> float:
    """[us] CPU time per call of `fn(k)`, the best of `BATCHES` batches of `CALLS`."""
    best = float("inf")
    for _ in range(BATCHES):
        start = time.process_time()
        for k in range(CALLS):
            fn(k)
        best = min(best, (time.process_time() - start) / CALLS)
    return 1e6 * best


def _add_walkers(c: BulletClient, folder: Path, n: int, first: int) -> list[int]:
    h, w = targets.EPTA.height, targets.EPTA.width
    bodies = []
    for i in range(first, first + n):
        body = build_walker(c, walker_model(h, w), folder)
        pose_walker(c, body, 10.0 + 2.0 * i, 3.0, 0.0, walker_pose(h, 0.1 * i, w))
        bodies.append(body)
    return bodies


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--json", type=Path, help="also write the figures here")
    args = parser.parse_args()
    h, w = targets.EPTA.height, targets.EPTA.width
    model = walker_model(h, w)
    poses = [walker_pose(h, k / CALLS, w) for k in range(CALLS)]
    figures: dict[str, float] = {}
    with tempfile.TemporaryDirectory(prefix="avsim-walker-") as tmp:
        c = make_client()
        add_ground(c)
        c.loadURDF(str(URDF), [0.0, 0.0, 0.5])
        for _ in range(240):  # the car settles on its tyres
            c.stepSimulation()
        figures["step_scene_us"] = _per_call(lambda k: c.stepSimulation())
        walker = _add_walkers(c, Path(tmp), 1, 0)[0]
        figures["step_scene_1_walker_us"] = _per_call(lambda k: c.stepSimulation())
        walkers = [walker, *_add_walkers(c, Path(tmp), 7, 1)]
        figures["step_scene_8_walkers_us"] = _per_call(lambda k: c.stepSimulation())
        for body in walkers:
            c.changeDynamics(body, -1, activationState=pybullet.ACTIVATION_STATE_WAKE_UP)
            c.changeDynamics(body, -1,
                             activationState=pybullet.ACTIVATION_STATE_DISABLE_SLEEPING)
        figures["step_scene_8_awake_walkers_us"] = _per_call(lambda k: c.stepSimulation())
        figures["pose_walker_us"] = _per_call(
            lambda k: pose_walker(c, walker, 10.0 + 0.01 * k, 3.0, 0.0, poses[k]))
        links = list(range(c.getNumJoints(walker)))
        figures["link_states_fk_us"] = _per_call(
            lambda k: c.getLinkStates(walker, links, computeForwardKinematics=1))
        figures["link_states_us"] = _per_call(lambda k: c.getLinkStates(walker, links))
        figures["numpy_fk_us"] = _per_call(lambda k: link_frames(model, poses[k]))
        c.disconnect()
    for name, value in figures.items():
        print(f"{name:28s} {value:9.1f}")
    if args.json is not None:
        args.json.write_text(json.dumps(figures, indent=2) + "\n")


if __name__ == "__main__":
    main()

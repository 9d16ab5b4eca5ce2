"""Milliseconds per LiDAR scan, Embree against Bullet, on one scene.

`normal_driving` (or `--scenario`), the world stepped one simulated second so its NPC cars
are on their way; for the `fast` (900 columns) and `default` (1800 columns) LiDARs, each
backend casts the same revolution from the ego's pose (`Lidar._cast`: rays to body and hit
fraction, no noise) `--scans` times after one warm-up scan; the median is printed, with
the share of rays on which the two agree. One run; the machine's load shows in the figures.
"""

from __future__ import annotations

import argparse
import math
import statistics
import time

import numpy as np

from avsim.scenario.load import load_scenario
from world.core.rates import PHYSICS_RATE
from world.sensors.lidar import Lidar, RayBackend
from world.sensors.sensor import vehicle_pose
from world.sensors.setup import Profile, sensor_setup
from world.world import World


def bench(scenario: str, profile: Profile, scans: int) -> None:
    """Print one line per backend for `profile`'s LiDAR."""
    w = World(load_scenario(scenario).world, sensor_setup(profile), cameras=False)
    try:
        for _ in range(PHYSICS_RATE):
            w.step()
        own = w.rig.sensor("lidar").lidar  # type: ignore[attr-defined]
        assert isinstance(own, Lidar)
        info = own.info
        origin, rotation = vehicle_pose(w.ego_truth, w.ego.geometry.ride_height)
        m = info.mount
        r = rotation @ m.rotation()
        o = origin + rotation @ np.array([m.x, m.y, m.z])
        dirs = own._dirs @ r.T
        heading = math.atan2(r[1, 0], r[0, 0])
        results = {}
        for backend in RayBackend:
            start = time.perf_counter()
            lidar = Lidar(w.client, info, np.random.default_rng(0), w.actors.bodies,
                          w.scene.ground, sorted(w.scene.static_bodies), w.shapes, backend)
            build = time.perf_counter() - start
            results[backend] = lidar._cast(o, dirs, heading)  # warm-up
            times = []
            for _ in range(scans):
                start = time.perf_counter()
                lidar._cast(o, dirs, heading)
                times.append(time.perf_counter() - start)
            print(f"{scenario:15s} {profile.value:8s} {info.rays:6d} rays  {backend.value:7s} "
                  f"{1e3 * statistics.median(times):6.1f} ms/scan  (build {1e3 * build:.0f} ms)")
        same = np.mean(results[RayBackend.EMBREE][0] == results[RayBackend.BULLET][0])
        print(f"{'':15s} {'':8s} same body hit on {same:.4%} of the rays")
    finally:
        w.close()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenario", default="normal_driving")
    parser.add_argument("--scans", type=int, default=20)
    args = parser.parse_args()
    for profile in (Profile.FAST, Profile.DEFAULT):
        bench(args.scenario, profile, args.scans)


if __name__ == "__main__":
    main()

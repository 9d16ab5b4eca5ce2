"""Per-call cost of the hot parts of the loop, in microseconds (best of several batches).

These are the budgets the real-time factor rests on. They are reported, not asserted: the
machines are shared and noisy.
- map projection of 4 points on a 12-segment road (criteria / log / triggers, 40 Hz);
- the speed planner's target on normal_driving (40 Hz);
- stepping and placing the NPCs of normal_driving (120 Hz);
- the recorder: ego pose + 5 scalars + 3 actor boxes per 40 Hz tick, flushes included.

`make bench` runs it after the real-time factor; `--json FILE` also writes the figures.
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from avsim.record.recorder import Recorder
from avsim.scenario.load import load_scenario
from planner.speed_planning import SpeedPlanner, SpeedPlanningParams
from vehicle_urdf import read_geometry
from world.core.rates import ACTOR_RATE, CONTROL_RATE
from world.ego.body import vehicle_info
from world.map.road import build_road_map
from world.spec import RoadSpec, SegmentSpec
from world.world import World


def best_per_call(fn: Callable[[], object], calls: int, batches: int = 5) -> float:
    """[us] the best batch's mean time per call."""
    best = float("inf")
    for _ in range(batches):
        start = time.perf_counter()
        for _ in range(calls):
            fn()
        best = min(best, (time.perf_counter() - start) / calls)
    return best * 1e6


def projection() -> float:
    def seg(length: float, curvature: float = 0.0) -> SegmentSpec:
        return SegmentSpec(length=length, curvature=curvature, lanes=2, oncoming_lanes=1,
                           lane_width=3.5, shoulder=2.5)
    road = build_road_map(RoadSpec(
        segments=tuple([seg(100.0), seg(70.0, 1 / 200), seg(50.0), seg(52.0, -1 / 150)] * 3),
        speed_limit=50 / 3.6))
    lane = road.lane(0)
    points = lane.position(np.array([10.0, 300.0, 600.0, 900.0]), 0.5)
    return best_per_call(lambda: lane.local_coordinates(points), 2000)


def speed_planner() -> float:
    road = build_road_map(load_scenario("normal_driving").world.road)
    planner = SpeedPlanner(road, road.lane(0), SpeedPlanningParams(),
                           vehicle_info(read_geometry()))
    stations = iter(np.tile(np.linspace(0.0, road.length, 1000), 20).tolist())
    return best_per_call(lambda: planner.target(next(stations), set_speed=13.9,
                                                max_speed=15.0), 2000)


def actors() -> float:
    world = World(load_scenario("normal_driving").world)
    try:
        t = iter(np.arange(1, 20001) / ACTOR_RATE.hz)
        return best_per_call(lambda: world.actors.step(next(t), ACTOR_RATE.period), 2000)
    finally:
        world.close()


def recorder(tmp: Path) -> float:
    """[us] per control tick over 60 s of sim time, close included (one batch)."""
    rate, ids = CONTROL_RATE.hz, ("npc_0", "npc_1", "ped_0")
    half = np.array([[2.4, 0.9, 0.75], [4.0, 1.2, 1.5], [0.3, 0.3, 0.9]])
    quats = np.tile([0.0, 0.0, 0.0, 1.0], (3, 1))
    n = int(60 * rate)
    start = time.perf_counter()
    with Recorder(tmp / "cost.rrd", recording_id="cost") as rec:
        for i in range(n):
            t = i / rate
            rec.log_ego_pose(t, (12.0 * t, 0.0, 0.33), (0.0, 0.0, 0.0, 1.0))
            rec.log_scalars(t, {"speed": 12.0, "target_speed": 12.0, "speed_limit": 13.9,
                                "steering": 0.0, "cross_track_error": 0.01 * i})
            centres = np.array([[12 * t + 20, 0, 0.8], [12 * t + 45, 3.5, 0.8], [0, 0, 0.9]])
            rec.log_actors(t, ids, centres, half, quats, ("car", "truck", "pedestrian"))
    return (time.perf_counter() - start) / n * 1e6


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        figures = {
            "map_projection_4_points_us": projection(),
            "speed_planner_target_us": speed_planner(),
            "npc_step_2_actors_us": actors(),
            "recorder_tick_us": recorder(Path(tmp)),
        }
    print("per-call cost (best batch)")
    for key, value in figures.items():
        print(f"  {key:<28} {value:8.1f} us")
    if args.json:
        args.json.write_text(json.dumps(figures, indent=2) + "\n")


if __name__ == "__main__":
    main()

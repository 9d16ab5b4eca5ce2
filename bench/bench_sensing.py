"""Real-time factor per sensor profile, next to its raw sensing floor, in one run.

For each profile (`fast`, `default`, `paper`), on `normal_driving` cut to `--seconds` of
simulated time:

- floor: the world with the profile's sensors, the stack's own joint commands of the full
  run replayed at the control rate (same path), physics and the sensors (GNSS and odometry
  included) at the rates a recorded run captures them (`avsim.run.sensor_loop.frames_read`:
  the side cameras only for the recording) and nothing else. Two floors: `inline` (one
  process, serial) and `process` (cameras rendered in the worker process, the rest in the
  main one: the pipeline the runner uses);
- full stack: the closed loop with perception, planner, control and scoring, no recording;
- full stack + recording.

Per-stage latencies (medians over the run): lane extraction per front frame, clustering +
tracking per LiDAR scan. Ratios (ours / floor) are what to compare across machines: they
are measured in the same run on the same (shared, noisy) machine.

`make bench` runs it; `--json FILE` also writes the figures; `--profiles default` for one.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import statistics
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from avsim.run.runner import Runner, RunResult
from avsim.run.sensor_loop import frames_read
from avsim.run.stack import ComposedStack
from avsim.scenario.load import load_scenario
from perception.perception import Perception
from world.core.rates import CAR_SENSORS, CONTROL_RATE, PHYSICS_RATE
from world.sensors.pipeline import InlineSensing, ProcessSensing, Sensing
from world.sensors.schedule import SensorSchedule
from world.sensors.setup import LIDAR, Profile, SensorSetup, sensor_setup, sensor_timings
from world.world import World

SCENARIO = "normal_driving"


def _timed(fn: Callable[..., Any], into: list[float]) -> Callable[..., Any]:
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        start = time.perf_counter()
        try:
            return fn(*args, **kwargs)
        finally:
            into.append(time.perf_counter() - start)
    return wrapper


def full_run(profile: Profile, seconds: float, record: bool) -> tuple[float, RunResult,
                                                                      dict[str, float]]:
    """(RTF, the run, stage latencies [ms]) of the closed loop."""
    scenario = dataclasses.replace(load_scenario(SCENARIO), duration=seconds)
    lanes: list[float] = []
    objects: list[float] = []
    with tempfile.TemporaryDirectory() as tmp:
        runner = Runner(scenario, Path(tmp) / "bench.rrd" if record else None, profile=profile)
        assert isinstance(runner.stack, ComposedStack)
        stack = runner.stack.perception
        assert isinstance(stack, Perception) and stack.lane_detector is not None
        stack.lane_detector.detect = _timed(stack.lane_detector.detect, lanes)  # type: ignore[method-assign]
        detect, track = stack.object_detector.detect, stack.tracker.update
        pair: list[float] = []
        stack.object_detector.detect = _timed(detect, pair)  # type: ignore[method-assign]
        stack.tracker.update = _timed(track, objects)  # type: ignore[method-assign]
        start = time.perf_counter()
        result = runner.run()
        wall = time.perf_counter() - start
        size = (Path(tmp) / "bench.rrd").stat().st_size if record else 0
    stages = {"lane_ms": 1e3 * statistics.median(lanes),
              "objects_ms": 1e3 * statistics.median(a + b for a, b in zip(pair, objects,
                                                                          strict=False)),
              "recording_mb_per_min": size / 1e6 * 60.0 / result.sim_time}
    return result.sim_time / wall, result, stages


def floor_rtf(profile: Profile, run: RunResult, mode: str) -> float:
    """Physics + the profile's sensors at their rates, the run's commands replayed."""
    setup = sensor_setup(profile)
    world = World(run.scenario.world, setup, cameras=mode == "inline")
    sensing: Sensing = InlineSensing(world) if mode == "inline" else ProcessSensing(world, setup)
    timings = sensor_timings(setup)
    schedule = SensorSchedule(timings, CONTROL_RATE, frames_read(timings, run_reads(setup),
                                                                 recording=True))
    log = run.log
    try:
        start = time.perf_counter()
        for steering, drive, brake in zip(log.steering, log.drive_torque, log.brake_torque,
                                          strict=True):
            step = world.clock.step
            sensing.collect(step)
            for due in schedule.due(step):
                sensing.submit(due)
            sensing.collect(step)
            world.ego.apply(steering, drive, brake)
            for _ in range(CONTROL_RATE.every):
                world.step()
        sensing.collect(world.clock.step + max(t.latency_steps for _, t in sensor_timings(setup)))
        wall = time.perf_counter() - start
    finally:
        sensing.close()
        world.close()
    return len(log.steering) * CONTROL_RATE.every / PHYSICS_RATE / wall


def run_reads(setup: SensorSetup) -> frozenset[str]:
    """The sensors the stack reads in full: the front camera, the LiDAR, GNSS, odometry."""
    return frozenset({setup.cameras[0].name, LIDAR, *CAR_SENSORS})


def bench(profile: Profile, seconds: float) -> dict[str, float]:
    rtf, run, _ = full_run(profile, seconds, record=False)
    rec_rtf, _, stages = full_run(profile, seconds, record=True)
    out = {"full": rtf, "full_recording": rec_rtf,
           "floor_inline": floor_rtf(profile, run, "inline"),
           "floor_process": floor_rtf(profile, run, "process")} | stages
    out["ratio_vs_inline_floor"] = rec_rtf / out["floor_inline"]
    out["ratio_vs_process_floor"] = rec_rtf / out["floor_process"]
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=30.0)
    parser.add_argument("--profiles", nargs="+", default=["fast", "default", "paper"])
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args()
    figures = {name: bench(Profile(name), args.seconds) for name in args.profiles}
    print(f"{SCENARIO}, {args.seconds:.0f} s simulated per run; RTF = sim time / wall time")
    header = ("profile", "floor inl", "floor proc", "full", "full+rec", "rec/inl", "rec/proc",
              "lane ms", "obj ms", "MB/min")
    print("  ".join(f"{h:>10}" for h in header))
    for name, f in figures.items():
        cells = [f["floor_inline"], f["floor_process"], f["full"], f["full_recording"],
                 f["ratio_vs_inline_floor"], f["ratio_vs_process_floor"], f["lane_ms"],
                 f["objects_ms"], f["recording_mb_per_min"]]
        print(f"{name:>10}  " + "  ".join(f"{c:10.2f}" for c in cells))
    if args.json:
        args.json.write_text(json.dumps(figures, indent=2) + "\n")


if __name__ == "__main__":
    main()

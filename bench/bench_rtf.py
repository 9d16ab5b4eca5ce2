"""Real-time factor of normal_driving, measured in one run against the raw physics floor.

Three figures for the same scene (`scenarios/normal_driving.yaml`, the same simulated span):
- floor: the world built and the stack's own joint commands of a full run replayed at the
  control rate (so the car drives the same path, through the same curves and speeds), with
  `stepSimulation()` and nothing else: the cost of the physics alone;
- stack: the full closed loop (GNSS/odometry, localisation, planner, control, criteria),
  no recording;
- stack + recording: the same, writing the `.rrd`.
Ratios (ours / floor) are what to compare across machines; the machines are shared and noisy,
so each figure is the best of `--repeat` runs.

`make bench` runs it; `python -m bench.bench_rtf --json out.json` also writes the figures.
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

from avsim.run.runner import Runner, RunResult, TrajectoryLog
from avsim.scenario.load import load_scenario
from world.core.rates import CONTROL_RATE, PHYSICS_RATE
from world.world import World

SCENARIO = "normal_driving"


def floor_rtf(log: TrajectoryLog) -> float:
    """Raw PyBullet stepping of the same scene, the run's joint commands replayed."""
    world = World(load_scenario(SCENARIO).world)
    try:
        step, apply = world.client.stepSimulation, world.ego.apply
        every = CONTROL_RATE.every
        commands = list(zip(log.steering, log.drive_torque, log.brake_torque, strict=True))
        start = time.perf_counter()
        for steering, drive, brake in commands:
            apply(steering, drive, brake)
            for _ in range(every):
                step()
        wall = time.perf_counter() - start
        return len(commands) * every / PHYSICS_RATE / wall
    finally:
        world.close()


def stack_rtf(record: bool) -> tuple[float, RunResult]:
    """(RTF, the run) of a full run, with or without the recording."""
    scenario = load_scenario(SCENARIO)
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "bench.rrd" if record else None
        runner = Runner(scenario, out, profile=None)  # no cameras or LiDAR: map + GNSS only
        start = time.perf_counter()
        result = runner.run()
        wall = time.perf_counter() - start
    return result.sim_time / wall, result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args()
    best: dict[str, float] = {}
    sim = 0.0
    for _ in range(args.repeat):
        rtf, run = stack_rtf(record=False)
        best["stack"] = max(best.get("stack", 0.0), rtf)
        rtf, run = stack_rtf(record=True)
        best["stack_recording"] = max(best.get("stack_recording", 0.0), rtf)
        best["floor"] = max(best.get("floor", 0.0), floor_rtf(run.log))
        sim = run.sim_time
    print(f"{SCENARIO}: {sim:.0f} s simulated, best of {args.repeat}")
    print(f"  {'raw physics floor':<28} RTF {best['floor']:6.1f}")
    for key, label in (("stack", "full stack, no recording"),
                       ("stack_recording", "full stack + recording")):
        print(f"  {label:<28} RTF {best[key]:6.1f}   {best[key] / best['floor']:5.1%} of floor")
    if args.json:
        args.json.write_text(json.dumps(best, indent=2) + "\n")


if __name__ == "__main__":
    main()

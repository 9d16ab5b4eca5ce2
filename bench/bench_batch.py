"""Batch throughput: the same runs with 1 and 2 local workers and on a local Ray instance.

The batch is a sweep of `cut_in_out` (the UN R157 cut-in: its trigger gap x the cutter's
speed, 2 x 2, cut to `--seconds` of simulated time, `--profile` sensors): four independent
runs, as `avsim sweep` makes them. For each executor, in one run of this script on the
same machine:

- wall time of the batch, runs per minute, simulated seconds per wall second;
- scaling efficiency of 2 workers, ``T(1) / (2 T(2))`` (1.0: perfect);
- each run's own overhead: its worker's time less the simulation's (interpreter start,
  imports, world building, writing its files), median;
- cores busy: the worker processes' CPU time over the batch's wall time (local executors;
  Ray's workers are not this process's children). One run already keeps more than one core
  busy (Bullet's threaded ray casts for the LiDAR, llvmpipe's render threads), which bounds
  what a second worker can add on two cores;
- that the outcomes are equal (verdicts, criteria, metrics), as the batch promises.

`make bench` runs it; `--json FILE` also writes the figures; `--no-ray` skips Ray.
"""

from __future__ import annotations

import argparse
import json
import math
import resource
import statistics
import tempfile
import time
from pathlib import Path

from avsim.batch.executors import Executor, LocalExecutor, RayExecutor
from avsim.batch.jobs import RunJob, RunOutcome
from avsim.batch.suite import comparable, plan

SCENARIO = "cut_in_out"
GAPS = (20, 40)  # [m] the cut-in trigger gap
CUTTER_KPH = (30, 45)  # [km/h] the cutter's speed (the ego's set speed is 60 km/h)


def batch(out: Path, seconds: float, profile: str) -> list[RunJob]:
    entries = [(f"{SCENARIO}_{k:03d}", SCENARIO,
                {"duration": seconds, "actors.0.actions.0.trigger.gap": gap,
                 "actors.0.speed_kph": kph})
               for k, (gap, kph) in enumerate((g, v) for g in GAPS for v in CUTTER_KPH)]
    return plan(entries, out, profile)


def measure(executor: Executor, jobs: list[RunJob]) -> tuple[float, float, list[RunOutcome]]:
    """[s] the batch's wall time, [s] its child processes' CPU time, and its outcomes."""
    cpu = _children_cpu()
    start = time.perf_counter()
    outcomes = executor.run(jobs)
    return time.perf_counter() - start, _children_cpu() - cpu, outcomes


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def figures(wall: float, cpu: float, outcomes: list[RunOutcome],
            local: bool) -> dict[str, float]:
    """The batch's figures (module doc) from its wall and CPU times [s] and its outcomes;
    cores busy only for a `local` executor (NaN otherwise)."""
    sim = sum(o.sim_time for o in outcomes)
    overhead = [o.wall_time - o.run_time for o in outcomes if o.result is not None]
    return {"wall_s": wall, "runs_per_min": 60.0 * len(outcomes) / wall,
            "sim_per_wall": sim / wall, "overhead_s": statistics.median(overhead),
            "cores_busy": cpu / wall if local else math.nan}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=20.0)
    parser.add_argument("--profile", default="default")
    parser.add_argument("--no-ray", action="store_true")
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args()
    executors: dict[str, Executor] = {"local x1": LocalExecutor(1), "local x2": LocalExecutor(2)}
    if not args.no_ray:
        executors["ray x2"] = RayExecutor(None, 2)
    results: dict[str, dict[str, float]] = {}
    reference: list[dict[str, object]] | None = None
    for name, executor in executors.items():
        with tempfile.TemporaryDirectory() as tmp:
            wall, cpu, outcomes = measure(executor, batch(Path(tmp), args.seconds,
                                                          args.profile))
        results[name] = figures(wall, cpu, outcomes, isinstance(executor, LocalExecutor))
        same = [comparable(o) for o in outcomes]
        results[name]["equal_outcomes"] = float(reference is None or same == reference)
        reference = reference or same
    one, two = results["local x1"]["wall_s"], results["local x2"]["wall_s"]
    print(f"{SCENARIO} sweep: {len(GAPS) * len(CUTTER_KPH)} runs of {args.seconds:.0f} s "
          f"simulated, profile {args.profile}")
    header = ("executor", "wall s", "runs/min", "sim/wall", "overhead s", "cores busy",
              "equal")
    print("  ".join(f"{h:>11}" for h in header))
    for name, f in results.items():
        cells = [f["wall_s"], f["runs_per_min"], f["sim_per_wall"], f["overhead_s"],
                 f["cores_busy"]]
        print(f"{name:>11}  " + "  ".join(f"{c:11.2f}" for c in cells)
              + f"  {'yes' if f['equal_outcomes'] else 'NO':>11}")
    print(f"scaling efficiency of 2 local workers: {one / (2.0 * two):.2f}")
    if "ray x2" in results:
        print(f"ray x2 / local x2 wall time: {results['ray x2']['wall_s'] / two:.2f}")
    if args.json:
        args.json.write_text(json.dumps(results, indent=2) + "\n")


if __name__ == "__main__":
    main()

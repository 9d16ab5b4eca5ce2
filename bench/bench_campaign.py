"""Campaign throughput: runs of 30 s per hour, in `none` and `fast`, with 1 and 2 workers.

The campaign is `scenarios/campaigns/cut_in.yaml` (a slower car cutting in ahead of the car
at 60 km/h, its speed, trigger gap and lateral speed drawn from the file's laws), `--runs`
runs of `--seconds` simulated seconds each, drawn and planned as `avsim campaign` does it
(`avsim.batch.campaign.draw_plan`) and run on the local executor, as `avsim campaign
--jobs J` runs them. In `none` the stack has no camera and no LiDAR, so it runs in
privileged truth mode (`stack.privileged: true`, perception
`avsim.stack.bundled:truth_perception`): the campaign a user runs to test planning and
control alone. In `fast` it drives on its own sensors.

For each (profile, workers), in one run of this script on the same machine:

- wall time of the campaign and runs per hour;
- runs per hour per core (the machine's cores, `os.cpu_count()`), the figure a cluster is
  sized by;
- the 2-worker scaling efficiency, ``T(1) / (2 T(2))``;
- the verdicts (passed / failed / error), and that 1 and 2 workers give the same outcomes.

`make bench` runs it; `--json FILE` also writes the figures.
"""

from __future__ import annotations

import argparse
import json
import os
import tempfile
import time
from pathlib import Path

from avsim.batch.campaign import Settings, draw_plan, load_family
from avsim.batch.executors import LocalExecutor
from avsim.batch.jobs import RunJob, RunOutcome, Status
from avsim.batch.suite import comparable

FAMILY = "scenarios/campaigns/cut_in.yaml"
PROFILES = ("none", "fast")
WORKERS = (1, 2)
TRUTH_STACK = {"stack.privileged": True,
               "stack.perception": "avsim.stack.bundled:truth_perception"}  # `none` only


def campaign(out: Path, profile: str, runs: int, seconds: float) -> list[RunJob]:
    """The campaign's jobs, `runs` runs of `seconds` each in `profile` (module doc)."""
    fixed: dict[str, object] = {"duration": seconds}
    if profile == "none":
        fixed |= TRUTH_STACK
    settings = Settings(out_dir=out, profile=profile, fixed=fixed, seed=1)
    jobs, _ = draw_plan([load_family(FAMILY, 0)], runs, settings)
    return jobs


def measure(profile: str, workers: int, runs: int,
            seconds: float) -> tuple[float, list[RunOutcome]]:
    """[s] the campaign's wall time and its outcomes."""
    with tempfile.TemporaryDirectory() as tmp:
        jobs = campaign(Path(tmp), profile, runs, seconds)
        start = time.perf_counter()
        outcomes = LocalExecutor(workers).run(jobs)
        return time.perf_counter() - start, outcomes


def verdicts(outcomes: list[RunOutcome]) -> dict[str, int]:
    """How many runs passed, failed and ended in error."""
    counts = {"passed": 0, "failed": 0, "error": 0}
    for o in outcomes:
        key = {Status.PASSED: "passed", Status.FAILED: "failed"}.get(o.status, "error")
        counts[key] += 1
    return counts


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=8)
    parser.add_argument("--seconds", type=float, default=30.0)
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args()
    cores = os.cpu_count() or 1
    results: dict[str, dict[str, object]] = {}
    print(f"campaign {FAMILY}: {args.runs} runs of {args.seconds:.0f} s simulated, "
          f"{cores} cores")
    print(f"{'profile':>8} {'workers':>8} {'wall s':>8} {'runs/h':>8} {'runs/h/core':>12} "
          f"{'passed':>7} {'failed':>7} {'error':>6}")
    for profile in PROFILES:
        reference = None
        for workers in WORKERS:
            wall, outcomes = measure(profile, workers, args.runs, args.seconds)
            per_hour = 3600.0 * len(outcomes) / wall
            counts = verdicts(outcomes)
            same = [comparable(o) for o in outcomes]
            equal = reference is None or same == reference
            reference = reference or same
            results[f"{profile} x{workers}"] = {
                "wall_s": wall, "runs_per_hour": per_hour, "runs_per_hour_per_core":
                per_hour / cores, "equal_outcomes": equal, **counts}
            print(f"{profile:>8} {workers:>8} {wall:8.1f} {per_hour:8.0f} "
                  f"{per_hour / cores:12.0f} {counts['passed']:7d} {counts['failed']:7d} "
                  f"{counts['error']:6d}" + ("" if equal else "  OUTCOMES DIFFER"))
        one = results[f"{profile} x1"]["wall_s"]
        two = results[f"{profile} x2"]["wall_s"]
        assert isinstance(one, float) and isinstance(two, float)
        print(f"{profile}: scaling efficiency of 2 workers {one / (2.0 * two):.2f}")
    if args.json:
        args.json.write_text(json.dumps(results, indent=2) + "\n")


if __name__ == "__main__":
    main()

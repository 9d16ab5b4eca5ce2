"""Where each simulated second goes: wall time per stage of the full stack, per profile.

For each sensor profile (`none`, `fast`, `default`, `paper`), one run of `normal_driving` cut
to `--seconds` of simulated time, the full stack with recording, the sensing as the runner
picks it on this machine (`--sensing auto`: cameras in the render worker on 2+ cores). The
run's `Stopwatch` (`world.core.stopwatch`) gives each stage's wall time; the table shows it
in milliseconds per simulated second, so a column's main-process rows add up to the wall
time of one simulated second (1000 / RTF), "untimed" being the rest of the loop.

Rows starting with "worker" ran in the render worker, beside the main process: they overlap
the main rows, and the main process waits for them in "ipc wait" only when they are late.
"worker ipc send" is the images into shared memory and the rest of the answer into the pipe.

The machines are shared and noisy (about +-10 % from run to run), so each profile runs
`--repeat` times, round robin, and the table shows the fastest run, with the slowest run's
real-time factor in the last row.

`make bench` runs it; `--json FILE` also writes the figures; `--profiles default paper` for
some; `--sensing inline` to time every capture in the main process.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import tempfile
import time
from pathlib import Path

from avsim.run.runner import Runner
from avsim.scenario.load import load_scenario
from world.sensors.setup import Profile

SCENARIO = "normal_driving"
PROFILES = ("none", "fast", "default", "paper")


def stage_times(profile: str, seconds: float, sensing: str) -> dict[str, float]:
    """[ms per simulated second] per stage of one run, plus "wall" and "rtf"."""
    scenario = dataclasses.replace(load_scenario(SCENARIO), duration=seconds)
    with tempfile.TemporaryDirectory() as tmp:
        runner = Runner(scenario, Path(tmp) / "bench.rrd",
                        profile=None if profile == "none" else Profile(profile), sensing=sensing)
        start = time.perf_counter()
        result = runner.run()
        wall = time.perf_counter() - start
    per_s = 1e3 / result.sim_time
    out = {stage: t * per_s for stage, t in result.stage_times.items()}
    main = sum(v for k, v in out.items() if not k.startswith("worker "))
    out["untimed"] = wall * per_s - main
    out["wall"] = wall * per_s
    out["rtf"] = result.sim_time / wall
    return out


def best(runs: list[dict[str, float]]) -> dict[str, float]:
    """The fastest run's figures, with the slowest run's real-time factor beside them."""
    fastest = min(runs, key=lambda r: r["wall"])
    return fastest | {"rtf slowest run": min(r["rtf"] for r in runs)}


def _order(stage: str) -> tuple[int, str]:
    groups = ("physics", "sensor", "ipc", "worker", "localisation", "perception", "planner",
              "control", "criteria", "scoring", "runner", "recording", "untimed", "wall",
              "rtf")
    return next((i for i, g in enumerate(groups) if stage.startswith(g)), len(groups)), stage


def table(figures: dict[str, dict[str, float]]) -> str:
    stages = sorted({s for f in figures.values() for s in f}, key=_order)
    lines = [f"{'stage [ms per sim s]':<28}" + "".join(f"{p:>10}" for p in figures)]
    for stage in stages:
        cells = "".join(f"{f[stage]:10.1f}" if stage in f else f"{'-':>10}"
                        for f in figures.values())
        lines.append(f"{stage:<28}{cells}")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=20.0)
    parser.add_argument("--profiles", nargs="+", default=list(PROFILES), choices=PROFILES)
    parser.add_argument("--sensing", default="auto", choices=("auto", "inline", "process"))
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args()
    runs: dict[str, list[dict[str, float]]] = {p: [] for p in args.profiles}
    for _ in range(args.repeat):  # round robin: a slow spell of the machine hits them all
        for profile in args.profiles:
            runs[profile].append(stage_times(profile, args.seconds, args.sensing))
    figures = {p: best(r) for p, r in runs.items()}
    print(f"{SCENARIO}, {args.seconds:.0f} s simulated per run, full stack + recording, "
          f"sensing {args.sensing}; the fastest of {args.repeat} runs per profile")
    print(table(figures))
    if args.json:
        args.json.write_text(json.dumps(figures, indent=2) + "\n")


if __name__ == "__main__":
    main()

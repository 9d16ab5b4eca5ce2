"""Soak: an hour of simulated time on a town loop, per sensor profile.

The ego drives round a 1 x 1 town of 250 m blocks (all-way stops at the four corners, left
at each) for `--minutes` simulated minutes, with three NPC cars on the same loop, and the
run is recorded. Every simulated minute it prints the resident memory of this process and
of its sensing worker, the recording's size so far and the real-time factor of that
minute, then the figures that tell a leak or a drift:

- resident memory at the start (after the first minute), the middle and the end: flat
  within 10 % (`FLAT`);
- the recording's size per simulated minute;
- the real-time factor of the first and the last ten minutes (no drift: their ratio).

`make soak` runs it with profiles `none` and `fast` (an hour each: about 15 and 35 minutes
here); `python -m bench.bench_soak --minutes 5 --profile fast` for a shorter look.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

import yaml

from avsim.run.runner import Runner
from avsim.scenario.load import load_scenario
from world.sensors.setup import Profile

BLOCK = 250.0  # [m]
SPEED_KPH = 40.0
FLAT = 0.10  # memory at the end within this fraction of the start's


def soak_scenario(minutes: float) -> dict[str, object]:
    """The town loop as a scenario file's data: enough left turns for `minutes`."""
    laps = int(minutes * 60 * SPEED_KPH / 3.6 / (4 * BLOCK)) + 2
    turns = ["left"] * (4 * laps)
    corners = [[1, 0, "north"], [1, 1, "west"], [0, 1, "south"]]  # the loop's other starts
    npcs = [{"id": f"npc_{k}", "type": "car", "start": start, "route": turns[:-4],
             "speed_kph": 30} for k, start in enumerate(corners)]
    return {
        "format": "avsim/1", "name": "soak_town_loop", "situation": "town",
        "duration": minutes * 60.0, "seed": 1,
        "town": {"blocks_x": 1, "blocks_y": 1, "block": BLOCK, "lanes": 1,
                 "speed_limit_kph": SPEED_KPH, "junctions": "stop_signs"},
        "ego": {"start": [0, 0, "east"], "route": turns, "set_speed_kph": SPEED_KPH},
        "actors": npcs,
        "sensors": {"gnss": {"preset": "rtk"}},
        "criteria": {"completes": False},
    }


@dataclass
class Samples:
    """One line per simulated minute."""

    minute: list[int] = field(default_factory=list)
    rss: list[float] = field(default_factory=list)  # [MB] this process + its children
    size: list[float] = field(default_factory=list)  # [MB] the recording so far
    rtf: list[float] = field(default_factory=list)  # of that minute


def rss_mb() -> float:
    """[MB] resident memory of this process and its descendants (the sensing worker, its
    forkserver), from /proc (Linux)."""
    parents: dict[int, int] = {}
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                stat = (entry / "stat").read_text()
            except OSError:
                continue
            parents[int(entry.name)] = int(stat.rsplit(")", 1)[1].split()[1])
    ours, grew = {os.getpid()}, True
    while grew:
        more = {pid for pid, parent in parents.items() if parent in ours} - ours
        ours |= more
        grew = bool(more)
    total = 0
    for pid in ours:
        try:
            status = Path(f"/proc/{pid}/status").read_text()
        except OSError:
            continue
        total += next((int(line.split()[1]) for line in status.splitlines()
                       if line.startswith("VmRSS:")), 0)
    return total / 1e3  # kB -> MB


def soak(minutes: float, profile: str) -> Samples:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "soak.yaml"
        path.write_text(yaml.safe_dump(soak_scenario(minutes)), encoding="utf-8")
        recording = Path(tmp) / "soak.rrd"
        runner = Runner(load_scenario(path), recording,
                        None if profile == "none" else Profile(profile))
        samples = Samples()
        mark = [time.perf_counter(), 0.0]

        def progress(t: float, _duration: float) -> None:
            if t - mark[1] < 60.0 - 1e-6:
                return
            now = time.perf_counter()
            samples.minute.append(round(t / 60))
            samples.rss.append(rss_mb())
            samples.size.append(recording.stat().st_size / 1e6 if recording.exists() else 0)
            samples.rtf.append((t - mark[1]) / (now - mark[0]))
            mark[:] = [now, t]
            print(f"  {profile} {samples.minute[-1]:3d} min: RSS {samples.rss[-1]:7.1f} MB, "
                  f"recording {samples.size[-1]:7.1f} MB, RTF {samples.rtf[-1]:.2f}",
                  flush=True)

        runner.run(progress)
    return samples


def report(profile: str, s: Samples) -> None:
    if len(s.rss) < 3:
        print(f"{profile}: too short to judge ({len(s.rss)} minutes)")
        return
    start, middle, end = s.rss[0], s.rss[len(s.rss) // 2], s.rss[-1]
    growth = end / start - 1.0
    tenth = max(1, len(s.rtf) // 6)
    first, last = sum(s.rtf[:tenth]) / tenth, sum(s.rtf[-tenth:]) / tenth
    per_minute = (s.size[-1] - s.size[0]) / max(s.minute[-1] - s.minute[0], 1)
    print(f"{profile}: RSS start {start:.0f} MB, middle {middle:.0f} MB, end {end:.0f} MB "
          f"({growth:+.1%}, {'flat' if abs(growth) <= FLAT else 'NOT flat'} within "
          f"{FLAT:.0%}); recording {per_minute:.2f} MB per simulated minute; RTF first "
          f"{tenth} min {first:.2f}, last {tenth} min {last:.2f} (ratio {last / first:.2f})")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=60.0)
    parser.add_argument("--profile", action="append", choices=["none", "fast", "default"])
    args = parser.parse_args()
    for profile in args.profile or ["none", "fast"]:
        report(profile, soak(args.minutes, profile))


if __name__ == "__main__":
    main()

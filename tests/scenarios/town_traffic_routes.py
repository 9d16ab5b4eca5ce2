"""Writes scenarios/acceptance/town_traffic.yaml (to stdout): a 4 x 4 town, 20 NPC cars and
the ego on long seeded random walks (no U-turns), so that nobody reaches its route's end in
the run's 10 min. `python -m tests.scenarios.town_traffic_routes > FILE`."""

from __future__ import annotations

import random

STEPS = {"east": (1, 0), "north": (0, 1), "west": (-1, 0), "south": (0, -1)}
LEFT = {"east": "north", "north": "west", "west": "south", "south": "east"}
RIGHT = {v: k for k, v in LEFT.items()}
N = 4
EGO_TURNS = 50  # [-] junctions on the ego's route (about 4 km)

def exists(j: tuple[int, int]) -> bool:
    return 0 <= j[0] <= N and 0 <= j[1] <= N

def route(rng: random.Random, start: tuple[int, int, str], n: int) -> list[str]:
    j, h = (start[0], start[1]), start[2]
    out: list[str] = []
    for _ in range(n):
        j = (j[0] + STEPS[h][0], j[1] + STEPS[h][1])
        opts: list[tuple[str, str]] = []
        for m, nh in (("straight", h), ("left", LEFT[h]), ("right", RIGHT[h])):
            if exists((j[0] + STEPS[nh][0], j[1] + STEPS[nh][1])):
                opts.append((m, nh))
        m, h = rng.choice(opts)
        out.append(m)
    return out

def walk_end(start: tuple[int, int, str], moves: list[str]) -> tuple[int, int, str]:
    """The junction of a walk's last move and the heading it leaves that junction with."""
    j, h = (start[0], start[1]), start[2]
    for m in moves:
        j = (j[0] + STEPS[h][0], j[1] + STEPS[h][1])
        h = {"straight": h, "left": LEFT[h], "right": RIGHT[h]}[m]
    return j[0], j[1], h


def trail(rng: random.Random, start: tuple[int, int, str], tries: int = 2000) -> list[str]:
    """The longest of `tries` random walks from `start` that use no street twice (either
    way): the ego's route begins so (it crosses junctions it crossed before, which the
    stations' projection near the car's last station keeps apart,
    `world.hdmap.ReferenceLine.project`)."""
    best: list[str] = []
    for _ in range(tries):
        j, h = (start[0], start[1]), start[2]
        used = {frozenset({j, (j[0] + STEPS[h][0], j[1] + STEPS[h][1])})}
        out: list[str] = []
        while True:
            j = (j[0] + STEPS[h][0], j[1] + STEPS[h][1])
            opts = []
            for m, nh in (("straight", h), ("left", LEFT[h]), ("right", RIGHT[h])):
                nxt = (j[0] + STEPS[nh][0], j[1] + STEPS[nh][1])
                if exists(nxt) and frozenset({j, nxt}) not in used:
                    opts.append((m, nh, nxt))
            if not opts:
                break
            m, h, nxt = rng.choice(opts)
            used.add(frozenset({j, nxt}))
            out.append(m)
        if len(out) > len(best):
            best = out
    return best


def main() -> None:
    rng = random.Random(7)
    starts = []
    for ix in range(N + 1):
        for iy in range(N + 1):
            for h, (dx, dy) in STEPS.items():
                if exists((ix + dx, iy + dy)):
                    starts.append((ix, iy, h))
    rng.shuffle(starts)
    ego_start = (0, 2, "east")
    starts = [s for s in starts if s != ego_start][:20]
    lines = []
    for k, st in enumerate(starts):
        r = route(rng, st, 50)
        speed = rng.choice([30, 35, 40])
        s = rng.choice([10, 25, 40])
        lines.append(f"  - {{id: car_{k:02d}, type: car, start: [{st[0]}, {st[1]}, {st[2]}], "
                     f"s: {s},\n     speed_kph: {speed}, route: [{', '.join(r)}]}}")
    ego_route = trail(rng, ego_start)
    # the longest trail (about 2.5 km) is driven within the ten minutes once the junctions
    # flow: it goes on as a random walk, streets used again, to EGO_TURNS junctions
    ego_route += route(random.Random(8), walk_end(ego_start, ego_route),
                       EGO_TURNS - len(ego_route))
    print(f"""format: avsim/1
name: town_traffic
description: >-
  Issue K 6: a 4 x 4 town of 80 m blocks, lights where ix + iy is even and all-way stops
  elsewhere, 20 NPC cars and the ego on long routes (seeded random walks without U-turns,
  made by a script; none reaches its end within the run), 10 minutes. Nobody may stand
  longer than 60 s while it has the right of way (no deadlock at any junction), and the
  ego touches nothing.
situation: town
duration: 600
seed: 1

town: {{blocks_x: {N}, blocks_y: {N}, block: 80, lanes: 1, lane_width: 3.5, speed_limit_kph: 40,
       junctions: mixed}}

ego:
  start: [{ego_start[0]}, {ego_start[1]}, {ego_start[2]}]
  route: [{', '.join(ego_route)}]
  set_speed_kph: 40

criteria:
  completes: false          # ten minutes of driving, not a destination
  max_wait_with_right_of_way: 60

# An RTK receiver, as in the other town scenarios: this one is about the junctions.
sensors: {{gnss: {{preset: rtk}}}}

actors:
""" + "\n".join(lines))


if __name__ == "__main__":
    main()

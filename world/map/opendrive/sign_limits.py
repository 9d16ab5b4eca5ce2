"""The speed limits the file's static speed-limit signs post on the route.

A sign for the route's traffic (orientation "+" or "none": the route runs in the
direction of increasing s) posts its limit from its station on the merged road (its road's
start on the chain plus its own s). Which limit holds at a station (`world.map.opendrive.
route`): a lane's own `<speed max>`, else the latest posting before it - a sign's value or
a road type record's limit (its `<speed>`, else its type's default) -, a sign winning over a
type record at the same station. Signs for the other direction post nothing on the route.
"""

from __future__ import annotations

from world.map.opendrive.chain import Chain
from world.map.opendrive.model import OpenDrive

SignPost = tuple[float, float]  # ([m] merged station, [m/s] limit)


def sign_posts(odr: OpenDrive, chain: Chain) -> tuple[SignPost, ...]:
    """Every forward speed-limit sign's (station, limit) on the merged road, by station
    (one per station: the last in the file of those at one station)."""
    posts: dict[float, float] = {}
    for road in odr.roads:
        start = chain.span(road.id).start
        for sig in road.signals:
            limit = sig.speed_limit
            if limit is not None and sig.applies_forward():
                s = start + min(max(sig.s, 0.0), road.length)
                posts[s] = limit
    return tuple(sorted(posts.items()))


def latest_sign(posts: tuple[SignPost, ...], s: float) -> SignPost | None:
    """The last sign at or before station `s` [m] (None: none yet)."""
    before = [p for p in posts if p[0] <= s + 1e-9]
    return before[-1] if before else None

"""Whose turn it is at an all-way stop: first to stop, first to go; ties to the right.

The world's own traffic keeps this order from the truth (`world.actors.town_traffic`); the
criterion `max_wait_with_right_of_way` judges by it. Pure: no PyBullet, no map.

A vehicle *arrives* at a junction when it stands at the stop line of its approach, first of
its queue (a vehicle queued behind it has not arrived: it arrives when it has moved up and
stopped at the line itself). It *leaves* when it is no longer standing there (it has gone
into the junction). Per junction (`AllWayStop.turn`, at time t):

1. Nobody has the turn before the earliest arrival has stood ``TIE`` (vehicles arriving
   within ``TIE`` of each other are a tie, and all of a tie must have arrived).
2. The turn goes, in order of arrival, to the first vehicle that has no tied vehicle on
   its right (right-hand traffic: the vehicle coming from the right, heading 90 deg left
   of one's own, goes first). When every tied vehicle has one on its right (four at
   once), the earliest goes (then the smallest key).
3. A turn, once given, stays with its vehicle until it leaves: a later arrival cannot take
   it. If it has not left ``GRANT_TIMEOUT`` after it was given (it stands for another
   reason: a pedestrian, a car ahead beyond the junction, a driver that judged otherwise),
   it goes to the back of the order (arrival time now) and the next vehicle gets the turn:
   nobody waits for a vehicle that does not go.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

TIE = 1.0  # [s] vehicles stopping this close in time arrived together
GRANT_TIMEOUT = 6.0  # [s] a turn not taken within this passes to the next vehicle
RIGHT_TOLERANCE = math.radians(30.0)  # [rad] a heading within this of 90 deg left of one's
#   own comes from the right

Key = str  # a vehicle's name: an NPC's id, or "ego"
JunctionKey = tuple[int, int]  # (ix, iy)


@dataclass(slots=True)
class _Arrival:
    heading: float  # [rad] its direction of travel into the junction
    t: float  # [s] when it came to a stop at its line


@dataclass(slots=True)
class _Junction:
    waiting: dict[Key, _Arrival] = field(default_factory=dict)
    granted: Key | None = None
    granted_at: float = 0.0  # [s]


def on_right(heading: float, other: float) -> bool:
    """Whether a vehicle travelling `other` [rad] comes from the right of one travelling
    `heading` [rad] (its heading is 90 deg left of it)."""
    diff = math.remainder(other - heading - 0.5 * math.pi, 2.0 * math.pi)
    return abs(diff) < RIGHT_TOLERANCE


def first_in_order(waiting: dict[Key, tuple[float, float]]) -> Key | None:
    """The vehicle whose turn it is among `waiting` (key -> ([s] arrival, [rad] heading)),
    by rule 2 of the module doc; None when nobody waits."""
    if not waiting:
        return None
    order = sorted(waiting, key=lambda k: (waiting[k][0], k))
    t0 = waiting[order[0]][0]
    tied = [k for k in order if waiting[k][0] - t0 < TIE]
    for k in tied:
        if not any(on_right(waiting[k][1], waiting[o][1]) for o in tied if o != k):
            return k
    return order[0]


class AllWayStop:
    """The order at every all-way stop of a town (module doc), keyed by junction index."""

    def __init__(self, grant_timeout: float = GRANT_TIMEOUT) -> None:
        """`grant_timeout` [s]: rule 3's (inf: a turn never passes on, as a judge of
        who had the right of way counts it)."""
        self.grant_timeout = grant_timeout
        self._junctions: dict[JunctionKey, _Junction] = {}

    def arrive(self, junction: JunctionKey, key: Key, heading: float, t: float) -> None:
        """`key` stands at its line at `junction` from time `t` [s] (a repeat is ignored)."""
        j = self._junctions.setdefault(junction, _Junction())
        j.waiting.setdefault(key, _Arrival(heading, t))

    def leave(self, junction: JunctionKey, key: Key) -> None:
        """`key` no longer stands at its line at `junction`."""
        j = self._junctions.get(junction)
        if j is None:
            return
        j.waiting.pop(key, None)
        if j.granted == key:
            j.granted = None

    def arrived_at(self, junction: JunctionKey, key: Key) -> float | None:
        """[s] when `key` arrived at `junction`; None if it is not standing there."""
        j = self._junctions.get(junction)
        arrival = j.waiting.get(key) if j is not None else None
        return arrival.t if arrival is not None else None

    def turn(self, junction: JunctionKey, t: float) -> Key | None:
        """Whose turn it is at `junction` at time `t` [s] (module doc); None: nobody's."""
        j = self._junctions.get(junction)
        if j is None or not j.waiting:
            return None
        if j.granted is not None and t - j.granted_at > self.grant_timeout:
            j.waiting[j.granted].t = t  # not taken: to the back of the order
            j.granted = None
        if j.granted is None:
            if t - min(a.t for a in j.waiting.values()) < TIE:
                return None
            j.granted = first_in_order({k: (a.t, a.heading) for k, a in j.waiting.items()})
            j.granted_at = t
        return j.granted

    def may_go(self, junction: JunctionKey, key: Key, t: float) -> bool:
        """Whether it is `key`'s turn at `junction` at time `t` [s]."""
        return self.turn(junction, t) == key

"""A planView's continuity: each record starts where the one before ends.

The simulated road is the file's only if its records meet. Between consecutive records k
and k + 1 (checked in this order):

- stations: s of record k + 1 within `STATION_GAP` of s_k + length_k (cheap, on the numbers
  alone: `check_stations`, before any curve is evaluated);
- position: record k's end, evaluated exactly on record k itself, within `POSITION_GAP` of
  record k + 1's (x, y);
- heading: record k's exact end heading within `HEADING_GAP` of record k + 1's hdg (modulo
  a full turn).

The tolerances are those of roads linked end to end (`chain`): real files keep well inside
them (ASAM's examples, the ALKS roads: at most 0.3 mm, 2e-6 rad, stations exact).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from itertools import pairwise
from typing import Protocol

from world.map.opendrive.errors import OpenDriveError
from world.map.opendrive.geometry import PlanView
from world.map.opendrive.model import Geometry

STATION_GAP = 1e-2  # [m] record k + 1's s vs where record k ends (s_k + length_k)
POSITION_GAP = 1e-2  # [m] record k + 1's (x, y) vs record k's exact end
HEADING_GAP = 1e-3  # [rad] record k + 1's hdg vs record k's exact end heading


class Located(Protocol):
    """Where a record is in the file (an `xmltree.Node`)."""

    def error(self, problem: str) -> OpenDriveError:
        """The error `problem` at this element."""
        ...


def check_stations(geoms: Sequence[Geometry], nodes: Sequence[Located]) -> None:
    """Refuse records whose s is not where the record before ends (module doc)."""
    for k, (prev, g) in enumerate(pairwise(geoms)):
        end = prev.s + prev.length
        if abs(g.s - end) > STATION_GAP:
            raise nodes[k + 1].error(
                f"starts at s = {g.s:g} m, {abs(g.s - end):.3g} m from where geometry[{k + 1}] "
                f"ends (s = {end:g} m; at most {STATION_GAP:g} m)")


def check_continuity(pv: PlanView, nodes: Sequence[Located]) -> None:
    """Refuse records that do not start where the record before ends, in position or
    heading (module doc); `nodes[k]` locates record k."""
    x, y, h = pv.record_ends()
    for k, g in enumerate(pv.geometries[1:]):
        gap = math.hypot(g.x - float(x[k]), g.y - float(y[k]))
        if not gap <= POSITION_GAP:
            raise nodes[k + 1].error(
                f"starts {gap:.3g} m from where geometry[{k + 1}] ends (at most "
                f"{POSITION_GAP:g} m)")
        turn = abs(math.remainder(g.hdg - float(h[k]), 2.0 * math.pi))
        if not turn <= HEADING_GAP:
            raise nodes[k + 1].error(
                f"starts heading {turn:.3g} rad off where geometry[{k + 1}] ends (at most "
                f"{HEADING_GAP:g} rad)")

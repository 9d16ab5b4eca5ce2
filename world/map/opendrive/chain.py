"""Roads linked end to end as one road: `chain_roads` merges a file's roads into the one
`Road` the route is built from, and says where each file road lies on it.

The chain follows the roads' `successor` / `predecessor` links of element type "road": it
starts at the one road no road of the file leads into and runs on along the links until the
road that leads nowhere in the file. A link to a road the file does not hold leads out of it
(as a lone road's links do). Every road of the file must be in the one chain, and the links
must agree where both ends give them: A's successor B joined at its start (contactPoint
"start" or none), B's predecessor A joined at its end. A file of one road is its own chain,
returned as it is (its links lead out of the file).

Refused as "not supported yet (...)": roads in junctions and links to junctions, a road
joined the other way round (a successor joined at its end, a predecessor at its start), roads
not linked into one line (a road network), a loop, roads of different traffic rules, and
lane links that renumber lanes across a road link (every lane keeps its id: a lane's
successor in the last section of a road, its predecessor in the first section of the next,
where the file names them, must be the lane's own id). An `OpenDriveError` also for links
that contradict each other, and for a gap: road i's reference line must end where road
i + 1's starts, within `JOIN_GAP` and `JOIN_TURN`.

On the merged road each file road starts at the station where the one before ends (its
planView's end): its planView records, lane sections, lane offsets and road type records
are shifted by that station (lane widths and road marks are relative to their section's
start, so they stay as they are). Each road's first planView record and first lane section
must start at s = 0. Each road's records hold on its own stretch only:

- road type (speed) records: a road without a record at its start has none there (esmini
  reads a road's limit from its own type records only, `Road::GetSpeedByS`); the merged
  road then gets a record of type "unknown" without a limit at that station, so the route's
  default rule (`world.map.opendrive.route`: the "unknown" type's limit) holds there rather
  than the road before's record;
- lane offsets: a road without a record at its start has none there (the centre lane on
  the reference line), so a zero record is added where the road before's is non-zero.

The merged road's id is the file roads' ids joined by "+" in the chain's order, its name
and predecessor the first road's, its successor the last road's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from itertools import pairwise

import numpy as np

from world.map.opendrive.errors import OpenDriveError
from world.map.opendrive.geometry import PlanView
from world.map.opendrive.model import (
    LaneSection,
    Link,
    OpenDrive,
    Poly3,
    Road,
    SpeedRecord,
)

JOIN_GAP = 1e-2  # [m] the largest gap between a road's end and the next road's start
JOIN_TURN = 1e-3  # [rad] the largest heading change there
DEFAULT_TYPE = "unknown"  # the road type of a stretch whose road posts no type record
ZERO = Poly3(0.0, 0.0, 0.0, 0.0, 0.0)


@dataclass(frozen=True, slots=True)
class Span:
    """Where one file road lies on the merged road."""

    road_id: str
    start: float  # [m] the merged station of the road's s = 0
    length: float  # [m] the road's own length (its `length` attribute)


@dataclass(frozen=True, slots=True)
class Chain:
    """The file's roads as one road (module doc)."""

    road: Road  # the merged road
    spans: tuple[Span, ...]  # the file roads in the chain's order

    @property
    def starts(self) -> dict[str, float]:
        """[m] each file road's s = 0 on the merged road, by road id."""
        return {span.road_id: span.start for span in self.spans}

    def span(self, road_id: str) -> Span:
        """The file road `road_id`'s place; KeyError if the chain has no such road."""
        for span in self.spans:
            if span.road_id == road_id:
                return span
        raise KeyError(road_id)

    def locate(self, s: float) -> tuple[str, float]:
        """(the file road, [m] its own s) at merged station `s` (the later road at a joint,
        the first before the start, the last beyond the end)."""
        i = int(np.searchsorted([sp.start for sp in self.spans], s, side="right")) - 1
        span = self.spans[max(i, 0)]
        return span.road_id, s - span.start


def _refuse(odr: OpenDrive, what: str) -> OpenDriveError:
    return OpenDriveError(odr.path, f"not supported yet ({what})")


def chain_roads(odr: OpenDrive) -> Chain:
    """The file's roads linked end to end as one road (module doc); `OpenDriveError`."""
    if not odr.roads:
        raise OpenDriveError(odr.path, "no <road>")
    if len(odr.roads) == 1:
        (road,) = odr.roads
        return Chain(road, (Span(road.id, 0.0, road.length),))
    order = _order(odr, _edges(odr))
    roads = [odr.road(road_id) for road_id in order]
    for before, after in pairwise(roads):
        _check_join(odr, before, after)
    return _merge(odr, roads)


def _edges(odr: OpenDrive) -> dict[str, str]:
    """The links as road id -> the id of the road after it (both ends' links agreeing)."""
    ids = {road.id for road in odr.roads}
    after: dict[str, str] = {}
    before: dict[str, str] = {}
    for road in odr.roads:
        if road.junction != "-1":
            raise _refuse(odr, f"junctions: road {road.id} is in junction {road.junction}")
        for link, ahead in ((road.successor, True), (road.predecessor, False)):
            other = _linked(odr, road, link, ahead, ids)
            if other is None:
                continue
            a, b = (road.id, other) if ahead else (other, road.id)
            for table, key, value in ((after, a, b), (before, b, a)):
                if table.setdefault(key, value) != value:
                    raise OpenDriveError(odr.path, f"the road links contradict each other: "
                                         f"road {key} is linked to roads {table[key]} and "
                                         f"{value} on the same end")
    return after


def _linked(odr: OpenDrive, road: Road, link: Link | None, ahead: bool,
            ids: set[str]) -> str | None:
    """The id of the file road `link` joins `road`'s end (`ahead`) or start to, None if it
    leads out of the file; refused unless the other road runs on the same way."""
    if link is None:
        return None
    which = "successor" if ahead else "predecessor"
    if link.element_type == "junction":
        raise _refuse(odr, f"junctions: road {road.id}'s {which} is junction "
                           f"{link.element_id}")
    if link.element_type != "road":
        raise OpenDriveError(odr.path, f"road {road.id}'s {which} elementType is not road or "
                             f"junction ({link.element_type!r})")
    if link.element_id not in ids:
        return None
    wrong = "end" if ahead else "start"
    if link.contact_point == wrong:
        raise _refuse(odr, f"road {link.element_id} joined at its {wrong}: a reversed road")
    return link.element_id


def _order(odr: OpenDrive, after: dict[str, str]) -> list[str]:
    """The road ids from the chain's first road along the links (module doc)."""
    led_into = set(after.values())
    firsts = [road.id for road in odr.roads if road.id not in led_into]
    if not firsts:
        raise _refuse(odr, "roads linked in a loop")
    if len(firsts) > 1:
        raise _refuse(odr, "roads not linked end to end into one route: road networks")
    order = [firsts[0]]
    while order[-1] in after and len(order) <= len(odr.roads):
        order.append(after[order[-1]])
    if len(order) != len(odr.roads):  # the rest are a loop of their own
        raise _refuse(odr, "roads not linked end to end into one route: road networks")
    return order


def _check_join(odr: OpenDrive, before: Road, after: Road) -> None:
    """Refuse a join that is not seamless (module doc)."""
    for road in (before, after):
        if road.plan_view.start != 0.0 or road.lane_sections[0].s != 0.0:
            raise OpenDriveError(odr.path, f"road {road.id}: its first planView record or "
                                 "lane section does not start at s = 0")
    if before.rule != after.rule:
        raise _refuse(odr, f"roads {before.id} and {after.id} of different traffic rules "
                           "linked")
    x0, y0, h0 = (float(v[0]) for v in before.plan_view.pose_unwrapped(
        np.array([before.plan_view.end])))
    x1, y1, h1 = (float(v[0]) for v in after.plan_view.pose_unwrapped(np.array([0.0])))
    gap = math.hypot(x1 - x0, y1 - y0)
    turn = math.remainder(h1 - h0, 2 * math.pi)
    if gap > JOIN_GAP or abs(turn) > JOIN_TURN:
        raise OpenDriveError(odr.path, f"road {after.id} does not start where road "
                             f"{before.id} ends: {gap:.3g} m apart, headings "
                             f"{turn:.3g} rad apart (at most {JOIN_GAP:g} m, "
                             f"{JOIN_TURN:g} rad)")
    _check_lane_links(odr, before, after)


def _check_lane_links(odr: OpenDrive, before: Road, after: Road) -> None:
    """Refuse lane links across the join that give a lane another id (module doc)."""
    last, first = before.lane_sections[-1], after.lane_sections[0]
    pairs = [(lane.id, lane.successors) for lane in (*last.left, *last.right)]
    pairs += [(lane.id, lane.predecessors) for lane in (*first.left, *first.right)]
    for lane_id, linked in pairs:
        if linked and linked != (lane_id,):
            raise _refuse(odr, f"lane links that renumber lanes: lane {lane_id} linked to "
                               f"lane {', '.join(map(str, linked))} between roads "
                               f"{before.id} and {after.id}")


def _merge(odr: OpenDrive, roads: list[Road]) -> Chain:
    """The roads (in the chain's order, joins checked) as one road (module doc)."""
    geometries, sections = [], []
    offsets: list[Poly3] = []
    speeds: list[SpeedRecord] = []
    spans: list[Span] = []
    start = 0.0
    for road in roads:
        spans.append(Span(road.id, start, road.length))
        geometries += [replace(g, s=g.s + start) for g in road.plan_view.geometries]
        sections += [_shifted_section(sec, start) for sec in road.lane_sections]
        offsets += _shifted_offsets(road, start, offsets)
        speeds += _shifted_speeds(road, start, speeds)
        start += road.plan_view.end
    first, last = roads[0], roads[-1]
    merged = Road(
        id="+".join(road.id for road in roads), name=first.name, length=start,
        junction="-1", rule=first.rule, predecessor=first.predecessor,
        successor=last.successor, plan_view=PlanView(tuple(geometries)),
        lane_offsets=tuple(offsets), lane_sections=tuple(sections), speeds=tuple(speeds))
    return Chain(merged, tuple(spans))


def _shifted_section(section: LaneSection, start: float) -> LaneSection:
    return replace(section, s=section.s + start)


def _shifted_offsets(road: Road, start: float, before: list[Poly3]) -> list[Poly3]:
    """The road's lane offsets at merged stations, a zero record first where the road has
    none at its start and the one before's last record is not zero."""
    out = [replace(p, s=p.s + start) for p in road.lane_offsets]
    if before and replace(before[-1], s=0.0) != ZERO and (not out or out[0].s > start):
        out.insert(0, replace(ZERO, s=start))
    return out


def _shifted_speeds(road: Road, start: float,
                    before: list[SpeedRecord]) -> list[SpeedRecord]:
    """The road's type records at merged stations, a record of the default type without a
    limit first where the road has none at its start and the road before had some."""
    out = [replace(r, s=r.s + start) for r in road.speeds]
    if before and (not out or out[0].s > start):
        out.insert(0, SpeedRecord(start, None, DEFAULT_TYPE))
    return out

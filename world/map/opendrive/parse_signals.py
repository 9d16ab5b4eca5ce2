"""A road's `<signals>` into `RoadSignal`s (`signals.py`).

Read: `<signal>` with s, t, zOffset, orientation, country, type, subtype, value, unit,
height, width and `dynamic`; its `<validity>` (the lanes it applies to) and `<userData>` are
read past. Static speed-limit signs (type 274) need a `value` above 0 in a speed `unit`.
Refused as "not supported yet": a dynamic signal (a traffic light: its phases are not in the
road file), a static signal of any other type (its rule would be ignored), a
`signalReference` (a signal of another road: roads without junctions have none to share),
and any other child of a signal (`dependency`, `reference`, `positionInertial`, ...).
Bounded: `MAX_SIGNALS` signals in a file, counted before any is read.
"""

from __future__ import annotations

from typing import Literal

from world.map.opendrive.parse_lanes import SPEED_UNITS
from world.map.opendrive.parse_objects import optional_size
from world.map.opendrive.signals import SPEED_LIMIT_TYPE, RoadSignal
from world.map.opendrive.xmltree import Node

MAX_SIGNALS = 2_000  # <signal>s in one file (the real motorway files: 40)
SIGNAL_CHILDREN = ("validity", "userData", "dependency", "reference", "positionInertial",
                   "positionRoad")
READ_PAST = frozenset({"validity", "userData"})
ORIENTATIONS: dict[str, Literal["+", "-", "none"]] = {"+": "+", "-": "-", "none": "none"}


def count_signals(roads: list[Node]) -> None:
    """Refuse a file with more than `MAX_SIGNALS` signals before any is read."""
    count = 0
    for road in roads:
        for group in road.children:
            if group.tag == "signals":
                count += sum(1 for n in group.children if n.tag == "signal")
                if count > MAX_SIGNALS:
                    raise group.error(f"more than {MAX_SIGNALS} signals in the file")


def road_signals(nodes: list[Node]) -> tuple[RoadSignal, ...]:
    """The signals of a road's `<signals>` elements (at most one in a valid file)."""
    out: list[RoadSignal] = []
    for group in nodes:
        kids = group.only("signal", "signalReference", "userData")
        if kids["signalReference"]:
            raise kids["signalReference"][0].unsupported("signalReference")
        out += [_signal(n) for n in kids["signal"]]
    return tuple(out)


def _signal(node: Node) -> RoadSignal:
    kids = node.only(*SIGNAL_CHILDREN)
    for tag in SIGNAL_CHILDREN:
        if tag not in READ_PAST and kids[tag]:
            raise kids[tag][0].unsupported(f"signal {tag}")
    dynamic = node.get("dynamic")
    if dynamic not in ("yes", "no"):
        raise node.error(f"dynamic is not yes or no ({dynamic!r})")
    if dynamic == "yes":
        raise node.unsupported("dynamic signal (a traffic light) on a road")
    kind = node.get("type").strip()
    if kind != SPEED_LIMIT_TYPE:
        raise node.unsupported(f"static signal of type {kind!r}: only speed-limit signs "
                               f"(type {SPEED_LIMIT_TYPE})")
    orientation = ORIENTATIONS.get(node.get("orientation"))
    if orientation is None:
        raise node.error(f"orientation is not +, - or none ({node.get('orientation')!r})")
    return RoadSignal(
        id=node.get("id"), name=node.get("name", ""), s=node.num("s"), t=node.num("t"),
        z_offset=node.num("zOffset", 0.0), orientation=orientation,
        country=node.get("country", ""), type=kind, subtype=node.get("subtype", "-1"),
        value=_limit(node), height=optional_size(node, "height"),
        width=optional_size(node, "width"))


def _limit(node: Node) -> float:
    """[m/s] a speed-limit sign's value in its unit."""
    if "value" not in node.attrib:
        raise node.error("a speed-limit sign (type 274) without a value")
    unit = node.get("unit", "")
    if unit not in SPEED_UNITS:
        raise node.error(f"unit is not m/s, km/h or mph ({unit!r})")
    value = node.num("value")
    if not value > 0.0:
        raise node.error(f"value must be > 0, got {value:g}")
    return value * SPEED_UNITS[unit]

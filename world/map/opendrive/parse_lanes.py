"""Reading a road's <lanes>: lane offsets, lane sections, lanes, widths, road marks, speeds.

Lenient on lane annotations that do not change the geometry (material, access, height, rule,
visibility, userData), strict on anything geometric (a lane <border> is refused). A lane's
<link> is kept: the ids of its predecessor and successor lanes.
"""

from __future__ import annotations

from world.map.opendrive.model import LaneSection, OdrLane, Poly3, RoadMark
from world.map.opendrive.xmltree import Node

MAX_SIDE_LANES = 32  # lanes on one side of a lane section (every type: driving, shoulder,
#   border, sidewalk, ...): a bound on the work; real roads have under a dozen

MAX_LATERAL = 100.0  # [m] a lane's width and the lane offset where each record starts
SPEED_UNITS = {"m/s": 1.0, "km/h": 1 / 3.6, "mph": 0.44704}  # [m/s] per unit
NO_LIMIT = frozenset({"no limit", "undefined"})
DEFAULT_MARK_WIDTH = 0.12  # [m]
LANE_ANNOTATIONS = ("material", "access", "height", "rule", "visibility")


def poly3(node: Node, s_name: str) -> Poly3:
    """A width/offset/elevation-like record `<... s_name= a= b= c= d=>`."""
    node.only()
    return Poly3(node.num(s_name), node.num("a"), node.num("b"), node.num("c"), node.num("d"))


def width_record(node: Node) -> Poly3:
    """A lane's <width>: it starts at or after its section's start, at a width of 0 ..
    `MAX_LATERAL`."""
    rec = poly3(node, "sOffset")
    if rec.s < 0.0:
        raise node.error(f"sOffset is negative ({rec.s:g})")
    if not 0.0 <= rec.a <= MAX_LATERAL:
        raise node.error(f"width a = {rec.a:g} m is not within 0 .. {MAX_LATERAL:g} m")
    return rec


def offset_record(node: Node) -> Poly3:
    """A road's <laneOffset>: at most `MAX_LATERAL` off the reference line where it
    starts."""
    rec = poly3(node, "s")
    if abs(rec.a) > MAX_LATERAL:
        raise node.error(f"a = {rec.a:g} m is beyond {MAX_LATERAL:g} m")
    return rec


def ascending(records: list[Poly3], nodes: list[Node], what: str) -> tuple[Poly3, ...]:
    """`records` (read from `nodes`), refused unless their starts ascend strictly."""
    for prev, rec, node in zip(records, records[1:], nodes[1:], strict=False):
        if rec.s <= prev.s:
            raise node.error(f"{what} records do not ascend in s ({rec.s} after {prev.s})")
    return tuple(records)


def speed(node: Node) -> float | None:
    """[m/s] of a <speed max= unit=> (None for "no limit"/"undefined")."""
    node.only()
    raw = node.get("max")
    if raw.strip() in NO_LIMIT:
        return None
    unit = node.get("unit", "m/s")
    if unit not in SPEED_UNITS:
        raise node.error(f"unit is not m/s, km/h or mph ({unit!r})")
    value = node.num("max")
    if value < 0:
        raise node.error(f"max is negative ({raw!r})")
    return value * SPEED_UNITS[unit]


def _mark_type(node: Node, mark: RoadMark) -> None:
    """Accept a roadMark's <type> only if it says what the roadMark's attributes say."""
    if node.get("name") != mark.type:
        raise node.unsupported("roadMark type differing from its type attribute")
    if abs(node.num("width", mark.width) - mark.width) > 1e-9:
        raise node.unsupported("roadMark type width differing from its roadMark")
    for line in node.only("line")["line"]:
        line.only()
        if abs(line.num("width", mark.width) - mark.width) > 1e-9:
            raise line.unsupported("roadMark line width differing from its roadMark")
        if abs(line.num("tOffset", 0.0)) > 0:
            raise line.unsupported("roadMark line tOffset")
        if line.get("color", mark.color) != mark.color:
            raise line.unsupported("roadMark line color differing from its roadMark")


def road_mark(node: Node) -> RoadMark:
    """A lane's <roadMark>."""
    kids = node.only("type")
    mark = RoadMark(
        s_offset=node.num("sOffset"),
        type=node.get("type"),
        color=node.get("color", "standard"),
        width=node.num("width", DEFAULT_MARK_WIDTH),
        weight=node.get("weight", "standard"),
        lane_change=node.get("laneChange", "both"),
    )
    if mark.width < 0:
        raise node.error(f"width is negative ({mark.width})")
    for t in kids["type"]:
        _mark_type(t, mark)
    return mark


def _level(node: Node) -> bool:
    raw = node.get("level", "false")
    if raw not in ("true", "false", "1", "0"):
        raise node.error(f"level is not true or false ({raw!r})")
    return raw in ("true", "1")


def lane_links(node: Node | None) -> tuple[tuple[int, ...], tuple[int, ...]]:
    """A lane's <link>: the ids of its predecessor and successor lanes (in file order)."""
    if node is None:
        return (), ()
    kids = node.only("predecessor", "successor")
    ids: list[tuple[int, ...]] = []
    for tag in ("predecessor", "successor"):
        for n in kids[tag]:
            n.only()
        ids.append(tuple(n.integer("id") for n in kids[tag]))
    return ids[0], ids[1]


def lane(node: Node) -> OdrLane:
    """One <lane>."""
    kids = node.only("width", "border", "roadMark", "speed", "link", *LANE_ANNOTATIONS)
    if kids["border"]:
        raise kids["border"][0].unsupported()
    lane_id = node.integer("id")
    widths = ascending([width_record(w) for w in kids["width"]], kids["width"], "width")
    if lane_id == 0 and widths:
        raise kids["width"][0].error("the centre lane has a <width>")
    if lane_id != 0 and not widths:
        raise node.error("missing <width>")
    speeds = {speed(sp) for sp in kids["speed"]}
    if len(speeds) > 1:
        raise kids["speed"][1].unsupported("lane speed changing along the lane")
    marks = tuple(road_mark(m) for m in kids["roadMark"])
    for prev, mark, m in zip(marks, marks[1:], kids["roadMark"][1:], strict=False):
        if mark.s_offset < prev.s_offset:
            raise m.error("roadMark records do not ascend in sOffset")
    predecessors, successors = lane_links(node.at_most_one(kids["link"], "link"))
    return OdrLane(
        id=lane_id,
        type=node.get("type", "none"),
        level=_level(node),
        widths=widths,
        road_marks=marks,
        speed=speeds.pop() if speeds else None,
        predecessors=predecessors,
        successors=successors,
    )


def _side(node: Node | None, sign: int) -> tuple[OdrLane, ...]:
    if node is None:
        return ()
    nodes = node.only("lane")["lane"]
    if len(nodes) > MAX_SIDE_LANES:
        raise node.error(f"{len(nodes)} lanes on one side: at most {MAX_SIDE_LANES}")
    lanes = sorted((lane(n) for n in nodes), key=lambda ln: abs(ln.id))
    ids = [ln.id for ln in lanes]
    want = [sign * (i + 1) for i in range(len(lanes))]
    if ids != want:
        raise node.error(f"lane ids are {sorted(ids)}, not {sorted(want)}")
    return tuple(lanes)


def lane_section(node: Node) -> LaneSection:
    """One <laneSection> (singleSide is accepted and has no effect)."""
    kids = node.only("left", "center", "right")
    center_node = node.exactly_one(kids["center"], "center")
    centre_lanes = center_node.only("lane")["lane"]
    centre = lane(center_node.exactly_one(centre_lanes, "lane"))
    if centre.id != 0:
        raise centre_lanes[0].error(f"the centre lane's id is {centre.id}, not 0")
    return LaneSection(
        s=node.num("s"),
        left=_side(node.at_most_one(kids["left"], "left"), 1),
        center=centre,
        right=_side(node.at_most_one(kids["right"], "right"), -1),
    )


def lanes(node: Node, length: float) -> tuple[tuple[Poly3, ...], tuple[LaneSection, ...]]:
    """A road's <lanes>: its lane offsets and lane sections (each starting at or after 0
    and before the road's `length` [m])."""
    kids = node.only("laneOffset", "laneSection")
    offsets = ascending(
        [offset_record(n) for n in kids["laneOffset"]], kids["laneOffset"], "laneOffset"
    )
    if not kids["laneSection"]:
        raise node.error("missing <laneSection>")
    sections = [lane_section(n) for n in kids["laneSection"]]
    for sec, n in zip(sections, kids["laneSection"], strict=True):
        if not 0.0 <= sec.s < length:
            raise n.error(f"starts at s = {sec.s:g} m, outside its road (0 .. {length:g} m)")
    for prev, sec, n in zip(sections, sections[1:], kids["laneSection"][1:], strict=False):
        if sec.s <= prev.s:
            raise n.error(f"laneSection records do not ascend in s ({sec.s} after {prev.s})")
    return offsets, tuple(sections)

"""A road's `<objects>` into `RoadObject`s (`objects.py`).

Read: `<object>` with its size (length/width, radius, height), pose (s, t, zOffset, hdg),
`<repeat>` records, `<outline>`s (1.4: directly in the object; 1.5+: in `<outlines>`) of
`cornerLocal` or `cornerRoad` points; a `<validity>` record (the lanes an object applies
to) is read past: the object stands whatever lanes it names. Refused as "not supported yet":
`objectReference`, `tunnel`, `bridge`, and any other child of an object (`markings`,
`borders`, `parkingSpace`, `material`, `skeleton`, ...); an object's pitch or roll other
than 0. Bounded: `MAX_OBJECTS` objects in a file, `MAX_RECORDS` repeat records or outlines
of one object, `MAX_CORNERS` corners of an outline; sizes at least 0.
"""

from __future__ import annotations

from world.map.opendrive.objects import ObjectRepeat, Outline, OutlineCorner, RoadObject
from world.map.opendrive.xmltree import Node

MAX_OBJECTS = 20_000  # <object>s in one file (the real files: at most 1076)
MAX_RECORDS = 100  # repeat records or outlines of one object
MAX_CORNERS = 1_000  # corners of one outline
OBJECT_CHILDREN = ("repeat", "outline", "outlines", "validity", "markings", "borders",
                   "parkingSpace", "material", "skeleton", "surface")
BUILT_CHILDREN = frozenset({"repeat", "outline", "outlines", "validity"})


def count_objects(roads: list[Node]) -> None:
    """Refuse a file with more than `MAX_OBJECTS` objects before any is read."""
    count = 0
    for road in roads:
        for group in road.children:
            if group.tag == "objects":
                count += sum(1 for n in group.children if n.tag == "object")
                if count > MAX_OBJECTS:
                    raise group.error(f"more than {MAX_OBJECTS} objects in the file")


def road_objects(nodes: list[Node]) -> tuple[RoadObject, ...]:
    """The objects of a road's `<objects>` elements (at most one in a valid file)."""
    out: list[RoadObject] = []
    for group in nodes:
        kids = group.only("object", "objectReference", "tunnel", "bridge")
        for tag in ("objectReference", "tunnel", "bridge"):
            if kids[tag]:
                raise kids[tag][0].unsupported()
        out += [_object(n) for n in kids["object"]]
    return tuple(out)


def optional_size(node: Node, name: str) -> float | None:
    """The size attribute `name` [m] if given (at least 0)."""
    if name not in node.attrib:
        return None
    value = node.num(name)
    if value < 0.0:
        raise node.error(f"{name} must be >= 0, got {value:g}")
    return value


def _object(node: Node) -> RoadObject:
    kids = node.only(*OBJECT_CHILDREN)
    for tag in OBJECT_CHILDREN:
        if tag not in BUILT_CHILDREN and kids[tag]:
            raise kids[tag][0].unsupported(f"object {tag}")
    for angle in ("pitch", "roll"):
        if node.num(angle, 0.0) != 0.0:
            raise node.unsupported(f"object {angle}")
    outlines = list(kids["outline"])
    for group in kids["outlines"]:
        outlines += group.only("outline")["outline"]
    if len(kids["repeat"]) > MAX_RECORDS or len(outlines) > MAX_RECORDS:
        raise node.error(f"more than {MAX_RECORDS} repeat records or outlines")
    return RoadObject(
        id=node.get("id"), type=node.get("type", "none"), name=node.get("name", ""),
        s=node.num("s"), t=node.num("t"), z_offset=node.num("zOffset", 0.0),
        hdg=node.num("hdg", 0.0), height=optional_size(node, "height") or 0.0,
        length=optional_size(node, "length"), width=optional_size(node, "width"),
        radius=optional_size(node, "radius"),
        repeats=tuple(_repeat(n, node) for n in kids["repeat"]),
        outlines=tuple(_outline(n) for n in outlines),
    )


def _repeat(node: Node, obj: Node) -> ObjectRepeat:
    node.only()
    length, distance = optional_size(node, "length"), optional_size(node, "distance")
    if length is None or distance is None:
        raise node.error("missing attribute length or distance")
    height = optional_size(obj, "height") or 0.0
    z = obj.num("zOffset", 0.0)
    return ObjectRepeat(
        s=node.num("s"), length=length, distance=distance,
        t_start=node.num("tStart"), t_end=node.num("tEnd"),
        z_offset_start=node.num("zOffsetStart", z), z_offset_end=node.num("zOffsetEnd", z),
        height_start=_or(optional_size(node, "heightStart"), height),
        height_end=_or(optional_size(node, "heightEnd"), height),
        width_start=optional_size(node, "widthStart"), width_end=optional_size(node, "widthEnd"),
        length_start=optional_size(node, "lengthStart"),
        length_end=optional_size(node, "lengthEnd"),
        radius_start=optional_size(node, "radiusStart"),
        radius_end=optional_size(node, "radiusEnd"),
    )


def _or(value: float | None, default: float) -> float:
    return default if value is None else value


def _outline(node: Node) -> Outline:
    kids = node.only("cornerLocal", "cornerRoad")
    local, road = kids["cornerLocal"], kids["cornerRoad"]
    if local and road:
        raise node.error("mixes cornerLocal and cornerRoad")
    corners = local or road
    if len(corners) < 3:
        raise node.error(f"has {len(corners)} corners, fewer than 3")
    if len(corners) > MAX_CORNERS:
        raise corners[MAX_CORNERS].error(f"more than {MAX_CORNERS} corners")
    out: list[OutlineCorner] = []
    for c in corners:
        c.only()
        if local:
            out.append(OutlineCorner(c.num("u"), c.num("v"), c.num("z", 0.0),
                                     optional_size(c, "height") or 0.0))
        else:
            out.append(OutlineCorner(c.num("s"), c.num("t"), c.num("dz", 0.0),
                                     optional_size(c, "height") or 0.0))
    return Outline(road_frame=bool(road), corners=tuple(out))

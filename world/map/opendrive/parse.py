"""`load_opendrive`: an ASAM OpenDRIVE 1.4-1.8 file into the model (`model.py`).

Supported: header (its geoReference ignored, an all-zero <offset>), roads with their links,
types and speeds, planView records (line, arc, spiral, poly3, paramPoly3), lanes (see
`parse_lanes`), flat elevation and lateral profiles (every coefficient 0), empty objects,
signals and surface; userData anywhere is skipped. Everything else - junctions, objects,
signals, elevation, superelevation, any other element - is refused as "not supported yet
(...)" naming the element, as are bad numbers and files beyond the size limits. Checked on
the geometry: records ascend in s and add up to the road's length (within 1 cm), a
paramPoly3's arc length is within 1 % of its record's length, no number is beyond 1e9, no
arc or spiral record turns more than 1e4 rad.
"""

from __future__ import annotations

from pathlib import Path
from typing import Literal

from world.map.opendrive.errors import OpenDriveError
from world.map.opendrive.geometry import PlanView
from world.map.opendrive.model import (
    Arc,
    Geometry,
    Line,
    Link,
    OpenDrive,
    ParamPoly3,
    Poly3Shape,
    Road,
    Shape,
    SpeedRecord,
    Spiral,
)
from world.map.opendrive.parse_lanes import lanes, speed
from world.map.opendrive.shapes import PolyCurve, local_curve
from world.map.opendrive.xmltree import Node, parse_xml

MAX_FILE_BYTES = 50 * 1024 * 1024  # [byte]
MAX_ROADS = 100_000
MAX_GEOMETRIES = 100_000  # planView records in the whole file
REV_MINORS = range(4, 9)  # OpenDRIVE 1.4 .. 1.8
LENGTH_TOLERANCE = 1e-2  # [m] the road length vs its planView's, at least
PARAM_LENGTH_TOLERANCE = 1e-2  # [1] paramPoly3 arc length vs its record's (esmini scales)
MAX_TURN = 1e4  # [rad] the most an arc or spiral record may turn (a bound on the work)
FLAT_PROFILES = {
    "elevation": "elevation",
    "superelevation": "superelevation",
    "shape": "lateral shape",
}


def load_opendrive(path: Path) -> OpenDrive:
    """The OpenDRIVE file `path`; raises `OpenDriveError` (one-line message)."""
    path = Path(path)
    try:
        size = path.stat().st_size
        if size > MAX_FILE_BYTES:
            raise OpenDriveError(path, f"file is {size} bytes, over the {MAX_FILE_BYTES} limit")
        data = path.read_bytes()
    except FileNotFoundError:
        raise OpenDriveError(path, "file not found") from None
    except OSError as e:
        raise OpenDriveError(path, f"cannot read: {e.strerror}") from None
    root = parse_xml(str(path), data)
    if root.tag != "OpenDRIVE":
        raise root.error(f"the root element is <{root.tag}>, not <OpenDRIVE>")
    kids = root.only("header", "road")
    header = root.exactly_one(kids["header"], "header")
    major, minor, name = _header(header)
    if len(kids["road"]) > MAX_ROADS:
        raise kids["road"][MAX_ROADS].error(f"more than {MAX_ROADS} roads")
    roads: list[Road] = []
    seen: set[str] = set()
    count = 0
    for node in kids["road"]:
        road = _road(node)
        count += len(road.plan_view.geometries)
        if count > MAX_GEOMETRIES:
            raise node.error(f"more than {MAX_GEOMETRIES} geometry records in the file")
        if road.id in seen:
            raise node.error(f"duplicate road id {road.id!r}")
        seen.add(road.id)
        roads.append(road)
    return OpenDrive(path, major, minor, name, tuple(roads))


def _header(node: Node) -> tuple[int, int, str]:
    kids = node.only("geoReference", "offset")
    major, minor = node.integer("revMajor"), node.integer("revMinor")
    if major != 1 or minor not in REV_MINORS:
        raise node.unsupported(f"OpenDRIVE {major}.{minor}")
    for off in kids["offset"]:
        off.only()
        if any(off.num(a, 0.0) != 0.0 for a in ("x", "y", "z", "hdg")):
            raise off.unsupported("header offset other than 0")
    return major, minor, node.get("name", "")


def _link(node: Node | None) -> tuple[Link | None, Link | None]:
    if node is None:
        return None, None
    kids = node.only("predecessor", "successor")
    out: list[Link | None] = []
    for tag in ("predecessor", "successor"):
        n = node.at_most_one(kids[tag], tag)
        if n is not None:
            n.only()
            contact = n.attrib.get("contactPoint")
            if contact not in (None, "start", "end"):
                raise n.error(f"contactPoint is not start or end ({contact!r})")
            out.append(Link(n.get("elementType"), n.get("elementId"), contact))
        else:
            out.append(None)
    return out[0], out[1]


def _speeds(nodes: list[Node]) -> tuple[SpeedRecord, ...]:
    records: list[SpeedRecord] = []
    for n in nodes:
        sp = n.at_most_one(n.only("speed")["speed"], "speed")
        rec = SpeedRecord(n.num("s"), speed(sp) if sp is not None else None, n.get("type"))
        if records and rec.s < records[-1].s:
            raise n.error(f"type records do not ascend in s ({rec.s} after {records[-1].s})")
        records.append(rec)
    return tuple(records)


def _shape(node: Node) -> Shape:
    node.only()
    tag = node.tag
    if tag == "line":
        return Line()
    if tag == "arc":
        return Arc(node.num("curvature"))
    if tag == "spiral":
        return Spiral(node.num("curvStart"), node.num("curvEnd"))
    if tag == "poly3":
        return Poly3Shape(node.num("a"), node.num("b"), node.num("c"), node.num("d"))
    p_range = node.get("pRange", "normalized")
    if p_range not in ("arcLength", "normalized"):
        raise node.error(f"pRange is not arcLength or normalized ({p_range!r})")
    au, bu, cu, du, av, bv, cv, dv = (node.num(f"{c}{uv}") for uv in "UV" for c in "abcd")
    return ParamPoly3(
        au, bu, cu, du, av, bv, cv, dv, "arcLength" if p_range == "arcLength" else "normalized"
    )


def _geometry(node: Node) -> Geometry:
    kids = node.only("line", "arc", "spiral", "poly3", "paramPoly3")
    shapes = [n for group in kids.values() for n in group]
    if len(shapes) != 1:
        raise node.error(f"has {len(shapes)} shapes, not one (line, arc, spiral, ...)")
    length = node.num("length")
    if length < 0:
        raise node.error(f"length is negative ({length})")
    shape = _shape(shapes[0])
    curvature = 0.0
    if isinstance(shape, Arc):
        curvature = abs(shape.curvature)
    elif isinstance(shape, Spiral):
        curvature = max(abs(shape.curv_start), abs(shape.curv_end))
    if curvature * length > MAX_TURN:
        raise shapes[0].error(f"turns more than {MAX_TURN:g} rad")
    geom = Geometry(node.num("s"), node.num("x"), node.num("y"), node.num("hdg"), length, shape)
    curve = local_curve(geom)
    if isinstance(curve, PolyCurve) and abs(curve.scale - 1.0) > PARAM_LENGTH_TOLERANCE:
        raise shapes[0].error(
            f"its arc length {curve.cum[-1]:.6g} m is not the record's length {length:.6g} m"
        )
    return geom


def _plan_view(node: Node, road_length: float) -> PlanView:
    nodes = node.only("geometry")["geometry"]
    if not nodes:
        raise node.error("missing <geometry>")
    if len(nodes) > MAX_GEOMETRIES:
        raise nodes[MAX_GEOMETRIES].error(f"more than {MAX_GEOMETRIES} geometry records")
    geoms = [_geometry(n) for n in nodes]
    for prev, g, n in zip(geoms, geoms[1:], nodes[1:], strict=False):
        if g.s < prev.s:
            raise n.error(f"geometry records do not ascend in s ({g.s} after {prev.s})")
    pv = PlanView(tuple(geoms))
    if abs(pv.length - road_length) > max(LENGTH_TOLERANCE, 1e-6 * road_length):
        raise node.error(
            f"the geometry records' length {pv.length} is not the road's length {road_length}"
        )
    return pv


def _flat(node: Node | None, *tags: str) -> None:
    """Accept an elevation or lateral profile only if it is flat (every coefficient 0)."""
    if node is None:
        return
    kids = node.only(*tags)
    for tag in tags:
        for n in kids[tag]:
            n.only()
            if any(n.num(c) != 0.0 for c in "abcd"):
                raise n.unsupported(FLAT_PROFILES[tag])


def _rule(node: Node) -> Literal["RHT", "LHT"]:
    rule = node.get("rule", "RHT")
    if rule == "RHT":
        return "RHT"
    if rule == "LHT":
        return "LHT"
    raise node.error(f"rule is not RHT or LHT ({rule!r})")


def _road(node: Node) -> Road:
    kids = node.only(
        "link",
        "type",
        "planView",
        "elevationProfile",
        "lateralProfile",
        "lanes",
        "objects",
        "signals",
        "surface",
    )
    for tag in ("objects", "signals", "surface"):
        for n in kids[tag]:
            if any(c.tag != "userData" for c in n.children):
                raise n.unsupported(tag)
    _flat(node.at_most_one(kids["elevationProfile"], "elevationProfile"), "elevation")
    _flat(node.at_most_one(kids["lateralProfile"], "lateralProfile"), "superelevation", "shape")
    length = node.num("length")
    predecessor, successor = _link(node.at_most_one(kids["link"], "link"))
    offsets, sections = lanes(node.exactly_one(kids["lanes"], "lanes"))
    return Road(
        id=node.get("id"),
        name=node.get("name", ""),
        length=length,
        junction=node.get("junction", "-1"),
        rule=_rule(node),
        predecessor=predecessor,
        successor=successor,
        plan_view=_plan_view(node.exactly_one(kids["planView"], "planView"), length),
        lane_offsets=offsets,
        lane_sections=sections,
        speeds=_speeds(kids["type"]),
    )

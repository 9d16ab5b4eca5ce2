"""`load_opendrive`: an ASAM OpenDRIVE 1.4-1.8 file into the model (`model.py`).

Supported: header (its geoReference ignored, an all-zero <offset>), roads with their links,
types and speeds, planView records (line, arc, spiral, poly3, paramPoly3), lanes (see
`parse_lanes`), flat elevation and lateral profiles (every coefficient 0), objects (see
`parse_objects`), signals (see `parse_signals`: static speed-limit signs), empty surface;
userData anywhere is skipped. Everything else - junctions, elevation, superelevation, any
other element - is refused as "not supported yet (...)" naming the element (a non-flat
elevation record by its road and station), as are bad numbers and files beyond the size
limits. Checked on
the geometry, in this order and all before any curve is evaluated: the counts (roads,
planView records in the file), every number (finite, at most 64 characters, within 1e9),
each road's length (above 0, the file's roads together at most `MAX_ROUTE_LENGTH`), each
record's length (at least `MIN_RECORD_LENGTH`), curvature (at most `MAX_CURVATURE`, 1 / the
smallest radius) and turn (at most `MAX_TURN`), each record starting at the station where the
one before ends and the records adding up to the road's length (within 1 cm); then, on the
exact curves (each record's cost bounded: `shapes`), a polynomial record's sampled curvature
and a paramPoly3's arc length (within 1 % of its record's length), and the planView's
continuity (`continuity`: each record starts where the one before ends, within 1 cm and
1e-3 rad). Lane sections start inside their road.
"""

from __future__ import annotations

from pathlib import Path
from typing import Literal

from world.core.safe_read import UnreadableFileError, read_bounded
from world.map.opendrive.continuity import check_continuity, check_stations
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
from world.map.opendrive.parse_objects import count_objects, road_objects
from world.map.opendrive.parse_signals import count_signals, road_signals
from world.map.opendrive.shapes import PolyCurve
from world.map.opendrive.xmltree import Node, parse_xml

MAX_FILE_BYTES = 50 * 1024 * 1024  # [byte]
MAX_ROADS = 100_000
MAX_GEOMETRIES = 5_000  # planView records in the whole file (at most `arcspline.MAX_PIECES`)
REV_MINORS = range(4, 9)  # OpenDRIVE 1.4 .. 1.8
LENGTH_TOLERANCE = 1e-2  # [m] the road length vs its planView's, at least
PARAM_LENGTH_TOLERANCE = 1e-2  # [1] paramPoly3 arc length vs its record's (esmini scales)
MAX_TURN = 1e4  # [rad] the most an arc or spiral record may turn (a bound on the work)
MAX_ROUTE_LENGTH = 20_000.0  # [m] a road, and the file's roads together (one route)
MIN_RECORD_LENGTH = 1e-3  # [m] the shortest planView record (real files: 12.7 mm)
MIN_RADIUS = 1.0  # [m] the tightest bend of a reference line (real files: 5.7 m)
MAX_CURVATURE = 1.0 / MIN_RADIUS  # [1/m]
FLAT_PROFILES = {
    "elevation": "elevation",
    "superelevation": "superelevation",
    "shape": "lateral shape",
}


def load_opendrive(path: Path) -> OpenDrive:
    """The OpenDRIVE file `path`; raises `OpenDriveError` (one-line message)."""
    path = Path(path)
    try:
        data = read_bounded(path, MAX_FILE_BYTES)
    except UnreadableFileError as e:
        raise OpenDriveError(path, e.problem) from None
    root = parse_xml(str(path), data)
    if root.tag != "OpenDRIVE":
        raise root.error(f"the root element is <{root.tag}>, not <OpenDRIVE>")
    kids = root.only("header", "road")
    header = root.exactly_one(kids["header"], "header")
    major, minor, name = _header(header)
    _check_counts(kids["road"])
    roads: list[Road] = []
    seen: set[str] = set()
    total = 0.0  # [m]
    for node in kids["road"]:
        road = _road(node)
        total += road.length
        if total > MAX_ROUTE_LENGTH:
            raise node.error(f"the roads add up to more than {MAX_ROUTE_LENGTH:g} m")
        if road.id in seen:
            raise node.error(f"duplicate road id {road.id!r}")
        seen.add(road.id)
        roads.append(road)
    return OpenDrive(path, major, minor, name, tuple(roads))


def _check_counts(roads: list[Node]) -> None:
    """Refuse too many roads or planView records before any is read."""
    if len(roads) > MAX_ROADS:
        raise roads[MAX_ROADS].error(f"more than {MAX_ROADS} roads")
    count = 0
    for node in roads:
        for view in node.children:
            if view.tag == "planView":
                count += sum(1 for g in view.children if g.tag == "geometry")
        if count > MAX_GEOMETRIES:
            raise node.error(f"more than {MAX_GEOMETRIES} geometry records in the file")
    count_objects(roads)
    count_signals(roads)


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


def _curvature(shape: Shape) -> float:
    """[1/m] the largest |curvature| of a line, arc or spiral record (0 for the others)."""
    if isinstance(shape, Arc):
        return abs(shape.curvature)
    if isinstance(shape, Spiral):
        return max(abs(shape.curv_start), abs(shape.curv_end))
    return 0.0


def _geometry(node: Node) -> Geometry:
    """One planView record, its numbers, length, curvature and turn checked (cheap)."""
    kids = node.only("line", "arc", "spiral", "poly3", "paramPoly3")
    shapes = [n for group in kids.values() for n in group]
    if len(shapes) != 1:
        raise node.error(f"has {len(shapes)} shapes, not one (line, arc, spiral, ...)")
    length = node.num("length")
    if not MIN_RECORD_LENGTH <= length <= MAX_ROUTE_LENGTH:
        raise node.error(f"length must be >= {MIN_RECORD_LENGTH:g} and <= "
                         f"{MAX_ROUTE_LENGTH:g} m, got {length:g}")
    shape = _shape(shapes[0])
    curvature = _curvature(shape)
    if curvature > MAX_CURVATURE:
        raise shapes[0].error(f"curvature {curvature:g} 1/m is beyond {MAX_CURVATURE:g} 1/m "
                              f"(a radius under {MIN_RADIUS:g} m)")
    if curvature * length > MAX_TURN:
        raise shapes[0].error(f"turns more than {MAX_TURN:g} rad")
    return Geometry(node.num("s"), node.num("x"), node.num("y"), node.num("hdg"), length, shape)


def _check_polynomials(pv: PlanView, nodes: list[Node]) -> None:
    """Refuse a poly3 or paramPoly3 record that bends beyond `MAX_CURVATURE` (sampled) or a
    paramPoly3 whose arc length is not its record's."""
    for g, curve, node in zip(pv.geometries, pv.curves, nodes, strict=True):
        if not isinstance(curve, PolyCurve):
            continue
        shape = next(c for c in node.children if c.tag in ("poly3", "paramPoly3"))
        curvature = curve.max_curvature()
        if not curvature <= MAX_CURVATURE:
            raise shape.error(f"curvature {curvature:g} 1/m is beyond {MAX_CURVATURE:g} "
                              f"1/m (a radius under {MIN_RADIUS:g} m)")
        if abs(curve.scale - 1.0) > PARAM_LENGTH_TOLERANCE:
            raise shape.error(f"its arc length {curve.cum[-1]:.6g} m is not the record's "
                              f"length {g.length:.6g} m")


def _plan_view(node: Node, road_length: float) -> PlanView:
    """A road's planView: the cheap checks on every record first, then the exact curves'
    (module doc)."""
    nodes = node.only("geometry")["geometry"]
    if not nodes:
        raise node.error("missing <geometry>")
    if len(nodes) > MAX_GEOMETRIES:
        raise nodes[MAX_GEOMETRIES].error(f"more than {MAX_GEOMETRIES} geometry records")
    geoms = [_geometry(n) for n in nodes]
    check_stations(geoms, nodes)
    last = geoms[-1]
    length = last.s + last.length - geoms[0].s
    if abs(length - road_length) > max(LENGTH_TOLERANCE, 1e-6 * road_length):
        raise node.error(
            f"the geometry records' length {length} is not the road's length {road_length}"
        )
    pv = PlanView(tuple(geoms))
    _check_polynomials(pv, nodes)
    check_continuity(pv, nodes)
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
                raise n.unsupported(f"{FLAT_PROFILES[tag]} other than flat, from s = "
                                    f"{n.num('s', 0.0):g} m")


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
    for n in kids["surface"]:
        if any(c.tag != "userData" for c in n.children):
            raise n.unsupported("surface")
    _flat(node.at_most_one(kids["elevationProfile"], "elevationProfile"), "elevation")
    _flat(node.at_most_one(kids["lateralProfile"], "lateralProfile"), "superelevation", "shape")
    length = node.num("length")
    if not 0.0 < length <= MAX_ROUTE_LENGTH:
        raise node.error(f"length must be > 0 and <= {MAX_ROUTE_LENGTH:g} m, got {length:g}")
    plan_view = _plan_view(node.exactly_one(kids["planView"], "planView"), length)
    predecessor, successor = _link(node.at_most_one(kids["link"], "link"))
    offsets, sections = lanes(node.exactly_one(kids["lanes"], "lanes"), length)
    return Road(
        id=node.get("id"),
        name=node.get("name", ""),
        length=length,
        junction=node.get("junction", "-1"),
        rule=_rule(node),
        predecessor=predecessor,
        successor=successor,
        plan_view=plan_view,
        lane_offsets=offsets,
        lane_sections=sections,
        speeds=_speeds(kids["type"]),
        objects=road_objects(kids["objects"]),
        signals=road_signals(kids["signals"]),
    )

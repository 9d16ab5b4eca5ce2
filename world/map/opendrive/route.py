"""An OpenDRIVE road as the simulator's route road: the `RoadSpec` that `world.map.road`
lays into the HD map the stack reads, built from the same file as the world's meshes.

The road is the file's roads linked end to end as one (`world.map.opendrive.chain`; a file
of one road is that road); the route's stations are the merged road's, and `OdrRoute.chain`
says where each file road lies on it.

The route runs along the road's driving lanes right of its reference line (right-hand
traffic, increasing s). Route lane 0 is the outermost of them, and the route's reference line
is that lane's centre t0(s) (the lane offset and every width polynomial included):

- where every lane of the route is constant along the road (one `uniform` layout in every
  lane section, no lane offset): the OpenDRIVE reference line's arc spline (`arc_spline`,
  exact start points and headings, < `TOLERANCE` off the exact curve) offset sideways by
  the lane's constant offset `ref_t`. An arc offset sideways is an arc, so the route's
  pieces are exact offsets of the spline's, each section uniform (one lane width);
- else: the curve ref(s) + t0(s) n(s) as an arc spline of its own and every other lane
  boundary as a cubic per piece (`lane_fit`: split also where a lane section, a width
  record or a lane-offset record starts), each segment with its `LaneProfile` (uniform
  where its boundaries are constant and its lanes equally wide).

Across, from each lane section:

- `lanes`: the contiguous run of `driving` lanes right of the reference line;
- `shoulder`: the lane right of the outermost driving lane when its type is `shoulder` or
  `stop` (a hard shoulder), else none (width 0);
- `oncoming_lanes`: the driving lanes left of the reference line when they adjoin the ego's
  (no median between them); a carriageway beyond a median is not part of the route: it is
  `OdrRoute.scenery`, a road drawn in the world and not on the HD map (`far_side`: only
  where the route is built from offset arcs, the far lanes constant too; not drawn where
  the lanes vary, the fitted path above);
- the paint: each lane's road mark lies on its outer border (OpenDRIVE); a boundary between
  the route's lanes takes the mark of the lane nearer the reference line (`lane_paint`).

The speed limit: a lane's `<speed max>`, else the latest posting before the station: a
static speed-limit sign's for the route's direction (`sign_limits`: a sign wins over a type
record at the same station) or a road type record's limit (its `<speed>`, else its type's
default, `TYPE_LIMITS`: the German rules, the motorway's advisory 130 km/h). The route is
split where each posting stands, so the map posts it there (and a sign of the route's own
look stands at the roadside: `world.scene.scenery`).

What does not fit this yet is refused with `OpenDriveError` "not supported yet (...)":
lane sections whose route lanes differ (lanes that begin or end), widths or a lane offset
that jump (route lane 0's centre would step), a route lane whose width reaches 0, lane 0
changing so fast that its edges' middle along the route's normal is more than
`SKEW_SHARE * TOLERANCE` off its centre (`lane_fit`), left-hand traffic, road marks other
than solid / broken / none; and what the chain refuses (junctions, roads not linked end to
end into one line, reversed roads, loops, lane links that renumber lanes).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from world.frames import MPS_PER_KPH
from world.hdmap import CrossSection, LaneProfile, LinePaint, Zone
from world.map.opendrive.arcspline import ArcPiece, PieceBoundError, arc_spline, piece_points
from world.map.opendrive.chain import Chain, chain_roads
from world.map.opendrive.errors import OpenDriveError
from world.map.opendrive.far_side import far_side
from world.map.opendrive.lane_fit import FittedPiece, cubic_values, fit_lanes
from world.map.opendrive.lane_paint import carriageway_paint
from world.map.opendrive.lanes import (
    SHOULDER_TYPES,
    constant_width,
    lane_centre_t,
    lane_section_index,
    lane_width,
)
from world.map.opendrive.model import LaneSection, OdrLane, OpenDrive, Road
from world.map.opendrive.object_layout import layout_objects
from world.map.opendrive.offset_spline import CurvePiece
from world.map.opendrive.sign_limits import SignPost, latest_sign, sign_posts
from world.spec import RoadSpec, SceneryObjectSpec, SegmentSpec

TOLERANCE = 1e-3  # [m] the route's pieces keep this close to the file's exact reference line
TYPE_LIMITS = {  # [km/h] a road type's limit where the file posts none (German rules)
    "motorway": 130.0,  # the advisory speed (Richtgeschwindigkeit)
    "rural": 100.0,
    "town": 50.0,
    "lowSpeed": 30.0,
    "pedestrian": 7.0,
    "bicycle": 25.0,
    "unknown": 100.0,
}
ZONES = {"motorway": Zone.HIGHWAY, "rural": Zone.HIGHWAY}  # others: Zone.CITY
WIDTH_CHECKS = 9  # [-] stations per piece where the route's lanes must be wider than 0
UNIFORM_EPS = 1e-9  # [m] lanes this close in width make a uniform cross-section
SKEW_SHARE = 0.2  # [-] of TOLERANCE: how far lane 0's edges may be off symmetric about its
#   centre along the route's normal (`lane_fit` module doc)


@dataclass(frozen=True, slots=True)
class Layout:
    """A lane section's layout as the route sees it."""

    lane_ids: tuple[int, ...]  # OpenDRIVE ids of route lanes 0, 1, ... (outermost first)
    oncoming_ids: tuple[int, ...]  # ids of the adjoining oncoming lanes, nearest first
    lane_width: float  # [m] route lane 0's width at the section's start
    shoulder: float  # [m] at the section's start
    ref_t: float  # [m] route lane 0's centre offset from the OpenDRIVE reference line, at
    #   the section's start (along it too where the layout is `uniform`)
    paint: LinePaint
    speed: float | None  # [m/s] the lanes' own <speed max>, if every one posts the same
    shoulder_id: int | None  # the hard shoulder's lane id (None: no shoulder)
    uniform: bool  # every lane of the route constant along the section, the driving lanes
    #   (oncoming ones too) all `lane_width` wide: the route's offset arcs are exact


@dataclass(frozen=True, slots=True)
class OdrRoute:
    """An OpenDRIVE road as the route: the spec, and how the file's roads and lanes map
    onto it."""

    spec: RoadSpec
    chain: Chain  # the file's roads as one road, and where each lies on it
    layout: Layout
    scenery: tuple[RoadSpec, ...] = ()  # drawn, not on the map: the far carriageway of a
    #   dual carriageway (`far_side`), at most one
    objects: tuple[SceneryObjectSpec, ...] = ()  # the file's road objects as static solids
    #   (`object_layout`)

    @property
    def road(self) -> Road:
        """The merged road (the file's one road if it has only one)."""
        return self.chain.road

    def lane_index(self, lane_id: int) -> int | None:
        """The route lane index of OpenDRIVE lane `lane_id` (None: not a route lane)."""
        ids = self.layout.lane_ids
        return ids.index(lane_id) if lane_id in ids else None

    def point(self, s: float, t: float) -> tuple[float, float, float]:
        """([m] x, [m] y, [rad] heading) of the file's road coordinates (s, t): exact."""
        x, y, h = self.road.plan_view.pose(np.array([s]))
        heading = float(h[0])
        return (float(x[0]) - t * math.sin(heading), float(y[0]) + t * math.cos(heading),
                heading)


def _refuse(odr: OpenDrive, what: str) -> OpenDriveError:
    return OpenDriveError(odr.path, f"not supported yet ({what})")


def build_route(odr: OpenDrive) -> OdrRoute:
    """The route road of the file's roads linked end to end (module doc); raises
    `OpenDriveError`, also for a road that needs more arc-spline pieces than
    `arcspline.MAX_PIECES` (the bound on the work)."""
    try:
        return _build_route(odr)
    except PieceBoundError as e:
        raise OpenDriveError(odr.path, str(e)) from None


def _build_route(odr: OpenDrive) -> OdrRoute:
    chain = chain_roads(odr)
    road = chain.road
    if road.rule != "RHT":
        raise _refuse(odr, "left-hand traffic")
    layouts = [_layout(odr, road, section) for section in road.lane_sections]
    if len({(lay.lane_ids, lay.oncoming_ids) for lay in layouts}) != 1:
        raise _refuse(odr, "lane sections with different route lanes: lanes that begin or "
                           "end")
    layout = layouts[0]
    signs = sign_posts(odr, chain)
    offsets = any(p.a != 0.0 or p.b != 0.0 or p.c != 0.0 or p.d != 0.0
                  for p in road.lane_offsets)
    scenery: tuple[RoadSpec, ...] = ()
    if offsets or len(set(layouts)) != 1 or not layout.uniform:
        segments = _fitted_segments(odr, road, layouts, signs)
    else:
        pieces = _split(arc_spline(road.plan_view, TOLERANCE),
                        [s for s in _postings(road, signs) if 0.0 < s < road.plan_view.length])
        segments = _offset_segments(odr, road, layout, pieces, signs)
        far = None if layout.oncoming_ids else far_side(
            odr, road, pieces, [_limit(road, layout, p.s0, signs) for p in pieces])
        scenery = (far,) if far is not None else ()
    segments = posted_once(segments)
    first = segments[0]
    assert first.start is not None and first.speed_limit is not None
    return OdrRoute(RoadSpec(tuple(segments), first.speed_limit, origin=first.start), chain,
                    layout, scenery, layout_objects(odr))


def posted_once(segments: list[SegmentSpec]) -> list[SegmentSpec]:
    """`segments` with a limit posted only where it changes (None where the segment before
    has the same): a limit is posted, and its sign stands, where the file's speed records
    change it, not at every piece of the arc spline."""
    out: list[SegmentSpec] = []
    in_force: float | None = None  # [m/s]
    for seg in segments:
        if out and seg.speed_limit == in_force:
            out.append(replace(seg, speed_limit=None))
        else:
            out.append(seg)
            in_force = seg.speed_limit if seg.speed_limit is not None else in_force
    return out


def _postings(road: Road, signs: tuple[SignPost, ...]) -> list[float]:
    """[m] the stations where a type record or a speed-limit sign posts a limit."""
    return sorted({r.s for r in road.speeds} | {s for s, _ in signs})


def _offset_segments(odr: OpenDrive, road: Road, layout: Layout, pieces: list[ArcPiece],
                     signs: tuple[SignPost, ...]) -> list[SegmentSpec]:
    """The segments of a road whose every lane is constant (one `uniform` layout, no lane
    offset): the reference line's arc spline `pieces` (split at the speed records) offset
    by `ref_t`, exactly (module doc)."""
    segments = []
    for piece in pieces:
        scale = 1.0 - piece.curvature * layout.ref_t
        if not scale > 0.0:
            raise OpenDriveError(odr.path, f"the reference line's radius at s = "
                                 f"{piece.s0:g} m is inside the route's lanes")
        heading = piece.heading0
        start = (piece.x0 - layout.ref_t * math.sin(heading),
                 piece.y0 + layout.ref_t * math.cos(heading), heading)
        limit, zone = _limit(road, layout, piece.s0, signs)
        segments.append(SegmentSpec(
            length=piece.length * scale, curvature=piece.curvature / scale,
            lanes=len(layout.lane_ids), oncoming_lanes=len(layout.oncoming_ids),
            lane_width=layout.lane_width, shoulder=layout.shoulder, speed_limit=limit,
            zone=zone, start=start, paint=layout.paint))
    return segments


def _borders(layout: Layout) -> tuple[int, ...]:
    """The lane ids whose outer border is each of the route's boundaries, right to left
    (`lane_fit.fit_lanes`): the shoulder's (lane 0's without one), lane 0's, each route
    lane's inner border (the outer one of the lane inside it, 0: the lane offset), each
    oncoming lane's."""
    ids = layout.lane_ids
    right = layout.shoulder_id if layout.shoulder_id is not None else ids[0]
    return (right, ids[0], *(i + 1 for i in ids), *layout.oncoming_ids)


def _fitted_segments(odr: OpenDrive, road: Road, layouts: list[Layout],
                     signs: tuple[SignPost, ...]) -> list[SegmentSpec]:
    """The segments of a road whose lanes change along it (module doc): lane 0's centre
    as an arc spline, the other boundaries as cubics per piece (`lane_fit`)."""
    view = road.plan_view
    fits = fit_lanes(road, [_borders(lay) for lay in layouts],
                     [s for s in _postings(road, signs) if view.start < s < view.end],
                     TOLERANCE)
    segments = []
    for k, fit in enumerate(fits):
        piece = fit.piece
        if k > 0:
            _check_joint(odr, fits[k - 1].piece, piece)
        layout = layouts[lane_section_index(road, 0.5 * (piece.s0 + piece.s1))]
        section = _fitted_section(odr, layout, fit)
        limit, zone = _limit(road, layout, piece.s0, signs)
        segments.append(SegmentSpec(
            length=piece.length, curvature=piece.curvature, lanes=section.lanes,
            oncoming_lanes=section.oncoming_lanes, lane_width=section.lane_width,
            shoulder=section.shoulder, speed_limit=limit, zone=zone,
            start=(piece.x0, piece.y0, piece.heading0), paint=layout.paint,
            profile=section.profile))
    return segments


def _check_joint(odr: OpenDrive, before: CurvePiece, after: CurvePiece) -> None:
    """Refuse a step in lane 0's centre between two pieces (widths or an offset that
    jump at a record start)."""
    x, y = piece_points(before.arc(), np.array([before.length]))
    step = math.hypot(float(x[0]) - after.x0, float(y[0]) - after.y0)
    if step > 2.0 * TOLERANCE:
        raise _refuse(odr, f"route lane 0's centre steps by {step:.3g} m at s = "
                           f"{after.s0:g} m: lane widths or a lane offset that jump")


def _fitted_section(odr: OpenDrive, layout: Layout, fit: FittedPiece) -> CrossSection:
    """The cross-section of one fitted piece: uniform where every boundary is constant and
    the lanes equally wide (within `UNIFORM_EPS`), else with its lane profile; refused if
    a lane of the route narrows to nothing on it."""
    b = fit.boundaries
    if fit.skew > SKEW_SHARE * TOLERANCE:
        raise _refuse(odr, f"lane widths or a lane offset that change this fast: route lane "
                           f"0's edges' middle {fit.skew * 1e3:.2g} mm off its "
                           f"centre at s = {fit.piece.s0:g} m")
    lanes, oncoming = len(layout.lane_ids), len(layout.oncoming_ids)
    u = np.linspace(0.0, fit.piece.length, WIDTH_CHECKS)
    across = cubic_values(b, u)  # (n, len(u))
    if np.min(np.diff(across[1:], axis=0)) <= 0.0:
        raise _refuse(odr, f"a lane width that reaches 0 at s = {fit.piece.s0:g} .. "
                           f"{fit.piece.s1:g} m")
    width, shoulder = float(b[2, 0] - b[1, 0]), float(b[1, 0] - b[0, 0])
    even = fit.constant and bool(np.all(np.abs(np.diff(b[1:, 0]) - width) <= UNIFORM_EPS))
    profile = None if even else LaneProfile(tuple(
        (float(r[0]), float(r[1]), float(r[2]), float(r[3])) for r in b))
    return CrossSection(lanes, oncoming, width, shoulder, Zone.HIGHWAY, layout.paint, profile)


def _split(pieces: list[ArcPiece], stations: list[float]) -> list[ArcPiece]:
    """`pieces` split at `stations` [m] (exactly: a part of an arc is an arc)."""
    out: list[ArcPiece] = []
    for p in pieces:
        cuts = sorted(s for s in stations if p.s0 < s < p.s0 + p.length)
        for a, b in zip([p.s0, *cuts], [*cuts, p.s0 + p.length], strict=True):
            x, y = piece_points(p, np.array([a - p.s0]))
            out.append(ArcPiece(a, b - a, p.curvature, float(x[0]), float(y[0]),
                                p.heading0 + p.curvature * (a - p.s0)))
    return out


def _limit(road: Road, layout: Layout, s: float,
           signs: tuple[SignPost, ...]) -> tuple[float, Zone]:
    """([m/s] the limit in force at station s, the zone) (module doc)."""
    records = [r for r in road.speeds if r.s <= s + 1e-9]
    record = records[-1] if records else None
    road_type = record.road_type if record is not None else "unknown"
    zone = ZONES.get(road_type, Zone.CITY)
    sign = latest_sign(signs, s)
    if layout.speed is not None:
        return layout.speed, zone
    if sign is not None and (record is None or sign[0] >= record.s):
        return sign[1], zone
    if record is not None and record.max_speed is not None:
        return record.max_speed, zone
    return TYPE_LIMITS.get(road_type, TYPE_LIMITS["unknown"]) * MPS_PER_KPH, zone


def _start_width(section: LaneSection, lane: OdrLane) -> float:
    """[m] the lane's width at its section's start."""
    return float(lane_width(section, lane, section.s))


def _layout(odr: OpenDrive, road: Road, section: LaneSection) -> Layout:
    """The route's view of one lane section (module doc)."""
    right = section.right
    first = next((i for i, lane in enumerate(right) if lane.type == "driving"), None)
    if first is None:
        raise _refuse(odr, f"a lane section at s = {section.s:g} m without driving lanes "
                           "right of the reference line")
    end = first
    while end < len(right) and right[end].type == "driving":
        end += 1
    drive = right[first:end]  # nearest the reference line first
    outside = right[end] if end < len(right) else None
    hard = outside if outside is not None and outside.type in SHOULDER_TYPES else None
    oncoming: tuple[OdrLane, ...] = ()
    if first == 0:
        n = 0
        while n < len(section.left) and section.left[n].type == "driving":
            n += 1
        oncoming = section.left[:n]
    constant = [constant_width(lane) for lane in (*right[:end], *oncoming)]
    widths = {constant_width(lane) for lane in (*drive, *oncoming)}
    uniform = (None not in constant and len(widths) == 1
               and (hard is None or constant_width(hard) is not None))
    if uniform:  # the numbers as ever
        (w,) = widths
        assert w is not None
        if w <= 0.0:
            raise OpenDriveError(odr.path, f"the route's lanes at s = {section.s:g} m are "
                                 f"{w:g} m wide: a driving lane needs a width above 0")
        inner = sum(constant_width(lane) or 0.0 for lane in right[:first])
        ref_t = -(inner + (len(drive) - 0.5) * w)
        shoulder = constant_width(hard) or 0.0 if hard is not None else 0.0
    else:
        w = _start_width(section, drive[-1])
        ref_t = lane_centre_t(road, drive[-1].id, section.s)
        shoulder = _start_width(section, hard) if hard is not None else 0.0
    # a lane's mark lies on its outer border: lane 0's right edge is its own mark, the line
    # between route lanes i - 1 and i is lane i's (nearer the reference line), the left edge
    # the mark of the lane inside the route's innermost (the centre lane's for -1)
    inside = right[first - 1] if first > 0 else section.center
    paint = carriageway_paint(odr, drive, inside, oncoming)
    speeds = {lane.speed for lane in drive}
    speed = speeds.pop() if len(speeds) == 1 else None
    return Layout(tuple(lane.id for lane in reversed(drive)),
                  tuple(lane.id for lane in oncoming), w, shoulder, ref_t, paint, speed,
                  hard.id if hard is not None else None, uniform)

"""The static HD map: the route's reference line, its lanes, limits and features.

What the stack may know of the road, and nothing more: lane geometry, speed limits, stop
lines, crosswalks, speed bumps, junctions and where the traffic lights' heads stand; no
signal timing and no actor (those stay in the world: `world.spec`, `world.map.signals`).
A map kind builds it: a route road (`world.map.road`), a town route (`world.map.town`).
The planner, the road mesh builder, the actors and the criteria code against this API.

Geometry (map frame, `world.frames`; metres, radians): the route's reference line is the
centre line of lane 0 (the rightmost lane of the ego's direction), a chain of straight and
constant-curvature arc pieces laid end to end from an origin pose (a road's: its `origin`; a
town route's: its start junction's mouth). Every lane shares the route's station `s`
(metres along the reference line); a lane is the reference line shifted sideways by the
lane's `offset_at(s)`. Lateral `r` is metres from the lane's centre, left of the route
direction positive (for oncoming lanes too: their travel `direction` is -1 but s and r stay
in route coordinates).

Across, on a uniform segment with `lanes` ego lanes of width w and `oncoming_lanes`
oncoming lanes (offsets from the reference line, left +):

- ego lane i: centre at i * w;
- yellow centre line: (lanes - 0.5) * w;
- oncoming lane -j (j = 1 next to the centre line): centre at (lanes + j - 1) * w;
- paved edges: right -(w / 2 + shoulder), left (lanes + oncoming_lanes - 0.5) * w.

A segment whose lanes change along it (a map file's polynomial lane widths and lane offsets)
carries a `LaneProfile`: every lane boundary, from the right paved edge to the left one, as
a cubic in the segment's station u = s - s0, lane 0's edges -w0(u) / 2 and +w0(u) / 2. A
lane's centre is the middle of its two boundaries and its width their difference, both
cubics; lane 0's centre is the reference line (offset 0) on every segment. Every lane,
edge and boundary is a cubic per segment (`SegmentCubics`, evaluated by Horner): a uniform
segment's are constants (b = c = d = 0) made by the rules above, so its numbers are exactly
those rules' (`RoadMap.lane_boundaries` at any station, `paved_edges`, `centre_line_at`,
`lane_of`). `Lane.curvature_at` is exact for offsets varying along s.

Lane layout is per segment: where a segment has no profile a value changes in a step at
its start station. An arc turns at most 360 degrees. Beyond the route's ends the
reference line goes on straight (the extension of the first and last piece) with the
first / last segment's layout (a profile's held at its ends' values).
`heading_at` is continuous along the route (not wrapped to (-pi, pi]).

No PyBullet here: the planner reads this module.
"""

from __future__ import annotations

import bisect
import enum
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.intp]
SHOULDER = -1000  # the lane index of the paved right shoulder (`RoadMap.lane`)

HALF_PI = 0.5 * np.pi  # [rad]
TWO_PI = 2.0 * np.pi  # [rad]
NEAR_WINDOW = 30.0  # [m] a projection near a station looks this far either side of it
#   (`ReferenceLine.project`): more than a car moves between two looks, or its pose estimate
#   jumps by, and less than the shortest loop of a town route (a block's four sides)
MAX_HINTS_KEPT = 8  # hints whose choice `ReferenceLine.project` keeps for the last points
HINT_SLACK = 10.0  # [m] the pass near the hint is kept unless the nearest of all is this
#   much nearer (then the hint is stale: the car has moved on by more than the window); a car
#   cutting a junction's corner is a few metres off its own pass, and on the other pass


# ---------------------------------------------------------------------------------------
# What the map holds: zones, features, lights, junctions
# ---------------------------------------------------------------------------------------


class Zone(enum.Enum):
    """Scenery style of a segment; it changes what is built beside the road, not the rules."""

    HIGHWAY = "highway"
    RAMP = "ramp"
    CITY = "city"
    JUNCTION = "junction"  # inside a town junction: no markings, the route's turn path


class Side(enum.Enum):
    """A side of the road, seen in the route direction."""

    RIGHT = "right"
    LEFT = "left"


@dataclass(frozen=True, slots=True)
class SpeedLimitSign:
    s: float  # [m] station of the sign; the limit applies from here on
    limit: float  # [m/s]


@dataclass(frozen=True, slots=True)
class StopSign:
    s: float  # [m] station of the stop line; the sign stands on the right


@dataclass(frozen=True, slots=True)
class Crosswalk:
    s: float  # [m] station of the near edge of the zebra
    width: float  # [m] along the route


@dataclass(frozen=True, slots=True)
class SpeedBump:
    s: float  # [m] station of the bump's centre
    height: float  # [m]
    length: float  # [m] along the route
    pass_speed: float  # [m/s] the speed to take it at


class LightColour(enum.Enum):
    """The lit lamp of a traffic light."""

    GREEN = "green"
    YELLOW = "yellow"
    RED = "red"


@dataclass(frozen=True, slots=True)
class LightHead:
    """Where a traffic light's head stands: the centre of its housing (the yellow lamp) in
    the map frame, and the way its lamps face (towards the traffic it controls)."""

    x: float  # [m]
    y: float  # [m]
    z: float  # [m] above the ground
    facing: float  # [rad] yaw of the lamps' outward normal


@dataclass(frozen=True, slots=True)
class TrafficLight:
    """A traffic light for the traffic on the route at stop line `s`: where its head stands.
    Its signal plan is not on the map (the world keeps it: `world.spec.TrafficLightSpec`);
    the stack learns the colour from the camera."""

    s: float  # [m] station of the stop line
    head: LightHead  # where the camera looks for it


Feature = SpeedLimitSign | StopSign | Crosswalk | SpeedBump | TrafficLight


class Manoeuvre(enum.Enum):
    """What a route does at a town junction."""

    STRAIGHT = "straight"
    LEFT = "left"
    RIGHT = "right"
    U_TURN = "u_turn"


class Control(enum.Enum):
    """How a town junction is controlled (every approach alike)."""

    NONE = "none"  # a bend at the town's corner: nothing to give way to
    STOP_SIGNS = "stop_signs"  # all-way stop
    TRAFFIC_LIGHTS = "traffic_lights"


@dataclass(frozen=True, slots=True)
class Junction:
    """A town junction met along a route, in the route's stations (`world.map.town`).

    The approach street runs along `heading` into the junction whose centre is (x, y); the
    box is the square where the streets cross, `half_width` each side of the centre."""

    index: tuple[int, int]  # (ix, iy) in the town grid
    manoeuvre: Manoeuvre
    control: Control
    s_stop: float  # [m] station of the approach's stop line
    s_enter: float  # [m] where the route's path starts to turn / enters the box
    s_exit: float  # [m] where it has turned and left the box, in its new lane
    x: float  # [m] the junction's centre
    y: float  # [m]
    heading: float  # [rad] the approach's direction of travel
    half_width: float  # [m] half the street's width (kerb to kerb)


@dataclass(frozen=True, slots=True)
class Piece:
    """One straight or arc piece of the reference line."""

    s0: float  # [m] station at its start
    length: float  # [m]
    curvature: float  # [1/m] signed, left +, 0 for straight
    x0: float  # [m] map frame start point
    y0: float  # [m]
    heading0: float  # [rad] heading at its start


class MarkKind(enum.Enum):
    """How a lane line is painted (OpenDRIVE's roadMark types that a camera tells apart)."""

    SOLID = "solid"
    BROKEN = "broken"
    NONE = "none"  # no paint


class PaintColour(enum.Enum):
    """A lane line's paint."""

    WHITE = "white"
    YELLOW = "yellow"


@dataclass(frozen=True, slots=True)
class LineMark:
    """One painted lane line."""

    kind: MarkKind
    width: float  # [m] across
    colour: PaintColour = PaintColour.WHITE


@dataclass(frozen=True, slots=True)
class LinePaint:
    """The lines of a cross-section as a map file paints them (OpenDRIVE road marks); a
    section without one is painted by the road's own rules (`world.scene.road_mesh`)."""

    right_edge: LineMark  # lane 0's right edge (the shoulder boundary)
    lane_lines: tuple[LineMark, ...]  # between ego lanes, right to left (lanes - 1 of them)
    left_edge: LineMark  # the ego lanes' left edge (the centre line with oncoming lanes)
    oncoming: tuple[LineMark, ...] = ()  # each oncoming lane's outer edge, from the centre


Cubic = tuple[float, float, float, float]  # a [m], b [1], c [1/m], d [1/m^2]: the value
#   a + b u + c u^2 + d u^3 at u [m] past a segment's start


@dataclass(frozen=True, slots=True)
class LaneProfile:
    """Lane boundaries that change along a segment (a map file's polynomial lane widths and
    lane offsets): each boundary's offset from the reference line (left +) as a cubic in the
    segment's station u = s - s0 [m], from the right paved edge to the left paved edge:

    the shoulder's outer edge (lane 0's right edge again where there is no shoulder), lane
    0's right edge, each ego lane's left edge (the last one is the centre line), each
    oncoming lane's outer edge: `lanes + oncoming_lanes + 2` cubics. Lane 0's edges are
    -w0(u) / 2 and +w0(u) / 2 (the reference line is its centre)."""

    boundaries: tuple[Cubic, ...]  # [m, 1, 1/m, 1/m^2] right to left

    def at(self, u: ArrayLike) -> FloatArray:
        """[m] the boundaries' offsets at stations u past the segment's start, shape
        u.shape + (n,)."""
        return horner(np.asarray(self.boundaries, dtype=np.float64), _as_float(u)[..., None])


@dataclass(frozen=True, slots=True)
class CrossSection:
    """The road's layout across, on one segment: uniform (every lane `lane_width` wide), or
    as its `profile` says where the widths change along the segment."""

    lanes: int  # [-] ego-direction lanes
    oncoming_lanes: int  # [-] lanes against the route direction
    lane_width: float  # [m] every lane's width (with a profile: lane 0's at the start)
    shoulder: float  # [m] paved right shoulder's width, 0 for none (with a profile: at the
    #   start)
    zone: Zone
    paint: LinePaint | None = None  # the map file's lines; None: the road's own rules
    profile: LaneProfile | None = None  # the boundaries along the segment; None: uniform

    def __post_init__(self) -> None:
        n = self.lanes + self.oncoming_lanes + 2
        if self.profile is not None and len(self.profile.boundaries) != n:
            raise ValueError(f"a lane profile of {self.lanes} + {self.oncoming_lanes} lanes "
                             f"needs {n} boundaries, got {len(self.profile.boundaries)}")

    @property
    def right_edge(self) -> float:
        """[m] offset of the right paved edge (outer edge of the shoulder), negative (with a
        profile: at the segment's start, `RoadMap.paved_edges` at any station)."""
        if self.profile is not None:
            return self.profile.boundaries[0][0]
        return -(0.5 * self.lane_width + self.shoulder)

    @property
    def left_edge(self) -> float:
        """[m] offset of the left paved edge (left edge of the outermost lane; with a
        profile: at the segment's start)."""
        if self.profile is not None:
            return self.profile.boundaries[-1][0]
        return (self.lanes + self.oncoming_lanes - 0.5) * self.lane_width

    @property
    def centre_line(self) -> float:
        """[m] offset of the boundary between ego and oncoming lanes (the left road edge
        when there are no oncoming lanes; with a profile: at the segment's start,
        `RoadMap.centre_line_at` at any station)."""
        if self.profile is not None:
            return self.profile.boundaries[self.lanes + 1][0]
        return (self.lanes - 0.5) * self.lane_width

    @property
    def paved_width(self) -> float:
        """[m] width of the paved road, shoulder included (with a profile: at the start)."""
        return self.left_edge - self.right_edge

    def boundary_cubics(self) -> FloatArray:
        """[m, 1, 1/m, 1/m^2] (lanes + oncoming_lanes + 2, 4) the boundaries' cubics as
        `LaneProfile` orders them; a uniform section's are constants (b = c = d = 0): the
        right edge, then (k - 1/2) w for k = 0 .. lanes + oncoming_lanes."""
        if self.profile is not None:
            return np.asarray(self.profile.boundaries, dtype=np.float64)
        n = self.lanes + self.oncoming_lanes
        out = np.zeros((n + 2, 4))
        out[0, 0] = self.right_edge
        out[1:, 0] = [(k - 0.5) * self.lane_width for k in range(n + 1)]
        return out


@dataclass(frozen=True, slots=True)
class Exit:
    """Where the route leaves its road by an exit on the right: the route goes on
    into the exit segment (a ramp: its own lanes and limit), the road goes on straight from
    the fork as scenery, with its lanes and its traffic (`RoadMap.through_line`).

    The ramp's lane 0 starts as the continuation of the road's lane 0 (the rightmost): the
    lanes left of it end at the fork, and a car on the route must be in lane 0 by then."""

    s: float  # [m] station of the fork (the exit segment's start)
    section: CrossSection  # the through road's layout (the route's before the fork)
    x: float  # [m] the fork on the reference line (lane 0's centre)
    y: float  # [m]
    heading: float  # [rad] the through road's heading


@dataclass(frozen=True, slots=True)
class SpeedLimitPosting:
    s: float  # [m] station where the limit starts to apply
    limit: float  # [m/s]


@dataclass(frozen=True, slots=True)
class _Candidates:
    """Points (N, 2) projected onto every piece (P + 2): `ReferenceLine._candidates`."""

    key: tuple[tuple[int, ...], str, bytes]  # the points' shape, dtype and bytes
    cost: FloatArray  # [m^2] (N, P + 2) squared distance to each piece
    t_clip: FloatArray  # [m] (N, P + 2) station along each piece, clipped to it
    d: FloatArray  # [m] (N, P + 2) offset from each piece's line, left +
    rows: IntArray  # (N,) 0 .. N - 1
    best: IntArray  # (N,) the nearest piece of all (no hint)
    hinted: dict[tuple[float, float], IntArray]  # the piece kept per (hint, window) [m]


class ReferenceLine:
    """The chain of pieces as arrays, with a straight extension before s = 0 and after the
    end. Internal piece index 0 is the extension before the start, 1..P the route's pieces,
    P + 1 the extension after the end. All methods are vectorised over stations / points."""

    def __init__(self, pieces: tuple[Piece, ...]) -> None:
        first, last = pieces[0], pieces[-1]
        end_xy, end_heading = piece_end(last)
        length = last.s0 + last.length
        before = Piece(0.0, 0.0, 0.0, first.x0, first.y0, first.heading0)
        after = Piece(length, 0.0, 0.0, float(end_xy[0]), float(end_xy[1]), end_heading)
        ext = [before, *pieces, after]
        self.length = length  # [m]
        self.n_pieces = len(pieces)
        # station boundaries between the route's pieces, shape (P + 1,): 0 .. length
        self.bounds: FloatArray = np.array([p.s0 for p in pieces] + [length])
        self.inner_bounds = self.bounds[1:-1]  # [m] joints between the route's pieces
        self.s0: FloatArray = np.array([p.s0 for p in ext])
        self.len: FloatArray = np.array([p.length for p in ext])
        # range of t = s - s0 per piece; the extensions reach to infinity
        self.t_lo = np.zeros(len(ext))
        self.t_lo[0] = -np.inf
        self.t_hi = self.len.copy()
        self.t_hi[-1] = np.inf
        self.k: FloatArray = np.array([p.curvature for p in ext])
        self.x0: FloatArray = np.array([p.x0 for p in ext])
        self.y0: FloatArray = np.array([p.y0 for p in ext])
        self.h0: FloatArray = np.array([p.heading0 for p in ext])
        self.is_arc = self.k != 0.0
        safe_k = np.where(self.is_arc, self.k, 1.0)
        radius0 = np.where(self.is_arc, 1.0 / safe_k, 0.0)
        self.cx = self.x0 - radius0 * np.sin(self.h0)  # [m] arc centres (start for straights)
        self.cy = self.y0 + radius0 * np.cos(self.h0)
        self.half_len = 0.5 * self.len
        self.straight = np.where(self.is_arc, 0.0, 1.0)
        self.sign_k = np.sign(self.k)
        self.inv_k = np.where(self.is_arc, 1.0 / safe_k, 0.0)  # [m] signed radius, 0 straight
        self.cos_h0 = np.cos(self.h0)
        self.sin_h0 = np.sin(self.h0)
        # projection onto an arc: the heading at the point's angle, relative to the arc's
        # middle heading (so arcs up to a full turn wrap correctly), shifted by +pi
        h_mid = self.h0 + 0.5 * self.k * self.len
        self.angle_shift = self.sign_k * HALF_PI - h_mid + np.pi
        # the same per piece as plain floats, for the scalar `pose_one` and `curvature_one`
        self._scalar: list[tuple[float, ...]] = list(zip(*(a.tolist() for a in (
            self.s0, self.h0, self.k, self.straight, self.inv_k, self.cx, self.cy,
            self.cos_h0, self.sin_h0)), strict=True))
        self._bounds_list: list[float] = self.bounds.tolist()
        self._inner_list: list[float] = self.inner_bounds.tolist()
        self._last: _Candidates | None = None  # `_candidates` of the last points projected

    def piece_index(self, s: FloatArray) -> IntArray:
        """Internal piece index (0 .. P + 1) of stations s; a joint belongs to the later."""
        if np.ndim(s) == 0:  # one station: `bisect` finds the same index without numpy's overhead
            return np.intp(bisect.bisect_right(self._bounds_list, float(s)))  # type: ignore[return-value]
        return np.searchsorted(self.bounds, s, side="right")

    def segment_index(self, s: FloatArray) -> IntArray:
        """Route piece (= segment) index 0 .. P - 1 of stations s, clipped at the ends."""
        if np.ndim(s) == 0:
            return np.intp(bisect.bisect_right(self._inner_list, float(s)))  # type: ignore[return-value]
        return np.searchsorted(self.inner_bounds, s, side="right")

    def heading(self, s: FloatArray) -> FloatArray:
        """[rad] heading at stations s: h0 + k (s - s0) of the piece, not wrapped."""
        i = self.piece_index(s)
        return self.h0[i] + self.k[i] * (s - self.s0[i])

    def curvature(self, s: FloatArray) -> FloatArray:
        """[1/m] signed curvature at stations s (left +)."""
        return self.k[self.piece_index(s)]

    def pose(self, s: FloatArray, d: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """(x, y, heading) of stations s at offsets d from the line: `point` and `heading`
        in one pass (one piece lookup), for callers that need both every step."""
        i = self.piece_index(s)
        t = s - self.s0[i]
        h = self.h0[i] + self.k[i] * t
        along = t * self.straight[i]
        radial = self.inv_k[i] - d
        sin_h, cos_h = np.sin(h), np.cos(h)
        x = self.cx[i] + along * self.cos_h0[i] + radial * sin_h
        y = self.cy[i] + along * self.sin_h0[i] - radial * cos_h
        return x, y, h

    def curvature_one(self, s: float) -> float:
        """[1/m] `curvature` at one station, in plain floats."""
        k: float = self._scalar[bisect.bisect_right(self._bounds_list, s)][2]
        return k

    def pose_one(self, s: float, d: float) -> tuple[float, float, float]:
        """(x, y, heading) at one station s and offset d: `pose` for a single point in plain
        floats, where numpy's per-call overhead would dominate."""
        s0, h0, k, straight, inv_k, cx, cy, cos_h0, sin_h0 = self._scalar[
            bisect.bisect_right(self._bounds_list, s)]
        t = s - s0
        h = h0 + k * t
        along = t * straight
        radial = inv_k - d
        return (cx + along * cos_h0 + radial * math.sin(h),
                cy + along * sin_h0 - radial * math.cos(h), h)

    def point(self, s: FloatArray, d: FloatArray) -> FloatArray:
        """[m] map-frame points, shape s.shape + (2,), at stations s and offsets d (left +)
        from the reference line."""
        # arcs: at radius (1/k - d) from the centre; straights: p0 + u t + d n (their
        # "centre" is p0 and 1/k is 0, so the same radial term gives d n)
        i = self.piece_index(s)
        t = s - self.s0[i]
        h = self.h0[i] + self.k[i] * t
        along = t * self.straight[i]
        radial = self.inv_k[i] - d
        x = self.cx[i] + along * self.cos_h0[i] + radial * np.sin(h)
        y = self.cy[i] + along * self.sin_h0[i] - radial * np.cos(h)
        return np.stack([x, y], axis=-1)

    def project(self, xy: FloatArray, near: float | None = None,
                window: float = NEAR_WINDOW) -> tuple[FloatArray, FloatArray]:
        """(s, d) of points xy, shape (N, 2): station and offset from the reference line.

        Every piece projects each point in closed form (straights: dot / cross product;
        arcs: the angle around the centre, wrapped about the arc's middle); the station is
        clipped to the piece, and the piece nearest to the point wins. With `near` [m] (the
        station the points were at a moment ago, or are known to be near), only the pieces
        within `window` [m] of it take part: a route that comes back through a junction it
        crossed before passes the same point twice, and the nearest piece there may be the
        other pass (the car's station would jump by the loop's length). The pass near the
        hint is kept unless the nearest of all is more than `HINT_SLACK` nearer (a stale
        hint: the car has moved on by more than the window since); without a piece in the
        window (a hint off the route), every piece takes part.
        """
        c = self._candidates(xy)
        best = c.best if near is None else self._kept(c, near, window)
        s = self.s0[best] + c.t_clip[c.rows, best]
        return s, c.d[c.rows, best]

    def _candidates(self, xy: FloatArray) -> _Candidates:
        """Every piece's projection of points xy (N, 2) and the nearest piece, without a
        hint. The answer for the last points asked is kept: within a tick the planner, the
        truth and the criteria project the same point several times (with different hints,
        which only choose among these candidates), and this is the costly part."""
        key = (xy.shape, xy.dtype.str, xy.tobytes())
        if self._last is not None and self._last.key == key:
            return self._last
        px = xy[:, 0:1]  # (N, 1) against pieces (1, P + 2)
        py = xy[:, 1:2]
        dx = px - self.x0
        dy = py - self.y0
        t_line = dx * self.cos_h0 + dy * self.sin_h0
        d_line = dy * self.cos_h0 - dx * self.sin_h0
        vx = px - self.cx
        vy = py - self.cy
        dh = np.mod(np.arctan2(vy, vx) + self.angle_shift, TWO_PI) - np.pi
        t_arc = self.half_len + dh * self.inv_k
        d_arc = self.inv_k - self.sign_k * np.hypot(vx, vy)
        t = np.where(self.is_arc, t_arc, t_line)
        d = np.where(self.is_arc, d_arc, d_line)
        t_clip = np.clip(t, self.t_lo, self.t_hi)
        # beyond a piece's end: the distance along at the point's own radius
        excess = (t - t_clip) * np.abs(1.0 - self.k * d)
        cost = excess * excess + d * d
        rows = np.arange(xy.shape[0])
        self._last = _Candidates(key, cost, t_clip, d, rows,
                                 self._nearest_piece(cost, t_clip, rows), {})
        return self._last

    def _kept(self, c: _Candidates, near: float, window: float) -> IntArray:
        """`_hinted`, once per hint for the same points."""
        best = c.hinted.get((near, window))
        if best is None:
            if len(c.hinted) >= MAX_HINTS_KEPT:
                c.hinted.clear()
            best = c.hinted[(near, window)] = self._hinted(c, near, window)
        return best

    def _hinted(self, c: _Candidates, near: float, window: float) -> IntArray:
        """Per point, the piece `project` keeps with the hint `near` [m] (its docstring)."""
        nearby = (self.s0 + self.t_lo <= near + window) & (self.s0 + self.t_hi >= near - window)
        if not nearby[1:-1].any():
            return c.best
        hinted = self._nearest_piece(np.where(nearby, c.cost, np.inf), c.t_clip, c.rows)
        # the pass near the hint, unless it is much farther than the nearest of all (a
        # stale hint: the car has moved on since, by more than the window)
        off = c.cost[c.rows, hinted] - c.cost[c.rows, c.best] > HINT_SLACK**2
        out: IntArray = np.where(off, c.best, hinted)
        return out

    def _nearest_piece(self, cost: FloatArray, t_clip: FloatArray,
                       rows: IntArray) -> IntArray:
        """Per point, the piece of least `cost` (N, P + 2), where a point lies beyond the
        route's start (end) only if its nearest point on the route is the start (end): on a
        route that comes back near itself (a loop nearly closed) the straight extensions
        must not claim points beside the route."""
        cost = cost.copy()
        inner = np.argmin(cost[:, 1:-1], axis=1) + 1
        s_inner = self.s0[inner] + t_clip[rows, inner]
        cost[:, 0] = np.where(s_inner <= 0.0, cost[:, 0], np.inf)
        cost[:, -1] = np.where(s_inner >= self.length, cost[:, -1], np.inf)
        out: IntArray = np.argmin(cost, axis=1)
        return out


def piece_end(piece: Piece) -> tuple[FloatArray, float]:
    """([m] end point (2,), [rad] end heading) of a piece, in closed form: with theta = k L,
    along = L sin(theta) / theta and side = L (1 - cos(theta)) / theta in the start frame,
    written with sinc so that a straight (theta = 0) takes no branch."""
    k, t, h0 = piece.curvature, piece.length, piece.heading0
    theta = k * t
    along = t * float(np.sinc(theta / np.pi))
    side = 0.5 * theta * t * float(np.sinc(theta / (2.0 * np.pi))) ** 2
    x = piece.x0 + np.cos(h0) * along - np.sin(h0) * side
    y = piece.y0 + np.sin(h0) * along + np.cos(h0) * side
    return np.array([x, y]), float(h0 + theta)


def _as_float(a: ArrayLike) -> FloatArray:
    return np.asarray(a, dtype=np.float64)


def horner(coef: FloatArray, u: FloatArray) -> FloatArray:
    """a + u (b + u (c + u d)) of cubics `coef` (..., 4) at u (broadcast): exactly a where
    b = c = d = 0."""
    a, b, c, d = coef[..., 0], coef[..., 1], coef[..., 2], coef[..., 3]
    out: FloatArray = a + u * (b + u * (c + u * d))
    return out


class SegmentCubics:
    """A value per segment as a cubic in the segment's station u = s - s0, held constant
    beyond the segment's ends (so before the route's start and after its end too)."""

    def __init__(self, line: ReferenceLine, coef: FloatArray) -> None:
        """`coef`: [m, 1, 1/m, 1/m^2] shape (P, 4), one cubic per segment."""
        self._line = line
        self.coef = coef
        self.constant = not bool(np.any(coef[:, 1:]))  # every segment's b = c = d = 0
        self.varying: NDArray[np.bool_] = np.any(coef[:, 1:] != 0.0, axis=1)  # per segment

    def station(self, s: FloatArray) -> tuple[IntArray, FloatArray]:
        """(segment index, [m] u clipped to the segment) of stations s."""
        seg = self._line.segment_index(s)
        bounds = self._line.bounds
        return seg, np.clip(s - bounds[seg], 0.0, bounds[seg + 1] - bounds[seg])

    def at(self, s: FloatArray) -> FloatArray:
        """The value at stations s (a constant segment's a exactly)."""
        if self.constant:
            out: FloatArray = self.coef[self._line.segment_index(s), 0]
            return out
        seg, u = self.station(s)
        return horner(self.coef[seg], u)

    def slopes(self, s: FloatArray) -> tuple[FloatArray, FloatArray]:
        """(first, second) derivatives along s at stations s ([1], [1/m])."""
        seg, u = self.station(s)
        _, b, c, d = (self.coef[seg, k] for k in range(4))
        return b + u * (2.0 * c + 3.0 * d * u), 2.0 * c + 6.0 * d * u


class Lane:
    """One lane: the reference line shifted by the lane's offset. Vectorised over arrays."""

    index: int  # ego-direction lanes 0.. (0 rightmost); oncoming lanes -1, -2, ... (-1 next
    #             to the centre line)
    direction: int  # +1 travels with increasing s, -1 against

    def __init__(
        self,
        index: int,
        line: ReferenceLine,
        offsets: FloatArray,
        widths: FloatArray,
        exists: NDArray[np.bool_],
    ) -> None:
        """`offsets`, `widths`: per segment cubics in u = s - s0, shape (P, 4) ([m, 1, 1/m,
        1/m^2]; constants have b = c = d = 0); `exists`: per segment, shape (P,)."""
        self.index = index
        self.direction = 1 if index >= 0 or index == SHOULDER else -1
        self._line = line
        self._offsets = SegmentCubics(line, offsets)
        self._exists = exists
        self._widths = SegmentCubics(line, widths)

    def __repr__(self) -> str:
        return f"Lane(index={self.index}, direction={self.direction})"

    def offset_at(self, s: ArrayLike) -> FloatArray:
        """[m] lateral offset of this lane's centre from the reference line at stations s."""
        return self._offsets.at(_as_float(s))

    def exists_at(self, s: ArrayLike) -> NDArray[np.bool_]:
        """Whether the lane exists at stations s (a segment may drop lanes)."""
        return self._exists[self._line.segment_index(_as_float(s))]

    def position(self, s: ArrayLike, r: ArrayLike) -> FloatArray:
        """[m] map-frame point(s) at station s, lateral r from this lane's centre.

        Scalars give shape (2,); arrays (broadcast together) give shape (N, 2).
        """
        s_arr, r_arr = np.broadcast_arrays(_as_float(s), _as_float(r))
        return self._line.point(s_arr, self.offset_at(s_arr) + r_arr)

    def local_coordinates(self, xy: ArrayLike,
                          near: float | None = None) -> tuple[FloatArray, FloatArray]:
        """(s, r) of map-frame point(s) xy, shape (2,) or (N, 2): station and offset from
        this lane's centre (left +). Exact for arcs (closed-form projection per piece, the
        nearest piece wins; with `near` [m], the nearest within `NEAR_WINDOW` of that
        station, `ReferenceLine.project`). Points beyond the route's ends project onto its
        extension."""
        pts = _as_float(xy)
        s, d = self._line.project(pts.reshape(-1, 2), near)
        r = d - self.offset_at(s)
        shape = pts.shape[:-1]
        return s.reshape(shape), r.reshape(shape)

    def heading_at(self, s: ArrayLike) -> FloatArray:
        """[rad] the route tangent at s (not flipped for oncoming lanes). Continuous along
        the route, not wrapped to (-pi, pi]: wrap differences before comparing."""
        return self._line.heading(_as_float(s))

    def width_at(self, s: ArrayLike) -> FloatArray:
        """[m] lane width at s."""
        return self._widths.at(_as_float(s))

    def curvature_at(self, s: ArrayLike) -> FloatArray:
        """[1/m] signed curvature of this lane's centre line at s, exact: with the offset o
        and a = 1 - k o, (k a^2 + a o'' + 2 k o'^2) / (a^2 + o'^2)^(3/2) (o' = do/ds); on a
        segment of constant offset that is k / a, computed so."""
        s_arr = _as_float(s)
        k = self._line.curvature(s_arr)
        a = 1.0 - k * self.offset_at(s_arr)
        uniform = k / a
        if self._offsets.constant:
            return uniform
        slope, bend = self._offsets.slopes(s_arr)
        exact = (k * a * a + a * bend + 2.0 * k * slope * slope) / (a * a + slope * slope) ** 1.5
        varying = self._offsets.varying[self._line.segment_index(s_arr)]
        out: FloatArray = np.where(varying, exact, uniform)
        return out


class RoadMap:
    """The HD map of one route: a road's or a town route's."""

    pieces: tuple[Piece, ...]
    length: float  # [m] route length (end station)
    lanes: tuple[Lane, ...]  # ego-direction lanes by index, as many as the widest segment
    shoulder: Lane  # the paved right shoulder, as a lane (`SHOULDER`)
    oncoming: tuple[Lane, ...]  # oncoming lanes, [0] next to the centre line
    features: tuple[Feature, ...]  # sorted by station
    traffic_lights: tuple[TrafficLight, ...]  # the features that are lights, by station; a
    #   light's index here is its id (`perception.lights`, `planner.junctions`)
    speed_limits: tuple[SpeedLimitPosting, ...]  # sorted by station, first at s = 0
    sections: tuple[CrossSection, ...]  # per segment (= piece)
    exits: tuple[Exit, ...]  # sorted by station
    junctions: tuple[Junction, ...]  # a town route's junctions, sorted by station

    def __init__(
        self,
        pieces: tuple[Piece, ...],
        sections: tuple[CrossSection, ...],
        features: tuple[Feature, ...],
        speed_limits: tuple[SpeedLimitPosting, ...],
        exit_pieces: tuple[int, ...] = (),
        junctions: tuple[Junction, ...] = (),
    ) -> None:
        """A map kind's builder makes it (`world.map.road.build_road_map`) from the laid
        pieces, one section per piece, and `exit_pieces`: the indices of the pieces that
        begin with an exit on the right (the route leaves its road at their start)."""
        self.pieces = pieces
        self.junctions = tuple(sorted(junctions, key=lambda j: j.s_stop))
        self.sections = sections
        self.features = features
        self.traffic_lights = tuple(f for f in features if isinstance(f, TrafficLight))
        self.speed_limits = speed_limits
        self.line = ReferenceLine(pieces)
        self.exits = tuple(
            Exit(pieces[i].s0, sections[i - 1], pieces[i].x0, pieces[i].y0, pieces[i].heading0)
            for i in exit_pieces)
        # the road the traffic keeps: the route up to the first fork, then straight on
        self.through_line = ReferenceLine(pieces[:exit_pieces[0]]) if exit_pieces else self.line
        self.length = self.line.length
        w = np.array([c.lane_width for c in sections])
        n_ego = np.array([c.lanes for c in sections])
        n_onc = np.array([c.oncoming_lanes for c in sections])
        shoulder = np.array([c.shoulder for c in sections])
        self._bounds = [c.boundary_cubics() for c in sections]  # [m, ...] per segment (n, 4)
        self.section_profiled: NDArray[np.bool_] = np.array(
            [c.profile is not None for c in sections])  # per segment: widths change along it
        self._right = SegmentCubics(self.line, np.array([b[0] for b in self._bounds]))
        self._left = SegmentCubics(self.line, np.array([b[-1] for b in self._bounds]))
        self._centre = SegmentCubics(
            self.line, np.array([b[c.lanes + 1] for b, c in zip(self._bounds, sections,
                                                                  strict=True)]))
        self.lanes = tuple(Lane(i, self.line, *self._lane_cubics(i, w, n_ego), n_ego > i)
                           for i in range(int(n_ego.max())))
        self.oncoming = tuple(
            Lane(-j, self.line, *self._lane_cubics(-j, w, n_ego), n_onc >= j)
            for j in range(1, int(n_onc.max()) + 1)
        )
        has_shoulder = shoulder > 0.0
        for k, b in enumerate(self._bounds):  # a varying shoulder: wide at either end
            if self.section_profiled[k]:
                ends = horner(b[1] - b[0], np.array([0.0, pieces[k].length]))
                has_shoulder[k] = bool(np.any(ends > 0.0))
        self.shoulder = Lane(SHOULDER, self.line, *self._lane_cubics(SHOULDER, w, n_ego),
                             has_shoulder)
        self.section_lanes: IntArray = n_ego  # [-] per segment: `CrossSection.lanes`
        self.section_widths: FloatArray = w  # [m] per segment: `CrossSection.lane_width`
        self.section_shoulders: FloatArray = shoulder  # [m] per segment: the shoulder's width
        self._limit_s: FloatArray = np.array([p.s for p in speed_limits])
        self._limit_v: FloatArray = np.array([p.limit for p in speed_limits])

    def _lane_cubics(self, index: int, w: FloatArray,
                     n_ego: IntArray) -> tuple[FloatArray, FloatArray]:
        """(offset cubics (P, 4), width cubics (P, 4)) of lane `index` per segment; a
        uniform segment's constants as ever: ego lane i at i w, oncoming lane -j at
        (lanes + j - 1) w, the shoulder at -(w + shoulder) / 2; a profiled one's from its
        boundaries (lane 0 at 0; a lane the segment lacks goes on at lane 0's width)."""
        offsets = np.zeros((len(w), 4))
        widths = np.zeros((len(w), 4))
        for k, b in enumerate(self._bounds):
            c = self.sections[k]
            if index == SHOULDER:
                i = -1  # the band between boundaries 0 and 1
                offsets[k, 0], widths[k, 0] = -0.5 * (w[k] + c.shoulder), c.shoulder
            else:
                i = index if index >= 0 else int(n_ego[k]) - index - 1
                offsets[k, 0], widths[k, 0] = i * w[k], w[k]
            if c.profile is None:
                continue
            if i + 2 < len(b):
                lo, hi = b[i + 1], b[i + 2]
            else:  # beyond the segment's lanes: lane 0's width on from the left edge
                lo = b[-1] + (i + 1 - (len(b) - 1)) * (b[2] - b[1])
                hi = lo + (b[2] - b[1])
            offsets[k] = 0.0 if i == 0 else 0.5 * (lo + hi)
            widths[k] = hi - lo
        return offsets, widths

    def through_road(self, exit_: Exit, length: float) -> RoadMap:
        """The road `exit_` leaves, from its fork straight on for `length` [m] (scenery),
        as a map of its own."""
        piece = Piece(0.0, length, 0.0, exit_.x, exit_.y, exit_.heading)
        limit = float(self.speed_limit_at(exit_.s - 1e-6))
        return RoadMap((piece,), (exit_.section,), (), (SpeedLimitPosting(0.0, limit),))

    def lane(self, index: int) -> Lane:
        """Ego-direction lane `index` >= 0, or oncoming lane for index < 0 (-1 is nearest),
        or the paved right shoulder for `SHOULDER` (a lane the car only pulls over into)."""
        if index == SHOULDER:
            return self.shoulder
        if 0 <= index < len(self.lanes):
            return self.lanes[index]
        if -len(self.oncoming) <= index < 0:
            return self.oncoming[-index - 1]
        raise IndexError(f"no lane {index} on this road")

    def cross_section_at(self, s: float) -> CrossSection:
        return self.sections[int(self.line.segment_index(_as_float(s)))]

    def lane_boundaries(self, s: float) -> FloatArray:
        """[m] offsets from the reference line (left +) of every lane boundary at station s,
        right to left: the right paved edge (the shoulder's outer edge), lane 0's right
        edge, each ego lane's left edge (the last is the centre line), each oncoming lane's
        outer edge (the last is the left paved edge); `CrossSection.boundary_cubics`."""
        return self.segment_boundaries(int(self.line.segment_index(_as_float(s))),
                                       _as_float(s))

    def segment_boundaries(self, index: int, s: ArrayLike) -> FloatArray:
        """[m] `lane_boundaries` of segment `index` at stations s (held at the segment's
        ends beyond them), shape s.shape + (lanes + oncoming_lanes + 2,)."""
        s_arr = _as_float(s)
        b = self._bounds[index]
        if not self.section_profiled[index]:
            return np.broadcast_to(b[:, 0], (*s_arr.shape, len(b))).copy()
        lo, hi = self.line.bounds[index], self.line.bounds[index + 1]
        return horner(b, (np.clip(s_arr, lo, hi) - lo)[..., None])

    def centre_line_at(self, s: ArrayLike) -> FloatArray:
        """[m] offset of the centre line (the ego lanes' left edge) at stations s."""
        return self._centre.at(_as_float(s))

    def lanes_at(self, s: float) -> int:
        """Number of ego-direction lanes at station s."""
        return self.cross_section_at(s).lanes

    def curvature_at(self, s: ArrayLike) -> FloatArray:
        """[1/m] signed curvature of the reference line at s."""
        return self.line.curvature(_as_float(s))

    def heading_at(self, s: ArrayLike) -> FloatArray:
        """[rad] the route tangent at s, continuous (not wrapped)."""
        return self.line.heading(_as_float(s))

    def position(self, s: ArrayLike, d: ArrayLike) -> FloatArray:
        """[m] map-frame point(s) at station s, offset d from the reference line (left +);
        shapes as `Lane.position`."""
        s_arr, d_arr = np.broadcast_arrays(_as_float(s), _as_float(d))
        return self.line.point(s_arr, d_arr)

    def local_coordinates(self, xy: ArrayLike,
                          near: float | None = None) -> tuple[FloatArray, FloatArray]:
        """(s, d) of point(s) xy, shape (2,) or (N, 2): station and offset from the
        reference line (lane 0's centre), left +; with `near` [m], the nearest pass of the
        route within `NEAR_WINDOW` of that station (`ReferenceLine.project`)."""
        pts = _as_float(xy)
        s, d = self.line.project(pts.reshape(-1, 2), near)
        shape = pts.shape[:-1]
        return s.reshape(shape), d.reshape(shape)

    def paved_edges(self, s: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """([m] right, [m] left) offsets of the paved edges from the reference line at s:
        right is the shoulder's outer edge -(w / 2 + shoulder), left the outermost lane's
        left edge (oncoming lanes included)."""
        s_arr = _as_float(s)
        return self._right.at(s_arr), self._left.at(s_arr)

    def speed_limit_at(self, s: ArrayLike) -> FloatArray:
        """[m/s] the posted limit in force at station s (the last posting at or before s)."""
        i = np.searchsorted(self._limit_s, _as_float(s), side="right") - 1
        return self._limit_v[np.maximum(i, 0)]

    def lane_at(self, xy: ArrayLike) -> tuple[int | None, float, float]:
        """(lane index or None if off every lane, s, r from that lane's centre) of a point.

        Lanes are half-open bands [right boundary, left boundary) across; a point before
        the route's start or after its end is off every lane. With None, r is the offset
        from the reference line (lane 0's centre).
        """
        s_arr, d_arr = self.local_coordinates(_as_float(xy).reshape(2))
        s, d = float(s_arr), float(d_arr)
        lane, r = self.lane_of(s, d)
        return lane, s, r

    def lane_of(self, s: float, d: float) -> tuple[int | None, float]:
        """(lane index or None, r from that lane's centre, or d with None) of route
        coordinates (s, d): `lane_at` for a point already projected."""
        c = self.cross_section_at(s)
        w = c.lane_width
        if not 0.0 <= s <= self.length:
            return None, d
        if c.profile is not None:
            return self._profiled_lane_of(c, s, d)
        band = int(np.floor((d + 0.5 * w) / w))  # 0 .. lanes - 1 ego, then oncoming
        if 0 <= band < c.lanes:
            return band, d - band * w
        if c.lanes <= band < c.lanes + c.oncoming_lanes:
            return c.lanes - 1 - band, d - band * w
        return None, d

    def band_edges(self, s: float, d: float) -> tuple[int, float, float]:
        """(band, [m] right, [m] left) of the lane band across that holds offset d at
        station s on a segment with a lane profile: band 0 .. lanes + oncoming_lanes - 1
        counts the lanes right to left (ego lanes, then oncoming from the centre line), its
        edges from `lane_boundaries`; beyond the lanes, -1 (right of lane 0) or the count,
        a band as wide as the lane next to it."""
        b = self.lane_boundaries(s)[1:]
        band = int(np.searchsorted(b, d, side="right")) - 1
        if band < 0:
            return band, float(2.0 * b[0] - b[1]), float(b[0])
        if band >= len(b) - 1:
            return band, float(b[-1]), float(2.0 * b[-1] - b[-2])
        return band, float(b[band]), float(b[band + 1])

    def _profiled_lane_of(self, c: CrossSection, s: float, d: float) -> tuple[int | None, float]:
        """`lane_of` on a segment with a lane profile: the band of boundaries holding d."""
        bounds = self.lane_boundaries(s)
        band = int(np.searchsorted(bounds[1:], d, side="right")) - 1
        if not 0 <= band < c.lanes + c.oncoming_lanes:
            return None, d
        index = band if band < c.lanes else c.lanes - 1 - band
        return index, d - float(self.lane(index).offset_at(s))

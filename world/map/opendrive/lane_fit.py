"""A road's lanes along a route: lane 0's centre as an arc spline (`offset_spline`), the
other lane boundaries across each piece as cubics in the piece's station u (what the HD
map's `LaneProfile` holds).

The route's pieces never straddle a planView record start, a lane section start, a
lane-width record start or a lane-offset record start (nor the caller's extra stations):
between those every border of the file is ref(s) + t(s) n(s) with t a cubic in s
(`lanes.border_polynomials`). Lane 0's centre is the middle of its two borders.

A boundary's offset at route station u is measured along the piece's normal there: where
that normal crosses the file's border curve (Newton on the crossing's station, to
`NEWTON_TOL`). Each boundary is interpolated by a cubic at the 4 Chebyshev points of the
piece and checked at `FIT_CHECKS` stations; a piece whose boundaries are off their cubics
by more than `FIT_SHARE * SAFETY * tolerance` is halved (so that a lane's width, the
difference of two boundaries, keeps within the tolerance too).

Lane 0's edges become -w0 / 2 and +w0 / 2 with w0 the cubic of their difference (the map's
lane 0 is centred on its reference line). The file's lane centre is the middle of the
edges along the file's normal; along the route's normal, which is turned from it by
atan(t0' / (1 - k t0)), the edges' middle is off the centre by `skew` ~ (w0 / 2) t0' w0': a
few micrometres for ordinary tapers (0.5 m over 100 m), irreducible by splitting; the
caller refuses lanes that change so fast that it matters.

The error budget where the boundaries vary, with `SAFETY` = 0.8: lane 0's centre within
`CENTRE_SHARE` (0.4 mm of 1 mm), each boundary's cubic within `FIT_SHARE` (0.2 mm) of the
exact crossing measured from the piece, so a lane width within 0.4 mm plus lane 0's
centre error where the lane adjoins lane 0 (its edge follows lane 0's centre); lane 0's
edges within its centre error + `skew` + 0.2 mm. Where every border is constant along an
interval the boundaries are constants (the route's normal is the file's there) and
nothing is fitted: the whole cross-section moves with lane 0's centre (within the full
tolerance) and the widths are exact.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from world.map.opendrive import arcspline
from world.map.opendrive.arcspline import SAFETY
from world.map.opendrive.arcspline import piece_points as arc_points
from world.map.opendrive.geometry import PlanView
from world.map.opendrive.lanes import border_polynomials, lane_section_index
from world.map.opendrive.model import Road
from world.map.opendrive.offset_spline import CurvePiece, OffsetCurve, offset_arc_spline
from world.map.opendrive.shapes import FloatArray

FIT_CHECKS = 17  # [-] stations per piece where the cubics are checked
NEWTON_TOL = 1e-10  # [m] a normal's crossing with a border: the along-normal residual
NEWTON_STEPS = 30  # [-] at most
CHEBYSHEV = 0.5 * (1.0 - np.cos((2.0 * np.arange(4) + 1.0) * np.pi / 8.0))  # on [0, 1]
FIT_SHARE = 0.25  # [-] a boundary's share of the tolerance (a width has two boundaries)
CENTRE_SHARE = 0.5  # [-] lane 0's centre's share where the boundaries vary
STATION_EPS = 1e-9  # [m] record starts closer than this are one


@dataclass(frozen=True, slots=True)
class FittedPiece:
    """One piece of the route: lane 0's centre, and every boundary across it."""

    piece: CurvePiece
    boundaries: FloatArray  # [m, 1, 1/m, 1/m^2] (n, 4) cubics in u, right to left
    constant: bool  # every boundary is constant along it (b = c = d = 0)
    skew: float  # [m] the largest distance along the piece's normals between the middle of
    #   lane 0's exact edges and its exact centre


def cubic_values(coef: FloatArray, u: FloatArray) -> FloatArray:
    """(n, len(u)) the cubics `coef` (n, 4) at stations u."""
    c = coef[:, :, None]
    out: FloatArray = c[:, 0] + u * (c[:, 1] + u * (c[:, 2] + u * c[:, 3]))
    return out


def normal_offsets(curve: OffsetCurve, piece: CurvePiece, u: FloatArray) -> FloatArray:
    """[m] (len(u),) the offsets (left +) along the piece's normals at stations u where
    they cross `curve` (module doc)."""
    out: FloatArray = crossings([curve], piece, u)[0]
    return out


def _polynomial(c: FloatArray, x: FloatArray) -> tuple[FloatArray, FloatArray]:
    """(value, derivative) of polynomials `c` (n, deg + 1), ascending, at x (n, m)."""
    value = np.broadcast_to(c[:, -1:], x.shape).copy()
    slope = np.zeros_like(x)
    for j in range(c.shape[1] - 2, -1, -1):
        slope = slope * x + value
        value = value * x + c[:, j:j + 1]
    return value, slope


def crossings(curves: list[OffsetCurve], piece: CurvePiece, u: FloatArray) -> FloatArray:
    """[m] (len(curves), len(u)) `normal_offsets` of curves that share one reference line
    and origin, in one Newton iteration over all of them."""
    record, origin = curves[0].plan_view, curves[0].origin
    if any(c.plan_view is not record or c.origin != origin for c in curves):
        raise ValueError("crossings: the curves must share their reference line and origin")
    coef = np.zeros((len(curves), max(len(c.t) for c in curves)))
    for i, c in enumerate(curves):
        coef[i, :len(c.t)] = c.t
    ax, ay = arc_points(piece.arc(), u)
    th = piece.heading0 + piece.curvature * u
    tx, ty = np.cos(th), np.sin(th)
    s = np.tile(piece.s0 + (piece.s1 - piece.s0) * u / piece.length, (len(curves), 1))

    def pose(s: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        x, y, h = record.pose_unwrapped(s)
        t, slope = _polynomial(coef, s - origin)
        along = 1.0 - record.curvature(s) * t
        return (x - t * np.sin(h), y + t * np.cos(h), h + np.arctan2(slope, along),
                np.hypot(along, slope))

    for _ in range(NEWTON_STEPS):
        bx, by, bh, speed = pose(s)
        gap = (bx - ax) * tx + (by - ay) * ty
        s = s - gap / (speed * np.cos(bh - th))
        if np.all(np.abs(gap) < NEWTON_TOL):
            break
    bx, by, _, _ = pose(s)
    return np.asarray((by - ay) * tx - (bx - ax) * ty, dtype=np.float64)


def fit_boundaries(curves: list[OffsetCurve], centre: OffsetCurve,
                   piece: CurvePiece) -> tuple[FloatArray, float, float]:
    """(cubics (n, 4) in u of the boundaries `curves` across `piece`, [m] their largest
    error at `FIT_CHECKS` stations, [m] lane 0's `skew`); curves[1] and curves[2] are lane
    0's edges, returned as -w0 / 2 and +w0 / 2, `centre` its exact centre (module doc)."""
    length = piece.length
    u = np.linspace(0.0, length, FIT_CHECKS)
    exact = crossings([*curves, centre], piece, np.concatenate([length * CHEBYSHEV, u]))
    values, checked = exact[:-1, :4], exact[:-1, 4:]
    vander = np.vander(CHEBYSHEV, 4, increasing=True)
    coef = np.linalg.solve(vander, values.T).T / length ** np.arange(4)
    error = float(np.max(np.abs(cubic_values(coef, u) - checked)))
    middle = 0.5 * (checked[1] + checked[2])  # the piece is off `centre` by its deviation
    skew = float(np.max(np.abs(middle - exact[-1, 4:])))
    width = coef[2] - coef[1]
    coef[1], coef[2] = -0.5 * width, 0.5 * width
    return coef, error, skew


def record_starts(road: Road) -> list[float]:
    """[m] every station where a planView record, a lane section, a lane-width record or a
    lane-offset record starts."""
    out = [g.s for g in road.plan_view.geometries]
    out += [r.s for r in road.lane_offsets]
    for sec in road.lane_sections:
        out.append(sec.s)
        out += [sec.s + w.s for lane in (*sec.left, *sec.right) for w in lane.widths]
    return out


def fit_lanes(road: Road, borders: list[tuple[int, ...]], stations: list[float],
              tolerance: float, max_pieces: int | None = None) -> list[FittedPiece]:
    """The route's pieces along the whole road (module doc): lane 0's centre within
    `tolerance` [m] of the file's, every boundary within it of its cubic. `borders`: per
    lane section, the lane ids whose outer border is each boundary, right to left ([1],
    [2]: lane 0's right and left edge; id 0: the lane offset); `stations` [m]: where
    pieces must split besides record starts; `PieceBoundError` beyond `max_pieces` (default
    `arcspline.MAX_PIECES`) pieces in all."""
    bound = arcspline.MAX_PIECES if max_pieces is None else max_pieces
    view = road.plan_view
    cuts = sorted({view.start, view.end, *(s for s in (*record_starts(road), *stations)
                                            if view.start < s < view.end)})
    out: list[FittedPiece] = []
    for a, b in itertools.pairwise(cuts):
        if b - a > STATION_EPS:
            section = borders[lane_section_index(road, 0.5 * (a + b))]
            out += _fit_interval(road, section, a, b, tolerance, bound - len(out))
    return out


def _fit_interval(road: Road, borders: tuple[int, ...], a: float, b: float,
                  tolerance: float, max_pieces: int) -> list[FittedPiece]:
    """`fit_lanes` between two consecutive record starts a and b."""
    mid = 0.5 * (a + b)
    polys = border_polynomials(road, mid, a)
    view = road.plan_view
    record = PlanView((view.geometries[int(view.record_index(mid))],))
    t = [polys[i] for i in borders]
    centre = 0.5 * (t[1] + t[2])
    curve = OffsetCurve(record, a, tuple(centre))
    if all(not np.any(p[1:]) for p in t):
        coef = np.zeros((len(t), 4))
        coef[:, 0] = [p[0] - centre[0] for p in t]
        width = t[2][0] - t[1][0]
        coef[1, 0], coef[2, 0] = -0.5 * width, 0.5 * width
        return [FittedPiece(p, coef, True, 0.0)
                for p in offset_arc_spline(curve, a, b, tolerance, None, max_pieces)]
    curves = [OffsetCurve(record, a, tuple(p)) for p in t]
    fits: dict[tuple[float, float], tuple[FloatArray, float]] = {}

    def accept(piece: CurvePiece) -> bool:
        coef, error, skew = fit_boundaries(curves, curve, piece)
        fits[(piece.s0, piece.s1)] = coef, skew
        return error <= FIT_SHARE * SAFETY * tolerance

    pieces = offset_arc_spline(curve, a, b, CENTRE_SHARE * tolerance, accept, max_pieces)
    for p in pieces:  # a piece at MIN_PIECE may have skipped `accept`
        if (p.s0, p.s1) not in fits:
            accept(p)
    out = []
    for p in pieces:
        coef, skew = fits[(p.s0, p.s1)]
        out.append(FittedPiece(p, coef, False, skew))
    return out

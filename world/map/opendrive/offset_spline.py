"""The arc spline of a curve laid sideways off a road's reference line: P(s) = ref(s) +
t(s) n(s), with t a polynomial in the station (a lane's centre: the lane offset and the
lane widths are cubics), as a chain of straight and constant-curvature pieces.

With the reference line's heading h(s) and curvature k(s), the curve's tangent is
(1 - k t) T + t' N: its heading is h + atan2(t', 1 - k t) and its arc length grows by
sqrt((1 - k t)^2 + t'^2) per metre of station. A constant t on an arc of radius R (left +)
gives an arc of radius R - t; a linear t on a straight gives a straight at atan(t') to it.

Each piece starts at an exact sample of the curve (position and heading), its length is
the curve's arc length between its ends (Gauss-Legendre quadrature of that integrand, exact
to rounding for the polynomial-times-smooth integrands of one record), and it turns at its
mean curvature (the exact heading change over that length), so the headings at the joints
are exact. The deviation is measured geometrically: the largest distance of `CHECKS` exact
samples of the curve from the piece's circle (or line), and of the curve's end point from
the piece's end. A piece whose deviation exceeds `SAFETY * tolerance` (or that a caller's
`accept` rejects) is halved, down to `MIN_PIECE`.

The curve must be smooth over the interval given (one planView record, one record of each
polynomial): the caller splits at record starts, where derivatives jump.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numpy.polynomial import legendre
from numpy.polynomial import polynomial as poly

from world.map.opendrive.arcspline import (
    CHECKS,
    MAX_PIECES,
    MIN_PIECE,
    SAFETY,
    ArcPiece,
    PieceBoundError,
)
from world.map.opendrive.arcspline import piece_points as arc_points
from world.map.opendrive.geometry import PlanView
from world.map.opendrive.shapes import FloatArray

GAUSS_NODES = 16  # [-] Gauss-Legendre nodes of a piece's length integral
_NODES, _WEIGHTS = legendre.leggauss(GAUSS_NODES)


@dataclass(frozen=True, slots=True)
class OffsetCurve:
    """P(s) = ref(s) + t(s) n(s) for stations s of `plan_view` (module doc)."""

    plan_view: PlanView  # the reference line, one record (its ends evaluated on itself)
    origin: float  # [m] the station where x = s - origin is 0
    t: tuple[float, ...]  # [m, 1, 1/m, ...] the offset (left +), polynomial in x, ascending

    def offset(self, s: FloatArray) -> tuple[FloatArray, FloatArray]:
        """([m] t, [1] dt/ds) at stations s."""
        c = np.asarray(self.t, dtype=np.float64)
        x = np.asarray(s, dtype=np.float64) - self.origin
        t = np.asarray(poly.polyval(x, c), dtype=np.float64)
        return t, np.asarray(poly.polyval(x, poly.polyder(c)), dtype=np.float64)

    def pose(self, s: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """([m] x, [m] y, [rad] heading (not wrapped), [1] d(arc length)/ds) at stations s."""
        x, y, h = self.plan_view.pose_unwrapped(s)
        k = self.plan_view.curvature(s)
        t, slope = self.offset(s)
        along = 1.0 - k * t
        return (x - t * np.sin(h), y + t * np.cos(h), h + np.arctan2(slope, along),
                np.hypot(along, slope))


class CurvePiece(NamedTuple):
    """One straight or arc piece of an offset curve's spline."""

    s0: float  # [m] reference-line station of its start
    s1: float  # [m] of its end
    length: float  # [m] along the curve
    curvature: float  # [1/m] + left
    x0: float  # [m] start position (exact)
    y0: float  # [m]
    heading0: float  # [rad] start heading (exact, not wrapped)

    def arc(self) -> ArcPiece:
        """The piece as the reference line's spline pieces are (`arcspline.piece_points`)."""
        return ArcPiece(self.s0, self.length, self.curvature, self.x0, self.y0,
                        self.heading0)


def arc_length(curve: OffsetCurve, a: float, b: float) -> float:
    """[m] the curve's length between stations a and b (Gauss-Legendre, `GAUSS_NODES`)."""
    half = 0.5 * (b - a)
    s = a + half * (_NODES + 1.0)
    return float(half * np.dot(_WEIGHTS, curve.pose(s)[3]))


def curve_piece(curve: OffsetCurve, a: float, b: float) -> CurvePiece:
    """The piece from the curve's exact pose at station a to the one at b (module doc)."""
    x, y, h, _ = curve.pose(np.array([a, b]))
    length = arc_length(curve, a, b)
    turn = (h[1] - h[0] + np.pi) % (2 * np.pi) - np.pi  # a piece turns less than half a turn
    k = float(turn) / length if length > 0.0 else 0.0
    return CurvePiece(a, b, length, k, float(x[0]), float(y[0]), float(h[0]))


def distance_to_arc(piece: CurvePiece, x: FloatArray, y: FloatArray) -> FloatArray:
    """[m] the distance of points (x, y) from the piece's circle (a straight's line): in the
    piece's start frame (u along, v left) |k (u^2 + v^2) - 2 v| / (1 + |k| r) with r the
    distance from the circle's centre, which needs no radius (stable for k -> 0)."""
    c, sn = np.cos(piece.heading0), np.sin(piece.heading0)
    dx, dy = x - piece.x0, y - piece.y0
    u, v = c * dx + sn * dy, c * dy - sn * dx
    k = piece.curvature
    return np.asarray(np.abs(k * (u * u + v * v) - 2.0 * v) / (1.0 + np.hypot(k * u, k * v - 1.0)),
                      dtype=np.float64)


def deviation(curve: OffsetCurve, piece: CurvePiece, checks: int = CHECKS) -> float:
    """[m] the piece's geometric deviation from the curve (module doc)."""
    x, y, _, _ = curve.pose(np.linspace(piece.s0, piece.s1, checks))
    ex, ey = arc_points(piece.arc(), np.array([piece.length]))
    gap = float(np.hypot(ex[0] - x[-1], ey[0] - y[-1]))
    return max(gap, float(np.max(distance_to_arc(piece, x, y))))


def offset_arc_spline(curve: OffsetCurve, a: float, b: float, tolerance: float,
                      accept: Callable[[CurvePiece], bool] | None = None,
                      max_pieces: int | None = None) -> list[CurvePiece]:
    """The chain of pieces approximating the curve between stations a and b within
    `tolerance` [m] and accepted by `accept` (module doc); `PieceBoundError` beyond
    `max_pieces` (default `MAX_PIECES`)."""
    bound = MAX_PIECES if max_pieces is None else max_pieces
    pieces: list[CurvePiece] = []
    stack = [(a, b)]
    while stack:
        lo, hi = stack.pop()
        piece = curve_piece(curve, lo, hi)
        good = (deviation(curve, piece) <= SAFETY * tolerance
                and (accept is None or accept(piece)))
        if good or hi - lo <= MIN_PIECE:
            pieces.append(piece)
            if len(pieces) > bound:
                raise PieceBoundError(f"the lanes need more arc-spline pieces than a road may "
                                      f"have (at s = {lo:g} m)")
            continue
        mid = 0.5 * (lo + hi)
        stack.extend([(mid, hi), (lo, mid)])  # the first half is popped first
    return pieces

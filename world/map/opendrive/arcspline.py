"""The reference line as a chain of straight and constant-curvature pieces (what the
simulator's HD map is made of).

Each piece starts at an exact sample of the line (position and heading) and turns at its
mean curvature (its exact heading change over its length), so the chain's headings at the
piece joints are exact. Lines and arcs are one piece each; spirals, poly3 and paramPoly3
records are halved until the piece's largest position deviation from the exact record
(checked at `CHECKS` stations per piece) is below `tolerance` (each record is approximated
on its own, so a gap between records in the file is not split into ever smaller pieces).
A reference line that needs more than `MAX_PIECES` pieces in all is refused
(`PieceBoundError`): each piece costs a bounded number of evaluations, so the work is bounded.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from world.map.opendrive.geometry import PlanView
from world.map.opendrive.model import Arc, Line
from world.map.opendrive.shapes import FloatArray

CHECKS = 65  # stations per piece where its deviation is checked
MIN_PIECE = 1e-3  # [m] pieces are not split below this length
SAFETY = 0.8  # the split criterion is SAFETY * tolerance (the deviation between checks)
MAX_PIECES = 5_000  # per road: the pieces of its whole reference line (a bound on the work;
#   the curviest ALKS road, 10 km of arcs and spirals, needs 337)


class PieceBoundError(ValueError):
    """A curve that needs more pieces than its bound (one-line message)."""


class ArcPiece(NamedTuple):
    """One straight (curvature 0) or constant-curvature piece of the chain."""

    s0: float  # [m] station of its start
    length: float  # [m]
    curvature: float  # [1/m] + left
    x0: float  # [m] start position (exact)
    y0: float  # [m]
    heading0: float  # [rad] start heading (exact, not wrapped)


def piece_points(piece: ArcPiece, ds: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Positions [m] along `piece` at `ds` [m] past its start."""
    th = piece.curvature * ds
    u = ds * np.sinc(th / np.pi)
    v = ds * np.sin(th / 2) * np.sinc(th / (2 * np.pi))
    c, s = np.cos(piece.heading0), np.sin(piece.heading0)
    return piece.x0 + c * u - s * v, piece.y0 + s * u + c * v


def piece_deviation(plan_view: PlanView, piece: ArcPiece, checks: int = CHECKS) -> float:
    """[m] the largest distance between `piece` and the exact line at `checks` stations."""
    ds = np.linspace(0.0, piece.length, checks)
    px, py = piece_points(piece, ds)
    x, y, _ = plan_view.pose_unwrapped(piece.s0 + ds)
    return float(np.max(np.hypot(px - x, py - y)))


def _piece(plan_view: PlanView, s0: float, s1: float) -> ArcPiece:
    x, y, h = plan_view.pose_unwrapped(np.array([s0, s1]))
    turn = (h[1] - h[0] + np.pi) % (2 * np.pi) - np.pi  # a piece turns less than half a turn
    k = turn / (s1 - s0) if s1 > s0 else 0.0
    return ArcPiece(s0, s1 - s0, float(k), float(x[0]), float(y[0]), float(h[0]))


def arc_spline(plan_view: PlanView, tolerance: float = 1e-3,
               max_pieces: int | None = None) -> list[ArcPiece]:
    """The chain of pieces approximating `plan_view` within `tolerance` [m] (module doc);
    `PieceBoundError` if it needs more than `max_pieces` (default `MAX_PIECES`) in all."""
    max_pieces = MAX_PIECES if max_pieces is None else max_pieces
    pieces: list[ArcPiece] = []
    for g in plan_view.geometries:
        if g.length <= 0:
            continue
        s0, s1 = g.s, g.s + g.length
        if isinstance(g.shape, Line | Arc):
            k = 0.0 if isinstance(g.shape, Line) else g.shape.curvature
            pieces.append(ArcPiece(s0, g.length, k, g.x, g.y, g.hdg))
        else:
            _split_record(PlanView((g,)), s0, s1, tolerance, pieces, max_pieces)
        if len(pieces) > max_pieces:
            raise PieceBoundError(f"the reference line needs over {max_pieces} arc-spline "
                                  f"pieces (at s = {g.s:g} m)")
    return pieces


def _split_record(record: PlanView, s0: float, s1: float, tolerance: float,
                  pieces: list[ArcPiece], max_pieces: int) -> None:
    """Append to `pieces` the pieces of one record (`record`: its end evaluated on itself,
    whatever the next record's start), halving each until it is within `tolerance`; stops
    once `pieces` holds more than `max_pieces`."""
    stack = [(s0, s1)]
    while stack and len(pieces) <= max_pieces:
        a, b = stack.pop()
        piece = _piece(record, a, b)
        if b - a > MIN_PIECE and piece_deviation(record, piece) > SAFETY * tolerance:
            mid = 0.5 * (a + b)
            stack.extend([(mid, b), (a, mid)])  # the first half is popped first
        else:
            pieces.append(piece)

"""The arc-spline approximation of a reference line: exact joints, the deviation bound."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest

from world.map.opendrive import (
    Arc,
    Geometry,
    Line,
    ParamPoly3,
    PlanView,
    Spiral,
    arc_spline,
    load_opendrive,
    piece_deviation,
)
from world.map.opendrive.arcspline import piece_points

DATA = Path(__file__).parent / "data"
ALKS_CURVES = (
    Path(__file__).parents[4]
    / "tests/data/alks/logical_scenarios/concrete_scenarios/road_networks"
    / "alks_road_different_curvatures.xodr"
)
MIXED = load_opendrive(DATA / "mixed.xodr").road("1").plan_view


@pytest.mark.parametrize("tolerance", [1e-1, 1e-3, 1e-5])
@pytest.mark.parametrize("name", ["mixed", "alks"])
def test_deviation_bound_by_dense_sampling(name: str, tolerance: float) -> None:
    pv = MIXED if name == "mixed" else load_opendrive(ALKS_CURVES).roads[0].plan_view
    pieces = arc_spline(pv, tolerance)
    worst = max(piece_deviation(pv, p, checks=1001) for p in pieces)
    assert worst < tolerance
    assert sum(p.length for p in pieces) == pytest.approx(pv.length, abs=1e-9)


def test_pieces_start_on_the_exact_line_and_chain() -> None:
    pieces = arc_spline(MIXED, 1e-3)
    x, y, h = MIXED.pose_unwrapped(np.array([p.s0 for p in pieces]))
    assert np.allclose(x, [p.x0 for p in pieces], atol=1e-12)
    assert np.allclose(y, [p.y0 for p in pieces], atol=1e-12)
    assert np.allclose(h, [p.heading0 for p in pieces], atol=1e-12)
    for a, b in itertools.pairwise(pieces):
        assert a.s0 + a.length == pytest.approx(b.s0, abs=1e-9)
        assert a.heading0 + a.curvature * a.length == pytest.approx(b.heading0, abs=1e-9)
        ex, ey = piece_points(a, np.array([a.length]))
        assert np.hypot(ex[0] - b.x0, ey[0] - b.y0) < 1e-3


def test_lines_and_arcs_are_one_piece_each() -> None:
    pv = PlanView(
        (
            Geometry(0.0, 0.0, 0.0, 0.0, 30.0, Line()),
            Geometry(30.0, 30.0, 0.0, 0.0, 40.0, Arc(-0.02)),
        )
    )
    pieces = arc_spline(pv, 1e-6)
    assert [(p.s0, p.length, p.curvature) for p in pieces] == [
        (0.0, 30.0, 0.0),
        (30.0, 40.0, -0.02),
    ]


def test_curved_records_split_and_mean_curvature() -> None:
    pv = PlanView((Geometry(0.0, 0.0, 0.0, 0.0, 100.0, Spiral(0.0, 0.02)),))
    coarse, fine = arc_spline(pv, 1e-1), arc_spline(pv, 1e-4)
    assert 1 < len(coarse) < len(fine)
    for p in fine:  # the mean curvature of a clothoid piece is its middle's
        assert p.curvature == pytest.approx(0.02 * (p.s0 + p.length / 2) / 100.0, abs=1e-12)
    straight = PlanView(
        (Geometry(0, 0, 0, 0, 50.0, ParamPoly3(0, 50, 0, 0, 0, 0, 0, 0, "normalized")),)
    )
    assert len(arc_spline(straight)) == 1


def test_a_gap_between_records_is_not_split_into_dust() -> None:
    gap = 5e-3  # [m] the second record starts this far off the first one's end
    x1, y1 = 100 * np.sinc(0.0), 0.0
    pv = PlanView(
        (
            Geometry(0.0, 0.0, 0.0, 0.0, 100.0, Spiral(0.0, 0.0)),
            Geometry(100.0, x1, y1 + gap, 0.0, 50.0, Spiral(0.0, 0.01)),
        )
    )
    pieces = arc_spline(pv, 1e-3)
    assert len(pieces) < 40
    assert pieces[0].length == 100.0

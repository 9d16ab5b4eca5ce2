"""Lane geometry across the reference line: sections, offsets, widths varying along s,
borders."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from world.map.opendrive import (
    Poly3,
    lane_borders,
    lane_centre_t,
    lane_offset,
    lane_section_index,
    lane_width,
    load_opendrive,
    poly3_at,
)

DATA = Path(__file__).parent / "data"
STRAIGHT = (
    Path(__file__).parents[4]
    / "tests/data/alks/logical_scenarios/concrete_scenarios/road_networks/alks_road_straight.xodr"
)
MIXED = load_opendrive(DATA / "mixed.xodr").road("1")


def test_alks_straight_lane_borders() -> None:
    road = load_opendrive(STRAIGHT).roads[0]
    for s in (0.0, 1234.5, road.length):
        b = lane_borders(road, s)
        assert b[0] == (0.0, 0.0)
        widths = {i: abs(outer - inner) for i, (inner, outer) in b.items()}
        for lane in (-3, -4, -5, 3, 4, 5):
            assert widths[lane] == pytest.approx(3.5)
        assert widths[-1] == widths[1] == pytest.approx(2.0)
        assert widths[-2] == widths[2] == pytest.approx(0.75)
        assert widths[-6] == widths[6] == pytest.approx(3.0)
        assert widths[-7] == widths[7] == pytest.approx(1.5)
        assert widths[-8] == widths[8] == pytest.approx(6.0)
        assert b[-3] == pytest.approx((-2.75, -6.25))
        assert b[-5] == pytest.approx((-9.75, -13.25))
        assert b[5] == pytest.approx((9.75, 13.25))
        assert b[-8][1] == pytest.approx(-(2 + 0.75 + 3 * 3.5 + 3 + 1.5 + 6))
        assert lane_centre_t(road, -4, s) == pytest.approx(-8.0)


def test_poly3_pieces() -> None:
    recs = (Poly3(0.0, 1.0, 0.0, 0.0, 0.0), Poly3(10.0, 2.0, 0.5, 0.1, -0.01))
    s = np.array([-1.0, 0.0, 9.99, 10.0, 12.0])
    ds = 2.0
    expected = [0.0, 1.0, 1.0, 2.0, 2 + 0.5 * ds + 0.1 * ds**2 - 0.01 * ds**3]
    assert np.allclose(poly3_at(recs, s), expected)
    assert np.allclose(poly3_at((), s, default=7.0), 7.0)
    assert recs[1].value(ds) == pytest.approx(expected[-1])


def test_lane_sections() -> None:
    assert [lane_section_index(MIXED, s) for s in (-5.0, 0.0, 79.9, 80.0, 500.0)] == [0, 0, 0, 1, 1]


def test_lane_offset_varying_along_s() -> None:
    s = np.array([0.0, 59.9, 60.0, 70.0, 100.0])
    d = s - 60.0
    cubic = 0.5 + 0.01 * d + 0.0002 * d**2 - 0.000001 * d**3
    assert np.allclose(lane_offset(MIXED, s), np.where(s < 60.0, 0.5, cubic))


def test_lane_widths_varying_along_s() -> None:
    first, second = MIXED.lane_sections
    s = np.array([0.0, 25.0, 50.0])
    assert np.allclose(lane_width(first, first.lane(1), s), 3 + 0.01 * s)  # b != 0
    cubic = 3.5 + 0.001 * s**2 - 0.00001 * s**3
    assert np.allclose(lane_width(first, first.lane(-1), s), cubic)
    # the second section's lane -1: s relative to the section start (80), two records
    s2 = np.array([80.0, 99.0, 100.0, 110.0])
    assert np.allclose(lane_width(second, second.lane(-1), s2), [3.5, 3.5, 3.5, 4.0])
    assert np.all(lane_width(first, first.center, s) == 0.0)


def test_mixed_lane_borders_stack_from_the_lane_offset() -> None:
    s = 70.0
    off = 0.5 + 0.01 * 10 + 0.0002 * 100 - 0.000001 * 1000
    w1, wm1 = 3 + 0.01 * s, 3.5 + 0.001 * s**2 - 0.00001 * s**3
    b = lane_borders(MIXED, s)
    assert b[0] == pytest.approx((off, off))
    assert b[1] == pytest.approx((off, off + w1))
    assert b[-1] == pytest.approx((off, off - wm1))
    assert b[-2] == pytest.approx((off - wm1, off - wm1 - 2.0))
    assert lane_centre_t(MIXED, -2, s) == pytest.approx(off - wm1 - 1.0)
    assert set(lane_borders(MIXED, 90.0)) == {0, -1}
    with pytest.raises(KeyError):
        lane_centre_t(MIXED, 1, 90.0)

"""`ReferenceLine.project` keeps its last points' candidates: the answers are those of a line
that never saw a point before, bit for bit, in any order of points and hints, and the
per-piece projection runs once for points asked again."""

from __future__ import annotations

import math

import numpy as np

from tests.roads import arc, make_map, seg
from world.hdmap import MAX_HINTS_KEPT, ReferenceLine


def crossing_loop() -> ReferenceLine:
    """A route whose last straight crosses its first (`test_hdmap.crossing_loop`)."""
    return make_map(seg(100.0), arc(10.0, 90.0), seg(50.0), arc(10.0, 90.0), seg(30.0),
                    arc(10.0, 90.0), seg(100.0)).line


def fresh(xy: np.ndarray, near: float | None) -> tuple[np.ndarray, np.ndarray]:
    """The projection by a line that has kept nothing."""
    return crossing_loop().project(xy, near)


def test_repeated_points_and_hints_give_the_fresh_answers_bit_for_bit() -> None:
    line = crossing_loop()
    second = 100.0 + 50.0 + 30.0 + 3 * 5.0 * math.pi + 60.0  # the crossing, second time
    rng = np.random.default_rng(3)
    points = [np.array([[60.0, 0.3]]), np.array([[20.0, 0.5]]),
              rng.uniform(-20.0, 120.0, size=(5, 2))]
    hints = [None, 58.0, second + 2.0, 200.0, None, 58.0]
    for xy in points:
        for near in hints:
            s, d = line.project(xy, near)
            s_new, d_new = fresh(xy, near)
            assert s.tobytes() == s_new.tobytes() and d.tobytes() == d_new.tobytes()
    # and back to an earlier point: its own answer, not the last one's
    s, d = line.project(points[0], 58.0)
    s_new, d_new = fresh(points[0], 58.0)
    assert s.tobytes() == s_new.tobytes() and d.tobytes() == d_new.tobytes()


def test_a_point_asked_again_is_projected_onto_the_pieces_once() -> None:
    line = crossing_loop()
    xy = np.array([[60.0, 0.3]])
    line.project(xy)
    kept = line._last
    for near in (58.0, 300.0, 58.0, None):
        line.project(xy.copy(), near)
        assert line._last is kept
    line.project(np.array([[60.0, 0.4]]))
    assert line._last is not kept


def test_the_hints_kept_for_a_point_are_bounded() -> None:
    line = crossing_loop()
    xy = np.array([[60.0, 0.3]])
    for k in range(3 * MAX_HINTS_KEPT):
        line.project(xy, float(k))
        assert line._last is not None and len(line._last.hinted) <= MAX_HINTS_KEPT


def test_one_station_finds_the_index_the_vectorised_search_finds() -> None:
    line = crossing_loop()
    joints = line.bounds.tolist()
    stations = [*joints, -5.0, -0.0, line.length + 3.0, math.nan, math.inf, -math.inf,
                *np.random.default_rng(5).uniform(-10.0, line.length + 10.0, 50).tolist()]
    for s in stations:
        arr = np.array([s])
        assert line.segment_index(np.array(s)) == line.segment_index(arr)[0]
        assert line.piece_index(np.array(s)) == line.piece_index(arr)[0]
        assert line.segment_index(s) == line.segment_index(arr)[0]

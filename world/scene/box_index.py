"""A uniform-grid index of axis-aligned ground rectangles, for "does a new box keep a gap
from every placed one" in time independent of how many are placed.

Each rectangle is filed under every square cell (`cell` [m] wide, map frame) that its
rectangle grown by the gap touches; a query looks only at the rectangles filed under the
cells the new rectangle touches. Two rectangles closer than the gap (the test of
`BoxIndex.clear`) overlap once one is grown by the gap, so they share a cell: the answer is
the same as comparing against every placed rectangle.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

Rect = tuple[float, float, float, float]  # [m] x0, y0, x1, y1 (map frame)


class BoxIndex:
    """Placed rectangles, queried by `clear` (module doc)."""

    def __init__(self, gap: float, cell: float) -> None:
        self._gap = gap  # [m] the least distance kept along x and along y
        self._cell = cell  # [m] side of a grid cell
        self._cells: dict[tuple[int, int], list[Rect]] = {}
        self.compared = 0  # rectangles `clear` has looked at so far: the index's work

    def _keys(self, x0: float, y0: float, x1: float, y1: float) -> Iterator[tuple[int, int]]:
        """The cells a rectangle touches."""
        c = self._cell
        for i in range(math.floor(x0 / c), math.floor(x1 / c) + 1):
            for j in range(math.floor(y0 / c), math.floor(y1 / c) + 1):
                yield i, j

    def clear(self, a: Rect) -> bool:
        """Whether `a` keeps the gap from every placed rectangle: for each, it lies the gap
        or more away along x or along y."""
        g = self._gap
        for key in self._keys(*a):
            for b in self._cells.get(key, ()):
                self.compared += 1
                if a[0] < b[2] + g and b[0] < a[2] + g and a[1] < b[3] + g and b[1] < a[3] + g:
                    return False
        return True

    def add(self, b: Rect) -> None:
        """Place `b`."""
        g = self._gap
        for key in self._keys(b[0] - g, b[1] - g, b[2] + g, b[3] + g):
            self._cells.setdefault(key, []).append(b)

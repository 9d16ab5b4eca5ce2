"""Compact columns for a run's per-tick log (`avsim.run.runner.TrajectoryLog`): typed arrays
for numbers and flags (8 bytes a float, 1 a flag, 4 an int, where a list holds a 32-byte
float object per value), and `Rows` for equal-length rows of numbers."""

from __future__ import annotations

from array import array
from typing import Any

import numpy as np
from numpy.typing import NDArray


def floats() -> array[float]:
    """An empty column of float64 values."""
    return array("d")


def flags() -> array[int]:
    """An empty column of flags (0 / 1; appending a bool stores it)."""
    return array("b")


def ints() -> array[int]:
    """An empty column of 32-bit integers."""
    return array("i")


class Rows:
    """Equal-length rows of numbers appended one at a time (a tick's wheel spins, its actors'
    stations), kept in one flat float64 array; ``np.array(rows)`` is the (ticks, width)
    matrix."""

    def __init__(self) -> None:
        self._flat: array[float] = array("d")
        self._width: int | None = None
        self._count = 0

    def append(self, row: NDArray[np.float64]) -> None:
        if self._width is None:
            self._width = len(row)
        elif len(row) != self._width:
            raise ValueError(f"a row of {len(row)} values in rows of {self._width}")
        self._flat.extend(row.tolist())
        self._count += 1

    def __len__(self) -> int:
        return self._count

    def __array__(self, dtype: Any = None, copy: bool | None = None) -> NDArray[np.float64]:
        matrix = np.array(self._flat, dtype=np.float64).reshape(self._count, self._width or 0)
        return matrix if dtype is None else matrix.astype(dtype, copy=False)

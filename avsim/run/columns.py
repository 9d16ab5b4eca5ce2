"""Compact columns for a run's per-tick log (`avsim.run.runner.TrajectoryLog`), flat in memory
however long the run.

A column keeps its newest values in a typed array (8 bytes a float, 1 a flag, 4 an int, where
a list holds a 32-byte float object per value) and, once it is given a spill file
(`spill_to`), moves each full chunk of `CHUNK` values there (`avsim.run.spill`): an hour's run
then holds at most a chunk per column in memory. Every read sees the whole
column, in the order appended: indexing, slicing, iteration, `len`, `==` and
``np.asarray(column)``. Chunks are cut at fixed counts of values, so the same run spills the
same way, and the bytes go to the file and back unchanged: the values read are bit for bit
those appended.

`Column` holds numbers (flags as 0 / 1), `Rows` equal-length rows of numbers
(``np.array(rows)`` is the (ticks, width) matrix) and `EnumColumn` members of one enum (a
byte each).
"""

from __future__ import annotations

import enum
from array import array
from collections.abc import Iterator, Sequence
from typing import Any, Generic, TypeVar, overload

import numpy as np
from numpy.typing import NDArray

from avsim.run.spill import SpillFile

CHUNK = 4096  # [values] a column holds in memory before it spills them: 102 s of 40 Hz
#   ticks, 32 kB of floats; an hour's log is then ~35 chunks a column on disk

N = TypeVar("N", int, float)
E = TypeVar("E", bound=enum.Enum)


class Column(Sequence[N]):
    """Numbers of one `array` type code ('d' float64, 'i' int32, 'b' int8)."""

    __slots__ = ("_chunk", "_dtype", "_offsets", "_spill", "_tail", "_typecode")

    def __init__(self, typecode: str, chunk: int = CHUNK) -> None:
        """`chunk`: values kept in memory before they go to the spill file (at least 1)."""
        if chunk < 1:
            raise ValueError(f"a chunk of {chunk} values")
        self._typecode, self._chunk = typecode, chunk
        self._dtype = np.dtype(typecode)
        self._tail: array[Any] = array(typecode)  # the values not spilled
        self._spill: SpillFile | None = None
        self._offsets: list[int] = []  # [bytes] where each spilled chunk starts in the file

    def spill_to(self, spill: SpillFile) -> None:
        """From now on, move each full chunk to `spill` (None before: all in memory)."""
        self._spill = spill
        self._spill_if_full()

    def append(self, value: N) -> None:
        self._tail.append(value)
        if len(self._tail) >= self._chunk:
            self._spill_if_full()

    def extend(self, values: Sequence[N]) -> None:
        self._tail.extend(values)
        self._spill_if_full()

    def _spill_if_full(self) -> None:
        if self._spill is None or len(self._tail) < self._chunk:
            return
        full = len(self._tail) // self._chunk * self._chunk
        view = memoryview(self._tail)
        for start in range(0, full, self._chunk):
            self._offsets.append(self._spill.write(view[start:start + self._chunk]))
        view.release()
        self._tail = self._tail[full:]

    @property
    def spilled(self) -> int:
        """Values on disk (the oldest)."""
        return len(self._offsets) * self._chunk

    def __len__(self) -> int:
        return self.spilled + len(self._tail)

    @overload
    def __getitem__(self, index: int) -> N: ...
    @overload
    def __getitem__(self, index: slice) -> array[Any]: ...
    def __getitem__(self, index: int | slice) -> N | array[Any]:
        if isinstance(index, slice):
            return array(self._typecode, np.asarray(self)[index].tobytes())
        n, spilled = len(self), self.spilled
        i = index + n if index < 0 else index
        if not 0 <= i < n:
            raise IndexError(f"index {index} of a column of {n} values")
        if i >= spilled:
            value: N = self._tail[i - spilled]
            return value
        assert self._spill is not None
        k, j = divmod(i, self._chunk)
        size = self._dtype.itemsize
        return array(self._typecode, self._spill.read(self._offsets[k] + j * size, size))[0]

    def __iter__(self) -> Iterator[N]:
        if not self._offsets:
            return iter(self._tail)
        values: list[N] = np.asarray(self).tolist()
        return iter(values)

    def __array__(self, dtype: Any = None, copy: bool | None = None) -> NDArray[Any]:
        tail = np.frombuffer(self._tail, dtype=self._dtype) if self._tail else \
            np.empty(0, self._dtype)
        if self._offsets:
            assert self._spill is not None
            nbytes = self._chunk * self._dtype.itemsize
            spill, dtype_ = self._spill, self._dtype
            chunks: list[NDArray[Any]] = [np.frombuffer(spill.read(at, nbytes), dtype=dtype_)
                                          for at in self._offsets]
            values = np.concatenate([*chunks, tail])
        else:
            values = tail.copy()  # not a view of the tail, which goes on growing
        return values if dtype is None else values.astype(dtype, copy=False)

    def __eq__(self, other: object) -> bool:
        """Equal values in the same order (NaN equals nothing, as with `array`)."""
        if isinstance(other, Column):
            return len(self) == len(other) and bool(np.array_equal(self, other))
        if isinstance(other, Sequence):
            return list(self) == list(other)
        return NotImplemented

    __hash__ = None  # type: ignore[assignment]  # mutable, as `array`

    def __repr__(self) -> str:
        return f"Column({self._typecode!r}, {len(self)} values, {self.spilled} spilled)"


class Rows:
    """Equal-length rows of numbers appended one at a time (a tick's wheel spins, its actors'
    stations), kept as one flat float64 `Column` that spills whole rows; ``np.array(rows)``
    is the (ticks, width) matrix."""

    __slots__ = ("_chunk", "_count", "_flat", "_spill", "_width")

    def __init__(self, chunk: int = CHUNK) -> None:
        """`chunk`: rows kept in memory before they go to the spill file."""
        self._chunk = chunk
        self._flat: Column[float] = Column("d", chunk)  # remade at the first row's width
        self._spill: SpillFile | None = None
        self._width: int | None = None
        self._count = 0

    def spill_to(self, spill: SpillFile) -> None:
        self._spill = spill
        self._flat.spill_to(spill)

    def append(self, row: NDArray[np.float64]) -> None:
        if self._width is None:
            self._width = len(row)
            self._flat = Column("d", self._chunk * max(1, self._width))
            if self._spill is not None:
                self._flat.spill_to(self._spill)
        elif len(row) != self._width:
            raise ValueError(f"a row of {len(row)} values in rows of {self._width}")
        self._flat.extend(row.tolist())
        self._count += 1

    def __len__(self) -> int:
        return self._count

    def __array__(self, dtype: Any = None, copy: bool | None = None) -> NDArray[np.float64]:
        matrix = np.asarray(self._flat).reshape(self._count, self._width or 0)
        return matrix if dtype is None else matrix.astype(dtype, copy=False)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Rows):
            return NotImplemented
        return self._count == other._count and bool(np.array_equal(self, other))

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        return f"Rows({self._count} of {self._width})"


class EnumColumn(Sequence[E], Generic[E]):
    """Members of one enum, a byte each (their index in the enum's order)."""

    __slots__ = ("_codes", "_index", "_members")

    def __init__(self, kind: type[E], chunk: int = CHUNK) -> None:
        self._members: tuple[E, ...] = tuple(kind)
        if len(self._members) > 256:
            raise ValueError(f"{kind.__name__} has more members than a byte can number")
        self._index = {m: i for i, m in enumerate(self._members)}
        self._codes: Column[int] = Column("B", chunk)

    def spill_to(self, spill: SpillFile) -> None:
        self._codes.spill_to(spill)

    def append(self, member: E) -> None:
        self._codes.append(self._index[member])

    def __len__(self) -> int:
        return len(self._codes)

    @overload
    def __getitem__(self, index: int) -> E: ...
    @overload
    def __getitem__(self, index: slice) -> list[E]: ...
    def __getitem__(self, index: int | slice) -> E | list[E]:
        if isinstance(index, slice):
            return [self._members[c] for c in self._codes[index]]
        return self._members[self._codes[index]]

    def __iter__(self) -> Iterator[E]:
        members = self._members
        return (members[c] for c in self._codes)

    def __eq__(self, other: object) -> bool:
        if isinstance(other, EnumColumn):
            return self._members == other._members and self._codes == other._codes
        if isinstance(other, Sequence):
            return list(self) == list(other)
        return NotImplemented

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        return f"EnumColumn({len(self)} values)"


def floats() -> Column[float]:
    """An empty column of float64 values."""
    return Column("d")


def flags() -> Column[int]:
    """An empty column of flags (0 / 1; appending a bool stores it)."""
    return Column("b")


def ints() -> Column[int]:
    """An empty column of 32-bit integers."""
    return Column("i")

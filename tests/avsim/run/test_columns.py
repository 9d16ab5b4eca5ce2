"""The log's columns read back exactly what was appended, across the chunks they spill to disk,
and leave no file behind (`avsim.run.columns`, `avsim.run.spill`)."""

from __future__ import annotations

import math
import os
from array import array
from pathlib import Path

import numpy as np
import pytest

from avsim.run.columns import CHUNK, Column, EnumColumn, Rows
from avsim.run.runner import TrajectoryLog
from avsim.run.spill import SpillFile
from planner.messages import Motion

SMALL = 3  # [values] a chunk, so that a few values cross several chunk boundaries


def spilled_floats(values: list[float], tmp_path: Path, chunk: int = SMALL) -> Column[float]:
    column: Column[float] = Column("d", chunk)
    column.spill_to(SpillFile(tmp_path))
    for v in values:
        column.append(v)
    return column


@pytest.mark.parametrize("n", [0, 1, SMALL - 1, SMALL, SMALL + 1, 4 * SMALL, 4 * SMALL + 2])
def test_floats_read_back_bit_for_bit_across_chunks(n: int, tmp_path: Path) -> None:
    values = [math.sin(k) * 10.0 ** (k % 7 - 3) for k in range(n)]
    values[1::5] = [math.nan] * len(values[1::5])  # NaN and -0.0 keep their bits
    values[2::5] = [-0.0] * len(values[2::5])
    column = spilled_floats(values, tmp_path)
    assert column.spilled == n // SMALL * SMALL
    assert len(column) == n
    assert np.asarray(column).tobytes() == array("d", values).tobytes()
    assert array("d", list(column)).tobytes() == array("d", values).tobytes()
    for k in range(n):  # each value, spilled or not, and from the end
        both = array("d", [column[k], column[k - n]])
        assert both.tobytes() == array("d", [values[k]] * 2).tobytes()
    assert column[1:-1].tobytes() == array("d", values[1:-1]).tobytes()
    with pytest.raises(IndexError):
        column[n]


def test_ints_and_flags_keep_their_type(tmp_path: Path) -> None:
    spill = SpillFile(tmp_path)
    lanes: Column[int] = Column("i", SMALL)
    flags: Column[int] = Column("b", SMALL)
    for c in (lanes, flags):
        c.spill_to(spill)
    for k in range(10):
        lanes.append(k - 4)
        flags.append(k % 3 == 0)
    assert list(lanes) == list(range(-4, 6)) and lanes[2] == -2
    assert list(flags) == [1, 0, 0] * 3 + [1]
    assert np.asarray(lanes).dtype == np.int32 and np.asarray(flags, dtype=bool).sum() == 4
    assert all(flags[0:10:3]) and not any(flags[1:3])


def test_columns_compare_by_value(tmp_path: Path) -> None:
    a = spilled_floats([1.0, 2.0, 3.0, 4.0], tmp_path)
    b: Column[float] = Column("d")  # all in memory: equal all the same
    for v in (1.0, 2.0, 3.0, 4.0):
        b.append(v)
    assert a == b and a == [1.0, 2.0, 3.0, 4.0]
    b.append(5.0)
    assert a != b
    assert spilled_floats([math.nan], tmp_path) != spilled_floats([math.nan], tmp_path)  # as
    #   `array` compares: NaN equals nothing


def test_rows_read_back_across_chunks(tmp_path: Path) -> None:
    rows = Rows(chunk=2)
    rows.spill_to(SpillFile(tmp_path))
    matrix = np.arange(21.0).reshape(7, 3) / 7.0
    for row in matrix:
        rows.append(row)
    assert len(rows) == 7
    np.testing.assert_array_equal(np.array(rows), matrix)
    with pytest.raises(ValueError, match="a row of 2 values"):
        rows.append(np.zeros(2))


def test_rows_of_no_values(tmp_path: Path) -> None:
    rows = Rows(chunk=2)  # a run without actors: (ticks, 0)
    rows.spill_to(SpillFile(tmp_path))
    for _ in range(5):
        rows.append(np.zeros(0))
    assert np.array(rows).shape == (5, 0)


def test_enum_members_read_back_across_chunks(tmp_path: Path) -> None:
    column = EnumColumn(Motion, SMALL)
    column.spill_to(SpillFile(tmp_path))
    members = [list(Motion)[k * 7 % len(Motion)] for k in range(11)]
    for m in members:
        column.append(m)
    assert list(column) == members and column == members
    assert column[0] is members[0] and column[-1] is members[-1] and column[4] is members[4]
    assert column[2:6] == members[2:6]


def test_a_log_spills_every_column_and_reads_the_whole_run(tmp_path: Path) -> None:
    log = TrajectoryLog()
    n = CHUNK + 5
    for k in range(n):
        log.t.append(k / 40)
        log.lane.append(k % 2)
        log.motion.append(Motion.LANE_KEEP)
        log.wheel_spin.append(np.full(4, float(k)))
    assert log.t.spilled == CHUNK and log.spill.size > 0
    np.testing.assert_array_equal(log.array("t"), np.arange(n) / 40)
    assert log.t[-1] == (n - 1) / 40 and log.t[CHUNK - 1] == (CHUNK - 1) / 40
    assert sum(log.lane) == n // 2 and set(log.motion) == {Motion.LANE_KEEP}
    np.testing.assert_array_equal(np.array(log.wheel_spin)[:, 0], np.arange(n))
    log.close()
    log.close()  # idempotent
    with pytest.raises(ValueError, match="closed"):
        log.array("t")


def test_no_file_is_left_behind_during_after_or_on_an_exception(tmp_path: Path) -> None:
    spill = SpillFile(tmp_path)
    column: Column[float] = Column("d", SMALL)
    column.spill_to(spill)

    class BoomError(Exception):
        pass

    with pytest.raises(BoomError):
        for k in range(10 * SMALL):
            column.append(float(k))
            assert os.listdir(tmp_path) == []  # the file has no name while in use
            if k == 5 * SMALL:
                raise BoomError
    assert spill.size > 0 and list(column)[-1] == 5.0 * SMALL
    spill.close()
    assert os.listdir(tmp_path) == []


def test_a_spill_file_rejects_reads_past_its_end(tmp_path: Path) -> None:
    spill = SpillFile(tmp_path)
    assert spill.write(b"abc") == 0 and spill.write(memoryview(b"de")) == 3
    assert spill.read(1, 3) == b"bcd" and spill.read(5, 0) == b""
    with pytest.raises(ValueError, match=r"bytes 4\.\.6"):
        spill.read(4, 2)
    spill.close()
    with pytest.raises(ValueError, match="closed"):
        spill.write(b"f")

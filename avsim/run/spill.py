"""Where a long run's log keeps its older values: an unnamed temporary file.

An hour's run logs 144,000 control ticks (~40 MB as typed arrays), which would make the
process's memory grow all run long (to be flat within 10 % over an hour). So the log's
columns (`avsim.run.columns`) move their values here chunk by chunk and read them back when
asked for the whole column.

The file is `tempfile.TemporaryFile`: on Linux it is opened with `O_TMPFILE` (or unlinked
right after it is made), so it has no name and nothing is left on disk however the run ends,
a crash or `kill -9` included; its space is freed when it is closed (`close()`, or when the
log is garbage collected). Reads and writes use `os.pread` / `os.pwrite` (POSIX), so they
keep no file position between them.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path
from typing import BinaryIO


class SpillFile:
    """Append-only bytes in an unnamed temporary file, opened at the first write."""

    def __init__(self, directory: Path | None = None) -> None:
        """`directory`: where the file lives while open (None: `tempfile`'s default)."""
        self._directory = directory
        self._file: BinaryIO | None = None
        self._size = 0  # [bytes] written so far
        self._closed = False

    @property
    def size(self) -> int:
        """[bytes] written so far."""
        return self._size

    @property
    def closed(self) -> bool:
        return self._closed

    def write(self, data: bytes | memoryview) -> int:
        """Append `data`; the offset [bytes] it starts at."""
        if self._closed:
            raise ValueError("write to a closed spill file")
        if self._file is None:
            self._file = tempfile.TemporaryFile(dir=self._directory)  # noqa: SIM115 (kept
            #   open for the log's lifetime; closed by `close()` or garbage collection)
        offset = self._size
        view = memoryview(data).cast("B")
        at = offset
        while view:  # pwrite may write less than asked
            done = os.pwrite(self._file.fileno(), view, at)
            view, at = view[done:], at + done
        self._size = at
        return offset

    def read(self, offset: int, size: int) -> bytes:
        """`size` bytes from `offset` [bytes], all of them written before."""
        if offset < 0 or offset + size > self._size:
            raise ValueError(f"bytes {offset}..{offset + size} of a spill file of {self._size}")
        if size == 0:
            return b""
        if self._file is None or self._closed:
            raise ValueError("read from a closed spill file")
        parts, at = [], offset
        while at < offset + size:  # pread may read less than asked
            part = os.pread(self._file.fileno(), offset + size - at, at)
            if not part:
                raise OSError(f"spill file ended at byte {at} of {offset + size}")
            parts.append(part)
            at += len(part)
        return b"".join(parts)

    def close(self) -> None:
        """Free the file's space (idempotent); the values spilled cannot be read after."""
        self._closed = True
        if self._file is not None:
            self._file.close()

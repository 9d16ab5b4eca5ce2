"""Reading a file a stranger names: only a regular file, and never more than a bound.

`read_bounded` opens the path without blocking (a FIFO would otherwise wait forever for a
writer), checks on the open descriptor that it is a regular file (so a symlink swapped
after a check, `/dev/zero`, a device or a socket is refused), and reads at most
`max_bytes + 1` bytes whatever `st_size` says (a file that grows while it is read cannot
make the reader take more). Problems are `UnreadableFileError`s whose text is one short
clause for the caller's one-line message.
"""

from __future__ import annotations

import errno
import os
import stat
from pathlib import Path

_CHUNK = 1 << 16  # [B] bytes read per call


class UnreadableFileError(Exception):
    """The file cannot be read as asked: `problem` is one short clause (`no such file`,
    `not a regular file (a FIFO)`, `over 524288 bytes`, ...)."""

    def __init__(self, problem: str) -> None:
        super().__init__(problem)
        self.problem = problem


def _kind(mode: int) -> str:
    """What a non-regular file is, in words."""
    kinds = ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO"),
             (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
             (stat.S_ISSOCK, "a socket"))
    return next((word for test, word in kinds if test(mode)), "not a plain file")


def _open_problem(exc: OSError) -> str:
    """The clause for an `open` that failed."""
    words = {errno.ENOENT: "no such file", errno.ELOOP: "a symlink loop",
             errno.EISDIR: "is a directory, not a file", errno.EACCES: "permission denied",
             errno.ENAMETOOLONG: "its name is too long", errno.ENOTDIR: "no such file"}
    return words.get(exc.errno or 0, f"cannot read it ({exc.strerror})")


def read_bounded(path: Path, max_bytes: int) -> bytes:
    """The bytes of the regular file at `path` (symlinks followed), at most `max_bytes` of
    them; an `UnreadableFileError` for anything else."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | os.O_CLOEXEC)
    except OSError as exc:
        raise UnreadableFileError(_open_problem(exc)) from None
    try:
        mode = os.fstat(fd).st_mode
        if not stat.S_ISREG(mode):
            raise UnreadableFileError(f"not a regular file ({_kind(mode)})")
        chunks: list[bytes] = []
        got = 0
        while got <= max_bytes:
            chunk = os.read(fd, min(_CHUNK, max_bytes + 1 - got))
            if not chunk:
                break
            chunks.append(chunk)
            got += len(chunk)
        if got > max_bytes:
            raise UnreadableFileError(f"over {max_bytes} bytes: at most {max_bytes}")
        return b"".join(chunks)
    except OSError as exc:
        raise UnreadableFileError(f"cannot read it ({exc.strerror})") from None
    finally:
        os.close(fd)

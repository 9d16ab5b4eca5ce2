"""Files that appear whole: written to a temporary file beside the target, then renamed
over it (a reader never sees half a file; a failure leaves nothing behind).

Every temporary file is created exclusively (`O_EXCL`, no symlink followed: what
`tempfile.mkstemp` does) under an unpredictable name, so that nobody who can write to the
folder can make avsim write through a link or a name they placed there. Its name is
`.NAME.XXXXXXXX.partial`, `NAME` cut to `PREFIX_BYTES` so that the whole name stays within
the file system's limit of `NAME_MAX` bytes whatever the target's name.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

FILE_MODE = 0o644  # [-] permission bits, as a plain `open` makes them (mkstemp: 0o600)
NAME_MAX = 255  # [bytes] the longest file name (Linux, macOS, Windows file systems)
PREFIX_BYTES = 200  # [bytes] of the target's name in a temporary name: with the dot, the
#   random part (8), the separator and `.partial` the name stays under NAME_MAX
TEMP_SUFFIX = ".partial"


def temporary_beside(path: Path) -> Path:
    """A new empty file in `path`'s folder (made if needed), created exclusively under an
    unpredictable name (module doc); the caller renames it over `path` (`publish`) or
    removes it."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, name = tempfile.mkstemp(dir=path.parent, prefix=_prefix(path), suffix=TEMP_SUFFIX)
    os.close(fd)
    return Path(name)


def publish(tmp: Path, path: Path) -> None:
    """Give the temporary file `tmp` plain permissions and rename it over `path` (the same
    folder: the rename is atomic)."""
    tmp.chmod(FILE_MODE)
    tmp.replace(path)


def write_atomic(path: Path, data: str | bytes) -> None:
    """Write `data` (text as UTF-8) to `path`, making its folder if needed."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, name = tempfile.mkstemp(dir=path.parent, prefix=_prefix(path), suffix=TEMP_SUFFIX)
    tmp = Path(name)
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data.encode() if isinstance(data, str) else data)
        publish(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def write_new(folder: Path, prefix: str, suffix: str, data: str) -> Path:
    """Write `data` (UTF-8) to a new file in `folder` named `PREFIX<random>SUFFIX`, created
    exclusively (module doc), and return its path; `prefix` is cut to `PREFIX_BYTES`."""
    fd, name = tempfile.mkstemp(dir=folder, prefix=_cut(prefix), suffix=suffix)
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data.encode())
    except BaseException:
        Path(name).unlink(missing_ok=True)
        raise
    return Path(name)


def _prefix(path: Path) -> str:
    """`.NAME.`, NAME cut to `PREFIX_BYTES`."""
    return f".{_cut(path.name)}."


def _cut(name: str) -> str:
    """`name` cut to its first `PREFIX_BYTES` bytes (file system encoding)."""
    return os.fsdecode(os.fsencode(name)[:PREFIX_BYTES])

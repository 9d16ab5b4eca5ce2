"""Where a scenario's referenced files may come from: the scenario file's own folder tree,
or a search path the user names (`--search-path DIR`, as esmini's `--path`).

A reference (the road's `LogicFile`, a catalog `Directory`, the sidecar found beside the
file) is tried relative to the scenario's folder, then relative to each search path in
order; the first that exists is taken (none: the first, for the caller's "not found"). Its
symlinks are resolved before the check, so a link that leads out of the allowed folders is
refused like a path that does (`/etc/passwd`, `../../..`). An explicit `--criteria FILE` is
the user's own choice and is not checked here.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

MAX_SEARCH_PATHS = 32  # the most `--search-path` folders
MAX_REFERENCE_CHARS = 1000  # the longest file or folder reference an attribute may write


class ReferenceError(ValueError):
    """A reference is refused: the message is one short clause."""


def _real(path: Path) -> Path:
    """`path` with every symlink resolved (missing parts kept as written)."""
    try:
        return path.resolve()
    except RuntimeError:  # a symlink loop (an OSError from Python 3.13)
        raise ReferenceError(f"a symlink loop: {path}") from None
    except OSError as exc:
        raise ReferenceError(f"cannot resolve {path} ({exc.strerror})") from None


def _exists(path: Path) -> bool:
    try:
        return path.exists()
    except OSError:  # a name too long for the file system, ...
        return False


def is_file(path: Path) -> bool:
    """Whether `path` is a file (False where the file system refuses to look: a name too
    long, ...)."""
    try:
        return path.is_file()
    except OSError:
        return False


def is_dir(path: Path) -> bool:
    """Whether `path` is a directory (False where the file system refuses to look)."""
    try:
        return path.is_dir()
    except OSError:
        return False


@dataclass(frozen=True, slots=True)
class Roots:
    """The folders a scenario's references may resolve into, each with symlinks resolved."""

    base: Path  # the scenario file's folder
    search: tuple[Path, ...] = ()  # the user's search paths, in order

    @classmethod
    def of(cls, scenario: Path, search_paths: Sequence[Path] = ()) -> Roots:
        """The roots of the scenario file `scenario` with the user's `search_paths`."""
        if len(search_paths) > MAX_SEARCH_PATHS:
            raise ReferenceError(f"{len(search_paths)} search paths: at most {MAX_SEARCH_PATHS}")
        return cls(_real(Path(scenario)).parent, tuple(_real(Path(p)) for p in search_paths))

    def allows(self, real: Path) -> bool:
        """Whether the resolved path `real` lies in the scenario's folder tree or in a
        search path's."""
        return any(real == root or real.is_relative_to(root)
                   for root in (self.base, *self.search))

    def find(self, written: str) -> Path:
        """The resolved path a reference written as `written` names (module doc);
        `ReferenceError` when it is too long, loops or leads out of the allowed folders."""
        if len(written) > MAX_REFERENCE_CHARS:
            raise ReferenceError(f"{len(written)} characters: at most {MAX_REFERENCE_CHARS}")
        if "\0" in written:
            raise ReferenceError("a NUL character in the path")
        candidates = [_real(root / written) for root in (self.base, *self.search)]
        chosen = next((c for c in candidates if _exists(c)), candidates[0])
        if not self.allows(chosen):
            raise ReferenceError(
                f"{chosen} is outside the scenario's folder and the search paths "
                "(--search-path DIR allows another folder)")
        return chosen

    def check(self, path: Path) -> Path:
        """The resolved `path` (a file found beside the scenario), refused like `find`'s."""
        real = _real(path)
        if not self.allows(real):
            raise ReferenceError(
                f"{real} is outside the scenario's folder and the search paths "
                "(--search-path DIR allows another folder)")
        return real

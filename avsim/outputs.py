"""A command's output files: checked before it runs, locked while it runs, kept if a write
fails after it (docs/cli.md, "Outputs").

Before anything runs (`check_outputs`; bad input, nothing written):

- every output differs from every other output and from every input file of the scenario
  (`Scenario.sources`), compared after resolving symlinks and `..`, and by device and inode
  where the file exists (a hard link is the same file); an existing OpenSCENARIO file
  (`.xosc`: a scenario or a catalog) is never an output;
- an output is a regular file or does not exist yet: never a directory, device, FIFO or
  socket (writing would replace the node with a file);
- its name is at most `NAME_MAX` bytes, and its folder exists or can be made (its nearest
  existing ancestor is a directory) and is writable: `os.access`, then a real check
  (a file created exclusively there and removed at once).

While it runs (`output_lock`): each output's lock file, `.NAME.<hash>.lock` beside it, is
held (`flock`) from before the run until its files are written; a second command writing the
same file is refused (`OutputBusyError`) instead of both writing it. A batch (suite, sweep)
holds its `--out` folder's lock (`batch_lock`: `BATCH_LOCK` in the folder) from before its
first run until its reports are written: a second batch into the same folder is refused.

After it runs, a write that fails (a read-only or removed folder, a full disk) keeps the
result: `keep_result` writes the result JSON to a new file in the system's temporary folder
and the command says where, in one line.
"""

from __future__ import annotations

import fcntl
import hashlib
import os
import stat
import tempfile
from collections.abc import Callable, Iterator, Sequence
from contextlib import ExitStack, contextmanager
from dataclasses import dataclass
from pathlib import Path

from avsim.files import NAME_MAX, publish, temporary_beside, write_atomic, write_new

LOCK_SUFFIX = ".lock"
LOCK_HASH_CHARS = 16  # [-] hex digits of the resolved path's SHA-256 in a lock file's name
LOCK_NAME_CHARS = 100  # [-] characters of the output's name in its lock file's name
PROBE_PREFIX = ".avsim-probe-"  # the folder check's file (removed at once)
BATCH_LOCK = ".avsim-batch.lock"  # a batch folder's lock file, in the folder


class OutputError(Exception):
    """An output that cannot be written: `<file>: <option>: <problem>`, one line."""

    def __init__(self, path: Path, option: str, problem: str) -> None:
        super().__init__(f"{path}: {option}: {problem}")
        self.path = path
        self.option = option
        self.problem = problem


class OutputBusyError(OutputError):
    """Another command holds the output's lock (it is writing the same file)."""


@dataclass(frozen=True, slots=True)
class Output:
    """A file a command writes, and the option that named it (for the message)."""

    option: str  # e.g. "--out", "--json", "--plot"
    path: Path


Identity = tuple[Path, tuple[int, int] | None]  # resolved path, (st_dev, st_ino) if it exists


def identity(path: Path) -> Identity:
    """Where `path` leads: its resolved path (symlinks and `..` followed) and, when it
    exists, its device and inode (`OSError` for a symlink loop)."""
    try:
        resolved = path.resolve()
    except RuntimeError as exc:  # Python < 3.13 raises it for a symlink loop
        raise OSError(str(exc)) from None
    try:
        st = os.stat(resolved)
    except OSError:
        return resolved, None
    return resolved, (st.st_dev, st.st_ino)


def same_file(a: Identity, b: Identity) -> bool:
    """Whether two identities are one file: the same resolved path or the same inode."""
    return a[0] == b[0] or (a[1] is not None and a[1] == b[1])


def check_outputs(outputs: Sequence[Output], inputs: Sequence[Path]) -> None:
    """Raise `OutputError` for the first output that breaks a rule of the module doc."""
    sources = [(path, _identity_of(path)) for path in inputs]
    seen: list[tuple[Output, Identity]] = []
    for output in outputs:
        ident = _identity_of(output.path, output)
        _check_node(output, ident)
        for source, source_ident in sources:
            if same_file(ident, source_ident):
                raise OutputError(output.path, output.option, f"is an input of the run "
                                  f"({source}): avsim never writes over its inputs")
        for other, other_ident in seen:
            if same_file(ident, other_ident):
                raise OutputError(output.path, output.option, f"the same file as "
                                  f"{other.option} ({other.path}): each output needs its own")
        _check_folder(output)
        seen.append((output, ident))


def _identity_of(path: Path, output: Output | None = None) -> Identity:
    """`identity`, its failure as an `OutputError` (for an input: a path that cannot be
    resolved cannot be named by an output either, so it is left as it is)."""
    try:
        return identity(path)
    except OSError as exc:
        if output is None:
            return path, None
        raise OutputError(output.path, output.option, f"cannot be resolved ({exc})") from None


def _check_node(output: Output, ident: Identity) -> None:
    """An output is a regular file or nothing yet, with a name that fits."""
    if len(os.fsencode(output.path.name)) > NAME_MAX:
        raise OutputError(output.path, output.option, f"the file name is longer than "
                          f"{NAME_MAX} bytes")
    if ident[1] is None:
        return
    mode = os.stat(ident[0]).st_mode
    if stat.S_ISDIR(mode):
        raise OutputError(output.path, output.option, "is a directory")
    if not stat.S_ISREG(mode):
        raise OutputError(output.path, output.option, "not a regular file (a device, FIFO "
                          "or socket): avsim writes only regular files")
    if ident[0].suffix == ".xosc":
        raise OutputError(output.path, output.option, "an OpenSCENARIO file (a scenario or "
                          "a catalog): avsim never writes over one")


def _check_folder(output: Output) -> None:
    """The output's folder exists and is writable, or its nearest existing ancestor is a
    directory where it can be made."""
    for folder in output.path.absolute().parents:
        if not folder.exists():
            continue
        if not folder.is_dir():
            raise OutputError(output.path, output.option, f"{folder} is not a directory")
        if not (os.access(folder, os.W_OK | os.X_OK) and _can_create_in(folder)):
            raise OutputError(output.path, output.option, f"cannot write in {folder}")
        return


def _can_create_in(folder: Path) -> bool:
    """Whether a file can be created in `folder` (it is created exclusively and removed):
    `os.access` says yes to root on a folder a read-only mount or its attributes protect."""
    try:
        fd, name = tempfile.mkstemp(dir=folder, prefix=PROBE_PREFIX)
    except OSError:
        return False
    os.close(fd)
    os.unlink(name)
    return True


# ---- locks ---------------------------------------------------------------------------------


def lock_path(path: Path) -> Path:
    """The lock file of the output `path` (its folder must exist): beside the file `path`
    resolves to, named after it and its resolved path's hash (two names of one file share
    the lock; the name stays within `NAME_MAX`)."""
    resolved = path.resolve()
    digest = hashlib.sha256(os.fsencode(resolved)).hexdigest()[:LOCK_HASH_CHARS]
    return resolved.with_name(f".{resolved.name[:LOCK_NAME_CHARS]}.{digest}{LOCK_SUFFIX}")


@contextmanager
def output_lock(outputs: Sequence[Output]) -> Iterator[None]:
    """Hold every output's lock (module doc) for the block: `OutputBusyError` when another
    command holds one (no lock kept then). The lock files are removed at the end."""
    with ExitStack() as held:
        for output in sorted(outputs, key=lambda o: str(lock_path(o.path))):
            held.enter_context(_locked(output))
        yield


@contextmanager
def batch_lock(folder: Path) -> Iterator[None]:
    """Make the batch folder `folder` (and its parents) and hold its lock, `BATCH_LOCK` in
    it, for the block: `OutputBusyError` when another batch holds it (another suite or
    sweep writing into the same folder), `OutputError` when the folder cannot be made. The
    lock file is removed at the end."""
    output = Output("--out", folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputError(folder, "--out", f"the folder cannot be made ({exc.strerror})"
                          ) from None
    with _locked(output, folder.resolve() / BATCH_LOCK, "writing into this folder"):
        yield


@contextmanager
def _locked(output: Output, path: Path | None = None,
            doing: str = "writing this file") -> Iterator[None]:
    """Hold `output`'s lock file (`path`, by default `lock_path(output.path)`): opened
    without following a symlink, locked without waiting, and still the file at its name
    once locked (a command that ended meanwhile removes its lock file: then the lock is the
    new command's to make). `doing`: what the holder does, for the busy message."""
    path = path if path is not None else lock_path(output.path)
    try:
        fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_CLOEXEC, 0o644)
    except OSError as exc:
        raise OutputError(output.path, output.option,
                          f"cannot open its lock file {path} ({exc.strerror})") from None
    try:
        _lock_fd(fd, path, output, doing)
        try:
            yield
        finally:
            path.unlink(missing_ok=True)  # before the unlock: no one locks a removed file
    finally:
        os.close(fd)


def _lock_fd(fd: int, path: Path, output: Output, doing: str) -> None:
    """Lock the open lock file `fd` (at `path`) or raise `OutputBusyError`."""
    busy = OutputBusyError(output.path, output.option, f"another avsim command is {doing} "
                           f"(it holds {path}); try again when it has ended")
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        raise busy from None
    mine = os.fstat(fd)
    try:
        there = os.stat(path, follow_symlinks=False)
    except FileNotFoundError:
        raise busy from None
    if not stat.S_ISREG(mine.st_mode) or (there.st_dev, there.st_ino) != (mine.st_dev,
                                                                          mine.st_ino):
        raise busy


# ---- after the run -------------------------------------------------------------------------


def keep_result(name: str, data: str) -> Path:
    """Write a result JSON that could not go where it was asked to a new file in the
    system's temporary folder, `avsim-result-<name>-<random>.json` (created exclusively),
    and return its path (`OSError` when that fails too)."""
    return write_new(Path(tempfile.gettempdir()), f"avsim-result-{name}-", ".json", data)


@dataclass(frozen=True, slots=True)
class RunFiles:
    """The files one `avsim run` writes."""

    recording: Path  # --out: the .rrd
    result: Path  # --json: the result JSON
    plot: Path | None = None  # --plot: the speed profile PNG, if asked

    def outputs(self) -> tuple[Output, ...]:
        """Each file with its option."""
        named = [Output("--out", self.recording), Output("--json", self.result)]
        return (*named, *([Output("--plot", self.plot)] if self.plot is not None else []))


class Claim:
    """What `claim_outputs` holds for a run, until the end of its `with` block: the outputs'
    locks and the recording's temporary file `partial`, removed at the end unless `deliver`
    renamed it into place or kept it for the user (`keep`)."""

    def __init__(self, partial: Path, locks: ExitStack) -> None:
        self.partial = partial  # the recording's temporary file, created beside `--out`
        self.keep = False  # leave `partial` at the end
        self._locks = locks

    def __enter__(self) -> Claim:
        return self

    def __exit__(self, *exc: object) -> None:
        try:
            if not self.keep:
                self.partial.unlink(missing_ok=True)
        finally:
            self._locks.close()


def claim_outputs(files: RunFiles) -> Claim:
    """Make the outputs' folders, take their locks (`output_lock`) and create the
    recording's temporary file (`avsim.files.temporary_beside`), for the run to write.
    `OutputError` (`OutputBusyError` for a lock another command holds), nothing held then."""
    outputs = files.outputs()
    for output in outputs:
        try:
            output.path.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise OutputError(output.path, output.option,
                              f"its folder cannot be made ({exc.strerror})") from None
    with ExitStack() as locks:
        locks.enter_context(output_lock(outputs))
        try:
            partial = temporary_beside(files.recording)
        except OSError as exc:
            raise OutputError(files.recording, "--out", f"cannot create a temporary file "
                              f"beside it ({exc.strerror})") from None
        return Claim(partial, locks.pop_all())
    raise AssertionError("unreachable")  # the block returns or raises


def deliver(files: RunFiles, claim: Claim, name: str, result_text: str,
            draw_plot: Callable[[Path], object] | None) -> str | None:
    """Rename the recording `claim.partial` into place, write the result JSON `result_text`
    and draw the plot (`draw_plot(path)`, when `files.plot` is set). None when every file
    was written; else one line: the first file that could not be, why, and where the result
    is (its `--json` file, else a new file from `keep_result`) and the recording so far."""
    steps: list[tuple[Output, Callable[[], object]]] = [
        (Output("--out", files.recording), lambda: publish(claim.partial, files.recording)),
        (Output("--json", files.result), lambda: write_atomic(files.result, result_text)),
    ]
    if files.plot is not None and draw_plot is not None:
        plot = files.plot
        steps.append((Output("--plot", plot), lambda: draw_plot(plot)))
    failures: list[tuple[Output, OSError]] = []
    for output, step in steps:
        try:
            step()
        except OSError as exc:
            failures.append((output, exc))
    if not failures:
        return None
    return _failure_line(files, claim, name, result_text, failures)


def _failure_line(files: RunFiles, claim: Claim, name: str, result_text: str,
                  failures: list[tuple[Output, OSError]]) -> str:
    """The one line `deliver` returns (its doc)."""
    first, exc = failures[0]
    line = f"{first.path}: {first.option}: could not be written ({exc.strerror or exc})"
    if any(output.option == "--json" for output, _ in failures):
        try:
            line += f"; the result is kept in {keep_result(name, result_text)}"
        except OSError as kept:
            line += f"; the result could not be kept either ({kept.strerror or kept})"
    else:
        line += f"; the result is in {files.result}"
    if any(output.option == "--out" for output, _ in failures) and claim.partial.exists():
        claim.keep = True
        line += f"; the recording so far is in {claim.partial}"
    return line

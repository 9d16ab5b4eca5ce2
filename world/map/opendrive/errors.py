"""The one error of the OpenDRIVE reader: where (file, line, element path) and what."""

from __future__ import annotations

from pathlib import Path


class OpenDriveError(ValueError):
    """An .xodr file that cannot be read. `str()` is one line:
    `<file>:<line>: <element path>: <problem>` for an element, `<file>: <problem>` for the
    file as a whole (not found, too big, malformed XML: the problem then names the line)."""

    def __init__(
        self, file: Path | str, problem: str, line: int | None = None, path: str | None = None
    ) -> None:
        self.file = str(file)
        self.problem = " ".join(problem.split())  # one line, whatever the problem text holds
        self.line = line  # 1-based line of the element's start tag, None for the whole file
        self.path = path  # the element path, e.g. /OpenDRIVE/road[id=0]/planView/geometry[3]
        where = self.file if line is None else f"{self.file}:{line}"
        message = f"{where}: {path}: {self.problem}" if path else f"{where}: {self.problem}"
        super().__init__(" ".join(message.splitlines()))  # one line, whatever an id holds

"""The loader's errors: `ScenarioError`, the one line a user sees, and `LocatedError`, a
problem at a key before the file's name is attached; plus how values from a file are shown
in messages.

Every problem with a scenario file is reported as one line `<file>: <key.path>: <problem>`.
The key path joins mapping keys and list indices with dots (`actors.0.lane`); it is
`line N` for a YAML syntax error and `(file)` (`FILE_KEY`) for the file as a whole.
"""

from __future__ import annotations

import math

FILE_KEY = "(file)"  # the key of a problem with the file as a whole

KeyPath = tuple[str | int, ...]  # a path into the file: mapping keys and list indices


class ScenarioError(Exception):
    """A scenario file cannot be loaded. `str()` is one line: `<file>: <key.path>: <problem>`.

    `key` is a dotted path into the file (`actors.0.lane`), `line N` for YAML syntax errors,
    or `(file)` for the file as a whole.
    """

    def __init__(self, file: str, key: str, problem: str) -> None:
        super().__init__(file, key, problem)
        self.file = file
        self.key = key
        self.problem = problem

    def __str__(self) -> str:
        return f"{self.file}: {self.key}: {self.problem}"


class LocatedError(Exception):
    """A problem at a key, before the file's name is attached: the loading steps raise it,
    `load_scenario` turns it into a `ScenarioError`."""

    def __init__(self, key: str, problem: str) -> None:
        super().__init__(key, problem)
        self.key = key
        self.problem = problem


def dotted(loc: KeyPath) -> str:
    """The key path as the message names it: `actors.0.lane`, or `(file)` when empty."""
    return ".".join(str(part) for part in loc) or FILE_KEY


def show(value: object) -> str:
    """A short rendering of a value from the file, for messages."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if value is None:
        return "null (nothing)"
    if isinstance(value, dict):
        return "a mapping"
    if isinstance(value, list | tuple):
        return "a list"
    if isinstance(value, int | float):
        return fmt(value)
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def fmt(value: object) -> str:
    """A number without a trailing `.0`."""
    if isinstance(value, float) and math.isfinite(value) and value.is_integer():
        return str(int(value))
    if isinstance(value, float):
        return f"{value:.6g}"
    return str(value)


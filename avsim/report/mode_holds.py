"""Mode chatter over many runs (outside safety transitions, no ACC mode is
held for less than 0.5 s): every hold under a minimum, read from the runs' result files by
the rule of `avsim.run.holds` (the one the chatter test and the ``acc_shortest_mode``
metric use).

    python -m avsim.report.mode_holds PATH... [--machine acc] [--min-hold 0.5]

PATH is a result JSON (`avsim run --json`, a suite's result files, or a golden record of
`tests/scenarios/golden`: anything with a ``state_changes`` list of ``t``, ``machine``,
``from``, ``to``, ``reason``) or a folder of them (its ``*.json``). Prints one line per run
(counted holds, the shortest, how many under the minimum), each short hold, and a total.
Exit 0 when no hold is under the minimum, 1 when some are, 2 on bad input (one line naming
the file and the problem). A measuring script, not a test: the figures are for reports.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from avsim.report.states import RecordedChange
from avsim.run.holds import Hold, holds

MIN_HOLD = 0.5  # [s] the least hold of an ACC mode outside safety transitions


class BadResultError(Exception):
    """A file that is not a run's result: its message is the one-line error."""


@dataclass(frozen=True, slots=True)
class RunHolds:
    label: str  # the run (its file's stem)
    holds: tuple[Hold, ...]  # the counted holds (`avsim.run.holds.holds`)

    @property
    def shortest(self) -> float:
        """[s] the shortest counted hold (inf: none)."""
        return min((h.duration for h in self.holds), default=math.inf)

    def under(self, min_hold: float) -> list[Hold]:
        return [h for h in self.holds if h.duration < min_hold]


def result_files(paths: Sequence[Path]) -> list[Path]:
    """The result files named, a folder's ``*.json`` in name order."""
    out: list[Path] = []
    for p in paths:
        if p.is_dir():
            out += sorted(p.glob("*.json"))
        elif p.is_file():
            out.append(p)
        else:
            raise BadResultError(f"{p}: no such file or folder")
    return out


def state_changes(path: Path) -> list[RecordedChange]:
    """The state changes of the result file at `path`."""
    try:
        record = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as e:
        raise BadResultError(f"{path}: not a readable JSON file ({e})") from e
    rows = record.get("state_changes") if isinstance(record, dict) else None
    if not isinstance(rows, list):
        raise BadResultError(f"{path}: state_changes: missing or not a list (not a run's result)")
    try:
        return [RecordedChange(float(c["t"]), str(c["machine"]), str(c["from"]),
                               str(c["to"]), str(c.get("reason", ""))) for c in rows]
    except (KeyError, TypeError, ValueError) as e:
        raise BadResultError(f"{path}: state_changes: an entry lacks t, machine, from or to "
                       f"({e!r})") from e


def measure(paths: Sequence[Path], machine: str = "acc") -> list[RunHolds]:
    """The counted holds of `machine` in each result file."""
    return [RunHolds(p.stem, tuple(holds(state_changes(p), machine)))
            for p in result_files(paths)]


def report(runs: Sequence[RunHolds], min_hold: float, machine: str = "acc") -> str:
    """The table: per run, its holds, the shortest and those under `min_hold` [s]."""
    width = max((len(r.label) for r in runs), default=3)
    lines = [f"{'run':<{width}}  holds  shortest [s]  under {min_hold:g} s"]
    for r in runs:
        lines.append(f"{r.label:<{width}}  {len(r.holds):5d}  {r.shortest:12.3f}  "
                     f"{len(r.under(min_hold)):d}")
        lines += [f"  {h.mode} held {h.duration:.3f} s from {h.t:.3f} s, then {h.then}"
                  for h in r.under(min_hold)]
    short = [r for r in runs if r.under(min_hold)]
    counted = sum(len(r.holds) for r in runs)
    worst = min(runs, key=lambda r: r.shortest, default=None)
    lines.append(f"total: {len(runs)} runs, {counted} {machine} holds outside safety "
                 f"transitions, {sum(len(r.under(min_hold)) for r in short)} under "
                 f"{min_hold:g} s in {len(short)} runs"
                 + (f"; shortest {worst.shortest:.3f} s ({worst.label})"
                    if worst is not None and math.isfinite(worst.shortest) else ""))
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m avsim.report.mode_holds",
                                     description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("paths", nargs="+", type=Path, help="result JSON files or folders")
    parser.add_argument("--machine", default="acc", help="state machine (default: acc)")
    parser.add_argument("--min-hold", type=float, default=MIN_HOLD,
                        help="[s] least hold (default: 0.5)")
    args = parser.parse_args(argv)
    try:
        runs = measure(args.paths, args.machine)
    except BadResultError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    print(report(runs, args.min_hold, args.machine))
    return 1 if any(r.under(args.min_hold) for r in runs) else 0


if __name__ == "__main__":
    sys.exit(main())

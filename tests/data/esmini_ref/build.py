"""Build this folder's compact copy of the esmini reference runs (README.md).

Usage: python tests/data/esmini_ref/build.py SOURCE_DIR
(SOURCE_DIR: the full reference, one `<output>.csv` and `<output>_events.csv` per run and
its `index.csv`.) Writes, per run of the index, `<output>.csv.gz`: every non-Ego entity's
`time,name,x,y,h` at the samples whose time is a multiple of `STEP` (and the last one),
and `<output>_events.csv.gz`: `time,element_type,element_name,from_state,to_state`, every
state change esmini logged; and `index.csv`: the index's columns the tests read. Output is
deterministic (gzip without a timestamp).
"""

from __future__ import annotations

import csv
import gzip
import io
import sys
from pathlib import Path

STEP = 0.1  # [s] the kept trajectory step (esmini's is 0.025 s or 0.05 s)
EGO = "ego"  # the car under test's entity name (lower case): not kept
INDEX_COLUMNS = ("output", "set", "source_file", "scenario_file", "run", "permutation",
                 "parameters", "t_end_s", "entities", "event_starts", "collisions",
                 "row_step_s", "time_limit_added_s")
HERE = Path(__file__).resolve().parent


def _write_gz(path: Path, header: list[str], rows: list[list[str]]) -> None:
    text = io.StringIO()
    writer = csv.writer(text, lineterminator="\n")
    writer.writerow(header)
    writer.writerows(rows)
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("wb") as raw, gzip.GzipFile(fileobj=raw, mode="wb", mtime=0,
                                               filename="") as gz:
        gz.write(text.getvalue().encode())


def _kept(t: float, last: float) -> bool:
    k = round(t / STEP)
    return abs(t - k * STEP) < 1e-6 or t == last


def _trajectories(src: Path) -> list[list[str]]:
    with src.open() as f:
        rows = list(csv.DictReader(f))
    last = max(float(r["time"]) for r in rows)
    return [[r["time"], r["name"], r["x"], r["y"], r["h"]] for r in rows
            if r["name"].lower() != EGO and _kept(float(r["time"]), last)]


def _events(src: Path) -> list[list[str]]:
    with src.open() as f:
        return [[r["time"], r["element_type"], r["element_name"], r["from_state"],
                 r["to_state"]]
                for r in csv.DictReader(f)]


def build(source: Path, out: Path = HERE) -> None:
    with (source / "index.csv").open() as f:
        index = list(csv.DictReader(f))
    for run in index:
        name = run["output"]
        _write_gz(out / f"{name}.csv.gz", ["time", "name", "x", "y", "h"],
                  _trajectories(source / f"{name}.csv"))
        _write_gz(out / f"{name}_events.csv.gz",
                  ["time", "element_type", "element_name", "from_state", "to_state"],
                  _events(source / f"{name}_events.csv"))
    with (out / "index.csv").open("w", newline="") as f:
        writer = csv.writer(f, lineterminator="\n")
        writer.writerow(INDEX_COLUMNS)
        writer.writerows([[run[c] for c in INDEX_COLUMNS] for run in index])


if __name__ == "__main__":
    build(Path(sys.argv[1]))

"""The vendored esmini reference (`tests/data/esmini_ref/`) and avsim's play of the same
file with a scripted car under test, side by side.

`runs()` lists every run of the reference; `play(run)` loads its scenario file (vendored
unchanged in `tests/data/`: `alks/`, `ncap/`, `asam_examples/`; a distribution file's
permutation K with its parameter values, `concrete`) with `scripted_ego`, runs it without
sensors and keeps every storyboard transition and every entity's reference point at each
trigger check (the director's snapshots). `event_starts` and `path_rms` compare.
"""

from __future__ import annotations

import csv
import gzip
import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from avsim.run.runner import Runner
from avsim.run.storyboard.snapshot import Snapshot
from avsim.scenario.load import load_scenario
from avsim.scenario.openscenario.distribution import load_distribution

DATA = Path(__file__).resolve().parents[1] / "data"
REF = DATA / "esmini_ref"
ALKS_PREFIX = "shared/standards/alks/"
EVENT_TOLERANCE = 0.05  # [s] an event starts within this of esmini's start
RMS_TOLERANCE = 0.2  # [m] an entity's path within this RMS of esmini's
END_MARGIN = 1.0  # [s] avsim plays this beyond esmini's end (an event starting there counts)


@dataclass(frozen=True, slots=True)
class RefRun:
    """One line of the reference's index."""

    output: str  # path stem below `REF`
    source: str  # the file esmini was given, `shared/standards/...`
    run: str  # default / --disable_controllers
    set: str
    time_limit_added: bool  # esmini was given a copy with a 60 s time limit
    permutation: int | None  # a distribution file's 0-based run (esmini's --param_permutation)
    parameters: str  # the values that permutation set, as esmini listed them (`N=V; ...`)
    t_end: float  # [s] when esmini's run ended

    @property
    def id(self) -> str:
        return self.output


def runs() -> list[RefRun]:
    with (REF / "index.csv").open() as f:
        return [RefRun(r["output"], r["source_file"], r["run"], r["set"],
                       bool(r["time_limit_added_s"]),
                       int(r["permutation"]) if r["permutation"] else None,
                       r["parameters"], float(r["t_end_s"])) for r in csv.DictReader(f)]


def scenario_file(run: RefRun) -> tuple[Path, list[Path]]:
    """(the file esmini was given, its search paths) for `run` on this machine: a scenario
    file, or for a permutation run the ParameterValueDistribution file."""
    if run.source.startswith(ALKS_PREFIX):
        return DATA / "alks" / run.source.removeprefix(ALKS_PREFIX), []
    rel = run.source.removeprefix("shared/standards/")
    root = DATA / rel.split("/")[0]
    return DATA / rel, [root]


def concrete(run: RefRun) -> tuple[Path, dict[str, object], list[Path]]:
    """(the scenario file, its parameter overrides, its search paths) that `run` plays: a
    permutation run's distribution file is expanded as `avsim run --permutation K` does
    (`avsim.scenario.openscenario.distribution`) and its run K's values set."""
    path, search = scenario_file(run)
    if run.permutation is None:
        return path, {}, search
    dist = load_distribution(path, search)
    return dist.scenario, dist.runs[run.permutation].overrides(), search


def esmini_parameters(run: RefRun) -> dict[str, str]:
    """The parameter values esmini set in a permutation run (index.csv's `parameters`)."""
    pairs = (item.split("=", 1) for item in run.parameters.split("; ") if item)
    return {name: value for name, value in pairs}


def _read_gz(path: Path) -> list[dict[str, str]]:
    with gzip.open(path, "rt") as f:
        return list(csv.DictReader(f))


def ref_event_starts(run: RefRun, events: frozenset[str] = frozenset(),
                     acts: frozenset[str] = frozenset()) -> dict[str, list[float]]:
    """Event name -> esmini's start times [s] (every start, in order): its changes from
    standby to running. A row typed Event counts; so does one typed otherwise whose name is
    one of the scenario's `events` and none of its `acts` (the reference's types were looked
    up by name: README.md)."""
    starts: dict[str, list[float]] = {}
    for r in _read_gz(REF / f"{run.output}_events.csv.gz"):
        name = r["element_name"]
        event = r["element_type"] == "Event" or (name in events and name not in acts)
        if event and r["from_state"] == "standbyState" and r["to_state"] == "runningState":
            starts.setdefault(name, []).append(float(r["time"]))
    return starts


def ref_paths(run: RefRun) -> dict[str, NDArray[np.float64]]:
    """Entity name -> (N, 3) esmini's time [s], x, y [m] of its reference point."""
    rows: dict[str, list[tuple[float, float, float]]] = {}
    for r in _read_gz(REF / f"{run.output}.csv.gz"):
        rows.setdefault(r["name"], []).append((float(r["time"]), float(r["x"]), float(r["y"])))
    return {name: np.array(v) for name, v in rows.items()}


@dataclass(frozen=True, slots=True)
class Played:
    """avsim's play of one file: event starts and the entities' reference points."""

    event_starts: dict[str, list[float]]  # event name -> start times [s]
    events: frozenset[str]  # the names of the scenario's events
    acts: frozenset[str]  # the names of its acts
    paths: dict[str, NDArray[np.float64]]  # entity name -> (N, 3) t [s], x, y [m]
    end: float  # [s] when the run ended


def play(run: RefRun) -> Played:
    """Play `run`'s file with a scripted car under test, no sensors (module doc)."""
    path, overrides, search = concrete(run)
    # no longer than esmini's run and a margin: beyond its end there is nothing to compare
    duration = run.t_end + END_MARGIN
    scenario = load_scenario(path, {"duration": duration, **overrides}, search_paths=search,
                             scripted_ego=True)
    runner = Runner(scenario, profile=None)
    director = runner.director
    assert director is not None
    snaps: list[Snapshot] = []
    take: Callable[[], Snapshot] = director.truth.snapshot

    def keep() -> Snapshot:
        snap = take()
        snaps.append(snap)
        return snap

    director.truth.snapshot = keep  # type: ignore[method-assign]
    result = runner.run()
    assert result.error is None, result.error
    starts: dict[str, list[float]] = {}
    for t, kind, name, transition in director.runtime.history():
        if kind == "event" and transition == "startTransition":
            starts.setdefault(name, []).append(t)
    paths = {name: np.array([(s.time, s.entities[name].x, s.entities[name].y)
                             for s in snaps]) for name in snaps[0].entities}
    nodes = [n for root in director.runtime.stories for n in root.walk()]
    return Played(starts, frozenset(n.name for n in nodes if n.element_type == "event"),
                  frozenset(n.name for n in nodes if n.element_type == "act"), paths,
                  result.sim_time)


def event_error(ref: dict[str, list[float]], got: dict[str, list[float]]) -> float:
    """[s] the largest difference between esmini's and avsim's start of any event (inf:
    an event started a different number of times)."""
    worst = 0.0
    for name in ref.keys() | got.keys():
        a, b = ref.get(name, []), got.get(name, [])
        if len(a) != len(b):
            return math.inf
        worst = max([worst, *(abs(x - y) for x, y in zip(a, b, strict=True))])
    return worst


def path_rms(ref: NDArray[np.float64], got: NDArray[np.float64]) -> float:
    """[m] RMS distance between avsim's samples and esmini's path interpolated linearly at
    their times, over the times both cover."""
    t = got[:, 0]
    inside = (t >= ref[0, 0]) & (t <= ref[-1, 0])
    x = np.interp(t[inside], ref[:, 0], ref[:, 1])
    y = np.interp(t[inside], ref[:, 0], ref[:, 2])
    d2 = (got[inside, 1] - x) ** 2 + (got[inside, 2] - y) ** 2
    return float(np.sqrt(np.mean(d2)))

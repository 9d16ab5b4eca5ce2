"""`avsim campaign`: runs drawn from a scenario file's laws (its `vary:` section).

1. Each campaign file (a family: an `avsim/1` YAML file with `vary:`) is loaded and
   checked; run k of file f draws its values (`avsim.batch.sampling.draw_run`), which are
   set into the file as overrides, the file's `vary:` left aside. Every run is then loaded
   and checked (`avsim.batch.suite.plan`) before any runs: bad input is one line, exit 2.
2. The runs go to the suite's executors (local processes or Ray) and write their result
   JSON and recording into the campaign's folder; a passing run's recording is deleted
   once it has finished unless every recording is kept (`--record all`).
3. Each failed run (a criterion failed) gets `repro/<run>.yaml`: the file with the run's
   values set (its seed included) and without `vary:`, which `avsim run` runs to the same
   result (`repro_yaml`). `--shrink` and `--search` add runs of their own
   (`avsim.batch.shrink`, `avsim.batch.search`), in `shrink/` and `search/`.
"""

from __future__ import annotations

import copy
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import yaml

from avsim.batch.jobs import SCRIPTED, STACK, RunJob, RunOutcome, Status
from avsim.batch.sampling import SEED_KEY, Law, draw_run, laws_of
from avsim.batch.suite import BatchError, overrides_of, plan
from avsim.scenario.errors import LocatedError, ScenarioError
from avsim.scenario.files import read_raw
from avsim.scenario.load import load_scenario, scenario_path
from avsim.scenario.model import grid_paths
from avsim.scenario.overrides import apply_overrides
from avsim.scenario.validation import validate

MAX_RUNS = 10_000  # runs of one family (`--n`)
REPRO_DIR = "repro"  # the failed runs' concrete scenario files, below the campaign's folder
MISSING = object()  # a key the file does not write (its value is the format's default)


@dataclass(frozen=True)
class Family:
    """A campaign file: its laws and its own data (the nominal case)."""

    file: str  # as the user gave it
    index: int  # its place among the campaign's files (a stream of the draws)
    name: str  # the scenario's name (the runs are NAME_0000, NAME_0001, ...)
    laws: tuple[Law, ...]
    raw: Mapping[str, Any]  # the file's YAML data, `vary:` included

    def nominal(self, key: str) -> object:
        """The file's own value of a `vary:` key (a list for several paths), `MISSING`
        when the file leaves one of its paths out."""
        values = [_value_at(self.raw, path) for path in grid_paths(key)]
        if any(v is MISSING for v in values):
            return MISSING
        return values[0] if len(values) == 1 else values


@dataclass(frozen=True)
class DrawnRun:
    """A run of the campaign: its family, drawn values and outcome."""

    family: Family
    values: Mapping[str, object]  # `vary:` key (and `seed`) -> the value drawn
    outcome: RunOutcome

    @property
    def failed_criteria(self) -> list[str]:
        """The names of the criteria the run failed, in the result's order."""
        return [str(c["name"]) for c in self.outcome.criteria() if c["passed"] is False]


@dataclass(frozen=True)
class Settings:
    """What every run of a campaign shares."""

    out_dir: Path
    profile: str = "default"
    fixed: Mapping[str, object] = field(default_factory=dict)  # `--set`: every run's
    seed: int = 0  # `--seed`: the campaign's draws
    ego: str = STACK  # what drives the car under test (`RunJob.ego`, `--ego`)


def _value_at(raw: Mapping[str, Any], path: str) -> object:
    """The value at a dotted key path of the file's data, `MISSING` if it has none."""
    node: object = raw
    for part in path.split("."):
        if isinstance(node, list) and part.isdigit() and int(part) < len(node):
            node = node[int(part)]
        elif isinstance(node, dict) and part in node:
            node = node[part]
        else:
            return MISSING
    return node


def load_family(file: str, index: int, ego: str = STACK) -> Family:
    """A campaign file, loaded and checked for `ego` (`RunJob.ego`); `ScenarioError` for a
    bad one (a YAML file's car under test cannot be scripted), `BatchError` for a file
    without `vary:` or an OpenSCENARIO file."""
    path = scenario_path(file)
    if path.suffix == ".xosc":
        raise BatchError(f"{file}: (file): a campaign file is an avsim/1 YAML file with vary:")
    loaded = load_scenario(file, scripted_ego=ego == SCRIPTED)
    try:
        raw = read_raw(path)
        model = validate(raw, {})
    except LocatedError as exc:  # load_scenario read the same file a moment ago
        raise ScenarioError(file, exc.key, exc.problem) from None
    if not model.vary:
        raise BatchError(f"{file}: vary: a campaign file needs a vary: section (the laws "
                         "its runs are drawn from)")
    return Family(file, index, loaded.name, laws_of(model.vary), raw)


def run_overrides(values: Mapping[str, object], settings: Settings) -> dict[str, object]:
    """A run's overrides: the `--set` values, then its drawn values."""
    return dict(settings.fixed) | overrides_of(values)


def draw_plan(families: Sequence[Family], runs: int, settings: Settings,
              ) -> tuple[list[RunJob], list[dict[str, object]]]:
    """The campaign's jobs (every run loaded and checked, `plan`) and each one's values."""
    if runs > MAX_RUNS:
        raise BatchError(f"--n: {runs} runs: at most {MAX_RUNS} per file")
    entries: list[tuple[str | None, str, Mapping[str, object]]] = []
    drawn: list[dict[str, object]] = []
    for family in families:
        for k in range(runs):
            values = draw_run(family.laws, settings.seed, family.index, k)
            entries.append((f"{family.name}_{k:04d}", family.file,
                            run_overrides(values, settings)))
            drawn.append(values)
    return jobs_of(entries, settings), drawn


def jobs_of(entries: Sequence[tuple[str | None, str, Mapping[str, object]]],
            settings: Settings, out_dir: Path | None = None) -> list[RunJob]:
    """Checked jobs (`plan`) into `out_dir` (default the campaign's), without plots."""
    planned = plan(entries, out_dir or settings.out_dir, settings.profile, ego=settings.ego)
    return [replace(job, plot=False) for job in planned]


def repro_yaml(family: Family, overrides: Mapping[str, object], note: str) -> str:
    """The concrete scenario of a run: the family's file with the overrides set, without
    `vary:`, headed by `note` (comment lines). YAML keeps every float exactly (its
    shortest repr), so that `avsim run` loads the very values the campaign's run had."""
    data: dict[str, Any] = apply_overrides(copy.deepcopy(dict(family.raw)), overrides)
    data.pop("vary", None)
    head = "".join(f"# {line}\n" for line in note.splitlines())
    return head + yaml.safe_dump(data, sort_keys=False, allow_unicode=True, width=100)


def note_of(run: str, family: Family, settings: Settings) -> str:
    """The header of a run's repro file: where it comes from, how to run it."""
    return (f"run {run} of the campaign over {family.file} (--seed {settings.seed}): "
            f"its drawn values set, its vary: removed.\n"
            f"avsim run {REPRO_DIR}/{run}.yaml --profile {settings.profile} "
            "gives the same result.")


def keep_recordings(runs: Sequence[DrawnRun], keep_all: bool) -> None:
    """Delete the recording of each run that passed, unless `keep_all`."""
    if keep_all:
        return
    for run in runs:
        if run.outcome.status is Status.PASSED:
            run.outcome.job.recording.unlink(missing_ok=True)


def failed(runs: Sequence[DrawnRun]) -> list[DrawnRun]:
    """The runs that failed a criterion (not those that ended in error)."""
    return [r for r in runs if r.outcome.status is Status.FAILED]


def shown_values(values: Mapping[str, object]) -> dict[str, object]:
    """Drawn values for a report: the seed last."""
    ordered = {k: v for k, v in values.items() if k != SEED_KEY}
    if SEED_KEY in values:
        ordered[SEED_KEY] = values[SEED_KEY]
    return ordered


CAMPAIGN_JSON, WORST_REPRO = "campaign.json", "worst.yaml"  # a campaign's own reports


@dataclass(frozen=True)
class Refined:
    """What `--shrink` and `--search` found (`avsim.batch.refine`'s results)."""

    shrunk: Sequence[Any] = ()  # `refine.Shrunk`s
    worst: Sequence[Any] = ()  # `refine.Worst`s


def write_reports(runs: Sequence[DrawnRun], refined: Refined, settings: Settings,
                  per_file: int, title: str) -> None:
    """The repro files, ``junit.xml``, ``results.json``, ``campaign.json`` and
    ``summary.md`` in the campaign's folder."""
    from avsim.batch.suite import JUNIT, RESULTS, SUMMARY, results_json
    from avsim.files import write_atomic
    from avsim.report.campaign import campaign_json, campaign_markdown
    from avsim.report.suite import junit_xml
    from avsim.run.result import dumps

    repros = _write_repros(runs, refined, settings)
    outcomes = [r.outcome for r in runs]
    write_atomic(settings.out_dir / JUNIT, junit_xml(outcomes, title))
    write_atomic(settings.out_dir / RESULTS, dumps(results_json(outcomes)))
    header: dict[str, object] = {
        "seed": settings.seed, "n": per_file, "profile": settings.profile,
        "set": dict(settings.fixed), "families": sorted({r.family.file for r in runs}),
        "worst_repro": repros.get(Path(WORST_REPRO).stem)}
    report = campaign_json(runs, repros, refined.shrunk, refined.worst, header)
    write_atomic(settings.out_dir / CAMPAIGN_JSON, dumps(report))
    write_atomic(settings.out_dir / SUMMARY, campaign_markdown(report, title))


def _write_repros(runs: Sequence[DrawnRun], refined: Refined,
                  settings: Settings) -> dict[str, str]:
    """Each failure's repro file, each shrunk failure's, the search's worst case's; their
    paths (relative to the campaign's folder) by name (run, run_shrunk, worst)."""
    written: dict[str, str] = {}

    def write(name: str, family: Family, values: Mapping[str, object], note: str) -> None:
        from avsim.files import write_atomic

        relative = f"{REPRO_DIR}/{name}.yaml"
        text = repro_yaml(family, run_overrides(values, settings), note)
        write_atomic(settings.out_dir / relative, text)
        written[name] = relative

    for run in failed(runs):
        name = run.outcome.job.name
        write(name, run.family, run.values, note_of(name, run.family, settings))
    for s in refined.shrunk:
        name = f"{s.run.outcome.job.name}_shrunk"
        write(name, s.run.family, s.values,
              f"{s.run.outcome.job.name} shrunk toward the nominal case: still fails "
              f"{s.criterion}.\n" + note_of(name, s.run.family, settings).split("\n")[1])
    found = [w for w in refined.worst if w.values]
    if found:
        w = min(found, key=lambda w: w.value)
        write(Path(WORST_REPRO).stem, w.family, w.values,
              f"the least {w.metric} the search found ({w.value:g}; nominal "
              f"{w.nominal:g}).\n" + note_of("worst", w.family, settings).split("\n")[1])
    return written

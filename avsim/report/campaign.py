"""The reports of `avsim campaign`: `campaign.json` and `summary.md`.

Pure functions over the campaign's runs (`avsim.batch.campaign.DrawnRun`), its shrunk
failures and its search results (`avsim.batch.refine`): nothing here runs or writes. Both
reports hold the counts; the failures by criterion and by family (the campaign file); the
worst margins over the runs (`WORST`: the least time to collision and gap, the most
deceleration and lateral error, the least tyre margin, with the run that had each); every
failure with its drawn values and repro file; each shrunk failure's values, those that
shrank marked; each family's search result.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING

from avsim.batch.jobs import Status
from avsim.report.suite import format_value

if TYPE_CHECKING:
    from avsim.batch.campaign import DrawnRun
    from avsim.batch.refine import Shrunk, Worst

WORST: tuple[tuple[str, str, Callable[[float, float], bool]], ...] = (
    # metric or criterion, heading, whether a value is worse than another
    ("min_ttc", "least time to collision [s]", lambda a, b: a < b),
    ("min_lead_gap", "least gap moving [m]", lambda a, b: a < b),
    ("max_decel", "most deceleration [m/s^2]", lambda a, b: a > b),
    ("max_lateral_error", "most lateral error [m]", lambda a, b: a > b),
    ("tyres_in_lane", "least tyre margin inside the lines [m] (negative: over)",
     lambda a, b: a < b),
)


def worst_margins(runs: Sequence[DrawnRun]) -> list[dict[str, object]]:
    """Each `WORST` measure's worst value over the runs and the run that had it (the
    first such run); measures no run had are left out."""
    found = []
    for name, heading, worse in WORST:
        best: tuple[float, str] | None = None
        for run in runs:
            value = run.outcome.metric(name)
            if math.isfinite(value) and (best is None or worse(value, best[0])):
                best = (value, run.outcome.job.name)
        if best is not None:
            found.append({"metric": name, "heading": heading, "value": best[0],
                          "run": best[1]})
    return found


def campaign_json(runs: Sequence[DrawnRun], repros: Mapping[str, str],
                  shrunk: Sequence[Shrunk], worst: Sequence[Worst],
                  settings: Mapping[str, object]) -> dict[str, object]:
    """`campaign.json`: the settings, counts, failures, margins, every run's values and
    verdict, the shrunk failures and the search results (module doc)."""
    statuses = Counter(r.outcome.status for r in runs)
    failures = [r for r in runs if r.outcome.status is Status.FAILED]
    return {
        **settings,
        "runs": len(runs), "passed": statuses[Status.PASSED],
        "failed": statuses[Status.FAILED],
        "errors": len(runs) - statuses[Status.PASSED] - statuses[Status.FAILED],
        "failures_by_criterion": dict(sorted(Counter(
            c for r in failures for c in r.failed_criteria).items())),
        "failures_by_family": dict(Counter(r.family.file for r in failures)),
        "worst_margins": worst_margins(runs),
        "failures": [{"run": r.outcome.job.name, "family": r.family.file,
                      "failed": r.failed_criteria, "values": dict(r.values),
                      "repro": repros.get(r.outcome.job.name)} for r in failures],
        "shrunk": [{"run": s.run.outcome.job.name, "criterion": s.criterion,
                    "values": dict(s.values), "runs": s.runs,
                    "shrank": {k: {"drawn": a, "shrunk": b} for k, (a, b) in s.moved.items()},
                    "repro": repros.get(s.run.outcome.job.name + "_shrunk")} for s in shrunk],
        "search": [{"family": w.family.file, "metric": w.metric, "nominal": _finite(w.nominal),
                    "worst": _finite(w.value), "values": dict(w.values), "runs": w.runs}
                   for w in worst],
        "run_list": [{"run": r.outcome.job.name, "family": r.family.file,
                      "status": r.outcome.status.value, "failed": r.failed_criteria,
                      "values": dict(r.values), "error": r.outcome.error} for r in runs],
    }


def _finite(x: float) -> float | None:
    """JSON has no NaN: None for it."""
    return x if math.isfinite(x) else None


def _values(values: Mapping[str, object], marked: Mapping[str, object] | None = None) -> str:
    """`key = value` pairs, a marked key in bold."""
    marked = marked or {}
    return ", ".join((f"**{k}** = {format_value(v)}" if k in marked else
                      f"{k} = {format_value(v)}") for k, v in values.items())


def _table(head: Sequence[str], rows: Sequence[Sequence[object]]) -> list[str]:
    """A markdown table."""
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return [*lines, ""]


def campaign_markdown(report: Mapping[str, object], title: str) -> str:
    """`summary.md` from `campaign.json`'s content (`campaign_json`)."""
    lines = [f"# {title}", "",
             f"**{report['runs']} runs**: {report['passed']} passed, {report['failed']} "
             f"failed, {report['errors']} errors (did not finish) · --seed {report['seed']}"
             f" · --n {report['n']} per file · profile {report['profile']}", ""]
    lines += _counts_section(report)
    lines += _failures_section(report)
    lines += _shrunk_section(report)
    lines += _search_section(report)
    return "\n".join(lines)


def _counts_section(report: Mapping[str, object]) -> list[str]:
    """Failures by criterion and by family; the worst margins."""
    by_criterion = report["failures_by_criterion"]
    by_family = report["failures_by_family"]
    margins = report["worst_margins"]
    assert isinstance(by_criterion, dict) and isinstance(by_family, dict)
    assert isinstance(margins, list)
    lines = ["## Failures by criterion", ""]
    lines += _table(["criterion", "runs failed"], sorted(by_criterion.items())) \
        if by_criterion else ["none", ""]
    lines += ["## Failures by family", ""]
    lines += _table(["family", "runs failed"], sorted(by_family.items())) \
        if by_family else ["none", ""]
    lines += ["## Worst margins", ""]
    lines += _table(["measure", "worst", "run"],
                    [(m["heading"], format_value(m["value"]), f"`{m['run']}`")
                     for m in margins]) if margins else ["none measured", ""]
    return lines


def _failures_section(report: Mapping[str, object]) -> list[str]:
    """Each failed run: its failed criteria, its values, its repro file."""
    failures = report["failures"]
    assert isinstance(failures, list)
    if not failures:
        return []
    rows = [(f"`{f['run']}`", ", ".join(f["failed"]), _values(f["values"]),
             f"`{f['repro']}`") for f in failures]
    return ["## Failures", "", *_table(["run", "failed", "drawn values", "repro"], rows)]


def _shrunk_section(report: Mapping[str, object]) -> list[str]:
    """Each shrunk failure: its values (the keys that shrank in bold, drawn -> shrunk)."""
    shrunk = report["shrunk"]
    assert isinstance(shrunk, list)
    if not shrunk:
        return []
    rows = []
    for s in shrunk:
        moved = "; ".join(f"{k}: {format_value(m['drawn'])} -> {format_value(m['shrunk'])}"
                          for k, m in s["shrank"].items()) or "none"
        rows.append((f"`{s['run']}`", s["criterion"], moved, _values(s["values"], s["shrank"]),
                     s["runs"], f"`{s['repro']}`"))
    return ["## Shrunk failures", "",
            "Each value moved toward the family's nominal while the run still failed the "
            "criterion; the values that shrank are in bold.", "",
            *_table(["run", "criterion", "shrank", "smallest failing case", "runs", "repro"],
                    rows)]


def _search_section(report: Mapping[str, object]) -> list[str]:
    """Each family's least metric found, against its nominal case's."""
    found = report["search"]
    assert isinstance(found, list)
    if not found:
        return []
    rows = [(f["family"], f["metric"], format_value(f["nominal"]), format_value(f["worst"]),
             _values(f["values"]), f["runs"]) for f in found]
    return ["## Search", "",
            f"The worst case found is `{report.get('worst_repro')}`.", "",
            *_table(["family", "metric", "nominal", "worst found", "values", "runs"], rows)]

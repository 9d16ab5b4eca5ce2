"""The Euro NCAP scorecard of a suite (`avsim suite DIR --criteria ncap`): from each run's
`ncap` verdict (`avsim.criteria.ncap`, its result's `details`), a table per protocol (AEB
C2C 2023, AEB VRU 2023) with a row per test run, and the points summed per protocol.

Pure functions over the batch's `RunOutcome`s; `avsim.report.suite` puts the section into
`summary.md` and the details into the JUnit case of each run's `ncap` criterion. A run
without an `ncap` verdict (not finished, or judged without the set) is left out.

Sums: "points" adds the points of the runs whose points are computed, "max points" the
most those same runs could have scored; "not computed" counts the runs whose points the
protocol's tables do not give (their rows say why, `ncap_protocol.points_of`). The sums are
the runs' sub-points as the assessment protocol's tables give them, before its
normalisation to the scenario's points (docs/ncap.md).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from avsim.batch.jobs import RunOutcome

NAME = "ncap"  # the criterion
UNKNOWN = "(no protocol)"  # the table of runs whose test is not a 2023 protocol's
DASH = "—"
COLUMNS = ("run", "test", "speed [km/h]", "target [km/h]", "overlap / variant", "avoided",
           "impact [km/h]", "reduction [km/h]", "colour", "points", "max points", "note")


@dataclass(frozen=True, slots=True)
class Row:
    """One run's line of the scorecard."""

    run: str  # the job's name
    protocol: str
    details: Mapping[str, object]  # the verdict's details

    def points(self) -> float | None:
        """The run's points, None when not computed."""
        value = self.details.get("points")
        return float(value) if isinstance(value, (int, float)) else None

    def max_points(self) -> float | None:
        """The most the run could score, None when not known."""
        value = self.details.get("max_points")
        return float(value) if isinstance(value, (int, float)) else None


def ncap_details(outcome: RunOutcome) -> Mapping[str, object] | None:
    """The details of the run's `ncap` verdict, None when it has none."""
    for criterion in outcome.criteria():
        details = criterion.get("details")
        if criterion.get("name") == NAME and isinstance(details, Mapping):
            return details
    return None


def rows(outcomes: Sequence[RunOutcome]) -> list[Row]:
    """The scorecard's rows, in the batch's order."""
    found = []
    for outcome in outcomes:
        details = ncap_details(outcome)
        if details is not None:
            found.append(Row(outcome.job.name, str(details.get("protocol") or UNKNOWN),
                             details))
    return found


def _number(x: object) -> str:
    """A number to 3 decimals without trailing zeros; a dash for none."""
    if isinstance(x, bool) or not isinstance(x, (int, float)):
        return DASH
    text = f"{x:.3f}".rstrip("0").rstrip(".")
    return "0" if text == "-0" else text


def _cell(x: object) -> str:
    """Text for a table cell: `|` escaped, none as a dash."""
    return DASH if x in (None, "") else str(x).replace("|", "\\|")


def _variant(d: Mapping[str, object]) -> str:
    """The overlap [%] and the variant the name gives."""
    parts = []
    if isinstance(d.get("overlap"), (int, float)):
        parts.append(f"{_number(d['overlap'])} %")
    if d.get("variant"):
        parts.append(str(d["variant"]))
    return " ".join(parts) or DASH


def _row(r: Row) -> str:
    d = r.details
    cells = [r.run, d.get("scenario_id"), _number(d.get("test_speed_kph")),
             _number(d.get("target_speed_kph")), _variant(d),
             "yes" if d.get("avoided") else "no", _number(d.get("impact_speed_kph")),
             _number(d.get("speed_reduction_kph")), d.get("colour"),
             _number(d.get("points")), _number(d.get("max_points")),
             "; ".join(str(d[k]) for k in ("points_note", "fcw") if d.get(k))]
    return "| " + " | ".join(_cell(c) for c in cells) + " |"


def totals(protocol_rows: Sequence[Row]) -> tuple[float, float, int]:
    """(points, max points of the runs scored, runs not computed) of a protocol's rows."""
    scored = [r for r in protocol_rows if r.points() is not None]
    points = sum(r.points() or 0.0 for r in scored)
    most = sum(r.max_points() or 0.0 for r in scored)
    return points, most, len(protocol_rows) - len(scored)


def scorecard_markdown(outcomes: Sequence[RunOutcome]) -> list[str]:
    """The scorecard section of `summary.md` (no lines when no run has an `ncap` verdict)."""
    found = rows(outcomes)
    if not found:
        return []
    lines = ["## Euro NCAP scorecard", ""]
    for protocol in sorted({r.protocol for r in found}):
        mine = [r for r in found if r.protocol == protocol]
        points, most, missing = totals(mine)
        lines += [f"### {protocol}", "", "| " + " | ".join(COLUMNS) + " |",
                  "|" + "---|" * len(COLUMNS)]
        lines += [_row(r) for r in mine]
        lines += ["", f"**{protocol}: {_number(points)} of {_number(most)} points** over "
                      f"{len(mine) - missing} scored test run(s); {missing} not computed "
                      "(the note says why).", ""]
    return lines


def junit_properties(criterion: Mapping[str, object]) -> dict[str, str]:
    """The JUnit properties of an `ncap` criterion's case: its details, `ncap.KEY`."""
    details = criterion.get("details")
    if criterion.get("name") != NAME or not isinstance(details, Mapping):
        return {}
    return {f"ncap.{k}": str(v) for k, v in details.items() if v is not None}

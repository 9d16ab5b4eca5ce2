"""The reports of `avsim suite`: JUnit XML, `summary.md` and the terminal table.

Pure functions over the `RunOutcome`s of a batch (`avsim.batch.jobs`): nothing here runs a
scenario or writes a file; the caller writes the text they return.

- `junit_xml`: one `<testsuite>` per run, one `<testcase>` per criterion (a failed
  criterion has a `<failure>`, a passed one with a note, such as a contact a rule excused,
  its note as `<system-out>`); a run that did not finish or ended in error has a
  `<testcase name="run">` with an `<error>` (a run that ended in error also keeps its
  criteria judged so far). Attributes follow the common (Jenkins / Surefire) JUnit schema.
- `summary_markdown`: the counts, the Euro NCAP scorecard when runs have an `ncap` verdict
  (`avsim.report.ncap`), a table of scenarios (pass rate, worst margins, every
  contact with those a rule excused), a table of runs with links to their files, a table
  of criteria per run (and its contacts), and the snapshot of each failed run at its first
  failure.
- `summary_table`: the same verdicts as a `rich` table for the terminal.

Times: "sim time" is the run's simulated time (the result's `sim_time`); "wall time" is
the job's whole time in its worker (`RunOutcome.wall_time`, loading included), so that runs
that did not finish have one too.
"""

from __future__ import annotations

import math
import os
import re
import xml.etree.ElementTree as ET
from collections.abc import Mapping, Sequence
from pathlib import Path
from types import MappingProxyType
from urllib.parse import quote

from rich.table import Table
from rich.text import Text

from avsim.batch.jobs import RunOutcome, Status
from avsim.report.ncap import junit_properties, scorecard_markdown

DASH = "—"  # a value that is absent (None) or not a number
PARAMETERS = "parameters."  # an OpenSCENARIO parameter's override key: `parameters.NAME`
DECIMALS = 3  # numbers are shown to this many decimals, trailing zeros dropped
VERDICTS: dict[Status, tuple[str, str]] = {  # status -> (word, rich style)
    Status.PASSED: ("PASS", "bold green"),
    Status.FAILED: ("FAIL", "bold red"),
    Status.BAD_INPUT: ("BAD INPUT", "bold yellow"),
    Status.ERROR: ("ERROR", "bold magenta"),
    Status.INTERRUPTED: ("INTERRUPTED", "bold yellow"),
}
_NO_SNAPSHOTS: Mapping[str, Path] = MappingProxyType({})  # an immutable empty default
_MD_SPECIAL = re.compile(r"([\\`*_{}\[\]<>|])")  # escaped in free text of a table cell
# characters XML 1.0 cannot hold, even escaped (control codes in a crash's message, say)
_NOT_XML = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ud800-\udfff\ufffe\uffff]")


# --- numbers -----------------------------------------------------------------------------


def format_value(x: object) -> str:
    """A number to `DECIMALS` without trailing zeros (`18.2`, `0.333`, `0`); `inf`, `-inf`;
    `—` for None and NaN; booleans and text as they are."""
    if x is None:
        return DASH
    if isinstance(x, bool) or not isinstance(x, (int, float)):
        return str(x)
    if math.isnan(x):
        return DASH
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    text = f"{x:.{DECIMALS}f}"
    if "." in text:
        text = text.rstrip("0").rstrip(".")
    return "0" if text == "-0" else text


def _seconds(x: float) -> str:
    """[s] a time attribute of the JUnit XML: a plain decimal, never `inf` or `nan`."""
    return f"{x:.3f}" if math.isfinite(x) else "0.000"


def _sim_time(outcome: RunOutcome) -> float:
    """[s] the run's simulated time; 0 if it did not finish."""
    if outcome.result is None:
        return 0.0
    value = outcome.result.get("sim_time")
    return float(value) if isinstance(value, (int, float)) else 0.0


def _failed_names(outcome: RunOutcome) -> list[str]:
    """The names of the run's failed criteria."""
    return [str(c["name"]) for c in outcome.criteria() if c["passed"] is False]


def _skipped_names(outcome: RunOutcome) -> list[str]:
    """The names of the run's criteria that were not applicable."""
    return [str(c["name"]) for c in outcome.criteria() if c["passed"] is None]


def _counts(outcomes: Sequence[RunOutcome]) -> tuple[int, int, int]:
    """(passed, failed, errors): errors are the runs that did not finish."""
    passed = sum(o.status is Status.PASSED for o in outcomes)
    failed = sum(o.status is Status.FAILED for o in outcomes)
    return passed, failed, len(outcomes) - passed - failed


# --- JUnit XML ---------------------------------------------------------------------------


def _failure_message(criterion: Mapping[str, object]) -> str:
    """`value V unit (threshold T)` of a criterion."""
    unit = str(criterion.get("unit", "")).strip()
    value = format_value(criterion.get("value"))
    value = f"{value} {unit}" if unit else value
    return f"value {value} (threshold {format_value(criterion.get('threshold'))})"


def _failure_text(criterion: Mapping[str, object]) -> str:
    """A failed criterion's message, its first failure time [s] and its note, a line each."""
    lines = [f"{criterion['name']}: {_failure_message(criterion)}"]
    if isinstance(t := criterion.get("first_failure"), (int, float)):
        lines.append(f"first failure at {format_value(t)} s")
    if criterion.get("note"):
        lines.append(f"note: {criterion['note']}")
    return "\n".join(lines)


def _xml_safe(text: str) -> str:
    """`text` with the characters XML cannot hold shown as `\\xNN` (ElementTree escapes the
    rest: `<`, `&`, quotes, newlines in attributes)."""
    return _NOT_XML.sub(lambda m: f"\\x{ord(m.group()):02x}", text)


def _sanitize(root: ET.Element) -> None:
    """Make every text and attribute below `root` XML-safe (`_xml_safe`), in place."""
    for element in root.iter():
        if element.text is not None:
            element.text = _xml_safe(element.text)
        for key, value in element.attrib.items():
            element.attrib[key] = _xml_safe(value)


def _properties(outcome: RunOutcome) -> dict[str, str]:
    """The run's facts: scenario, file, seed (if known), profile, what drove the car under
    test (stack or scripted), status, overrides."""
    result = outcome.result or {}
    props = {
        "scenario": str(result.get("scenario", outcome.job.scenario)),
        "file": str(result.get("file", outcome.job.scenario)),
        "seed": format_value(result.get("seed")),
        "profile": str(result.get("profile", outcome.job.profile)),
        "ego": str(result.get("ego", outcome.job.ego)),
        "status": outcome.status.value,
    }
    stack = result.get("stack")
    if isinstance(stack, dict):  # which stack drove it, and its version
        privileged = " (privileged: ground truth)" if stack.get("privileged") is True else ""
        props["stack"] = f"{stack.get('name')} {stack.get('version')}{privileged}"
    if "seed" not in result:  # a run that did not finish: its seed is not known here
        del props["seed"]
    for key, value in outcome.job.overrides.items():
        props[f"override.{key}"] = str(value)
    return props


def _criterion_case(suite: ET.Element, outcome: RunOutcome,
                    criterion: Mapping[str, object]) -> None:
    """Append a criterion's `<testcase>`: with its `<failure>` if it failed (and its first
    failure's sim time as a property), `<skipped>` if it was not applicable, its note as
    `<system-out>` if it passed with one (a contact a rule excused, the judging ended
    early). No time: the criteria are judged together over the whole run, which the
    suite's time is."""
    case = ET.SubElement(suite, "testcase", classname=f"avsim.{outcome.job.name}",
                         name=str(criterion["name"]))
    first = criterion.get("first_failure")
    facts = ({} if first is None else {"first_failure_sim_time": f"{first}"}) \
        | junit_properties(criterion)
    if facts:
        properties = ET.SubElement(case, "properties")
        for name, value in facts.items():
            ET.SubElement(properties, "property", name=name, value=value)
    if criterion["passed"] is None:
        ET.SubElement(case, "skipped", message=str(criterion.get("note") or "not applicable"))
    elif criterion["passed"] and criterion.get("note"):
        ET.SubElement(case, "system-out").text = f"note: {criterion['note']}"
    elif not criterion["passed"]:
        said = _infractions(outcome, str(criterion["name"]))
        message = _failure_message(criterion)
        if said:  # what happened first, then the numbers
            message = f"{said[0]}; {message}"
        failure = ET.SubElement(case, "failure", message=message, type="criterion")
        failure.text = "\n".join([_failure_text(criterion), *said[1:]])


def _infractions(outcome: RunOutcome, name: str) -> list[str]:
    """The run's infractions of criterion `name` in time order, each as `at T s: message`."""
    found = (outcome.result or {}).get("infractions")
    if not isinstance(found, list):
        return []
    mine = [i for i in found if isinstance(i, dict) and i.get("kind") == name]
    return [f"at {format_value(i.get('t'))} s: {i.get('message')}" for i in mine]


def _error_case(suite: ET.Element, outcome: RunOutcome) -> None:
    """Append the `<testcase name="run">` with the `<error>` of a run that did not finish
    or ended in error (its text: the message, then the traceback when the result has
    one)."""
    case = ET.SubElement(suite, "testcase", classname=f"avsim.{outcome.job.name}",
                         name="run", time=_seconds(outcome.wall_time))
    message = outcome.error or f"the run did not finish ({outcome.status.value})"
    error = ET.SubElement(case, "error", message=message, type=outcome.status.value)
    fault = (outcome.result or {}).get("error")
    trace = fault.get("traceback") if isinstance(fault, Mapping) else None
    error.text = f"{message}\n{trace}" if trace else message


def _in_error(outcome: RunOutcome) -> bool:
    """The run did not finish (no result) or ended in error."""
    return outcome.result is None or outcome.status is Status.ERROR


def _testsuite(parent: ET.Element, outcome: RunOutcome) -> tuple[int, int, int]:
    """Append the run's `<testsuite>`; returns its (tests, failures, errors)."""
    suite = ET.SubElement(parent, "testsuite", name=outcome.job.name)
    properties = ET.SubElement(suite, "properties")
    for name, value in _properties(outcome).items():
        ET.SubElement(properties, "property", name=name, value=value)
    criteria = outcome.criteria()
    if _in_error(outcome):
        _error_case(suite, outcome)
    elif not criteria:  # a finished run with nothing to check still shows, as passed
        ET.SubElement(suite, "testcase", classname=f"avsim.{outcome.job.name}", name="run",
                      time=_seconds(outcome.wall_time))
    for criterion in criteria:
        _criterion_case(suite, outcome, criterion)
    errors = int(_in_error(outcome))
    tests = max(len(criteria) + errors, 1)
    failures = len(_failed_names(outcome))
    suite.attrib.update(tests=str(tests), failures=str(failures), errors=str(errors),
                        skipped=str(len(_skipped_names(outcome))),
                        time=_seconds(outcome.wall_time))
    return tests, failures, errors


def junit_xml(outcomes: Sequence[RunOutcome], suite_name: str) -> str:
    """The batch as a JUnit XML document (UTF-8 text with its declaration).

    `<testsuites name=suite_name>` holds one `<testsuite name=job name>` per run, with
    `<properties>` (scenario, file, seed, profile, ego, status, `override.<key>` per swept
    key)
    and one `<testcase classname="avsim.<job name>" name=<criterion>>` per criterion; a
    failed criterion's `<failure message="at T s: <its first infraction>; value V unit
    (threshold T)">` (no infraction: the numbers only) has as text the numbers, its first
    failure time [s], note and later infractions, a line each.
    A run that did not finish is one `<testcase name="run">` with
    `<error message=<its error line> type=bad_input|error>`. `time` attributes are wall
    times [s]. ElementTree escapes `<`, `&` and quotes in attributes and text.
    """
    root = ET.Element("testsuites", name=suite_name)
    totals = [0, 0, 0]
    for outcome in outcomes:
        for i, n in enumerate(_testsuite(root, outcome)):
            totals[i] += n
    root.attrib.update(tests=str(totals[0]), failures=str(totals[1]), errors=str(totals[2]),
                       time=_seconds(sum(o.wall_time for o in outcomes)))
    _sanitize(root)
    ET.indent(root)
    body = ET.tostring(root, encoding="unicode")
    return f'<?xml version="1.0" encoding="UTF-8"?>\n{body}\n'


# --- summary.md --------------------------------------------------------------------------


def _md_text(text: object) -> str:
    """Free text for a Markdown table cell: one line, Markdown's specials escaped."""
    one_line = " ".join(str(text).split())
    return _MD_SPECIAL.sub(r"\\\1", one_line)


def _md_code(text: object) -> str:
    """A name as a code span in a table cell (only the pipe needs escaping there)."""
    return "`" + str(text).replace("`", "'").replace("|", "\\|") + "`"


def _inline_code(text: object) -> str:
    """A code span outside a table (a backtick in it would end the span early)."""
    return "`" + str(text).replace("`", "'") + "`"


def _link(label: str, path: Path, out_dir: Path) -> str:
    """A Markdown link to `path`, relative to `out_dir` (POSIX separators, URL-quoted)."""
    rel = Path(os.path.relpath(path, out_dir)).as_posix()
    return f"[{label}]({quote(rel)})"


def _verdict(outcome: RunOutcome) -> str:
    """The run's verdict word (`VERDICTS`)."""
    return VERDICTS[outcome.status][0]


def _header(outcomes: Sequence[RunOutcome], title: str) -> list[str]:
    """The title and a line of counts and total sim and wall times [s]."""
    passed, failed, errors = _counts(outcomes)
    sim = sum(_sim_time(o) for o in outcomes)
    wall = sum(o.wall_time for o in outcomes)
    interrupted = sum(o.status is Status.INTERRUPTED for o in outcomes)
    stopped = (f" · **interrupted**: {interrupted} runs ended early or never started"
               if interrupted else "")
    return [
        f"# {title}", "",
        f"**{len(outcomes)} runs**: {passed} passed, {failed} failed, {errors} errors "
        f"(did not finish) · sim time {format_value(sim)} s · wall time {format_value(wall)} s"
        + stopped,
        "",
    ]


def _run_row(outcome: RunOutcome, out_dir: Path, values: bool = False) -> str:
    """A run's row of the runs table: verdict, times [s], links to its files; with
    `values`, its overrides (an OpenSCENARIO parameter by its name)."""
    job = outcome.job
    if outcome.result is None:
        files = [DASH, DASH]
    else:
        files = [_link(job.recording.name, job.recording, out_dir),
                 _link(job.result_file.name, job.result_file, out_dir)]
    plot = _link(job.plot_file.name, job.plot_file, out_dir) if job.plot_file.is_file() else DASH
    sim = format_value(_sim_time(outcome)) if outcome.result is not None else DASH
    cells = [_md_code(job.name), f"**{_verdict(outcome)}**", sim,
             format_value(outcome.wall_time), *files, plot]
    if values:
        given = ", ".join(f"{k.removeprefix(PARAMETERS)}={v}" for k, v in job.overrides.items())
        cells.append(_md_code(given) if given else DASH)
    return "| " + " | ".join(cells) + " |"


def _runs_table(outcomes: Sequence[RunOutcome], out_dir: Path) -> list[str]:
    """The table of runs, a row each."""
    values = any(o.job.overrides for o in outcomes)  # a sweep's, a distribution's runs
    lines = ["| run | verdict | sim time [s] | wall time [s] | recording | result | "
             "speeds + margins |" + (" values |" if values else ""),
             "|---|---|--:|--:|---|---|---|" + ("---|" if values else "")]
    lines += [_run_row(o, out_dir, values) for o in outcomes]
    return [*lines, ""]


MARGINS = (  # the scenario table's worst margins: metric, heading, the worst of the runs
    ("min_ttc", "least time to collision [s]", min),
    ("min_lead_gap", "least gap moving [m]", min),
    ("max_decel", "most deceleration [m/s^2]", max),
)


def _metric(outcome: RunOutcome, name: str) -> float | None:
    """A finished run's metric, None where it has none (or it is null: no lead)."""
    metrics = (outcome.result or {}).get("metrics")
    value = metrics.get(name) if isinstance(metrics, Mapping) else None
    return float(value) if isinstance(value, int | float) else None


CONTACTS, EXCUSED = "collisions", "collisions_excused"  # the metrics of the contacts


def _contacts(runs: Sequence[RunOutcome]) -> str:
    """Every contact of the finished runs, with those a rule excused: `3 (2 excused)`, `0`;
    `—` when no run has the metric."""
    counts = [v for o in runs if (v := _metric(o, CONTACTS)) is not None]
    if not counts:
        return DASH
    excused = sum(v for o in runs if (v := _metric(o, EXCUSED)) is not None)
    text = format_value(sum(counts))
    return f"{text} ({format_value(excused)} excused)" if excused else text


def _scenario_table(outcomes: Sequence[RunOutcome]) -> list[str]:
    """A row per scenario file (a grid's points together): runs, passed, the pass rate,
    the worst of each of `MARGINS` over its finished runs and their contacts (`_contacts`:
    every one, also those a rule excused)."""
    groups: dict[str, list[RunOutcome]] = {}
    for outcome in outcomes:
        groups.setdefault(outcome.job.scenario, []).append(outcome)
    lines = ["| scenario | runs | passed | pass rate | "
             + " | ".join(heading for _, heading, _ in MARGINS) + " | contacts |",
             "|---|--:|--:|--:|" + "--:|" * len(MARGINS) + "--:|"]
    for scenario, runs in groups.items():
        passed = sum(o.passed for o in runs)
        worst = []
        for name, _, pick in MARGINS:
            values = [v for o in runs if (v := _metric(o, name)) is not None]
            worst.append(format_value(pick(values)) if values else DASH)
        lines.append("| " + " | ".join([_md_code(Path(scenario).stem), str(len(runs)),
                                        str(passed), f"{100 * passed / len(runs):.0f} %",
                                        *worst, _contacts(runs)]) + " |")
    return [*lines, ""]


def _criterion_row(c: Mapping[str, object]) -> str:
    """A criterion's row of a run's section."""
    verdict = "n/a" if c["passed"] is None else "pass" if c["passed"] else "**FAIL**"
    cells = [_md_code(c["name"]), verdict,
             format_value(c.get("value")), format_value(c.get("threshold")),
             _md_text(c.get("unit", "")), format_value(c.get("first_failure")),
             _md_text(c["note"]) if c.get("note") else ""]
    return "| " + " | ".join(cells) + " |"


def _run_section(outcome: RunOutcome) -> list[str]:
    """A run's section: its facts, then its criteria table (or its error line)."""
    job = outcome.job
    lines = [f"## {job.name}: {_verdict(outcome)}", ""]
    props = _properties(outcome)
    values = "".join(f", {_inline_code(k)} = {_inline_code(v)}"
                     for k, v in job.overrides.items())
    stack = f", stack {_inline_code(props['stack'])}" if "stack" in props else ""
    lines += [f"Scenario `{props['file']}`, seed {props.get('seed', DASH)}, profile "
              f"{props['profile']}, ego {props['ego']}{stack}{values}.", ""]
    if _in_error(outcome):
        lines += [f"> {_md_text(outcome.error or outcome.status.value)}", ""]
    if outcome.result is None:
        return lines
    contacts = _contacts([outcome])
    if contacts not in (DASH, "0"):
        lines += [f"Contacts: {contacts} (every contact onset; `no_collision`'s note says "
                  "which a rule excused and why).", ""]
    lines += ["| criterion | verdict | value | threshold | unit | first failure [s] | note |",
              "|---|---|--:|--:|---|--:|---|"]
    lines += [_criterion_row(c) for c in outcome.criteria()]
    return [*lines, ""]


def _snapshots(outcomes: Sequence[RunOutcome], out_dir: Path,
               snapshots: Mapping[str, Path]) -> list[str]:
    """The snapshot section: each failed run's picture, titled with its first failure."""
    shown = [o for o in outcomes if o.status is Status.FAILED and o.job.name in snapshots]
    if not shown:
        return []
    lines = ["## Snapshots at the first failure", ""]
    for outcome in shown:
        t = outcome.first_failure()
        when = f"first failure at {format_value(t)} s" if t is not None else "failed"
        failed = ", ".join(_failed_names(outcome))
        lines += [f"### {outcome.job.name}: {when} ({failed})", "",
                  "!" + _link(f"{outcome.job.name}, {when}", snapshots[outcome.job.name],
                              out_dir), ""]
    return lines


def summary_markdown(outcomes: Sequence[RunOutcome], *, title: str, out_dir: Path,
                     snapshots: Mapping[str, Path] = _NO_SNAPSHOTS) -> str:
    """The text of `summary.md`, written into `out_dir` (links are relative to it).

    A header with the counts and total sim and wall times [s]; a table with a row per
    scenario file (a grid's runs together: pass rate, worst margins, `MARGINS`, and every
    contact, those a rule excused too); a table
    with a row per run
    (verdict, times, links to its .rrd and .json, and its speed-profile .png if that file
    exists); a section per run with its scenario, seed, profile, car under test (ego stack
    or scripted), overrides, its contacts
    (when it had any) and a row per criterion (or its error line); then, for each failed
    run with a snapshot in `snapshots` (job name -> PNG), the image, titled with its first
    failure's time.
    """
    lines = (_header(outcomes, title) + scorecard_markdown(outcomes)
             + _scenario_table(outcomes) + _runs_table(outcomes, out_dir))
    for outcome in outcomes:
        lines += _run_section(outcome)
    lines += _snapshots(outcomes, out_dir, snapshots)
    return "\n".join(lines).rstrip("\n") + "\n"


# --- terminal ----------------------------------------------------------------------------


def summary_table(outcomes: Sequence[RunOutcome]) -> Table:
    """The terminal summary: a row per run (name, coloured verdict, failed criteria or the
    error line, sim time [s], wall time [s]). Messages are `Text`, never parsed as markup."""
    passed, failed, errors = _counts(outcomes)
    table = Table(title=f"{passed} passed, {failed} failed, {errors} errors",
                  title_justify="left")
    table.add_column("run", style="bold", no_wrap=True,  # whole names: they are ids
                     min_width=max((len(o.job.name) for o in outcomes), default=3))
    table.add_column("verdict")
    table.add_column("failed criteria / error", overflow="fold")
    # headers as `Text`: in a markup string "[s]" would be read as a style tag
    table.add_column(Text("sim time [s]"), justify="right")
    table.add_column(Text("wall time [s]"), justify="right")
    for outcome in outcomes:
        word, style = VERDICTS[outcome.status]
        if outcome.result is None or outcome.status is Status.ERROR:
            detail = Text(outcome.error or "", style="yellow")
            sim = DASH if outcome.result is None else format_value(_sim_time(outcome))
        else:
            detail = Text(", ".join(_failed_names(outcome)), style="red")
            sim = format_value(_sim_time(outcome))
        table.add_row(Text(outcome.job.name), Text(word, style=style), detail, sim,
                      format_value(outcome.wall_time))
    return table

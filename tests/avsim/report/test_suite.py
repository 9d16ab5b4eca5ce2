"""Tests of the suite reports (`avsim.report.suite`) on synthetic outcomes: no simulation.

Four runs: one passed, one failed (a contact and a too-small gap, with a note full of XML
and Markdown specials), one with bad input and one that crashed, both of whose error lines
hold `<`, `&` and quotes.
"""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from pathlib import Path
from urllib.parse import unquote

import pytest
from junitparser import Error, Failure, JUnitXml
from rich.console import Console

from avsim.batch.jobs import RunJob, RunOutcome, Status
from avsim.report.suite import format_value, junit_xml, summary_markdown, summary_table

NASTY = 'gap < 5 m & "lead" <car> | `x` *y*'
BAD_INPUT = "actors.0.speed_kph: -3 < 0 & 'must be' \"positive\""
CRASH = "crash: RuntimeError: list index out of range <boom> & more"


def _criterion(name: str, passed: bool | None, value: float | None, threshold: float, unit: str,
               first_failure: float | None = None, note: str | None = None) -> dict[str, object]:
    verdict = "not_applicable" if passed is None else "pass" if passed else "fail"
    out: dict[str, object] = {"name": name, "verdict": verdict, "passed": passed,
                              "value": value, "threshold": threshold, "unit": unit}
    if first_failure is not None:
        out["first_failure"] = first_failure
    if note is not None:
        out["note"] = note
    return out


def _result(job: RunJob, criteria: list[dict[str, object]], sim_time: float,
            metrics: dict[str, float | None]) -> dict[str, object]:
    return {"scenario": "cut_in", "file": "scenarios/cut_in.yaml", "seed": 3,
            "profile": job.profile, "passed": all(c["passed"] is not False for c in criteria),
            "sim_time": sim_time, "wall_time": sim_time / 2, "criteria": criteria,
            "metrics": metrics, "state_changes": [], "recording": str(job.recording)}


def _outcomes(out_dir: Path) -> list[RunOutcome]:
    ok = RunJob("cut_in_ok", "cut_in", out_dir / "cut_in_ok",
                overrides={"actors.0.speed_kph": 20, "actors.0.s": 40})
    bad = RunJob("cut_in_fail", "cut_in", out_dir / "cut_in_fail",
                 overrides={"actors.0.speed_kph": 40, "actors.0.s": 10}, profile="fast")
    passed = [_criterion("no_collision", True, 0, 0, "contacts"),
              _criterion("min_gap", True, 18.2, 15.6, "m"),
              _criterion("max_decel", True, 1.0 / 3.0, 6.0, "m/s^2"),
              _criterion("stop_signs", None, None, 1.0, "s", note="no stop line on the route")]
    failed = [_criterion("no_collision", False, 1, 0, "contacts", 12.3, NASTY),
              _criterion("min_gap", False, 0.0, 15.6, "m", 11.95),
              _criterion("reach_goal", False, 40.0, 100.0, "m", note="no goal reached")]
    return [
        RunOutcome(ok, Status.PASSED, _result(ok, passed, 45.0, {"min_gap": 18.2}), None, 21.5),
        RunOutcome(bad, Status.FAILED, _result(bad, failed, 30.0, {"collisions": 1.0}), None,
                   12.25),
        RunOutcome(RunJob("typo", "typo.yaml", out_dir / "typo"), Status.BAD_INPUT,
                   error=BAD_INPUT, wall_time=0.1),
        RunOutcome(RunJob("crash", "cut_in", out_dir / "crash"), Status.ERROR, error=CRASH,
                   wall_time=2.0),
    ]


# --- numbers -------------------------------------------------------------------------------


@pytest.mark.parametrize(("x", "text"), [
    (18.2, "18.2"), (1.0 / 3.0, "0.333"), (0, "0"), (0.0, "0"), (-0.0001, "0"),
    (45.0, "45"), (math.inf, "inf"), (-math.inf, "-inf"), (math.nan, "—"), (None, "—"),
    (True, "True"), ("fast", "fast"), (12345.6789, "12345.679"),
])
def test_format_value(x: object, text: str) -> None:
    assert format_value(x) == text


# --- JUnit ---------------------------------------------------------------------------------


def _junit(tmp_path: Path) -> tuple[list[RunOutcome], ET.Element]:
    outcomes = _outcomes(tmp_path)
    text = junit_xml(outcomes, 'nightly <suite> & "co"')
    assert text.startswith('<?xml version="1.0" encoding="UTF-8"?>')
    return outcomes, ET.fromstring(text.encode())


def _check_schema(root: ET.Element) -> None:
    """The JUnit schema's rules (Jenkins junit-10.xsd) that matter to CI readers."""
    assert root.tag == "testsuites"
    totals = {"tests": 0, "failures": 0, "errors": 0}
    for suite in root:
        assert suite.tag == "testsuite"
        assert {"name", "tests", "failures", "errors", "skipped", "time"} <= set(suite.attrib)
        children = [c.tag for c in suite]
        assert children[0] == "properties"  # properties first, then the cases
        assert set(children[1:]) == {"testcase"}
        cases = suite.findall("testcase")
        for case in cases:
            assert {"classname", "name"} <= set(case.attrib)
            # a criterion's case has no time (none is invented); a run's own case has its own
            assert ("time" in case.attrib) is (case.attrib["name"] == "run")
            results = [c for c in case if c.tag != "properties"]
            assert len(results) <= 1
            assert all(c.tag in {"failure", "error", "skipped"} for c in results)
            assert all("message" in c.attrib for c in results)
            assert all("type" in c.attrib for c in results if c.tag != "skipped")
        counts = {"tests": len(cases),
                  "failures": sum(c.find("failure") is not None for c in cases),
                  "errors": sum(c.find("error") is not None for c in cases),
                  "skipped": sum(c.find("skipped") is not None for c in cases)}
        for key, n in counts.items():
            assert int(suite.attrib[key]) == n, (suite.attrib["name"], key)
            totals[key] = totals.get(key, 0) + n
        assert float(suite.attrib["time"]) >= 0.0
    for key in ("tests", "failures", "errors"):
        assert int(root.attrib[key]) == totals[key]


def test_junit_counts_and_schema(tmp_path: Path) -> None:
    _, root = _junit(tmp_path)
    _check_schema(root)
    assert root.attrib["name"] == 'nightly <suite> & "co"'
    assert (root.attrib["tests"], root.attrib["failures"], root.attrib["errors"]) == (
        "9", "3", "2")
    assert float(root.attrib["time"]) == pytest.approx(21.5 + 12.25 + 0.1 + 2.0)
    suites = {s.attrib["name"]: s for s in root}
    assert list(suites) == ["cut_in_ok", "cut_in_fail", "typo", "crash"]
    ok = suites["cut_in_ok"]
    assert [c.attrib["name"] for c in ok.iter("testcase")] == [
        "no_collision", "min_gap", "max_decel", "stop_signs"]
    assert {c.attrib["classname"] for c in ok.iter("testcase")} == {"avsim.cut_in_ok"}
    assert not list(ok.iter("failure"))
    skipped = ok.find("testcase[@name='stop_signs']/skipped")
    assert skipped is not None and skipped.attrib["message"] == "no stop line on the route"
    assert ok.attrib["skipped"] == "1"
    bad = suites["cut_in_fail"]
    first = bad.find("testcase[@name='min_gap']/properties/property")
    assert first is not None and first.attrib == {"name": "first_failure_sim_time",
                                                  "value": "11.95"}


def test_junit_failures(tmp_path: Path) -> None:
    _, root = _junit(tmp_path)
    suite = next(s for s in root if s.attrib["name"] == "cut_in_fail")
    failures = {c.attrib["name"]: c.find("failure") for c in suite.iter("testcase")}
    contact, gap, goal = failures["no_collision"], failures["min_gap"], failures["reach_goal"]
    assert contact is not None and gap is not None and goal is not None
    assert contact.attrib["message"] == "value 1 contacts (threshold 0)"
    assert gap.attrib["message"] == "value 0 m (threshold 15.6)"
    assert goal.attrib["message"] == "value 40 m (threshold 100)"
    assert "first failure at 12.3 s" in (contact.text or "")
    assert NASTY in (contact.text or "")  # the note, escaped and back
    assert "first failure at 11.95 s" in (gap.text or "")
    assert "first failure" not in (goal.text or "") and "no goal reached" in (goal.text or "")


def test_junit_errors_round_trip(tmp_path: Path) -> None:
    _, root = _junit(tmp_path)
    suites = {s.attrib["name"]: s for s in root}
    for name, message, kind in (("typo", BAD_INPUT, "bad_input"), ("crash", CRASH, "error")):
        cases = suites[name].findall("testcase")
        assert len(cases) == 1 and cases[0].attrib["name"] == "run"
        error = cases[0].find("error")
        assert error is not None
        assert error.attrib["message"] == message
        assert error.attrib["type"] == kind
        assert error.text == message


def test_junit_properties(tmp_path: Path) -> None:
    _, root = _junit(tmp_path)
    suites = {s.attrib["name"]: s for s in root}
    props = {p.attrib["name"]: p.attrib["value"]
             for p in suites["cut_in_fail"].findall("properties/property")}
    assert props == {"scenario": "cut_in", "file": "scenarios/cut_in.yaml", "seed": "3",
                     "profile": "fast", "ego": "stack", "status": "failed",
                     "override.actors.0.speed_kph": "40", "override.actors.0.s": "10"}
    typo = {p.attrib["name"]: p.attrib["value"] for p in suites["typo"].iter("property")}
    assert typo["file"] == "typo.yaml" and typo["status"] == "bad_input"
    assert "seed" not in typo  # not known for a run that did not finish


def test_junit_control_characters(tmp_path: Path) -> None:
    """A crash message with codes XML cannot hold (a terminal colour, a NUL) still parses."""
    message = "boom \x1b[31mred\x1b[0m \x00 end\nsecond line"
    outcome = RunOutcome(RunJob("crash", "cut_in", tmp_path), Status.ERROR, error=message)
    root = ET.fromstring(junit_xml([outcome], "s"))
    error = root.find("testsuite/testcase/error")
    assert error is not None
    assert error.attrib["message"] == "boom \\x1b[31mred\\x1b[0m \\x00 end\nsecond line"


def test_junit_with_junitparser(tmp_path: Path) -> None:
    """A second reader: junitparser's own counts agree with ours, case by case."""
    outcomes = _outcomes(tmp_path)
    xml = JUnitXml.fromstring(junit_xml(outcomes, "nightly"))
    stated = [(s.name, s.tests, s.failures, s.errors) for s in xml]
    assert stated == [("cut_in_ok", 4, 0, 0), ("cut_in_fail", 3, 3, 0), ("typo", 1, 0, 1),
                      ("crash", 1, 0, 1)]
    for suite in xml:
        before = (suite.tests, suite.failures, suite.errors, suite.skipped)
        suite.update_statistics()  # type: ignore[no-untyped-call]
        assert (suite.tests, suite.failures, suite.errors, suite.skipped) == before
    crash = next(iter(next(s for s in xml if s.name == "crash")))
    assert isinstance(crash.result[0], Error) and crash.result[0].message == CRASH
    fail = next(s for s in xml if s.name == "cut_in_fail")
    assert all(isinstance(c.result[0], Failure) for c in fail)


def test_junit_run_without_criteria(tmp_path: Path) -> None:
    job = RunJob("empty", "empty", tmp_path)
    outcome = RunOutcome(job, Status.PASSED, _result(job, [], 1.0, {}), wall_time=0.5)
    root = ET.fromstring(junit_xml([outcome], "s"))
    _check_schema(root)
    (case,) = root.iter("testcase")
    assert case.attrib["name"] == "run" and len(case) == 0


# --- summary.md ----------------------------------------------------------------------------


def _write_run_files(outcomes: list[RunOutcome], plots: set[str]) -> None:
    for outcome in outcomes:
        job = outcome.job
        if outcome.result is None:
            continue
        job.out_dir.mkdir(parents=True, exist_ok=True)
        job.recording.write_bytes(b"rrd")
        job.result_file.write_text("{}")
        if job.name in plots:
            job.plot_file.write_bytes(b"png")


def _links(text: str) -> list[tuple[bool, str, str]]:
    """(is an image, label, target) of every Markdown link."""
    return [(bang == "!", label, target)
            for bang, label, target in re.findall(r"(!?)\[([^\]]*)\]\(([^)]*)\)", text)]


def _summary(tmp_path: Path) -> tuple[list[RunOutcome], Path, str]:
    out_dir = tmp_path / "suite out"  # a space: links must be quoted
    outcomes = _outcomes(out_dir / "runs")
    _write_run_files(outcomes, plots={"cut_in_fail"})
    snapshot = out_dir / "snapshots" / "cut_in_fail.png"
    snapshots = {"cut_in_fail": snapshot, "cut_in_ok": out_dir / "ok.png"}
    text = summary_markdown(outcomes, title="Nightly", out_dir=out_dir, snapshots=snapshots)
    return outcomes, out_dir, text


def test_summary_header_and_run_table(tmp_path: Path) -> None:
    _, _, text = _summary(tmp_path)
    assert text.startswith("# Nightly\n")
    assert "**4 runs**: 1 passed, 1 failed, 2 errors" in text
    assert "sim time 75 s" in text and "wall time 35.85 s" in text
    rows = [line for line in text.splitlines() if line.startswith("| `")]
    first = {line.split(" | ")[0]: line for line in rows[2:6]}  # after the scenarios
    assert "**PASS** | 45 | 21.5 |" in first["| `cut_in_ok`"]
    assert "**FAIL** | 30 | 12.25 |" in first["| `cut_in_fail`"]
    assert "**BAD INPUT** | — | 0.1 | — | — | — |" in first["| `typo`"]
    assert "**ERROR** | — | 2 |" in first["| `crash`"]


def test_summary_links_are_relative_and_point_at_the_files(tmp_path: Path) -> None:
    outcomes, out_dir, text = _summary(tmp_path)
    links = _links(text)
    targets = {unquote(t) for image, _, t in links if not image}
    expected = {o.job.recording for o in outcomes[:2]} | {o.job.result_file for o in outcomes[:2]}
    expected.add(outcomes[1].job.plot_file)  # the only run with a plot file
    assert {(out_dir / t).resolve() for t in targets} == {p.resolve() for p in expected}
    for _, _, target in links:
        assert not Path(unquote(target)).is_absolute() and "\\" not in target
        assert " " not in target  # quoted
    assert all((out_dir / t).is_file() for t in targets)


def test_summary_lists_every_criterion(tmp_path: Path) -> None:
    outcomes, _, text = _summary(tmp_path)
    sections = re.split(r"^## ", text, flags=re.MULTILINE)[1:]
    by_run = {s.split(":")[0]: s for s in sections}
    for outcome in outcomes:
        section = by_run[outcome.job.name]
        rows = [line for line in section.splitlines() if line.startswith("| `")]
        assert [r.split("`")[1] for r in rows] == [str(c["name"]) for c in outcome.criteria()]
    fail_rows = {r.split("`")[1]: r.split(" | ") for r in by_run["cut_in_fail"].splitlines()
                 if r.startswith("| `")}
    assert fail_rows["no_collision"][1:6] == ["**FAIL**", "1", "0", "contacts", "12.3"]
    assert fail_rows["reach_goal"][2] == "40" and fail_rows["reach_goal"][5] == "—"
    ok_rows = {r.split("`")[1]: r.split(" | ") for r in by_run["cut_in_ok"].splitlines()
               if r.startswith("| `")}
    assert ok_rows["stop_signs"][1:3] == ["n/a", "—"]  # not applicable: no value
    assert fail_rows["reach_goal"][6] == "no goal reached |"
    assert "`actors.0.speed_kph` = `40`" in by_run["cut_in_fail"]


def test_summary_escapes_and_errors(tmp_path: Path) -> None:
    _, _, text = _summary(tmp_path)
    note_row = next(line for line in text.splitlines() if line.startswith("| `no_collision` | **"))
    assert "<car>" not in note_row and "\\<car\\>" in note_row  # not read as HTML
    assert note_row.count(" | ") == 6  # the note's pipe does not split the row
    assert "> actors.0.speed\\_kph: -3 \\< 0 & 'must be' \"positive\"" in text
    assert "> crash: RuntimeError: list index out of range \\<boom\\> & more" in text


def test_summary_snapshots(tmp_path: Path) -> None:
    _, out_dir, text = _summary(tmp_path)
    images = [(label, t) for image, label, t in _links(text) if image]
    # only the failed run's snapshot: the passed run's is not shown
    assert images == [("cut_in_fail, first failure at 11.95 s", "snapshots/cut_in_fail.png")]
    assert out_dir / images[0][1] == out_dir / "snapshots" / "cut_in_fail.png"
    assert "### cut_in_fail: first failure at 11.95 s (no_collision, min_gap, reach_goal)" in text


def test_summary_without_snapshots(tmp_path: Path) -> None:
    outcomes = _outcomes(tmp_path)
    text = summary_markdown(outcomes, title="T", out_dir=tmp_path)
    assert "Snapshots" not in text and not [i for i in _links(text) if i[0]]


# --- terminal ------------------------------------------------------------------------------


def test_summary_table(tmp_path: Path) -> None:
    table = summary_table(_outcomes(tmp_path))
    assert table.row_count == 4
    console = Console(width=200, record=True, color_system=None)
    console.print(table)
    text = console.export_text()
    lines = {line.split()[1]: line for line in text.splitlines() if line.startswith("│ ")
             and line.split()[1] in {"cut_in_ok", "cut_in_fail", "typo", "crash"}}
    assert "PASS" in lines["cut_in_ok"] and "45" in lines["cut_in_ok"]
    assert "no_collision, min_gap, reach_goal" in lines["cut_in_fail"]
    assert "BAD INPUT" in lines["typo"] and "-3 < 0" in lines["typo"]
    assert "<boom> & more" in lines["crash"]  # error text not read as rich markup
    assert "1 passed, 1 failed, 2 errors" in text
    assert "sim time [s]" in text and "wall time [s]" in text
    ansi = Console(width=200, record=True, color_system="standard", force_terminal=True)
    ansi.print(summary_table(_outcomes(tmp_path)))
    coloured = ansi.export_text(styles=True)
    for word, code in (("PASS", "1;32"), ("FAIL", "1;31"), ("BAD INPUT", "1;33"),
                       ("ERROR", "1;35")):
        assert f"\x1b[{code}m{word}" in coloured


def test_summary_scenario_table_gives_pass_rates_and_worst_margins(tmp_path: Path) -> None:
    out_dir = tmp_path / "out"
    outcomes = _outcomes(out_dir)
    for k, (ttc, gap, decel) in enumerate([(2.5, 12.0, 1.5), (1.1, None, 4.2)]):
        result = outcomes[k].result
        assert result is not None
        result["metrics"] = {"min_ttc": ttc, "min_lead_gap": gap, "max_decel": decel}
    text = summary_markdown(outcomes, title="T", out_dir=out_dir)
    rows = [line for line in text.splitlines() if line.startswith("| `")][:2]
    assert rows == ["| `cut_in` | 3 | 1 | 33 % | 1.1 | 12 | 4.2 | — |",
                    "| `typo` | 1 | 0 | 0 % | — | — | — | — |"]


def _excused(tmp_path: Path) -> list[RunOutcome]:
    """Two runs of a cut-in: one passed with a contact UN R157 excuses, one failed on a
    contact no rule excuses."""
    note = ("1 contact(s) excused: unavoidable: r157, actor cutter at 7.72 s: TTC at lane "
            "intrusion 0.48 s <= bound 1.28 s")
    hit = RunJob("cut_in_hit", "cut_in", tmp_path / "hit")
    crash = RunJob("cut_in_crash", "cut_in", tmp_path / "crash")
    excused = [_criterion("no_collision", True, 0, 0, "contacts", note=note),
               _criterion("min_gap", None, None, 2.0, "m", note="not judged")]
    counted = [_criterion("no_collision", False, 1, 0, "contacts", 9.5, "actor cutter")]
    return [RunOutcome(hit, Status.PASSED, _result(hit, excused, 35.0, {
                "collisions": 1.0, "collisions_excused": 1.0, "max_decel": 2.1}), None, 4.0),
            RunOutcome(crash, Status.FAILED, _result(crash, counted, 35.0, {
                "collisions": 2.0, "collisions_excused": 0.0}), None, 4.0)]


def test_junit_an_excused_contact_is_a_passed_testcase_with_its_note(tmp_path: Path) -> None:
    root = ET.fromstring(junit_xml(_excused(tmp_path), "r157").encode())
    hit = next(s for s in root if s.attrib["name"] == "cut_in_hit")
    case = hit.find("testcase[@name='no_collision']")
    assert case is not None
    assert case.find("skipped") is None and case.find("failure") is None
    out = case.find("system-out")
    assert out is not None and out.text is not None
    assert out.text.startswith("note: 1 contact(s) excused: unavoidable: r157, actor cutter")
    assert "<= bound 1.28 s" in out.text
    assert (hit.attrib["failures"], hit.attrib["skipped"]) == ("0", "1")  # min_gap only
    plain = next(s for s in root if s.attrib["name"] == "cut_in_crash")
    assert plain.find("testcase/system-out") is None  # a failure says it in <failure>


def test_summary_counts_every_contact_also_excused(tmp_path: Path) -> None:
    text = summary_markdown(_excused(tmp_path), title="T", out_dir=tmp_path)
    rows = [line for line in text.splitlines() if line.startswith("| `cut_in` |")]
    assert rows == ["| `cut_in` | 2 | 1 | 50 % | — | — | 2.1 | 3 (1 excused) |"]
    assert ("Contacts: 1 (1 excused) (every contact onset; `no_collision`'s note says which "
            "a rule excused and why).") in text
    assert "Contacts: 2 (every contact onset" in text


def test_junit_failure_says_what_happened_first(tmp_path: Path) -> None:
    job = RunJob("cut_in_fail", "cut_in", tmp_path)
    criteria = [_criterion("no_collision", False, 2, 0, "contacts", 12.3),
                _criterion("min_gap", False, 0.5, 15.6, "m")]
    result = _result(job, criteria, 30.0, {})
    result["infractions"] = [
        {"t": 12.3, "kind": "no_collision", "message": "contact with car <lead> & co",
         "where": [1.0, 2.0]},
        {"t": 13.0, "kind": "speed_limit", "message": "62 km/h over a 50 km/h limit",
         "where": None},
        {"t": 20.25, "kind": "no_collision", "message": "contact with truck_1",
         "where": None},
    ]
    root = ET.fromstring(junit_xml([RunOutcome(job, Status.FAILED, result)], "s").encode())
    failures = {c.attrib["name"]: c.find("failure") for c in root.iter("testcase")}
    contact, gap = failures["no_collision"], failures["min_gap"]
    assert contact is not None and gap is not None
    assert contact.attrib["message"] == ("at 12.3 s: contact with car <lead> & co; "
                                         "value 2 contacts (threshold 0)")
    text = (contact.text or "").splitlines()
    assert text[-1] == "at 20.25 s: contact with truck_1"
    assert "speed_limit" not in (contact.text or "") and "62 km/h" not in (contact.text or "")
    assert gap.attrib["message"] == "value 0.5 m (threshold 15.6)"  # no infraction: numbers

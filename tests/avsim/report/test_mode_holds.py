"""The mode-chatter measure over result files (`avsim.report.mode_holds`)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from avsim.report.mode_holds import main, measure, report


def result(path: Path, changes: list[tuple[float, str, str, str]]) -> Path:
    path.write_text(json.dumps({"state_changes": [
        {"t": t, "machine": m, "from": a, "to": b, "reason": ""} for t, m, a, b in changes]}))
    return path


def test_it_lists_every_short_hold_outside_safety_transitions(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    result(tmp_path / "a.json", [(0.0, "acc", "acc_off", "cruise"),  # switched on: not counted
                                 (0.3, "acc", "cruise", "trail"),
                                 (18.8, "acc", "trail", "yield"),
                                 (18.9, "acc", "yield", "cruise"),  # 0.1 s: chatter
                                 (19.0, "acc", "cruise", "brake"),  # safety: not counted
                                 (19.2, "acc", "brake", "trail"),
                                 (25.0, "acc", "trail", "cruise"),
                                 (25.1, "motion", "lane_keep", "turn_left")])
    result(tmp_path / "b.json", [(0.0, "acc", "acc_off", "cruise"),
                                 (1.0, "acc", "cruise", "trail"),
                                 (4.0, "acc", "trail", "red_light")])
    runs = measure([tmp_path])
    assert [r.label for r in runs] == ["a", "b"]
    assert [(h.mode, h.then) for h in runs[0].under(0.5)] == [("yield", "cruise")]
    assert runs[0].shortest == pytest.approx(0.1) and runs[1].shortest == pytest.approx(3.0)
    assert "2 runs, 4 acc holds" in report(runs, 0.5)  # a: trail, yield, trail; b: trail
    assert main([str(tmp_path)]) == 1
    assert "yield held 0.100 s from 18.800 s, then cruise" in capsys.readouterr().out
    assert main([str(tmp_path / "b.json")]) == 0


@pytest.mark.parametrize(("text", "problem"), [
    ("not json", "not a readable JSON file"),
    ('{"criteria": []}', "state_changes: missing"),
    ('{"state_changes": [{"t": 0.0}]}', "lacks t, machine, from or to"),
])
def test_bad_input_is_one_line_naming_the_file_exit_2(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], text: str, problem: str) -> None:
    bad = tmp_path / "bad.json"
    bad.write_text(text)
    assert main([str(bad)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and str(bad) in err and problem in err

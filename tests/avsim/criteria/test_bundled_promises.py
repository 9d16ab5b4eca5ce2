"""The bundled scenarios promise in their `description:` only what their criteria check:
each promise below, where a description makes it, needs its criterion configured in the
file's `criteria:` with the promised figure (the default criteria, always on, need nothing:
no contact, tyres in the lane, the posted limit, stop lines, red lights, crossings, speed
bumps, reaching the end, the minimum-risk stop). Every description says what is checked
after "Checked:" or states only such promises."""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path

import pytest

from avsim.scenario.load import load_scenario
from avsim.scenario.scenario import Scenario

REPO = Path(__file__).parents[3]
BUNDLED = sorted([*REPO.glob("scenarios/*.yaml"), *REPO.glob("scenarios/acceptance/*.yaml"),
                  *REPO.glob("scenarios/faults/*.yaml")])


def _get(s: Scenario, key: str) -> object:
    return s.criteria.get(key)


def _gap_band(s: Scenario) -> tuple[float, float] | None:
    band = _get(s, "standstill_gap")
    if not isinstance(band, tuple | list):
        return None
    return float(band[0]), float(band[1])


# a phrase of a description -> what must hold of the scenario's criteria
PROMISES: dict[str, Callable[[Scenario, re.Match[str]], bool]] = {
    r"at least ([0-9.]+) m short": lambda s, m: (b := _gap_band(s)) is not None
    and b[0] >= float(m.group(1)),
    r"([0-9.]+) (?:to|-) ([0-9.]+) m (?:short|behind)|standstill gap of ([0-9.]+) to "
    r"([0-9.]+) m": lambda s, m: _gap_band(s) == tuple(
        float(x) for x in (m.groups()[:2] if m.group(1) else m.groups()[2:])),
    r"d_min": lambda s, _m: any(_get(s, k) == "r157" for k in ("min_gap", "following_gap")),
    r"ISO 15622's comfort|comfort \(ISO 15622\)": lambda s, _m: _get(s, "comfort") is not None,
    r"decelerat\w* harder than ([0-9.]+) m/s\^2|deceleration of at most ([0-9.]+) m/s\^2":
        lambda s, m: _get(s, "max_decel") == float(m.group(1) or m.group(2)),
    r"([0-9.]+) m/s\^2 of lateral acceleration": lambda s, m: getattr(
        _get(s, "lane_change"), "max_lateral_accel", None) == float(m.group(1)),
    r"in under ([0-9.]+) s": lambda s, m: getattr(
        _get(s, "lane_change"), "max_duration", None) == float(m.group(1)),
    r"within ([0-9.]+) s of the lane ahead clearing": lambda s, m: _get(
        s, "resume_within") == float(m.group(1)),
    r"longer than ([0-9.]+) s with the right of way": lambda s, m: _get(
        s, "max_wait_with_right_of_way") == float(m.group(1)),
    r"to s = ([0-9.]+) m": lambda s, m: _get(s, "reach_s") == float(m.group(1)),
}


@pytest.mark.parametrize("path", BUNDLED, ids=lambda p: p.stem)
def test_each_promise_of_a_description_is_configured(path: Path) -> None:
    scenario = load_scenario(path)
    for pattern, holds in PROMISES.items():
        for match in re.finditer(pattern, scenario.description):
            assert holds(scenario, match), (path.name, match.group(0))


def test_the_bundled_set_is_read() -> None:
    assert len(BUNDLED) >= 30
    sudden = load_scenario(REPO / "scenarios" / "sudden_stop.yaml")
    assert "at least 0.5 m short" in sudden.description
    assert _gap_band(sudden) == (0.5, 15.0)

"""The rates table: every rate of the program, each dividing the 240 Hz physics rate, the
rates checked on another rate's steps multiples of it, and no rate declared anywhere else
(checked on the source with `ast`)."""

from __future__ import annotations

import ast
from collections.abc import Iterator
from pathlib import Path

import pytest

from world.core import rates
from world.core.rates import (
    ACTOR_RATE,
    ACTOR_RECORD_RATE,
    CAR_SENSORS,
    CONTACT_RATE,
    CONTROL_RATE,
    CRITERIA_RATE,
    FRAME_LATENCY,
    GNSS,
    ODOMETRY,
    PHYSICS_RATE,
    PROFILE_SENSORS,
    RECORD_RATE,
    TRIGGER_RATE,
    TRUTH,
    Rate,
    SensorTiming,
    check_nested,
)
from world.sensors.setup import Profile

REPO = Path(__file__).resolve().parents[3]
PACKAGES = ("vehicle_urdf", "world", "perception", "planner", "control", "avsim", "bench")
TABLE = REPO / "world" / "core" / "rates.py"
DECLARES = ("Rate", "SensorTiming")  # the types a rate is declared with


def test_the_table() -> None:
    assert PHYSICS_RATE == 240
    assert {r.name: r.hz for r in (TRIGGER_RATE, ACTOR_RATE, CONTROL_RATE, CRITERIA_RATE,
                                   CONTACT_RATE, RECORD_RATE, ACTOR_RECORD_RATE)} == {
        "npc_triggers": 40, "npc_motion": 120, "control": 40, "criteria": 40,
        "contacts": 120, "record": 20, "record_actors": 10}
    assert (GNSS.rate.hz, GNSS.latency, GNSS.record_every) == (10, 0.0, 0)
    assert (ODOMETRY.rate.hz, ODOMETRY.latency, ODOMETRY.record_every) == (40, 0.0, 0)
    assert CAR_SENSORS == {"gnss": GNSS, "odometry": ODOMETRY}
    assert FRAME_LATENCY == 0.1
    hz = {profile: {name: (t.rate.hz, t.latency, t.record_every) for name, t in table.items()}
          for profile, table in PROFILE_SENSORS.items()}
    front, lidar = (10, 0.1, 5), (10, 0.1, 10)  # recorded at 2 Hz and 1 Hz
    assert hz == {
        "fast": {"front": front, "lidar": lidar},
        "default": {"front": front, "left": (2, 0.1, 4), "right": (2, 0.1, 4), "lidar": lidar},
        "paper": {"front": front, "left": (10, 0.1, 4), "right": (10, 0.1, 4), "lidar": lidar},
    }
    assert set(PROFILE_SENSORS) == {p.value for p in Profile}


def table_rates() -> Iterator[Rate]:
    """Every `Rate` of the table, those inside its sensor entries included."""
    def walk(value: object) -> Iterator[Rate]:
        if isinstance(value, Rate):
            yield value
        elif isinstance(value, SensorTiming):
            yield value.rate
        elif isinstance(value, dict):
            for v in value.values():
                yield from walk(v)
        elif isinstance(value, tuple):
            for v in value:
                yield from walk(v)
    for name in dir(rates):
        if not name.startswith("__"):
            yield from walk(getattr(rates, name))


def test_every_rate_of_the_table_divides_the_physics_rate() -> None:
    found = list(table_rates())
    assert {r.name for r in found} == {
        "npc_triggers", "npc_motion", "control", "criteria", "contacts", "record",
        "record_actors", "gnss", "odometry", "front", "left", "right", "lidar", "truth"}
    for rate in found:
        assert PHYSICS_RATE % rate.hz == 0, rate
        assert rate.every * rate.hz == PHYSICS_RATE, rate
        assert rate.period == rate.every / PHYSICS_RATE
    for timing in (GNSS, ODOMETRY, TRUTH,
                   *(t for p in PROFILE_SENSORS.values() for t in p.values())):
        assert timing.latency_steps / PHYSICS_RATE == pytest.approx(timing.latency, abs=1e-12)


def test_a_rate_that_does_not_divide_the_physics_rate_is_refused() -> None:
    for hz in (7, 0, -40, 480, 50):
        with pytest.raises(ValueError, match="must divide 240 Hz"):
            Rate("x", hz)
    assert Rate("x", 48).every == 5


def test_rates_looked_at_on_another_rates_steps_are_multiples_of_it() -> None:
    check_nested()  # the table's own
    for rate, on in rates.NESTED:
        assert rate.every % on.every == 0
    with pytest.raises(ValueError, match="multiple"):
        check_nested(((Rate("record", 80), Rate("contacts", 120)),))  # 3 steps on every 2nd
    check_nested(((Rate("record", 40), Rate("contacts", 120)),))  # 6 steps on every 2nd


def declarations(source: str) -> list[int]:
    """Lines where `source` calls one of `DECLARES` (a rate declared), or assigns a name
    `PHYSICS_RATE`."""
    lines = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Call):
            func = node.func
            name = func.id if isinstance(func, ast.Name) else \
                func.attr if isinstance(func, ast.Attribute) else ""
            if name in DECLARES:
                lines.append(node.lineno)
        elif isinstance(node, ast.Assign | ast.AnnAssign):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            if any(isinstance(t, ast.Name) and t.id == "PHYSICS_RATE" for t in targets):
                lines.append(node.lineno)
    return sorted(lines)


def test_the_checker_finds_declarations() -> None:
    assert declarations("from world.core.rates import Rate\nX = Rate('x', 10)\n") == [2]
    assert declarations("import world.core.rates as r\n\nY = r.SensorTiming(r.Rate('y', 5))\n") \
        == [3, 3]
    assert declarations("PHYSICS_RATE = 120\n") == [1]
    assert declarations("from world.core.rates import PHYSICS_RATE\nn = PHYSICS_RATE // 6\n") \
        == []


def test_the_table_is_the_only_place_rates_are_declared() -> None:
    found = []
    for package in PACKAGES:
        for path in sorted((REPO / package).rglob("*.py")):
            if path == TABLE:
                continue
            found += [f"{path.relative_to(REPO)}:{line}"
                      for line in declarations(path.read_text(encoding="utf-8"))]
    assert not found, "rates declared outside world/core/rates.py:\n" + "\n".join(found)
    assert declarations(TABLE.read_text(encoding="utf-8"))  # and the table does declare them

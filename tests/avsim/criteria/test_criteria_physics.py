"""The core criteria fail on real physics when the car really breaks their rule.

A reckless driver stands in for the stack's commands (the stack still runs, so the run is
wired as usual; its commands are replaced before they reach the joints): full throttle
into a parked car, past a speed limit, over a stop line, into a red light; a panic stop.
The car drives through its joints in the PyBullet world; each test asserts that the
situation happened (the contact, the speed, the crossing) as well as the verdict, from the
truth in the run's log."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
import yaml

from avsim.run.runner import Runner, RunResult
from avsim.scenario.load import load_scenario
from control.command import StackStep, VehicleCommand
from world.frames import MPS_PER_KPH as KPH

Driver = Callable[[float], tuple[float, float]]  # t [s] -> (drive, brake) torque [N m]
THROTTLE = 2000.0  # [N m] total drive torque: about 4 m/s^2 at first (capped at 5)
PANIC = 12000.0  # [N m] total brake torque: the tyres' grip is the limit


def scenario(tmp_path: Path, name: str, *, speed_kph: float, limit_kph: float = 50.0,
             features: list[dict[str, object]] | None = None,
             actors: list[dict[str, object]] | None = None,
             criteria: dict[str, object] | None = None, duration: float = 12.0,
             events: list[dict[str, object]] | None = None, lanes: int = 1) -> Path:
    text = {"format": "avsim/1", "name": name, "duration": duration,
            "road": {"lanes": lanes, "shoulder": 2.5, "speed_limit_kph": limit_kph,
                     "segments": [{"straight": 400}], "features": features or []},
            "events": events or [],
            "ego": {"s": 10, "speed_kph": speed_kph, "set_speed_kph": speed_kph,
                    "max_speed_kph": 100},
            "actors": actors or [], "criteria": {"completes": False, **(criteria or {})}}
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump(text), encoding="utf-8")
    return path


def reckless(path: Path, driver: Driver, steer: Callable[[float], float] = lambda t: 0.0,
             declare: tuple[int, int] | None = None) -> RunResult:
    """Run `path` without sensors, the stack's commands replaced by `driver`'s torques and
    `steer`'s wheel angle [rad]; with `declare` (lane, origin lane) its plan claims that
    lane change all along."""
    runner = Runner(load_scenario(path), None, profile=None)
    stack_tick = runner.stack.tick

    def tick(t: float, dt: float) -> StackStep:
        out = stack_tick(t, dt)
        assert out.plan is not None
        plan = out.plan if declare is None else dataclasses.replace(
            out.plan, lane=declare[0], origin_lane=declare[1])
        drive, brake = driver(t)
        return StackStep(VehicleCommand(steer(t), drive, brake, 0.0), plan)

    runner.stack.tick = tick  # type: ignore[method-assign]
    return runner.run()


def verdicts(result: RunResult) -> dict[str, bool | None]:
    return {c.name: c.passed for c in result.criteria}


def test_driving_into_a_parked_car_fails_no_collision(tmp_path: Path) -> None:
    path = scenario(tmp_path, "ram", speed_kph=20,
                    actors=[{"id": "parked", "type": "obstacle", "lane": 0, "s": 60}])
    result = reckless(path, lambda t: (THROTTLE, 0.0))
    touched = [i for i in result.infractions if i.kind == "no_collision"]
    assert touched and "actor parked" in touched[0].message  # it did hit the parked car
    assert max(result.log.station) > 60.0 - 2.4 - 2.4 - 0.5  # bumper to its rear
    assert verdicts(result)["no_collision"] is False and not result.passed


def test_full_throttle_past_the_limit_fails_speed_limit(tmp_path: Path) -> None:
    result = reckless(scenario(tmp_path, "speeding", speed_kph=25, limit_kph=30),
                      lambda t: (THROTTLE, 0.0))
    assert max(result.log.speed) > 35 * KPH  # it did go well over 30 km/h
    limit = next(c for c in result.criteria if c.name == "speed_limit")
    assert limit.passed is False and limit.value is not None and limit.value > 1.0


def test_a_panic_stop_fails_max_decel(tmp_path: Path) -> None:
    path = scenario(tmp_path, "panic", speed_kph=50, criteria={"max_decel": 5.0}, duration=8)
    result = reckless(path, lambda t: (1000.0, 0.0) if t < 2.0 else (0.0, PANIC))
    speed = result.log.array("speed")
    assert speed[0] > 13.0 and speed[-1] < 0.5  # it did stop, from 50 km/h
    decel = next(c for c in result.criteria if c.name == "max_decel")
    assert decel.passed is False and decel.value is not None and decel.value > 6.0
    assert decel.first_failure is not None and 2.0 < decel.first_failure < 2.5


def test_rolling_over_a_stop_line_fails_stop_signs(tmp_path: Path) -> None:
    path = scenario(tmp_path, "roll", speed_kph=30, features=[{"type": "stop_sign", "s": 80}])
    result = reckless(path, lambda t: (400.0, 0.0))  # about holds 30 km/h
    front = result.log.array("station") + 2.4
    over = int(np.argmax(front > 80.0))
    assert over > 0 and result.log.speed[over] > 5.0  # over the line, never stopped
    stop = next(c for c in result.criteria if c.name == "stop_signs")
    assert stop.passed is False and stop.value == 0.0
    assert stop.first_failure == pytest.approx(result.log.t[over], abs=0.05)


def test_driving_through_a_red_light_fails_red_lights(tmp_path: Path) -> None:
    light = {"type": "traffic_light", "s": 80, "green": 2, "yellow": 1, "red": 30, "phase": 0}
    path = scenario(tmp_path, "red", speed_kph=30, features=[light])
    result = reckless(path, lambda t: (400.0, 0.0))
    front = result.log.array("station") + 2.4
    t_over = result.log.t[int(np.argmax(front > 80.0))]
    assert 3.0 < t_over < 33.0  # over the stop line while the light was red
    red = next(c for c in result.criteria if c.name == "red_lights")
    assert red.passed is False and red.value == pytest.approx(3.0 - t_over, abs=0.05)
    # the other feature criteria had nothing to judge: they say so
    assert verdicts(result)["stop_signs"] is None
    assert all(i.kind != "no_collision" for i in result.infractions)


def test_a_panic_stop_in_lane_after_a_flat_tyre_is_no_minimum_risk_stop(tmp_path: Path) -> None:
    flat = {"trigger": {"time": 1.0}, "flat_tire": {"wheel": "front_left"}}
    path = scenario(tmp_path, "flat", speed_kph=50, events=[flat], duration=10,
                    criteria={"completes": True})
    result = reckless(path, lambda t: (1000.0, 0.0) if t < 2.0 else (0.0, PANIC))
    assert result.story[0].fired_at == pytest.approx(1.0)  # the tyre did go flat
    assert result.log.speed[-1] < 0.1 and abs(result.log.lane_error[-1]) < 0.5  # in lane
    mrm = next(c for c in result.criteria if c.name == "minimum_risk_stop")
    assert mrm.passed is False and mrm.value is not None and mrm.value > 6.0
    assert mrm.first_failure is not None and 2.0 < mrm.first_failure < 2.5
    assert mrm.note == "it stood off the shoulder, which the road has there"
    completes = next(c for c in result.criteria if c.name == "completes")
    assert completes.passed is False  # the stop does not count as completion


def test_a_stack_that_declares_a_lane_change_but_weaves_fails_tyres_in_lane(
        tmp_path: Path) -> None:
    """Its plan says "lane 1 from lane 0" the whole run; the car swerves over the line and
    back. The criterion judges the tyres, not the claim."""
    path = scenario(tmp_path, "weave", speed_kph=40, lanes=2, duration=8)

    def swerve(t: float) -> float:  # one period of cos from 1 to 4 s: out by ~1.2 m and back
        return 0.055 * math.cos(2.0 * math.pi * (t - 1.0) / 3.0) if 1.0 < t < 4.0 else 0.0

    result = reckless(path, lambda t: (350.0, 0.0), steer=swerve, declare=(1, 0))
    assert all(lane == 1 for lane in result.log.lane)  # the claim, all along
    lateral = result.log.array("lane_error")
    assert lateral.max() > 0.9 and abs(lateral[-1]) < 0.9  # over the line (tyres) and back
    tyres = next(c for c in result.criteria if c.name == "tyres_in_lane")
    assert tyres.passed is False and tyres.value is not None and tyres.value < 0.0
    assert any("no lane change" in i.message for i in result.infractions)

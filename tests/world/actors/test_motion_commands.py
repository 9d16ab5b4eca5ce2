"""A director's newer commands on one `NpcMotion`: a teleport jumps at once and is done, a
speed profile runs through its points, and a speed command while an untimed path runs
changes the speed the path is followed at instead of ending the path."""

from __future__ import annotations

import pytest

from world.actors.behaviour import NpcMotion
from world.actors.profiles import PathCommand, ProfileCommand, TeleportCommand, TrackCommand

DT = 1.0 / 120.0  # [s] the motion step


def motion(speed: float = 10.0) -> NpcMotion:
    return NpcMotion(100.0, 0.0, speed, 1, ())


def test_a_teleport_jumps_keeps_the_speed_and_is_done() -> None:
    m = motion()
    m.command(TeleportCommand("jump", 300.0, 3.5, 1))
    assert (m.s, m.offset, m.lane, m.speed, m.jumped) == (300.0, 3.5, 1, 10.0, True)
    assert m.finished == ["jump"]
    m.step(0.0, DT, 0.0)
    assert m.s == pytest.approx(300.0 + 10.0 * DT)
    assert m.offset == 3.5


def test_a_speed_profile_runs_through_its_points() -> None:
    m = motion()
    m.command(ProfileCommand("p", (0.0, 2.0, 2.0, 4.0), (10.0, 14.0, 6.0, 6.0)))
    t, speeds = 0.0, {}
    for _ in range(int(5.0 / DT)):
        m.step(t, DT, 0.0)
        t += DT
        speeds[round(t, 3)] = m.speed
    assert speeds[1.0] == pytest.approx(12.0)
    assert speeds[3.0] == pytest.approx(6.0)  # the step at 2 s
    assert m.finished == ["p"]


def test_a_speed_command_on_an_untimed_path_sets_its_speed() -> None:
    m = motion(speed=2.0)
    m.command(PathCommand("path", (100.0, 100.0), (0.0, 10.0), None))  # across the road
    m.command(TrackCommand("sync", 4.0, 1e9, 1e9))
    t = 0.0
    for _ in range(60):  # 0.5 s at 4 m/s: 2 m across
        m.step(t, DT, 0.0)
        t += DT
    assert m.offset == pytest.approx(2.0, abs=1e-6)
    assert m.s == pytest.approx(100.0)
    assert m.finished == []  # the path still runs

"""A LongitudinalDistanceAction's command (`Commands.follow`): the gap is measured along the
referenced entity's direction of travel (ahead of it for leadingReferencedEntity, also when
both drive against the route), and without acceleration limits it is closed by the next
check, as esmini places the actor at the distance each step."""

from __future__ import annotations

import math

import pytest

from avsim.run.storyboard.commands import Commands, Follow
from avsim.run.storyboard.snapshot import EntityState, Snapshot
from avsim.scenario.openscenario.actions import LongitudinalDistanceAction

PERIOD = 0.025  # [s] between two checks
SPEED = 20.0  # [m/s] the referenced entity's


def _entity(name: str, s: float, heading: float, ahead: float = 1.4) -> EntityState:
    return EntityState(name=name, x=s, y=0.0, heading=heading, speed=SPEED, s=s, offset=0.0,
                       lane=0, route_heading=0.0, length=4.0, width=2.0, centre_ahead=ahead,
                       odometer=0.0, standing_for=0.0, off_road_for=0.0, end_of_road_for=0.0)


def _target(me_s: float, ref_s: float, heading: float, displacement: str,
            me_ahead: float = 1.4) -> float:
    action = LongitudinalDistanceAction("GVT", 10.0, None, True, True, "road", displacement,
                                        None)
    me, ref = _entity("SOV", me_s, heading, me_ahead), _entity("GVT", ref_s, heading)
    snap = Snapshot(0.0, {"SOV": me, "GVT": ref}, {})
    commands = Commands.__new__(Commands)  # `follow` reads only the snapshot
    cmd, _ = commands.follow(Follow("keep", "SOV", action), me, snap, 70.0, PERIOD)
    assert math.isinf(cmd.max_accel) and math.isinf(cmd.max_decel)
    return cmd.target


@pytest.mark.parametrize(("heading", "ahead"), [(0.0, 1.0), (math.pi, -1.0)])
def test_an_actor_leading_closes_its_gap_by_the_next_check(heading: float,
                                                           ahead: float) -> None:
    """10.2 m of free space where 10 m are wanted (4 m boxes: 14.2 m between the points),
    0.2 m too far ahead along the way both drive: 0.2 m / 0.025 s slower than the entity."""
    target = _target(100.0 + ahead * 14.2, 100.0, heading, "leadingReferencedEntity")
    assert target == pytest.approx(SPEED - 0.2 / PERIOD)


@pytest.mark.parametrize(("heading", "ahead"), [(0.0, 1.0), (math.pi, -1.0)])
def test_an_actor_trailing_closes_its_gap_by_the_next_check(heading: float,
                                                            ahead: float) -> None:
    """10.3 m of free space behind the entity where 10 m are wanted: 0.3 m / 0.025 s
    faster."""
    target = _target(100.0 - ahead * 14.3, 100.0, heading, "trailingReferencedEntity")
    assert target == pytest.approx(SPEED + 0.3 / PERIOD)


@pytest.mark.parametrize(("heading", "ahead"), [(0.0, 1.0), (math.pi, -1.0)])
def test_a_gap_error_smaller_than_the_reached_band_is_closed_too(heading: float,
                                                                 ahead: float) -> None:
    """10.05 m of free space where 10 m are wanted: closed by the next check as any other
    error (esmini moves the actor onto the distance at every step), not left to drift."""
    target = _target(100.0 + ahead * 14.05, 100.0, heading, "leadingReferencedEntity")
    assert target == pytest.approx(SPEED - 0.05 / PERIOD)


@pytest.mark.parametrize(("heading", "ahead"), [(0.0, 1.0), (math.pi, -1.0)])
def test_free_space_is_measured_between_the_boxes(heading: float, ahead: float) -> None:
    """The actor's box centre 1.5 m ahead of its reference point, the entity's 1.4 m: with
    the reference points 14.0 m apart the boxes are 14.1 m apart, 10.1 m of free space
    where 10 m are wanted: 0.1 m / 0.025 s slower than the entity."""
    target = _target(100.0 + ahead * 14.0, 100.0, heading, "leadingReferencedEntity",
                     me_ahead=1.5)
    assert target == pytest.approx(SPEED - 0.1 / PERIOD)

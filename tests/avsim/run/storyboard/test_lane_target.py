"""The lane a relative lane change counts from: the entity's lane as its position named it
(esmini keeps a lane position's lane even where the offset puts the entity over the
border), else the lane its reference point is in."""

from __future__ import annotations

from pathlib import Path

import pytest

from avsim.run.storyboard.commands import target_route_lane
from avsim.scenario.load import load_scenario
from avsim.scenario.openscenario.model import (
    LaneChangeAction,
    RelativeTargetLane,
    TransitionDynamics,
)
from tests.avsim.run.storyboard.helpers import entity, snapshot

ASAM = Path("tests/data/asam_examples")
CHANGE = LaneChangeAction(TransitionDynamics("sinusoidal", "distance", 20.0, None),
                          RelativeTargetLane("A1", 1), 2.0)


def test_a_relative_lane_change_counts_from_the_named_lane() -> None:
    snap = snapshot(entity("A1", lane=1))  # its point 5 cm over the border into lane 1
    assert target_route_lane(CHANGE, (-4, -3, -2), 3, snap, {"A1": 0}) == 1
    assert target_route_lane(CHANGE, (-4, -3, -2), 3, snap) == 2  # no named lane


def test_a_lane_position_over_its_border_keeps_its_lane() -> None:
    """ASAM's 1.2 EndofTrafficJamNeighboringLaneOccupied puts A1 2.0 m left of lane -4's
    centre (3.9 m wide): 5 cm into lane -3, in lane -4 as esmini reads it."""
    path = ASAM / "exampleFilesVersion1_2/EndofTrafficJamNeighboringLaneOccupied.xosc"
    scenario = load_scenario(path, search_paths=[ASAM])
    a1 = scenario.world.actors[0]
    assert a1.lane == scenario.world.ego.lane
    assert a1.offset == pytest.approx(2.0)

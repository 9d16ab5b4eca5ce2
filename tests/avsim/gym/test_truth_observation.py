"""The `truth` observation takes the actors as the privileged truth frame gives them: their
velocity over ground from their motion between observations, the unsensed ones left out."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any, cast

import numpy as np
import pytest

from avsim.gym.truth import TruthObservation
from world.actors.actor_set import ActorPoses
from world.spec import ActorType
from world.world import World


def _world(t: float, walker_y: float, unsensed: set[int]) -> World:
    poses = ActorPoses(
        ids=("walker", "parked"), kinds=(ActorType.PEDESTRIAN, ActorType.CAR),
        centres=np.array([[20.0, walker_y, 0.9], [30.0, 3.0, 0.7]]), yaws=np.zeros(2),
        half_sizes=np.array([[0.25, 0.3, 0.9], [2.4, 0.9, 0.7]]), stations=np.zeros(2),
        offsets=np.zeros(2), speeds=np.array([1.2, 0.0]), accels=np.zeros(2))
    ego = SimpleNamespace(position=np.zeros(3), yaw=0.0, speed=0.0, yaw_rate=0.0,
                          velocity=np.zeros(3))
    fake: Any = SimpleNamespace(ego_truth=ego, ego_route=SimpleNamespace(station=0.0),
                                actors=SimpleNamespace(poses=poses, bodies=[1, 2]),
                                unsensed=unsensed, t=t)
    return cast(World, fake)


def test_a_walker_stepping_sideways_moves_sideways_and_an_unsensed_actor_is_absent() -> None:
    obs = TruthObservation(nearest=4, period=0.1)
    obs.encode(_world(1.0, -2.0, set()), 0.0)
    second = obs.encode(_world(1.1, -1.88, set()), 0.0)  # 1.2 m/s to the left, facing +x
    walker = second["actors"][0]
    assert (walker[3], walker[4]) == pytest.approx((0.0, 1.2), abs=1e-5)
    assert second["actors_mask"].tolist() == [1, 1, 0, 0]
    hidden = obs.encode(_world(1.2, -1.76, {1}), 0.0)  # the parked car hidden from sensors
    assert hidden["actors_mask"].tolist() == [1, 0, 0, 0]

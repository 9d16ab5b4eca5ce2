"""`world.truth.vehicles_ahead` gives its last answer again only to the same question: the
same poses object and map and the same numbers bit for bit."""

from __future__ import annotations

import numpy as np

from tests.roads import make_map, seg
from world.actors.actor_set import ActorPoses
from world.spec import ActorType
from world.truth import find_vehicles_ahead, vehicles_ahead


def poses(station: float) -> ActorPoses:
    """One car on lane 0's centre (1.75 m left of the line) at `station` [m]."""
    n = 1
    return ActorPoses(
        ids=("car",), kinds=(ActorType.CAR,),
        centres=np.array([[station, 1.75, 0.7]]), yaws=np.zeros(n),
        half_sizes=np.array([[2.3, 0.9, 0.7]]), speeds=np.full(n, 10.0),
        accels=np.zeros(n), stations=np.array([station]), offsets=np.array([1.75]))


def test_a_new_question_gets_a_new_answer_and_the_same_question_the_same() -> None:
    road = make_map(seg(500.0))
    ahead = poses(100.0)
    first = vehicles_ahead(road, ahead, 10.0, 1.75, 4.6)
    assert first == find_vehicles_ahead(road, ahead, 10.0, 1.75, 4.6) and len(first) == 1
    assert vehicles_ahead(road, ahead, 10.0, 1.75, 4.6) is first
    moved = vehicles_ahead(road, ahead, 20.0, 1.75, 4.6)  # the ego moved on
    assert moved[0].gap == first[0].gap - 10.0
    other = poses(100.0)  # equal numbers, another tick's poses
    assert vehicles_ahead(road, other, 20.0, 1.75, 4.6) is not moved
    assert vehicles_ahead(road, other, 120.0, 1.75, 4.6) == ()  # past it

"""The box of each actor's body: a vehicle's catalogue model (`world.actors.catalogue`: the
actor's `model`, else its type's default), or `SIZES` for the bodies that are not vehicles.

A leaf (no PyBullet): the scenario loader checks that bodies do not overlap where they
start (`avsim.scenario.checks.check_spawn`) before anything heavy is imported; the physics
world (`world.actors.actor_set`) builds the same boxes.
"""

from __future__ import annotations

from dataclasses import dataclass

from world.actors.catalogue import CATALOGUE, DEFAULT_MODEL, VehicleModel
from world.spec import ActorSpec, ActorType


@dataclass(frozen=True, slots=True)
class BoxSize:
    """An actor's box."""

    length: float  # [m]
    width: float  # [m]
    height: float  # [m]


SIZES = {  # the bodies that are not vehicles (those are catalogue models)
    ActorType.OBSTACLE: BoxSize(1.0, 1.0, 1.0),  # [m] length, width, height: a crate / block
    ActorType.PEDESTRIAN: BoxSize(0.5, 0.6, 1.75),
}
VEHICLES = (ActorType.CAR, ActorType.TRUCK)


def vehicle_of(spec: ActorSpec) -> VehicleModel | None:
    """The catalogue model of a vehicle actor (its own, else its type's default); None for a
    pedestrian or an obstacle."""
    if spec.type not in VEHICLES:
        return None
    return spec.model if spec.model is not None else CATALOGUE[DEFAULT_MODEL[spec.type.value]]


def body_size(spec: ActorSpec) -> BoxSize:
    """[m] the box of an actor's body."""
    model = vehicle_of(spec)
    if model is None:
        return SIZES[spec.type] if spec.size is None else BoxSize(*spec.size)
    return BoxSize(model.length, model.width, model.height)

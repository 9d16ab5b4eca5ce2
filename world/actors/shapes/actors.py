"""Which shape an actor's body has: its vehicle model's, or a Euro NCAP target's.

- a vehicle whose model is one of the catalogue's (`world.actors.catalogue`) has that
  model's shape; a model from an OpenSCENARIO file has the Euro NCAP target's shape when it
  is the Euro NCAP catalogue's entry (`OPENSCENARIO_TARGETS`: the GVT, the bicycle EBTa, the
  motorcycle EMT, each with its rider);
- a pedestrian whose box is an Euro NCAP pedestrian target's envelope (EPTa, EPTc: the
  catalogue's bounding boxes, as a file gives them) has that target's shape, standing at
  gait phase 0;
- anything else (an obstacle, a pedestrian of another size, a vehicle model the shapes do
  not know) has none: its body stays its box.

A shape is used only when its footprint is the actor's box's (length and width within
`MATCH`), so a body is never longer or wider than the box the rest of the world reasons
with. Its height may differ: the Euro NCAP files give the bicycle's and the motorcycle's
boxes without their riders.
"""

from __future__ import annotations

from functools import lru_cache

from world.actors.shapes import targets as t
from world.actors.shapes.body import Body
from world.actors.shapes.catalogue import bodies, pedestrian

MATCH = 0.01  # [m] largest difference of a shape's length or width from the actor's box

# the Euro NCAP OpenSCENARIO catalogue's vehicle entries -> the targets' shapes
OPENSCENARIO_TARGETS = {
    "NCAP_GlobalVehicleTarget": t.GVT.name,
    "NCAP_Bicycle": t.EBTA.name,
    "NCAP_Motorcycle": t.EMT.name,
}
PEDESTRIAN_TARGETS = (t.EPTA, t.EPTC)


@lru_cache(maxsize=1)
def _bodies() -> dict[str, Body]:
    return bodies()


def vehicle_shape(model: str, length: float, width: float) -> Body | None:
    """The shape of vehicle model `model` whose box is `length` x `width` [m] (None: none)."""
    body = _bodies().get(OPENSCENARIO_TARGETS.get(model, model))
    return body if body is not None and _fits(body, length, width) else None


@lru_cache(maxsize=len(PEDESTRIAN_TARGETS))
def _pedestrian(index: int) -> Body:
    return pedestrian(PEDESTRIAN_TARGETS[index], 0.0)


def pedestrian_shape(length: float, width: float, height: float) -> Body | None:
    """The shape of a pedestrian whose box is `length` x `width` x `height` [m]: the Euro NCAP
    target with that envelope, at gait phase 0 (None: no target has it)."""
    for i, target in enumerate(PEDESTRIAN_TARGETS):
        if max(abs(target.length - length), abs(target.width - width),
               abs(target.height - height)) <= MATCH:
            return _pedestrian(i)
    return None


def _fits(body: Body, length: float, width: float) -> bool:
    return abs(body.length - length) <= MATCH and abs(body.width - width) <= MATCH

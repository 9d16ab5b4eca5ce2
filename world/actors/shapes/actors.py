"""Which shape an actor's body has: its vehicle model's, or a Euro NCAP target's.

- a vehicle whose model is one of the catalogue's (`world.actors.catalogue`) has that
  model's shape; a model from an OpenSCENARIO file has the Euro NCAP target's shape when it
  is the Euro NCAP catalogue's entry (`OPENSCENARIO_TARGETS`: the GVT, the bicycle EBTa, the
  motorcycle EMT, each with its rider);
- a pedestrian walks (`walker_stature`): its body is the articulated walker
  (`world.actors.shapes.walker`) of its box's height, its shoulders no wider than the box,
  when the walker's swept footprint fits the box (the Euro NCAP EPTa's and EPTc's do);
  else the tallest walker whose swept footprint fits. (`pedestrian_shape`: the Euro NCAP
  target frozen at gait phase 0, for drawings and assets;)
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
from world.actors.shapes.walker import swept_half_extents

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


def walker_stature(length: float, width: float, height: float) -> float | None:
    """[m] the stature of the walker that is the body of a pedestrian whose box is `length` x
    `width` x `height` [m], its shoulders no wider than `width`: `height` when the walker's
    swept footprint (`swept_half_extents`) fits the box's (within `MATCH`), else that height
    scaled down until it does (every length of the walker is proportional to its stature;
    None: no walker fits)."""
    stature = height
    for _ in range(3):  # the width bound makes the sweep not quite proportional
        half_x, half_y = swept_half_extents(stature, width)
        if half_x <= 0.5 * length + MATCH and half_y <= 0.5 * width + MATCH:
            return stature
        stature *= min(1.0, 0.5 * length / half_x, 0.5 * width / half_y)
    return None


def _fits(body: Body, length: float, width: float) -> bool:
    return abs(body.length - length) <= MATCH and abs(body.width - width) <= MATCH

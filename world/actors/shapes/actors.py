"""Which shape an actor's body has: its vehicle model's, or a Euro NCAP target's.

- a vehicle whose model is one of the catalogue's (`world.actors.catalogue`) has that
  model's shape; a model from an OpenSCENARIO file has the Euro NCAP target's shape when it
  is the Euro NCAP catalogue's entry (`OPENSCENARIO_TARGETS`: the GVT, the bicycle EBTa, the
  motorcycle EMT, each with its rider);
- a pedestrian walks (`walker_amplitude`): its body is the articulated walker
  (`world.actors.shapes.walker`) of its box's height, its shoulders no wider than the box,
  walking with the full gait when its swept footprint fits the box (the Euro NCAP EPTa's and
  EPTc's do), else with the largest gait amplitude whose swept footprint fits (a shorter
  stride, never a shorter person); if even the standing walker is longer than the box, it
  stands (amplitude 0) and its feet exceed the box by what the standing walker is longer
  (`walker_excess`). (`pedestrian_shape`: the Euro NCAP target frozen at gait phase 0, for
  drawings and assets;)
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
from world.actors.shapes.humans import swept_range

MATCH = 0.01  # [m] largest difference of a shape's length or width from the actor's box
AMPLITUDE_STEPS = 10  # [-] bisection steps of a walker's gait amplitude (to 1/1024)

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


def _half_sweep(length: float, width: float, height: float, amplitude: float) -> float:
    """[m] half the x range a walker of stature `height` [m], shoulders no wider than `width`
    [m], sweeps with the gait `amplitude` [-] (`length` [m] unused: the cache's key)."""
    lo, hi, _ = swept_range(height, width, amplitude)
    return 0.5 * (hi - lo)


@lru_cache(maxsize=64)
def walker_amplitude(length: float, width: float, height: float) -> float:
    """[-] the gait amplitude (0 to 1, `humans.gait`) of the walker of stature `height` [m],
    its shoulders no wider than `width` [m], that is the body of a pedestrian whose box is
    `length` x `width` x `height` [m]: 1 when its swept footprint is no more than `MATCH`
    longer than the box at each end, else the largest amplitude whose is (bisected to
    1 / 2 ** `AMPLITUDE_STEPS`), 0 when not even the standing walker's is
    (`walker_excess`)."""
    room = 0.5 * length + MATCH

    def fits(amplitude: float) -> bool:
        return _half_sweep(length, width, height, amplitude) <= room

    if fits(1.0):
        return 1.0
    lo, hi = 0.0, 1.0
    if not fits(lo):
        return lo
    for _ in range(AMPLITUDE_STEPS):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if fits(mid) else (lo, mid)
    return lo


def walker_excess(length: float, width: float, height: float) -> float:
    """[m] how far the walker of a pedestrian whose box is `length` x `width` x `height` [m]
    reaches beyond the box's front and back faces at most over its gait (<= 0: inside)."""
    amplitude = walker_amplitude(length, width, height)
    return _half_sweep(length, width, height, amplitude) - 0.5 * length


def _fits(body: Body, length: float, width: float) -> bool:
    return abs(body.length - length) <= MATCH and abs(body.width - width) <= MATCH

"""Every body's shape by name: the vehicle catalogue's models (`world.actors.catalogue`) and
Euro NCAP's targets, the pedestrians at `GAIT_PHASES` phases of their walk."""

from __future__ import annotations

import dataclasses

from world.actors.catalogue import CATALOGUE, VehicleModel
from world.actors.shapes import targets as t
from world.actors.shapes.body import Body
from world.actors.shapes.cars import HATCHBACK, SALOON, SUV, VAN, CarProfile, car_parts
from world.actors.shapes.heavy import bus_parts, rigid_truck_parts, semi_trailer_parts
from world.actors.shapes.humans import pedestrian_parts
from world.actors.shapes.parts import BodyPart
from world.actors.shapes.two_wheelers import bicyclist_parts, motorcycle_parts, motorcyclist_parts
from world.actors.shapes.tyres import TYRES, Tyre

GAIT_PHASES = 8  # [-] pedestrian poses kept as files per gait cycle

_CARS: dict[str, CarProfile] = {"small_car": HATCHBACK, "sedan": SALOON, "suv": SUV, "van": VAN}


def vehicle_parts(m: VehicleModel) -> tuple[BodyPart, ...]:
    """The parts of catalogue model `m`."""
    if m.name in _CARS:
        return car_parts(m.length, m.width, m.height, m.wheelbase, TYRES[m.name], _CARS[m.name])
    if m.name == "bus":
        return bus_parts(m.length, m.width, m.height, m.wheelbase)
    if m.name == "rigid_truck":
        return rigid_truck_parts(m.length, m.width, m.height, m.wheelbase)
    if m.name == "semi_trailer":
        return semi_trailer_parts(m.length, m.width, m.height, m.wheelbase)
    if m.name == "motorbike":
        return motorcycle_parts(m.length, m.width, m.height, m.wheelbase,
                                TYRES["motorbike_front"], TYRES["motorbike_rear"], screen=True)
    raise KeyError(f"no shape for vehicle model {m.name!r}")


def _gvt() -> Body:
    g = t.GVT
    share = (g.length - t.GVT_WHEELBASE - t.GVT_REAR_OVERHANG) / (g.length - t.GVT_WHEELBASE)
    tyre = Tyre(0.5 * t.GVT_WHEEL_DIAMETER, 0.2, "GVT wheel, 0.656 m")
    parts = car_parts(g.length, g.width, g.height, t.GVT_WHEELBASE, tyre,
                      dataclasses.replace(HATCHBACK, front_overhang=share))
    return Body(g.name, parts, g.length, g.width, g.height, g.source)


def _wheel(diameter: float, width: float) -> Tyre:
    return Tyre(0.5 * diameter, width, f"{diameter} m")


def pedestrian(target: t.Target, phase: float) -> Body:
    """A pedestrian target at gait `phase` (0 to 1); its dimensions are the envelope."""
    parts = pedestrian_parts(target.height, phase, target.width)
    return Body(f"{target.name}_phase{round(phase * GAIT_PHASES)}", parts,
                target.length, target.width, target.height, target.source)


def bodies() -> dict[str, Body]:
    """Every shape kept as a file, by name."""
    out = {m.name: Body(m.name, vehicle_parts(m), m.length, m.width, m.height, m.source)
           for m in CATALOGUE.values()}
    out["ncap_gvt"] = _gvt()
    e = t.EBTA
    out[e.name] = Body(e.name, bicyclist_parts(
        e.length, e.width, e.height, t.EBTA_BARS, t.EBTA_WHEELBASE,
        0.5 * t.EBTA_WHEEL_DIAMETER, t.RIDER_STATURE), e.length, e.width, e.height, e.source)
    m = t.EMT
    out[m.name] = Body(m.name, motorcyclist_parts(
        m.length, m.width, m.height, t.EMT_BIKE_HEIGHT, t.EMT_WHEELBASE,
        _wheel(t.EMT_FRONT_WHEEL, 0.12), _wheel(t.EMT_REAR_WHEEL, 0.16), t.RIDER_STATURE),
        m.length, m.width, m.height, m.source)
    for target in (t.EPTA, t.EPTC):
        for k in range(GAIT_PHASES):
            body = pedestrian(target, k / GAIT_PHASES)
            out[body.name] = body
    return out

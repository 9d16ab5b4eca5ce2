"""The stack's view of the car's sizes (`world.frames.VehicleInfo`) is the URDF's."""

from __future__ import annotations

from vehicle_urdf import read_geometry
from world.ego.body import vehicle_info


def test_vehicle_info_is_the_urdf_geometry() -> None:
    g = read_geometry()
    v = vehicle_info(g)
    assert (v.length, v.width, v.wheelbase, v.track) == (g.body_length, g.body_width,
                                                          g.wheelbase, g.track)
    assert (v.front_axle, v.rear_axle) == (g.front_axle, g.rear_axle)
    assert v.front_overhang == g.front_overhang == v.rear_overhang == g.body_length / 2

"""`python -m vehicle_urdf`: rewrite vehicle_urdf/car.urdf from the named dimensions."""

from vehicle_urdf.builder import write_urdf

print(write_urdf())

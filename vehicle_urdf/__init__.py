"""The ego car's URDF and the small builder that writes it from named dimensions."""

from vehicle_urdf.builder import URDF_PATH, CarDimensions, build_urdf
from vehicle_urdf.geometry import WHEELS, CarGeometry, read_geometry

__all__ = ["URDF_PATH", "WHEELS", "CarDimensions", "CarGeometry", "build_urdf", "read_geometry"]
